# SPDX-License-Identifier: MIT
"""Every C model of a weights folder, from the ONNX and calibration files in it.

    python -m lidet_codegen regen [FOLDER]          # default weights

Runs, in this order, the commands that made the committed weights/*.c (and that CI's drift check,
tests/python/test_pointnet.py, replays):

    python -m lidet_codegen emit --int8 --calib FOLDER/<name>.calib.json FOLDER/<name>.onnx --out FOLDER
        (every <name>.calib.json: the int8 models <name>_s8.{c,h})
    python -m lidet_codegen emit FOLDER/<a>.onnx FOLDER/<b>.onnx ... --out FOLDER --index
        (every <name>.onnx: the float models <name>.{c,h}, then lidet_weights.{c,h}, the table of both)

No data and no training: deterministic, and the folder's path as given is what the files' `cmd:` lines say (run it
from the repository root with `weights` for the committed files). The calibration files come first: `make weights`
(lidet_tools.train.weights) writes them with `python -m lidet_tools.train.calibrate` (and `calibrate --refit`) for
the models it trained, then calls emit_all (each int8 layer's error against float on the calibration proposals:
`python -m lidet_tools.train.calibrate --report`). A calibration file of another ONNX file than the one beside it is
refused (`emit --int8`: "recalibrate").
"""
from __future__ import annotations

import pathlib
import sys


def commands(folder="weights") -> list[list[str]]:
    """The `python -m lidet_codegen emit` argument lists that regenerate every C model of `folder`, in order."""
    d = pathlib.Path(folder)
    od = d.as_posix()
    out = []
    for cal in sorted(d.glob("*.calib.json")):
        stem = cal.name[:-len(".calib.json")]
        out.append(["--int8", "--calib", f"{od}/{cal.name}", f"{od}/{stem}.onnx", "--out", od])
    onnx = sorted(p.name for p in d.glob("*.onnx"))
    if onnx:
        out.append([f"{od}/{n}" for n in onnx] + ["--out", od, "--index"])
    return out


def emit_all(folder="weights") -> list[list[str]]:
    """Run commands(folder). Raises RuntimeError on the first that fails; returns the commands."""
    from . import emit as E
    cmds = commands(folder)
    if not cmds:
        raise RuntimeError(f"{folder}: no *.onnx models")
    for argv in cmds:
        rc = E.main(argv)
        if rc:
            raise RuntimeError(f"python -m lidet_codegen emit {' '.join(argv)}: failed ({rc})")
    return cmds


def main(argv=None) -> int:
    import argparse
    ap = argparse.ArgumentParser(prog="python -m lidet_codegen regen", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("folder", nargs="?", default="weights", help="weights folder (default weights)")
    a = ap.parse_args(argv)
    try:
        emit_all(a.folder)
    except RuntimeError as e:
        print(f"lidet_codegen regen: error: {e}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
