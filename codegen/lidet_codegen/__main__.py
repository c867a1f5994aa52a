# SPDX-License-Identifier: MIT
"""python -m lidet_codegen {emit,regen,macs,qtables,pnqtables} ... (see each subcommand's --help)."""
import sys

#: commands that need lidet_tools (PyTorch and the models; the bindings and the simulator) and moved there:
#: lidet_codegen never imports lidet_tools (tests/python/test_package_flow.py)
MOVED = {"export": "lidet_tools.train.export", "calibrate": "lidet_tools.train.calibrate"}


def main(argv=None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    cmds = {"emit": "lidet_codegen.emit", "macs": "lidet_codegen.macs", "qtables": "lidet_codegen.qtables",
            "pnqtables": "lidet_codegen.pnq_tables", "regen": "lidet_codegen.regen"}
    if argv and argv[0] in MOVED:
        print(f"lidet_codegen: '{argv[0]}' is now python -m {MOVED[argv[0]]} (the same options)", file=sys.stderr)
        return 2
    if not argv or argv[0] not in cmds:
        print("usage: python -m lidet_codegen {emit|regen|macs|qtables|pnqtables} ...\n"
              "  emit    ONNX -> weights/<name>.{c,h} (const arrays + model descriptor);\n"
              "          --int8 --calib FILE: the int8 model weights/<name>_s8.{c,h}\n"
              "  regen   every C model of a weights folder (float, int8, lidet_weights.{c,h}) from its\n"
              "          ONNX and calibration files: the commands of the committed weights/\n"
              "  macs    multiply-adds and parameters of ONNX models\n"
              "  qtables the integer math tables of the fixed-point build (lib/src/qmath/lidet_qmath_tables.c)\n"
              "  pnqtables the int8 PointNets' energy tables (lib/src/pointnet/lidet_pointnet_q_tables.c)\n"
              "PyTorch checkpoint -> ONNX: python -m lidet_tools.train.export; int8 calibration files\n"
              "(<name>.calib.json): python -m lidet_tools.train.calibrate",
              file=sys.stderr)
        return 2
    import importlib
    return importlib.import_module(cmds[argv[0]]).main(argv[1:])


if __name__ == "__main__":
    sys.exit(main())
