# SPDX-License-Identifier: MIT
"""Real labelled frames (issue 36): the float and the integer detector on the validation frames of
tools/lidet_tools/real/split.txt (`python -m lidet_tools.eval_real`, `make eval-real`), in the same run on the
same frames; the section says how far the integer build is from the float one. Skipped without ../shared."""
from __future__ import annotations

import json
import os
import pathlib
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parents[2]
OUT = ROOT / "data" / "bench" / "eval_real"


def _run(real, out, *extra):
    subprocess.run([sys.executable, "-m", "lidet_tools.eval_real", "--root", str(real), "--out", str(out),
                    "--no-pictures", *extra], check=True, capture_output=True, text=True)
    rep = json.loads((out / "report.json").read_text())
    return rep, (out / "report.md").read_text()


def _draws(real, k: int) -> list:
    """The float and integer detectors over k draws of the proposals' points (`eval_real --seeds k`): per figure
    the mean and the range over the draws, all sources within 20 and 40 m."""
    js = {}
    for tag, extra in (("float", ()), ("integer", ("--fixed",))):
        out = OUT / f"seeds_{tag}"
        subprocess.run([sys.executable, "-m", "lidet_tools.eval_real", "--root", str(real), "--out", str(out),
                        "--no-pictures", "--seeds", str(k), *extra], check=True, capture_output=True, text=True)
        js[tag] = json.loads((out / "seeds.json").read_text())
    lines = [f"### Over {k} draws of the proposals' points", "",
             "Each proposal is 64 points drawn from its cluster with a seed (the figures above: the default seed). "
             f"`python -m lidet_tools.eval_real --seeds {k} [--fixed]`: the same frames with the default seed and "
             f"seeds 1 .. {k - 1}; mean over the draws and, in brackets, their range (docs/EVALUATION.md, section 4). "
             "The draw alone moves a figure by that much. Both detectors pick each run's member by its pixel "
             "(lidet_cluster.h), so they draw the same points wherever their clusters share the pixels. The KITTI "
             "frames' rows: KITTI's protocol, AP R40 moderate (the table above).", "",
             "| figure | float | integer | integer - float (means) |", "|---|---|---|---:|"]
    fl, fx = js["float"], js["integer"]
    objs = fl["meta"].get("objects", {})
    for key in fl["stats"]:
        a, b = fl["stats"][key], fx["stats"].get(key)
        if a is None or b is None or key.startswith("Cyclist") or " BEV " in key:
            continue
        d = 2 if key.startswith("FP") else 1  # decimals of the mean
        e = 0 if " found " in key else d       # of the range (whole objects)

        def cell(v):
            return f"{v['mean']:.{d}f} [{v['min']:.{e}f} - {v['max']:.{e}f}]"
        name = key + (f" (of {objs[key]})" if key in objs else "")
        lines.append(f"| {name} | {cell(a)} | {cell(b)} | {b['mean'] - a['mean']:+.{d}f} |")
    return lines + [""]


def run(args) -> str:
    os.environ.setdefault("LIDET_BUILD_DIR", str(args.build))
    head = ["## Real labelled frames (issue 36)", ""]
    if not (pathlib.Path(args.real) / "kitti").is_dir():
        return "\n".join(head + [f"Skipped: {args.real} is not there (the real frames live in ../shared).", ""])
    fl, fl_md = _run(args.real, OUT / "float")
    fx, _ = _run(args.real, OUT / "fixed", "--fixed")
    fm, _ = _run(args.real, OUT / "float_mm", "--round-mm")
    lines = head + ["`make eval-real` (`python -m lidet_tools.eval_real`): the validation frames of "
                    "tools/lidet_tools/real/split.txt, 360 degrees, each source with its sensor preset and mount "
                    "height; pictures of every frame in out/eval_real/pictures/.", "", fl_md.strip(), "",
                    "The integer detector on the same frames (`--fixed`), against the float one of this run: "
                    "AP R40 BEV loose / 3D KITTI within 40 m, all sources together. The integer detector takes the "
                    "scan in whole millimetres; the float one fed the same millimetres (`--round-mm`) shows how far "
                    "that rounding alone moves the figures (a point near a column edge changes pixel, and the boxes "
                    "of the few objects near an overlap threshold move across it):", "",
                    "| class | float BEV loose | float, mm input | integer BEV loose | float 3D | float, mm input | "
                    "integer 3D | float found | float, mm input | integer found |",
                    "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    a, b, m = (r["summary"].get("all", next(iter(r["summary"].values()))) for r in (fl, fx, fm))

    def g(v):
        return "-" if v is None else f"{v:.1f}"
    for c in ("Car", "Pedestrian", "Cyclist"):
        ca, cb, cm = a["classes"][c]["40"], b["classes"][c]["40"], m["classes"][c]["40"]
        lines.append(f"| {c} | {g(a['ap']['loose'][c]['bev']['40 m'])} | {g(m['ap']['loose'][c]['bev']['40 m'])} | "
                     f"{g(b['ap']['loose'][c]['bev']['40 m'])} | {g(a['ap']['kitti'][c]['3d']['40 m'])} | "
                     f"{g(m['ap']['kitti'][c]['3d']['40 m'])} | {g(b['ap']['kitti'][c]['3d']['40 m'])} | "
                     f"{ca['found']} / {ca['objects']} | {cm['found']} / {cm['objects']} | "
                     f"{cb['found']} / {cb['objects']} |")
    lines.append("")
    wl = b.get("where_lost") or {}
    if any(sum(v.values()) for v in wl.values()):
        from lidet_tools.where_lost import STAGES
        lines += ["Where the integer detector lost the objects within 40 m (`--fixed`: `lidet_tools.where_lost` over its "
                  "own per-point labels, all sources together; the float detector's rows are the table's above):", "",
                  "| class | " + " | ".join(STAGES) + " |", "|---|" + "---:|" * len(STAGES)]
        for c in ("Car", "Pedestrian", "Cyclist"):
            row = wl.get(c, {})
            if sum(row.values()):
                lines.append(f"| {c} ({sum(row.values())}) | " + " | ".join(str(row.get(x, 0)) for x in STAGES) + " |")
        lines.append("")
    lines += _draws(args.real, 5)
    # the robot's families on real HDL-64 frames thinned to their beams
    lines += ["### The robot's sensor families on thinned real scans", "",
              "No labelled real VLP-16 or VLP-32C scan exists here: the HDL-64 validation frames thinned to the beams "
              "each sensor shares with the HDL-64 (`--as-sensor NAME`, `lidet_tools.real.thin`: 9 of a VLP-16's 16 "
              "beams, -15 to +1 degrees; 26 of a VLP-32C's 32), at the HDL-64's height. Within 40 m, all sources "
              "together (KITTI, KITTI-360, PandaSet, SemanticKITTI, SqueezeSeg):", "",
              "| sensor, detector | car found | car prec. | ped found | ped prec. | cyc found | FP/frame | car AP BEV loose | "
              "ped AP BEV loose |", "|---|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for tag, extra in (("vlp16, float (vlp16 models)", ("--as-sensor", "vlp16")),
                       ("vlp16, integer (vlp16s: the firmware's)", ("--as-sensor", "vlp16", "--fixed", "--model", "vlp16s")),
                       ("vlp32c, float (hdl64 models)", ("--as-sensor", "vlp32c"))):
        rep, _ = _run(args.real, OUT / tag.split(",")[0].replace(" ", "") / ("q" if "--fixed" in extra else "f"), *extra)
        a = rep["summary"].get("all", next(iter(rep["summary"].values())))
        c = {k: a["classes"][k]["40"] for k in ("Car", "Pedestrian", "Cyclist")}

        def pr(v):
            return "-" if v is None else f"{v:.2f}"
        lines.append(f"| {tag} | {c['Car']['found']} / {c['Car']['objects']} | {pr(c['Car']['precision'])} | "
                     f"{c['Pedestrian']['found']} / {c['Pedestrian']['objects']} | {pr(c['Pedestrian']['precision'])} | "
                     f"{c['Cyclist']['found']} / {c['Cyclist']['objects']} | {a['fp_per_frame']['40']:.2f} | "
                     f"{g(a['ap']['loose']['Car']['bev']['40 m'])} | {g(a['ap']['loose']['Pedestrian']['bev']['40 m'])} |")
    lines.append("")
    # the simulator against the real training frames, as the detector sees them
    from lidet_tools.real import compare
    n_sim = 20 if getattr(args, "quick", False) else 60
    lines += ["### Simulated against real road users (the training side)", "",
              f"`python -m lidet_tools.real.compare --sim-scans {n_sim}`: per class and distance band, simulated / real: "
              "objects, median points that win their pixel, median span of those points along the box's length, width "
              "and height (5-95 %), where the object is seen from (the 5th percentile of those points above its box "
              "bottom: how much of it is hidden from below), the share whose cluster was clean (not merged, split or dropped), and of those the "
              "share past gate 1, past both gates, and detected (loose BEV overlap). Real: the training frames of the "
              f"HDL-64-profile sources; simulated: {n_sim} `lidet-sim --sensor hdl64` scans of the hdl64 family's training "
              "seed 1000. Same float detector.", "",
              compare.table(compare.sim_rows(n_sim, 1000), compare.real_rows(args.real, "train")).strip(), ""]
    return "\n".join(lines)


if __name__ == "__main__":
    sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
    from run_bench import standalone
    standalone(run, __doc__)
