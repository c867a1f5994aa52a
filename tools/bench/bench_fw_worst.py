# SPDX-License-Identifier: MIT
"""The integer detector's worst case on a microcontroller (issues 19 and 37): the adversarial VLP-16 scans of
bench_adversarial.py, each built into the Cortex-M4 integer image (`mps2-an386-q`: ports/firmware, fw_detect.c, the
scan as the sensor's returns, `lidet_detector_q_run_returns`, models vlp16s, capacities of
ports/firmware/config/vlp16) and run under QEMU for the exact instructions per stage, against the typical scan
(the simulated sample the firmware ctests use). Two runs per scan, as every firmware image: `default` (the gates on)
and `open` (gates and size checks off, so every classified proposal is boxed: the box net's worst case for that
scan). The latency of a streamed scan (`lidet_detector_q_stream_end`, docs/PORTING.md) is the run's stages after
the projection; their worst case over the scans, and over both runs for the networks, is what this page bounds.

Needs the Arm cross compiler and qemu-system-arm (tools/scripts/install_deps.sh); the images are built in
BUILD/firmware-worst (one build folder, the scan swapped between builds: only the scan's object is rebuilt)."""
from __future__ import annotations

import pathlib
import shutil
import subprocess
import sys
import tempfile

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "tools"))
sys.path.insert(0, str(ROOT / "tools" / "firmware"))
sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))

import bench_adversarial as BA  # noqa: E402
import run_fw as RF  # noqa: E402
from lidet_tools.sensors import get_sensor  # noqa: E402

BOARD, IMAGE = "mps2-an386", "mps2-an386-q"
STAGES = ["project", "ground", "cluster", "classify", "box", "post"]
LATENCY = ["ground", "cluster", "classify", "box", "post"]  # what stream_end runs (the projection streams)
#: the integer detector's network caps on this configuration (lidet_detector_q_cfg_default, 16 beams, 64 clusters)
MAX_PROPOSALS, MAX_BOXES = 64, 24


def rings_of(pts: np.ndarray, sensor: str = "vlp16") -> np.ndarray:
    """The ring of each point: the beam (ring order) whose elevation is nearest the point's."""
    s = get_sensor(sensor)
    el = np.asarray(s.beam_elev_rad, np.float64)
    p = pts.astype(np.float64)
    e = np.arctan2(p[:, 2], np.hypot(p[:, 0], p[:, 1]))
    e = np.where(np.isfinite(e), e, 0.0)
    return np.abs(e[:, None] - el[None, :]).argmin(1).astype(np.uint16)


def _configure(bdir: pathlib.Path, scan: pathlib.Path, ring: pathlib.Path, name: str) -> None:
    py = ROOT / ".venv" / "bin" / "python"
    subprocess.run(["cmake", "-S", str(ROOT / "ports" / "firmware"), "-B", str(bdir),
                    f"-DCMAKE_TOOLCHAIN_FILE={ROOT / 'cmake' / 'toolchains' / 'arm-none-eabi.cmake'}",
                    f"-DLIDET_FW_BOARD={BOARD}", "-DLIDET_FW_SENSOR=vlp16", "-DLIDET_FW_FIXED=ON",
                    "-DLIDET_FW_MODELS=vlp16s", "-DLIDET_FW_APP=detect", f"-DLIDET_FW_SCAN={scan}",
                    f"-DLIDET_FW_RING={ring}", f"-DLIDET_FW_SCAN_NAME={name}",
                    f"-DPython3_EXECUTABLE={py if py.exists() else sys.executable}"],
                   check=True, capture_output=True)


def _measure(bdir: pathlib.Path, scan: pathlib.Path, ring: pathlib.Path, name: str) -> dict:
    """the image built with this scan, run: {run: {stage: insn}}, stats {run: {...}}"""
    _configure(bdir, scan, ring, name)
    b = subprocess.run(["cmake", "--build", str(bdir), "-j", "2"], capture_output=True, text=True)
    if b.returncode != 0:
        return {"error": "build failed: " + (b.stdout + b.stderr).strip().splitlines()[-1]}
    cmd = RF.qemu_cmd(BOARD, shutil.which("qemu-system-arm"), str(bdir / "lidet_fw.elf"))
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, timeout=900)
    fw = RF.parse(p.stdout)
    if p.returncode != 0 or not fw["pass"] or "default" not in fw["insn"]:
        return {"error": f"QEMU exit {p.returncode}: " + (p.stdout.strip().splitlines() or ["?"])[-1]}
    return {"insn": fw["insn"], "stats": fw["stats"]}


def _m(v: int) -> str:
    return f"{v / 1e6:.2f}"


def run(args) -> str:
    head = "## The integer detector's worst case on the Cortex-M4 (issues 19 and 37)"
    if shutil.which("arm-none-eabi-gcc") is None or shutil.which("qemu-system-arm") is None:
        raise RuntimeError("arm-none-eabi-gcc or qemu-system-arm not found (tools/scripts/install_deps.sh)")
    bdir = pathlib.Path(args.build).resolve() / "firmware-worst"
    BA.SENSOR = "vlp16"
    typ = ROOT / "tests/data/sim_vlp16/velodyne/000000.bin"
    typ_ring = ROOT / "tests/data/sim_vlp16/ring/000000.bin"
    typical = np.fromfile(typ, np.float32).reshape(-1, 4)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        tmp = pathlib.Path(tmp)
        r = _measure(bdir, typ, typ_ring, "typical")
        r["n"] = len(typical)
        rows.append(("typical: the simulated VLP-16 sample (the firmware ctests' scan)", "reference", r))
        for i, (name, pts, ring, what) in enumerate(BA.scans(typical)):
            pts = pts.astype(np.float32)
            # the integer detector takes int32 millimetres: points beyond them (the 1e30 scan's) have no returns
            ok = np.isfinite(pts[:, :3]).all(1) & (np.abs(pts[:, :3].astype(np.float64)) < 1e6).all(1)
            pts = pts[ok]
            ring = rings_of(pts) if ring is None else ring[ok]
            sp, rp = tmp / f"{i}.bin", tmp / f"{i}.ring"
            pts.tofile(sp)
            ring.astype(np.uint16).tofile(rp)
            r = _measure(bdir, sp, rp, f"adversarial_{i}")
            r["n"] = len(pts)
            rows.append((name, what, r))
    ref = rows[0][2]
    if "error" in ref:
        raise RuntimeError(f"the typical scan's image: {ref['error']}")
    lines = [head, "",
             "`python tools/bench/bench_fw_worst.py` (also `make bench`): the adversarial VLP-16 scans of the "
             "adversarial page (bench_adversarial.py; rings from each point's nearest beam where a scan has none; "
             "points beyond 1,000 km left out: the integer detector's input is int32 millimetres), each built into "
             f"the Cortex-M4 integer image (`{IMAGE}`: fw_detect.c, models vlp16s, the capacities of "
             "ports/firmware/config/vlp16: 30,000 returns, 64 clusters) and run under QEMU: instructions per stage, "
             "exact, run `default` (gates on) and, for the networks, run `open` (gates and size checks off: every "
             "classified proposal boxed). Ratio: against the typical scan, the ctests' sample. `rest` = the stages "
             "after the projection, what `lidet_detector_q_stream_end` runs after a streamed scan's last payload "
             "(docs/PORTING.md, \"Streaming the returns\").", "",
             "| scan | status | points | clusters | classified | boxed (open) | " +
             " | ".join(f"{s} M (x)" for s in STAGES) + " | rest M (x) | rest, open M | what it hurts |",
             "|---" * (6 + len(STAGES) + 3) + "|"]
    worst = {s: 0 for s in STAGES}
    worst_rest = worst_rest_open = 0
    per_cls = per_box = 0.0  # the largest classify instructions per classified proposal, box per boxed one
    for name, what, r in rows:
        if "error" in r:
            lines.append(f"| {name} | error: {r['error']} |" + " |" * (4 + len(STAGES) + 2) + f" {what} |")
            continue
        d, o = r["insn"]["default"], r["insn"].get("open", r["insn"]["default"])
        st, so = r["stats"]["default"], r["stats"].get("open", {})
        rest, rest_o = sum(d[s] for s in LATENCY), sum(o[s] for s in LATENCY)
        ref_d = ref["insn"]["default"]
        ref_rest = sum(ref_d[s] for s in LATENCY)
        cells = []
        for s in STAGES:
            cells.append(f"{_m(d[s])} ({d[s] / ref_d[s]:.1f}x)" if ref_d[s] > 0 else _m(d[s]))
            worst[s] = max(worst[s], d[s], o[s] if s in ("classify", "box", "post") else 0)
        worst_rest, worst_rest_open = max(worst_rest, rest), max(worst_rest_open, rest_o)
        for ins, sts in ((d, st), (o, so)):
            if sts.get("classified"):
                per_cls = max(per_cls, ins["classify"] / sts["classified"])
            if sts.get("boxed"):
                per_box = max(per_box, ins["box"] / sts["boxed"])
        lines.append(f"| {name} | {st.get('status', '?')} | {r['n']} | {st.get('clusters', '?')} | "
                     f"{st.get('classified', '?')} | {st.get('boxed', '?')} ({so.get('boxed', '?')}) | "
                     + " | ".join(cells) + f" | {_m(rest)} ({rest / ref_rest:.1f}x) | {_m(rest_o)} | {what} |")
    nets = MAX_PROPOSALS * per_cls + MAX_BOXES * per_box
    bound = worst["ground"] + worst["cluster"] + nets + worst["post"]
    lines += ["", "Status 1 = LIDET_TRUNCATED (a capacity reached: the 64 clusters of this configuration, the 30,000 "
              "returns, or the box net's budget). Worst case per stage over the scans (networks and NMS over both "
              "runs): " + ", ".join(f"{s} {_m(worst[s])} M" for s in STAGES) + ".", "",
              f"**The latency after a streamed scan's last payload** (`stream_end`: the stages after the projection) "
              f"measured at most {_m(worst_rest)} M instructions over these scans (gates on; {_m(worst_rest_open)} M "
              f"with them off), against {_m(ref_rest)} M on the typical scan. A bound from the parts: the ground "
              f"stage and the clustering at their worst here ({_m(worst['ground'])} M and {_m(worst['cluster'])} M; "
              "both bounded per pixel by issue 19's budgets), the networks at the configuration's caps "
              f"(`max_proposals` {MAX_PROPOSALS} classified at most {per_cls / 1e6:.3f} M each, `max_boxes` "
              f"{MAX_BOXES} boxed at most {per_box / 1e6:.3f} M each, the largest per-proposal costs measured: "
              f"{_m(nets)} M) and NMS ({_m(worst['post'])} M): **{_m(bound)} M instructions**, "
              f"{bound / 200e6 * 1e3:.0f} ms at 200 MHz and one instruction a cycle (the M4's 1.35-1.59 estimated "
              "cycles per instruction on top: docs/benchmarks/firmware.md, \"Cycles, estimated\").", ""]
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    from run_bench import standalone
    standalone(run, __doc__)
