#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Estimated cycles of a Cortex-M0+, M3 or M4 (or M4F) firmware image: QEMU's trace of the instructions it executes,
priced with the cycle counts of the core's Technical Reference Manual (instruction set summary, zero wait states);
and the same trace's profile (instructions per function and per source line) of the RV32 images, which it does
not price.

    python3 tools/firmware/cycles.py --elf build/firmware/mps2-an386-q/lidet_fw.elf --core m4 \\
        [--report build/firmware/mps2-an386-q/report.json] [--json OUT] [--functions N] [--lines N]
    python3 tools/firmware/cycles.py --elf build/firmware/mps2-an385-m0plus-q/lidet_fw.elf --core m0plus ...
    python3 tools/firmware/cycles.py --elf build/firmware/virt-rv32imac-q/lidet_fw.elf --core rv32 \\
        --nm riscv64-unknown-elf-nm --functions 30 --lines 30

QEMU counts instructions exactly but has no timing model. This tool runs the image once more with
`-d in_asm,exec,nochain` (every translated block's instructions once, then one line per executed block), limited
with `-dfilter` to the code of lidet and the application (the port's counter and console routines are left out:
they are not lidet's, and the counter check loops would swamp the trace), streams the log through a pipe and
prices every executed instruction:

- data processing, moves, compares, shifts, extends, bit fields, saturation, IT: 1 cycle;
- multiplies: M4 1 (MUL, MLA, MLS, SMULL, UMULL, SMLAL, UMLAL, the DSP MACs); M3 MUL 1, MLA/MLS 2,
  SMULL/UMULL 3-5, SMLAL/UMLAL 4-7;
- SDIV/UDIV: 2-12 (data dependent);
- the single-precision FPU (the M4F images): VADD, VSUB, VMUL, VNMUL, VABS, VNEG, VCMP, VCVT, VMOV, VMRS, VMSR
  1; VMLA/VMLS/VNMLA/VNMLS and VFMA/VFMS/VFNMA/VFNMS 3; VDIV, VSQRT 14; VLDR/VSTR 2 (3 for a d register);
  VLDM/VSTM/VPUSH/VPOP 1 + N (N 32-bit registers);
- single loads and stores: 2, or 1 when they follow another single load or store (the TRM's pipelining of
  neighbouring loads and stores; the low estimate assumes it always applies there, the high one never);
  LDRD/STRD 3; LDM/STM/PUSH/POP 1 + N registers;
- branches: 1 when not taken, 1 + P taken (P, the pipeline refill, 1-3); a block's branch counts as taken
  when the next executed block does not start right after it; TBB/TBH 2 + P; writes to PC (POP {..., pc},
  BX, LDR pc) 1 (+ N) + P.

The Cortex-M0+ (`--core m0plus`, the ARMv6-M images, which QEMU runs on the AN385's Cortex-M3) by its own TRM:
data processing 1, MULS 1 (the single-cycle multiplier, as on the RP2040), single loads and stores 2 (no
pipelining), LDM/STM/PUSH/POP 1 + N, branches 1 not taken and 2 taken (a two-stage pipeline: P = 1), BL 3,
POP {..., pc} 3 + N; both estimates are then the same.
RV32 (`--core rv32`, the virt-rv32* images under qemu-system-riscv32): no cycle model (the cores differ too much),
the instruction counts and the profiles only.

The result is two estimates (low: P = 1, divides 2 cycles, loads pipelined where the TRM allows; high: P = 3,
divides 12, no pipelining) and the cycles per instruction (CPI) of each. They are estimates on a zero-wait-state
memory system: flash wait states, bus contention and interrupts add to them. `--report` applies both CPIs to
the exact per-scan instruction counts of run_fw.py's report. `--functions N` also prints the N functions that executed
the most instructions (a block counts for the function holding its first address; all of the image's runs, its
initialisations included) and the calls into the C library's helpers by caller (64-bit divisions, soft-float): a
profile, in instructions, of where a firmware scan goes. `--lines N` prints the N source lines that executed the
most (each executed instruction credited to the line `addr2line` gives its address: for inlined code the inlined
function's own line; the image is built with -g): where inside a function the instructions go.
"""
import argparse
import bisect
import json
import os
import re
import subprocess
import sys
import tempfile
import threading

SKIP = 77
QEMU = {"m4": ["qemu-system-arm", "-M", "mps2-an386"], "m3": ["qemu-system-arm", "-M", "mps2-an385"],
        # ARMv6-M code on the AN385's Cortex-M3 (QEMU has no M0+ board), as run_fw.py runs it
        "m0plus": ["qemu-system-arm", "-M", "mps2-an385"],
        "rv32": ["qemu-system-riscv32", "-M", "virt", "-bios", "none"]}
#: the cores priced in cycles (rv32: instructions and profiles only)
PRICED = ("m0plus", "m3", "m4")
#: the pipeline refill of a taken branch, (low, high) cycles
REFILL = {"m0plus": (1, 1), "m3": (1, 3), "m4": (1, 3)}
#: the default nm of each core's toolchain
NM = {"m0plus": "arm-none-eabi-nm", "m3": "arm-none-eabi-nm", "m4": "arm-none-eabi-nm", "rv32": "riscv64-unknown-elf-nm"}
#: the default clock (MHz) for scans per second: a 200 MHz M4, a 100 MHz M3, the RP2040's 133 MHz M0+
MHZ = {"m0plus": 133.0, "m3": 100.0, "m4": 200.0}
# symbols left out of the trace: the port (counter, console, exit, faults) and the startup code (RV32: _start, park)
EXCLUDE = re.compile(r"^(fw_(?!main$)|Reset_Handler|Fault_Handler|put_|measure$|rec_clock$|_start$|park$)")

DP = {"adc", "add", "addw", "adr", "and", "asr", "bic", "bfc", "bfi", "clz", "cmn", "cmp", "eor", "lsl", "lsr",
      "mov", "movw", "movt", "mvn", "neg", "orn", "orr", "rbit", "rev", "rev16", "revsh", "ror", "rrx", "rsb", "sbc",
      "sbfx", "sub", "subw", "sxtb", "sxth", "sxtb16", "sxtab", "sxtah", "sxtab16", "teq", "tst", "ubfx", "uxtb",
      "uxth", "uxtb16", "uxtab", "uxtah", "uxtab16", "ssat", "usat", "ssat16", "usat16", "it", "nop", "sel",
      "qadd", "qsub", "qadd16", "qsub16", "qadd8", "qsub8", "sadd16", "ssub16", "uadd16", "usub16", "sadd8",
      "uadd8", "ssub8", "usub8", "shadd16", "uhadd16", "pkhbt", "pkhtb", "usad8", "usada8", "dmb", "dsb", "isb",
      "cpsid", "cpsie", "mrs", "msr", "svc", "bkpt", "wfi", "wfe", "sev", "yield"}
MUL1 = {"mul", "smulbb", "smulbt", "smultb", "smultt", "smulwb", "smulwt", "smmul", "smmulr", "smuad", "smuadx",
        "smusd", "smusdx"}
MAC = {"mla", "mls", "smlabb", "smlabt", "smlatb", "smlatt", "smlawb", "smlawt", "smmla", "smmlar", "smmls",
       "smmlsr", "smlad", "smladx", "smlsd", "smlsdx"}
LONG = {"smull", "umull"}
LONGACC = {"smlal", "umlal", "smlald", "smlaldx", "smlsld", "smlsldx", "smlalbb", "smlalbt", "smlaltb", "smlaltt",
        "umaal"}
BRANCH = {"b", "bl", "blx", "bx", "cbz", "cbnz"}
CONDS = ("eq", "ne", "cs", "hs", "cc", "lo", "mi", "pl", "vs", "vc", "hi", "ls", "ge", "lt", "gt", "le", "al")


def base_mnemonic(m: str) -> str:
    """'adds.w' -> 'add', 'ldrbne' -> 'ldrb', 'beq.n' -> 'b', 'it' stays"""
    m = m.split(".")[0].lower()
    if m.startswith("it") and set(m[2:]) <= {"t", "e"}:
        return "it"
    for c in CONDS:  # a condition suffix (inside an IT block, or a conditional branch)
        if m.endswith(c) and len(m) > len(c):
            stem = m[: -len(c)]
            if stem in BRANCH or stem in DP or stem in MUL1 or stem in MAC or stem in LONG or stem in LONGACC \
                    or stem in ("sdiv", "udiv") or stem.startswith(("ldr", "str", "ld", "st")) or stem in FP_ALL \
                    or stem.rstrip("s") in DP or stem.rstrip("s") in MUL1:
                m = stem
                break
    if m.endswith("s") and m[:-1] in DP | MUL1 | {"mul"}:
        m = m[:-1]
    return m


def n_regs(ops: str) -> int:
    """registers in a {...} list: r4, r5, r6 or r4-r7"""
    m = re.search(r"\{([^}]*)\}", ops)
    if not m:
        return 1
    n = 0
    for part in m.group(1).split(","):
        part = part.strip()
        if "-" in part:
            a, b = (int(re.sub(r"\D", "", x) or 0) for x in part.split("-"))
            n += b - a + 1
        elif part:
            n += 1
    return n


FP1 = {"vadd", "vsub", "vmul", "vnmul", "vabs", "vneg", "vcmp", "vcmpe", "vcvt", "vcvtr", "vmov", "vmrs", "vmsr"}
FP3 = {"vmla", "vmls", "vnmla", "vnmls", "vfma", "vfms", "vfnma", "vfnms"}
FPLS = {"vldm", "vldmia", "vldmdb", "vstm", "vstmia", "vstmdb", "vpush", "vpop"}
FP_ALL = FP1 | FP3 | FPLS | {"vdiv", "vsqrt", "vldr", "vstr"}


def price_fp(m: str, ops: str):
    """(low, high) cycles of a Cortex-M4 FPU instruction (the TRM's FPU table), None if m is not one"""
    if m in FP1:
        return 1, 1
    if m in FP3:
        return 3, 3
    if m in ("vdiv", "vsqrt"):
        return 14, 14
    if m in ("vldr", "vstr"):
        return (3, 3) if re.match(r"\s*d\d", ops) else (2, 2)
    if m in FPLS:
        n = n_regs(ops) * (2 if re.search(r"\{\s*d", ops) else 1)
        return 1 + n, 1 + n
    return None


def _writes_pc(m: str, ops: str) -> bool:
    """whether instruction m (base mnemonic) with operands ops writes the PC (a destination pc, or pc in a POP's or
    LDM's register list)"""
    return bool(re.match(r"\s*pc\b", ops)) or ("pc}" in ops.replace(" ", "") and m in ("pop", "ldm", "ldmia"))


def price_m0plus(m: str, ops: str):
    """(low, high) cycles and kind of a Cortex-M0+ instruction (base mnemonic m; the M0+ TRM's table)"""
    writes_pc = _writes_pc(m, ops)
    if m == "bl":
        return 2, 2, "br"  # 3 with the refill of the taken branch
    if m in BRANCH:
        return 1, 1, "br"
    if m == "mul":  # MULS (base_mnemonic drops the S)
        return 1, 1, ""
    if m in ("push", "pop", "stm", "stmia", "ldm", "ldmia", "stmea", "ldmfd"):
        n = n_regs(ops)
        return (2 + n, 2 + n, "pc") if writes_pc else (1 + n, 1 + n, "")
    if m.startswith(("ldr", "str")):
        return 2, 2, "pc" if writes_pc else ""
    if m in ("dmb", "dsb", "isb"):
        return 3, 3, ""
    if m in DP:
        return 1, 1, "pc" if writes_pc and m in ("mov", "add") else ""
    raise ValueError(f"no cycle count for '{m} {ops}' (Cortex-M0+)")


def price(mn: str, ops: str, core: str, prev_ls: bool):
    """(low, high) cycles of one instruction, its kind ('ls' single load/store, 'br' branch, 'pc' PC write, '')
    and the refill it adds when taken (1 = yes)"""
    m = base_mnemonic(mn)
    if core == "m0plus":
        return price_m0plus(m, ops)
    fp = price_fp(m, ops) if m in FP_ALL else None
    if fp is not None:
        return fp[0], fp[1], ""
    writes_pc = _writes_pc(m, ops)
    if m in BRANCH:
        return 1, 1, "br"
    if m in ("tbb", "tbh"):
        return 2, 2, "pc"
    if m in ("udiv", "sdiv"):
        return 2, 12, ""
    if m in MUL1:
        return 1, 1, ""
    if m in MAC:
        return (1, 1, "") if core == "m4" else (2, 2, "")
    if m in LONG:
        return (1, 1, "") if core == "m4" else (3, 5, "")
    if m in LONGACC:
        return (1, 1, "") if core == "m4" else (4, 7, "")
    if m in ("ldrd", "strd"):
        return 3, 3, ""
    if m in ("push", "pop", "stmdb", "stmia", "stm", "ldm", "ldmia", "ldmdb", "stmea", "ldmfd", "stmfd"):
        n = n_regs(ops)
        return 1 + n, 1 + n, "pc" if writes_pc else ""
    if m.startswith(("ldr", "str", "ldrex", "strex")):
        kind = "pc" if writes_pc else "ls"
        return (1 if prev_ls else 2), 2, kind
    if m in DP:
        return 1, 1, "pc" if writes_pc and m in ("mov", "add") else ""
    raise ValueError(f"no cycle count for '{mn} {ops}'")


def call_target(mn: str, ops: str):
    """The callee of a direct call (Arm 'bl #0x8b7e'; RV32 'jal ra,964  # 0x8000166c'), else None"""
    m = base_mnemonic(mn)
    if m == "bl" and ops.startswith("#0x"):
        return int(ops.lstrip("#"), 16)
    if m == "jal" and ops.startswith("ra,") and "# 0x" in ops:
        return int(ops.rsplit("# 0x", 1)[1].split()[0], 16)
    return None


def code_symbols(elf: str, nm: str):
    """The image's code symbols [(start, end, name, sized)], sorted by address; a symbol without a size (the C
    library's assembly helpers) ends where the next one starts."""
    out = subprocess.run([nm, "-S", "-n", elf], capture_output=True, text=True, check=True).stdout
    fs = []
    for line in out.splitlines():
        f = line.split()
        if len(f) == 4 and f[2] in "tT":
            a = int(f[0], 16) & ~1
            fs.append([a, a + int(f[1], 16), f[3], True])
        elif len(f) == 3 and f[1] in "tT" and not f[2].startswith("$"):
            fs.append([int(f[0], 16) & ~1, None, f[2], False])
    fs.sort(key=lambda x: x[0])
    for i, x in enumerate(fs):
        if x[1] is None:
            x[1] = fs[i + 1][0] if i + 1 < len(fs) else x[0] + 4
    return [tuple(x) for x in fs]


def text_ranges(syms) -> str:
    """QEMU's -dfilter of the traced code: the sized symbols but the port's (EXCLUDE)."""
    return ",".join(f"0x{a:x}..0x{b - 1:x}" for a, b, name, sized in syms if sized and not EXCLUDE.match(name))


def source_lines(elf: str, nm: str, per_addr: dict) -> dict:
    """Instructions per source line ('file:line', paths relative to the repository) from executions per
    instruction address, with the toolchain's addr2line (the one beside nm)."""
    a2l = nm[:-2] + "addr2line" if nm.endswith("nm") else "addr2line"
    addrs = sorted(per_addr)
    out = subprocess.run([a2l, "-e", elf], input="\n".join(hex(a) for a in addrs), capture_output=True, text=True,
                         check=True).stdout.splitlines()
    root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))) + os.sep
    lines = {}
    for a, loc in zip(addrs, out):
        loc = loc.split(" (discriminator")[0].replace(root, "")
        lines[loc] = lines.get(loc, 0) + per_addr[a]
    return dict(sorted(lines.items(), key=lambda kv: -kv[1]))


def tally(log, syms, core: str, lines: bool = False) -> dict:
    """The counts of a QEMU `-d in_asm,exec,nochain` log (an iterable of its lines) against the image's code symbols
    (code_symbols): instructions, cycle estimates (the PRICED cores; None otherwise), per function, the calls into
    the C library's routines by caller ('helper_calls') and, with lines, executions per instruction address
    ('per_addr')."""
    priced = core in PRICED
    refill = REFILL.get(core, (0, 0))
    starts = [a for a, _, _, _ in syms]
    # (pc, cflags) -> (insns, low, high, end address, kind, callee, addresses); also pc -> the first translation at
    # pc. With -icount QEMU retranslates some blocks shorter (an instruction budget in the cflags), so one address
    # can have several blocks: each execution line names its translation's flags.
    blocks = {}
    per_fn = {}  # function name -> instructions executed in it (blocks attributed by their first address)
    calls = {}  # (C library routine, calling function) -> calls
    per_addr = {}  # instruction address -> executions (lines only)
    tot_insn = lo = hi = 0
    pending = None  # the previous executed block's last instruction: (end address, kind)
    cur = None
    for line in log:
        if line.startswith("IN:"):
            cur = []
            continue
        if cur is not None and line.startswith("0x"):
            m = re.match(r"0x([0-9a-f]+):\s+([0-9a-f]+)(?:\s+([0-9a-f]{4}))?\s+(\S+)\s*(.*)", line)
            if m:
                size = (len(m.group(2)) + (len(m.group(3)) if m.group(3) else 0)) // 2
                cur.append((int(m.group(1), 16), size, m.group(4), m.group(5).strip()))
            continue
        if line.startswith("Trace"):
            m = re.search(r"\[[0-9a-f]+/([0-9a-f]+)/[0-9a-f]+/([0-9a-f]+)\]", line)
            pc = int(m.group(1), 16)
            key = (pc, m.group(2))
            if cur:
                l_ = h_ = 0
                prev_ls = False
                if priced:
                    for a, size, mn, ops in cur:
                        cl, ch, kind = price(mn, ops, core, prev_ls)
                        l_ += cl
                        h_ += ch
                        prev_ls = kind == "ls"
                a, size, mn, ops = cur[-1]
                blk = (len(cur), l_, h_, a + size, price(mn, ops, core, False)[2] if priced else "",
                       call_target(mn, ops), tuple(x[0] for x in cur) if lines else ())
                if cur[0][0] == pc:  # a block is logged when translated, just before its first run
                    blocks[key] = blk
                blocks.setdefault(cur[0][0], blk)
            cur = None
            b = blocks.get(key) or blocks.get(pc)
            if b is None:
                continue
            # the previous block's branch: taken unless this block starts right after it; a PC write always refills
            if pending is not None:
                end, kind = pending
                if (kind == "br" and pc != end) or kind == "pc":
                    lo += refill[0]
                    hi += refill[1]
            n, l_, h_, end, kind, callee, addrs = b
            for x in addrs:
                per_addr[x] = per_addr.get(x, 0) + 1
            i = bisect.bisect_right(starts, pc) - 1
            fn = syms[i][2] if i >= 0 and pc < syms[i][1] else "?"
            per_fn[fn] = per_fn.get(fn, 0) + n
            if callee is not None:
                j = bisect.bisect_right(starts, callee) - 1
                if j >= 0 and syms[j][2].startswith("__"):  # calls into the C library's routines
                    k = (syms[j][2], fn)
                    calls[k] = calls.get(k, 0) + 1
            tot_insn += n
            lo += l_
            hi += h_
            pending = (end, kind)
    if tot_insn == 0:
        raise RuntimeError("empty trace: QEMU wrote nothing (wrong core or image?)")
    r = dict(core=core, instructions=tot_insn, cycles_low=lo if priced else None,
             cycles_high=hi if priced else None, cpi_low=lo / tot_insn if priced else None,
             cpi_high=hi / tot_insn if priced else None,
             per_function=dict(sorted(per_fn.items(), key=lambda kv: -kv[1])),
             helper_calls=[(h, c, n) for (h, c), n in sorted(calls.items(), key=lambda kv: -kv[1])])
    if lines:
        r["per_addr"] = per_addr
    return r


def estimate(elf: str, core: str, nm: str, qemu: str = None, timeout: int = 1800, lines: bool = False) -> dict:
    """QEMU's trace of the image (streamed through a pipe) tallied (tally); with lines, 'per_line' too."""
    qcmd = [qemu] + QEMU[core][1:] if qemu else QEMU[core]
    syms = code_symbols(elf, nm)
    with tempfile.TemporaryDirectory() as td:
        fifo = os.path.join(td, "trace")
        os.mkfifo(fifo)
        # the Arm images exit through semihosting, the RV32 ones through the virt board's test device (run_fw.py)
        arm = ["-icount", "shift=8", "-semihosting-config", "enable=on,target=native"]
        cmd = qcmd + (arm if core != "rv32" else ["-icount", "shift=0"]) + [
            "-display", "none", "-monitor", "none", "-serial", "null", "-kernel", elf, "-d", "in_asm,exec,nochain",
            "-dfilter", text_ranges(syms), "-D", fifo]
        proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        timer = threading.Timer(timeout, proc.kill)
        timer.start()
        try:
            with open(fifo, errors="replace") as f:
                r = tally(f, syms, core, lines)
        finally:
            timer.cancel()
            proc.wait()
    if lines:
        r["per_line"] = source_lines(elf, nm, r.pop("per_addr"))
    return r


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--elf", required=True)
    ap.add_argument("--core", choices=sorted(QEMU), required=True)
    ap.add_argument("--report", help="run_fw.py's report.json of the same image: cycles per scan from its counts")
    ap.add_argument("--nm", help="the toolchain's nm (default: arm-none-eabi-nm, RV32 riscv64-unknown-elf-nm)")
    ap.add_argument("--qemu")
    ap.add_argument("--mhz", type=float, default=None,
                    help="clock for scans per second (default: M4 200, M3 100, M0+ 133 as the RP2040)")
    ap.add_argument("--json")
    ap.add_argument("--functions", type=int, default=0, metavar="N",
                    help="also print the N functions that executed the most instructions (all runs of the image)")
    ap.add_argument("--lines", type=int, default=0, metavar="N",
                    help="also print the N source lines that executed the most instructions (addr2line)")
    a = ap.parse_args(argv)
    a.nm = a.nm or NM[a.core]
    for tool in (a.qemu or QEMU[a.core][0], a.nm):
        if subprocess.run(["which", tool], capture_output=True).returncode != 0:
            print(f"cycles: {tool} not found", file=sys.stderr)
            return SKIP
    if not os.path.exists(a.elf):
        print(f"cycles: {a.elf} not found (make firmware)", file=sys.stderr)
        return 2
    r = estimate(a.elf, a.core, a.nm, a.qemu, lines=a.lines > 0)
    mhz = a.mhz or MHZ.get(a.core)
    if r["cycles_low"] is None:
        print(f"{a.core}: {r['instructions']:,} instructions traced (no cycle model for this core: the profile only)")
    else:
        print(f"{a.core}: {r['instructions']:,} instructions traced, estimated {r['cycles_low']:,} to "
              f"{r['cycles_high']:,} cycles: CPI {r['cpi_low']:.3f} to {r['cpi_high']:.3f}")
    if a.functions:
        print(f"the {a.functions} functions that executed the most instructions (all of the image's runs):")
        for fn, n in list(r["per_function"].items())[:a.functions]:
            print(f"  {n:>12,}  {100.0 * n / r['instructions']:5.1f} %  {fn}")
        print("calls into the C library's helpers (helper, caller, calls):")
        for h, c, n in r["helper_calls"][:a.functions]:
            print(f"  {n:>12,}  {h} from {c}")
    if a.lines:
        print(f"the {a.lines} source lines that executed the most instructions (all of the image's runs):")
        for loc, n in list(r["per_line"].items())[:a.lines]:
            print(f"  {n:>12,}  {100.0 * n / r['instructions']:5.1f} %  {loc}")
    if a.report and r["cycles_low"] is not None:
        rep = json.load(open(a.report))
        ins = rep["insn"]["default"]
        r["scan_instructions"] = ins["scan"]
        r["scan_cycles_low"] = ins["scan"] * r["cpi_low"]
        r["scan_cycles_high"] = ins["scan"] * r["cpi_high"]
        r["mhz"] = mhz
        print(f"per scan ({ins['scan']:,} instructions, run default): {r['scan_cycles_low'] / 1e6:.1f} to "
              f"{r['scan_cycles_high'] / 1e6:.1f} M cycles (estimates): {r['scan_cycles_low'] / mhz / 1e3:.0f} to "
              f"{r['scan_cycles_high'] / mhz / 1e3:.0f} ms at {mhz:.0f} MHz")
    if a.json:
        with open(a.json, "w") as f:
            json.dump(r, f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
