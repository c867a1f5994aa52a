# lidet: the two commands a newcomer runs are `make demo` and `make test`; the rest are their parts.
# Everything real lives in CMake (C/C++) and pytest (Python); this file only chains them.

VENV     ?= .venv
PY       := $(VENV)/bin/python
BUILD    ?= build
ASAN     ?= build-asan
JOBS     ?= $(shell nproc 2>/dev/null || echo 2)
CMAKE_FLAGS ?=
SAMPLE   ?= tests/data/sim_hdl64/velodyne/000000.bin
REAL     ?= ../shared/data/real

.PHONY: all deps build test test-c test-py test-asan demo bench weights clean

all: build

deps:
	@bash tools/scripts/install_deps.sh

$(BUILD)/CMakeCache.txt:
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release -DLIDET_BUILD_TESTS=ON $(CMAKE_FLAGS)

build: $(BUILD)/CMakeCache.txt
	cmake --build $(BUILD) -j $(JOBS)

# Every test: C (Unity + Eigen + consumer projects), Python (pytest), then the sanitizer build.
test: deps
	$(MAKE) --no-print-directory build
	$(MAKE) --no-print-directory test-c test-py test-asan

test-c:
	ctest --test-dir $(BUILD) --output-on-failure -j $(JOBS)

test-py:
	LIDET_BUILD_DIR=$(abspath $(BUILD)) $(PY) -m pytest -q

test-asan:
	cmake -S . -B $(ASAN) -DCMAKE_BUILD_TYPE=Debug -DLIDET_BUILD_TESTS=ON -DLIDET_SANITIZE=ON \
	      -DLIDET_BUILD_CONSUMER_TESTS=OFF $(CMAKE_FLAGS)
	cmake --build $(ASAN) -j $(JOBS)
	ctest --test-dir $(ASAN) --output-on-failure -j $(JOBS)

# Runs the host CLI on a simulated scan shipped in the repo, stage by stage: figures on stdout,
# pictures in out/ (range image, ground in a bird's-eye view, clusters in a bird's-eye view).
demo: build
	@mkdir -p out
	@echo "== projection"
	$(BUILD)/ports/host/lidet project $(SAMPLE) --sensor hdl64 --png out/demo_project.png
	@echo "== ground segmentation"
	$(BUILD)/ports/host/lidet ground $(SAMPLE) --sensor hdl64 --png out/demo_ground.png --repeat 20
	@echo "== depth clustering and proposals"
	$(BUILD)/ports/host/lidet cluster $(SAMPLE) --sensor hdl64 --png out/demo_cluster.png --repeat 20
	@echo "demo: pictures in out/demo_project.png, out/demo_ground.png, out/demo_cluster.png"

# Benchmarks against peers measured in the same run; results go to docs/BENCHMARKS.md.
bench: deps build
	-$(PY) -m pip install -q -r requirements-bench.txt || echo "bench: peers not installable here; their rows are skipped"
	$(PY) tools/bench/run_bench.py --build $(BUILD) --real $(REAL) --out docs/BENCHMARKS.md

# Trains the PointNets from nothing: simulated proposal datasets (C stages through the bindings),
# classifier + box net per sensor family, ONNX export, test-split figures and weights/MODEL_CARD.md.
# Resumable (state under data/train/); about 45 min on a 2-core machine (docs/TRAINING.md).
WEIGHTS_ARGS ?=
weights: deps build
	LIDET_BUILD_DIR=$(abspath $(BUILD)) $(PY) -m lidet_tools.train.weights --work data/train --weights weights \
	    --jobs $(JOBS) --threads 1 --real $(REAL)/kitti/training --real-semantickitti $(REAL)/semantickitti $(WEIGHTS_ARGS)

clean:
	rm -rf $(BUILD) $(ASAN) out
