#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Prove that lidet's integer-only build contains no floating point (issue 16, docs/FIXED_POINT.md).

Compiles the integer-only library's sources (the list CMake gives, or --sources) with a cross compiler for one
target, then checks the objects:
  1. no undefined reference to a soft-float helper (__aeabi_f*, __aeabi_d*, __aeabi_[ui]2[fd], __addsf3,
     __muldf3, __fixsfsi, __floatsisf, __extendsfdf2, ... and libm's sinf/sqrtf/...), which a core without an
     FPU (Cortex-M0+, RV32IMAC) would need for a float operation;
  2. no floating-point instruction in the disassembly, when the target has an FPU (Cortex-M4F: VFP instructions
     on s/d registers; RV32IMAFC: f-extension instructions), where a float operation compiles inline instead.
Exit 0: clean; 1: floating point found (each finding printed with its object and function); 2: usage/tool error.
A ctest plants a float into an extra source and expects exit 1 (tests/fixed/plant_float.c), so the check is
known to bite.
"""
from __future__ import annotations

import argparse
import pathlib
import re
import subprocess
import sys
import tempfile

TARGETS = {
    # name: (compiler, flags, has an FPU whose instructions to scan for)
    "cortex-m0plus": ("arm-none-eabi-gcc", ["-mcpu=cortex-m0plus", "-mthumb", "-mfloat-abi=soft"], False),
    "cortex-m4f": ("arm-none-eabi-gcc", ["-mcpu=cortex-m4", "-mthumb", "-mfloat-abi=hard", "-mfpu=fpv4-sp-d16"],
                   True),
    "rv32imac": ("riscv64-unknown-elf-gcc", ["-march=rv32imac", "-mabi=ilp32", "--specs=picolibc.specs"], False),
    "rv32imafc": ("riscv64-unknown-elf-gcc", ["-march=rv32imafc", "-mabi=ilp32f", "--specs=picolibc.specs"], True),
}

# soft-float / libm entry points a float operation turns into on a core without FPU
SOFT_FLOAT = re.compile(
    r"^(__aeabi_(f|d)\w+|__aeabi_[ui]l?2[fd]|__aeabi_[fd]2\w+"
    r"|__(add|sub|mul|div|neg)[sdt]f3|__(fix|fixuns)[sdt]f[sdt]i|__float(un)?[sdt]i[sdt]f"
    r"|__(extend|trunc)[sdt]f[sdt]f2|__(eq|ne|lt|le|gt|ge|un|cmp)[sdt]f2|__powi[sdt]f2"
    r"|(sin|cos|tan|atan2?|asin|acos|exp|log|log2|log10|pow|sqrt|fabs|floor|ceil|round|lround|lrint|fmod|hypot)f?)$")

# FPU instructions: ARM VFP (v<op>.f32/.f64 and vmov/vldr/vstr touching s/d registers), RISC-V F/D extension
ARM_FP = re.compile(r"\b(v(add|sub|mul|div|mla|mls|nmul|fma|fms|neg|abs|sqrt|cmp|cmpe|cvt|cvtr|sel|maxnm|minnm|rint\w*)"
                    r"\.(f32|f64|s32\.f32|f32\.s32|u32\.f32|f32\.u32)|vmov(\.f32|\.f64)?\s+[sd]\d|vmov\s+\w+,\s*[sd]\d"
                    r"|vldr\s+[sd]\d|vstr\s+[sd]\d|vpush|vpop|vldm|vstm|vmrs|vmsr)\b")
RISCV_FP = re.compile(r"\b(f(add|sub|mul|div|sqrt|min|max|madd|msub|nmadd|nmsub|sgnj\w*|eq|lt|le|class)\.[sdq]"
                      r"|fcvt\.\w+|fmv\.\w+|flw|fsw|fld|fsd|c\.flw|c\.fsw|c\.fld|c\.fsd|c\.flwsp|c\.fswsp|frcsr|fscsr"
                      r"|frrm|fsrm|frflags|fsflags)\b")


def _run(cmd: list[str]) -> str:
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        sys.stderr.write(f"check_nofloat: command failed: {' '.join(cmd)}\n{r.stdout}{r.stderr}")
        sys.exit(2)
    return r.stdout


def check(target: str, sources: list[pathlib.Path], includes: list[str], defines: list[str]) -> list[str]:
    cc, flags, has_fpu = TARGETS[target]
    triple = cc[:-len("gcc")]
    findings = []
    with tempfile.TemporaryDirectory() as tmp:
        for i, src in enumerate(sources):
            obj = pathlib.Path(tmp) / f"{i}_{src.stem}.o"
            _run([cc, *flags, "-std=c99", "-O2", "-ffunction-sections", "-Wall", "-Wextra", "-Wpedantic", "-Werror",
                  "-Wdouble-promotion", *[f"-I{d}" for d in includes], *[f"-D{d}" for d in defines],
                  "-c", str(src), "-o", str(obj)])
            for line in _run([triple + "nm", "-u", str(obj)]).splitlines():
                sym = line.split()[-1] if line.split() else ""
                if SOFT_FLOAT.match(sym):
                    findings.append(f"{src}: references soft-float/libm helper {sym}")
            if has_fpu:
                func = "?"
                pat = ARM_FP if triple.startswith("arm") else RISCV_FP
                for line in _run([triple + "objdump", "-d", "--no-show-raw-insn", str(obj)]).splitlines():
                    m = re.match(r"^[0-9a-f]+ <(.+)>:$", line)
                    if m:
                        func = m.group(1)
                        continue
                    parts = line.split("\t", 1)
                    if len(parts) == 2 and pat.search(parts[1]):
                        findings.append(f"{src}: {func}: float instruction: {parts[1].strip()}")
    return findings


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--target", choices=sorted(TARGETS), required=True)
    ap.add_argument("--sources", required=True, help="';'-separated C sources (CMake list)")
    ap.add_argument("-I", dest="includes", action="append", default=[])
    ap.add_argument("-D", dest="defines", action="append", default=[])
    ap.add_argument("--expect-float", action="store_true",
                    help="invert: exit 0 only when floating point IS found (the planted-float self-test)")
    a = ap.parse_args(argv)
    sources = [pathlib.Path(s) for s in a.sources.split(";") if s]
    if not sources:
        print("check_nofloat: no sources", file=sys.stderr)
        return 2
    findings = check(a.target, sources, a.includes, a.defines)
    for f in findings:
        print(f)
    if a.expect_float:
        print(f"check_nofloat[{a.target}]: {len(findings)} finding(s) in the planted build "
              + ("(the check bites)" if findings else "(NONE: the check is blind)"))
        return 0 if findings else 1
    print(f"check_nofloat[{a.target}]: {len(sources)} sources, "
          + ("no floating point" if not findings else f"{len(findings)} finding(s)"))
    return 0 if not findings else 1


if __name__ == "__main__":
    sys.exit(main())
