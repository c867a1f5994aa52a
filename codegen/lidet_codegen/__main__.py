# SPDX-License-Identifier: MIT
"""python -m lidet_codegen {export,emit,regen,macs,qtables,calibrate,pnqtables} ... (see each subcommand's --help)."""
import sys


def main(argv=None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    cmds = {"emit": "lidet_codegen.emit", "export": "lidet_codegen.export_cli", "macs": "lidet_codegen.macs",
            "qtables": "lidet_codegen.qtables", "calibrate": "lidet_codegen.quant",
            "pnqtables": "lidet_codegen.pnq_tables", "regen": "lidet_codegen.regen"}
    if not argv or argv[0] not in cmds:
        print("usage: python -m lidet_codegen {export|emit|regen|macs|qtables|calibrate|pnqtables} ...\n"
              "  export  PyTorch checkpoint (or --untrained KIND) -> ONNX with lidet's metadata\n"
              "  emit    ONNX -> weights/<name>.{c,h} (const arrays + model descriptor);\n"
              "          --int8 --calib FILE: the int8 model weights/<name>_s8.{c,h}\n"
              "  regen   every C model of a weights folder (float, int8, lidet_weights.{c,h}) from its\n"
              "          ONNX and calibration files: the commands of the committed weights/\n"
              "  calibrate activation ranges of a model for its int8 version (<name>.calib.json)\n"
              "  macs    multiply-adds and parameters of ONNX models\n"
              "  qtables the integer math tables of the fixed-point build (lib/src/qmath/lidet_qmath_tables.c)\n"
              "  pnqtables the int8 PointNets' energy tables (lib/src/pointnet/lidet_pointnet_q_tables.c)",
              file=sys.stderr)
        return 2
    import importlib
    return importlib.import_module(cmds[argv[0]]).main(argv[1:])


if __name__ == "__main__":
    sys.exit(main())
