# lidet: the two commands a newcomer runs are `make demo` and `make test`; the rest are their parts.
# Everything real lives in CMake (C/C++) and pytest (Python); this file only chains them.

VENV     ?= .venv
PY       := $(VENV)/bin/python
BUILD    ?= build
ASAN     ?= build-asan
FUZZ     ?= build-fuzz
FUZZ_SECONDS ?= 60
JOBS     ?= $(shell nproc 2>/dev/null || echo 2)
CMAKE_FLAGS ?=
SAMPLE   ?= tests/data/sim_hdl64/velodyne/000000.bin
REAL     ?= ../shared/data/real

.PHONY: all deps build test test-c test-py test-asan test-fuzz fuzz fuzz-build demo bench eval-real weights clean firmware firmware-run

all: build

deps:
	@bash tools/scripts/install_deps.sh

$(BUILD)/CMakeCache.txt:
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release -DLIDET_BUILD_TESTS=ON $(CMAKE_FLAGS)

build: $(BUILD)/CMakeCache.txt
	cmake --build $(BUILD) -j $(JOBS)

# Every test: C (Unity + Eigen + consumer projects), Python (pytest), then the sanitizer build.
# (re)configure after deps: a build folder configured earlier (e.g. by `make demo` on a fresh machine, before
# Eigen was installed) picks up what deps installed, so no test is silently left out
test: deps
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release -DLIDET_BUILD_TESTS=ON $(CMAKE_FLAGS)
	$(MAKE) --no-print-directory build
	$(MAKE) --no-print-directory test-c test-py test-asan test-fuzz

test-c:
	ctest --test-dir $(BUILD) --output-on-failure -j $(JOBS)

test-py:
	LIDET_BUILD_DIR=$(abspath $(BUILD)) $(PY) -m pytest -q

test-asan:
	cmake -S . -B $(ASAN) -DCMAKE_BUILD_TYPE=Debug -DLIDET_BUILD_TESTS=ON -DLIDET_SANITIZE=ON \
	      -DLIDET_BUILD_CONSUMER_TESTS=OFF $(CMAKE_FLAGS)
	cmake --build $(ASAN) -j $(JOBS)
	ctest --test-dir $(ASAN) --output-on-failure -j $(JOBS)
	# determinism across builds: the Release CLI and the sanitizer CLI write the same bytes
	LIDET_BUILD_DIR=$(abspath $(BUILD)) LIDET_ASAN_BUILD_DIR=$(abspath $(ASAN)) $(PY) -m pytest -q tests/python/test_determinism.py

# libFuzzer harnesses (tests/fuzz, clang only): the library at small capacities under ASan + UBSan. test-fuzz
# replays each harness's committed corpus and crash regressions and fuzzes it for a few seconds (ctest);
# `make fuzz` runs every harness for FUZZ_SECONDS (default 60). Without clang both say so and skip (the
# gcc and sanitizer builds still replay the corpus and the regressions: the fuzz_replay_* tests).
FUZZ_CC ?= clang
fuzz-build:
	@if command -v $(FUZZ_CC) >/dev/null 2>&1; then \
	  cmake -S . -B $(FUZZ) -DCMAKE_C_COMPILER=$(FUZZ_CC) -DCMAKE_BUILD_TYPE=Debug -DLIDET_BUILD_FUZZ=ON \
	        -DLIDET_BUILD_HOST=OFF -DLIDET_BUILD_TESTS=OFF && cmake --build $(FUZZ) -j $(JOBS); \
	else echo "fuzz: SKIPPED: $(FUZZ_CC) not found (make deps installs clang; the fuzz_replay_* tests of the other builds still run)"; fi

test-fuzz: fuzz-build
	@if [ -f $(FUZZ)/CTestTestfile.cmake ]; then ctest --test-dir $(FUZZ) --output-on-failure -j $(JOBS); fi

fuzz: fuzz-build
	@if [ -d $(FUZZ)/tests/fuzz ]; then FUZZ_SECONDS=$(FUZZ_SECONDS) FUZZ_JOBS=$(JOBS) tools/scripts/fuzz_run.sh $(FUZZ); fi

# The detector on the simulated scans shipped in the repo (hdl64 and vlp16; ground truth drawn in green),
# and on a real KITTI frame when ../shared/data/real is there; then the stages one by one with their pictures.
REAL_FRAME ?= $(REAL)/kitti/training
REAL_CAPTURE ?= $(REAL)/../packets/ouster/OS-2-128-U1_v2.3.0_1024x10
# builds only what it runs (the host CLI): the first picture comes about 10 s after a fresh configure here, where the
# whole build (tests, firmware references) takes minutes; `make test` builds the rest
demo: $(BUILD)/CMakeCache.txt
	cmake --build $(BUILD) --target lidet_cli -j $(JOBS)
	@mkdir -p out
	@echo "== detector: simulated HDL-64 scan (tests/data/sim_hdl64)"
	$(BUILD)/ports/host/lidet detect $(SAMPLE) --sensor hdl64 --gt tests/data/sim_hdl64/boxes/000000.txt \
	    --png out/demo_detect.png --repeat 20
	@echo "== detector: simulated VLP-16 scan (tests/data/sim_vlp16)"
	$(BUILD)/ports/host/lidet detect tests/data/sim_vlp16/velodyne/000000.bin --sensor vlp16 \
	    --gt tests/data/sim_vlp16/boxes/000000.txt --png out/demo_detect_vlp16.png --repeat 20
	@if [ -f $(REAL_FRAME)/velodyne/000000.bin ]; then \
	  echo "== detector: real KITTI frame ($(REAL_FRAME)/velodyne/000000.bin, ground truth from label_2)"; \
	  $(BUILD)/ports/host/lidet detect $(REAL_FRAME)/velodyne/000000.bin --sensor hdl64 \
	    --calib $(REAL_FRAME)/calib/000000.txt --gt-kitti $(REAL_FRAME)/label_2/000000.txt \
	    --png out/demo_detect_real.png --repeat 20; \
	else echo "== (no real KITTI frame at $(REAL_FRAME): skipped)"; fi
	@if [ -f $(REAL_CAPTURE).pcap ]; then \
	  echo "== detector: real Ouster OS2-128 packets ($(REAL_CAPTURE).pcap: decoded by lidet_ouster)"; \
	  $(BUILD)/ports/host/lidet detect --pcap $(REAL_CAPTURE).pcap --lidar ouster --ouster-meta $(REAL_CAPTURE).json \
	    --mount-height 1.98 --png out/demo_capture.png 2>out/demo_capture.log \
	    || { grep -q "without libpcap" out/demo_capture.log && echo "== (lidet built without libpcap: skipped)" \
	         || { cat out/demo_capture.log; exit 1; }; }; \
	else echo "== (no real packet capture at $(REAL_CAPTURE).pcap: skipped)"; fi
	@echo "== the integer detector (no float: int8 models, the scan in millimetres) on the same VLP-16 scan"
	$(BUILD)/ports/host/lidet detect tests/data/sim_vlp16/velodyne/000000.bin --sensor vlp16 --fixed \
	    --gt tests/data/sim_vlp16/boxes/000000.txt --png out/demo_detect_vlp16_fixed.png --repeat 5
	@echo "== the stages alone: projection, ground segmentation, depth clustering"
	$(BUILD)/ports/host/lidet project $(SAMPLE) --sensor hdl64 --png out/demo_project.png
	$(BUILD)/ports/host/lidet ground $(SAMPLE) --sensor hdl64 --png out/demo_ground.png --repeat 20
	$(BUILD)/ports/host/lidet cluster $(SAMPLE) --sensor hdl64 --png out/demo_cluster.png --repeat 20
	@echo "demo: pictures in out/ (demo_detect*.png: detections, car red, cyclist cyan, pedestrian yellow;"
	@echo "      ground truth green; demo_detect_vlp16_fixed.png: the integer detector;"
	@echo "      demo_capture.png: a real Ouster capture's frame, when ../shared is there;"
	@echo "      demo_project/ground/cluster.png: the stages)"

# Firmware images (ports/firmware: Cortex-M3/M4F/M7 on QEMU's MPS2 boards, RISC-V rv32imafc on QEMU virt), built
# by the normal build when the cross compilers are installed (make deps installs them); firmware-run runs each
# image under QEMU and compares it with the host build, printing instruction counts, stack and sizes.
firmware: $(BUILD)/CMakeCache.txt
	cmake --build $(BUILD) --target firmware -j $(JOBS)

firmware-run: firmware
	ctest --test-dir $(BUILD) -R '^firmware_' -V

# Benchmarks against peers measured in the same run; results go to docs/benchmarks/<name>.md, indexed by docs/BENCHMARKS.md.
bench: deps build
	-$(PY) -m pip install -q -r requirements-bench.txt || echo "bench: peers not installable here; their rows are skipped"
	$(PY) tools/bench/run_bench.py --build $(BUILD) --real $(REAL) --out docs/BENCHMARKS.md

# The detector on the real labelled frames of ../shared/data/real (validation side of
# tools/lidet_tools/real/split.txt): recall, precision, AP per source and class, where objects are lost, a BEV
# picture per frame in out/eval_real/pictures/. EVAL_REAL_ARGS: e.g. --fixed, --side train, --sources kitti,
# --seeds 5 (five draws of the proposals' points: out/eval_real/seeds.md).
EVAL_REAL_ARGS ?=
eval-real: deps build
	LIDET_BUILD_DIR=$(abspath $(BUILD)) $(PY) -m lidet_tools.eval_real --root $(REAL) --out out/eval_real $(EVAL_REAL_ARGS)

# Trains the PointNets from nothing: simulated proposal datasets (C stages through the bindings),
# classifier + box net per sensor family, ONNX export, test-split figures and a model card per run: the hdl64 family
# (weights/MODEL_CARD_hdl64.md), the vlp16 family (weights/MODEL_CARD.md); then the
# small VLP-16 pair of the integer firmware (family vlp16s, weights/MODEL_CARD_vlp16s.md), then the 32-beam family
# (beams32: simulated VLP-32C, HDL-32E and Ouster 32-beam scans at four mounts, weights/MODEL_CARD_beams32.md; about
# 12 min more), the 128-beam family (beams128: the Ouster 128-beam presets at four mounts, MODEL_CARD_beams128.md) and the
# Ouster 64-beam family (beams64: the Ouster 64-beam presets at four mounts, MODEL_CARD_beams64.md). Each run ends with the int8 calibration of the models it trained (weights/*.calib.json) and every C model of weights/ regenerated
# from the ONNX files (float *.c, int8 *_s8.c, lidet_weights.{c,h}: python -m lidet_codegen regen weights);
# then the build, so build/ (lidet, the bindings, the tests) runs the new models.
# Resumable (state under data/train/); about 65 min on a 2-core machine (docs/TRAINING.md).
WEIGHTS_ARGS ?=
weights: deps build
	LIDET_BUILD_DIR=$(abspath $(BUILD)) $(PY) -m lidet_tools.train.weights --work data/train --weights weights \
	    --jobs $(JOBS) --threads 1 --families hdl64 --card weights/MODEL_CARD_hdl64.md \
	    --real $(REAL)/kitti/training --real-semantickitti $(REAL)/semantickitti $(WEIGHTS_ARGS)
	LIDET_BUILD_DIR=$(abspath $(BUILD)) $(PY) -m lidet_tools.train.weights --work data/train --weights weights \
	    --jobs $(JOBS) --threads 1 --families vlp16 --real $(REAL)/kitti/training $(WEIGHTS_ARGS)
	LIDET_BUILD_DIR=$(abspath $(BUILD)) $(PY) -m lidet_tools.train.weights --work data/train --weights weights \
	    --jobs $(JOBS) --threads 1 --families vlp16s --card weights/MODEL_CARD_vlp16s.md $(WEIGHTS_ARGS)
	LIDET_BUILD_DIR=$(abspath $(BUILD)) $(PY) -m lidet_tools.train.weights --work data/train --weights weights \
	    --jobs $(JOBS) --threads 1 --families beams32 --card weights/MODEL_CARD_beams32.md $(WEIGHTS_ARGS)
	LIDET_BUILD_DIR=$(abspath $(BUILD)) $(PY) -m lidet_tools.train.weights --work data/train --weights weights \
	    --jobs $(JOBS) --threads 1 --families beams128 --card weights/MODEL_CARD_beams128.md $(WEIGHTS_ARGS)
	LIDET_BUILD_DIR=$(abspath $(BUILD)) $(PY) -m lidet_tools.train.weights --work data/train --weights weights \
	    --jobs $(JOBS) --threads 1 --families beams64 --card weights/MODEL_CARD_beams64.md $(WEIGHTS_ARGS)
	$(MAKE) --no-print-directory build

clean:
	rm -rf $(BUILD) $(ASAN) $(FUZZ) out
