/* SPDX-License-Identifier: MIT */
/* The host side of fw_port.h: fw_detect.c built as an ordinary program (fw_host_ref, tests/CMakeLists.txt)
 * against lidet built with the firmware's capacities, so that the QEMU images have a reference that ran
 * the same code on the same scan. No instruction counter and no stack painting on the host. */
#include <stdio.h>
#include <stdlib.h>

#include "fw_port.h"

const char fw_board_name[] = "host";
const char fw_core_name[] = "host";

void fw_putc(char c)
{
    putchar(c);
}

void fw_exit(int code)
{
    fflush(stdout);
    exit(code);
}

uint32_t fw_clock(void *ctx)
{
    (void)ctx;
    return 0u;
}

uint64_t fw_insn64(void)
{
    return 0u;
}

int fw_have_counter(void)
{
    return 0;
}

void fw_spin(uint32_t n)
{
    (void)n;
}

uint32_t fw_spin_insn(uint32_t n)
{
    return n;
}

void fw_stack_paint(void)
{
}

uint32_t fw_stack_used(void)
{
    return 0u;
}

uint32_t fw_stack_size(void)
{
    return 0u;
}

int main(void)
{
    fw_exit(fw_main());
    return 0;
}
