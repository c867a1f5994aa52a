/* SPDX-License-Identifier: MIT */
/* Port layer of a Cortex-M firmware (an example to copy into the firmware's tree): build lidet with
 * -DLIDET_PORT_DIR=<folder of this file> (CMake) or -DLIDET_PORT -I<folder>. Every hook is optional;
 * lidet_opt.h gives the defaults of those left out. */
#ifndef LIDET_PORT_H
#define LIDET_PORT_H

/* asserts (only with LIDET_DEBUG 1) go to the firmware's fault handler, with file and line */
void lidet_port_assert_failed(const char *file, int line);
#define LIDET_ASSERT(c) ((c) ? (void)0 : lidet_port_assert_failed(__FILE__, __LINE__))

/* 32-byte alignment: one cache line of a Cortex-M7 (the workspace is streamed by every stage) */
#define LIDET_ALIGN(n) __attribute__((aligned((n) > 32 ? (n) : 32)))

/* the detector workspace in external SDRAM (the linker script defines .sdram, NOLOAD); a board
 * whose workspace fits its DTCM would name that section instead:
 *   static lidet_workspace_t ws LIDET_WORKSPACE_SECTION LIDET_ALIGN(32); */
#define LIDET_WORKSPACE_SECTION __attribute__((section(".sdram")))

/* generated weights stay in flash (.rodata is already there on Cortex-M; a QSPI flash would use a section) */
#define LIDET_RODATA

#endif
