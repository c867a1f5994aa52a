/* SPDX-License-Identifier: MIT */
/* Include first in an integer source (lib/src/<stage>/lidet_*_q.c) whose code moves 64-bit integers: on an
 * ARM core with an FPU (Cortex-M4F, -mfloat-abi=hard) GCC may hold or copy an int64_t in a VFP register
 * (vldr/vstr/vpush of a d register: no float arithmetic, but FPU instructions the integer-only build must not
 * contain, and tools/firmware/check_nofloat.py reports them). This keeps the rest of the file on the general
 * registers. Other compilers and targets: no effect. Never installed. */
#ifndef LIDET_Q_GPR_H
#define LIDET_Q_GPR_H

#if defined(__GNUC__) && !defined(__clang__) && defined(__arm__) && defined(__ARM_FP)
#pragma GCC target("general-regs-only")
#endif

#endif
