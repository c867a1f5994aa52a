/* SPDX-License-Identifier: MIT */
/**
 * @file fw_port.h
 * @brief What a board gives the firmware application (fw_detect.c): a console, an instruction counter,
 *        exit, and the stack bounds for the high-water mark. Implemented by ports/cortex-m/mps2_port.c,
 *        ports/riscv/virt_port.c, ports/aarch64/virt_port.c and, for the host reference program, fw_host_port.c.
 */
#ifndef LIDET_FW_PORT_H
#define LIDET_FW_PORT_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/** Board and core names printed in the report ("mps2-an386", "cortex-m4f"). */
extern const char fw_board_name[];
extern const char fw_core_name[];

/** One byte to the console (semihosting or UART; the port may buffer until '\n'). */
void fw_putc(char c);

/** Leave the program: 0 = success. Under QEMU this ends QEMU with a matching exit status. */
void fw_exit(int code);

/** Instructions executed since the counter started, low 32 bits (a lidet_clock_fn; ctx unused): the
 *  difference of two values is the exact instruction count in between (ports: the method). 0 on the host. */
uint32_t fw_clock(void *ctx);

/** Instructions since the counter started, 64 bits (a whole scan on a core without FPU exceeds 2^32). */
uint64_t fw_insn64(void);

/** Nonzero when fw_clock counts instructions (QEMU with -icount); 0 on the host. */
int fw_have_counter(void);

/**
 * Calibration of the counter: executes a loop of exactly fw_spin_insn(n) instructions (hand-written
 * assembly, so the count is known), for checking fw_clock against a known answer.
 */
void fw_spin(uint32_t n);
uint32_t fw_spin_insn(uint32_t n);

/** Stack painting (fw_start.c): fill the unused stack with a pattern at reset; bytes ever used, and size. */
void fw_stack_paint(void);
uint32_t fw_stack_used(void);
uint32_t fw_stack_size(void);

/** The application (fw_detect.c); returns the exit code. */
int fw_main(void);

#ifdef __cplusplus
}
#endif

#endif /* LIDET_FW_PORT_H */
