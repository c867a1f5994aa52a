/* SPDX-License-Identifier: MIT */
/* What every bare-metal image does between reset and fw_main, whatever the core: copy .data from flash,
 * zero .bss, paint the stack; then fw_exit(fw_main()). The core's reset code (ports/cortex-m/mps2_startup.c,
 * ports/riscv/virt_start.S, ports/aarch64/virt_start.S) sets the stack pointer (and the FPU, gp; the MMU on
 * aarch64) first, then calls fw_start. Symbols from the board's linker script (ports/cortex-m/mps2_an38x.ld /
 * mps2_an500.ld with mps2_sections.ld, ports/riscv/virt.ld, ports/aarch64/virt.ld). */
#include <stdint.h>

#include "fw_port.h"

extern uint32_t __data_load[], __data_start[], __data_end[];
extern uint32_t __bss_start[], __bss_end[];
extern uint32_t __stack_bottom[], __stack_top[];

#define FW_STACK_PAINT 0xC5A5C5A5u

void fw_start(void);

void fw_stack_paint(void)
{
    /* everything below this frame (and a margin for the calls still to come) is unused so far */
    volatile uint32_t *p = __stack_bottom;
    volatile uint32_t *end = (volatile uint32_t *)__builtin_frame_address(0) - 32;
    while (p < end)
        *p++ = FW_STACK_PAINT;
}

uint32_t fw_stack_used(void)
{
    const volatile uint32_t *p = __stack_bottom;
    while (p < __stack_top && *p == FW_STACK_PAINT)
        ++p;
    return (uint32_t)((uintptr_t)__stack_top - (uintptr_t)p);
}

uint32_t fw_stack_size(void)
{
    return (uint32_t)((uintptr_t)__stack_top - (uintptr_t)__stack_bottom);
}

void fw_start(void)
{
    /* volatile pointers: the compiler must not turn these loops into memcpy/memset calls before .data exists */
    volatile uint32_t *dst = __data_start;
    const volatile uint32_t *src = __data_load;
    while (dst < __data_end)
        *dst++ = *src++;
    for (dst = __bss_start; dst < __bss_end;)
        *dst++ = 0u;
    fw_stack_paint();
    fw_exit(fw_main());
}
