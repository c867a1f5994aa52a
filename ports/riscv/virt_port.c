/* SPDX-License-Identifier: MIT */
/* fw_port.h for QEMU's RISC-V `virt` machine: console on the NS16550A UART (0x10000000), exit through the
 * SiFive test device (0x100000: QEMU ends with the given status), and the instruction counter.
 *
 * Instruction counting (exact): with `-icount shift=0` QEMU's minstret CSR returns its instruction counter
 * (without -icount it returns host time), one per executed guest instruction; a difference of two reads is
 * the instructions in between, including the csrr itself. fw_detect.c checks it against loops of known
 * length at every run. fw_clock reads the low half (differences up to 4.29 G), fw_insn64 both halves. */
#include <stdint.h>

#include "fw_port.h"

/* a CSR read: GCC 12 needs Zicsr enabled for it, which rv32imafc implies and rv32imac does not */
#define ZICSR(insn) ".option push\n\t.option arch, +zicsr\n\t" insn "\n\t.option pop"

#define UART_THR (*(volatile uint8_t *)0x10000000u)
#define UART_LSR (*(volatile uint8_t *)0x10000005u)
#define UART_LSR_THRE 0x20u
#define TEST_DEVICE (*(volatile uint32_t *)0x00100000u)
#define TEST_PASS 0x5555u
#define TEST_FAIL 0x3333u

void fw_virt_report_trap(uint32_t mcause, uint32_t mepc, uint32_t mtval);

void fw_putc(char c)
{
    while ((UART_LSR & UART_LSR_THRE) == 0u)
    {
    }
    UART_THR = (uint8_t)c;
}

void fw_exit(int code)
{
    for (;;)
        TEST_DEVICE = code == 0 ? TEST_PASS : (((uint32_t)code & 0xFFFFu) << 16) | TEST_FAIL;
}

uint32_t fw_clock(void *ctx)
{
    uint32_t v;
    (void)ctx;
    __asm__ volatile(ZICSR("csrr %0, minstret") : "=r"(v));
    return v;
}

uint64_t fw_insn64(void)
{
    uint32_t hi, lo, hi2;
    do
    {
        __asm__ volatile(ZICSR("csrr %0, minstreth") : "=r"(hi));
        __asm__ volatile(ZICSR("csrr %0, minstret") : "=r"(lo));
        __asm__ volatile(ZICSR("csrr %0, minstreth") : "=r"(hi2));
    } while (hi != hi2);
    return ((uint64_t)hi << 32) | lo;
}

int fw_have_counter(void)
{
    return 1;
}

/* 2 n + 1 instructions: n x (addi, bnez), ret */
__attribute__((naked, noinline)) void fw_spin(uint32_t n)
{
    (void)n;
    __asm__ volatile("1:\n\t"
                     "addi a0, a0, -1\n\t"
                     "bnez a0, 1b\n\t"
                     "ret\n\t");
}

uint32_t fw_spin_insn(uint32_t n)
{
    return 2u * n + 1u;
}

static void put_s(const char *s)
{
    while (*s != '\0')
        fw_putc(*s++);
}

static void put_hex(uint32_t v)
{
    int k;
    for (k = 28; k >= 0; k -= 4)
        fw_putc("0123456789abcdef"[(v >> k) & 15u]);
}

void fw_virt_report_trap(uint32_t mcause, uint32_t mepc, uint32_t mtval)
{
    put_s("lidet-fw: FAIL (trap mcause ");
    put_hex(mcause);
    put_s(" mepc ");
    put_hex(mepc);
    put_s(" mtval ");
    put_hex(mtval);
    put_s(")\n");
    fw_exit(3);
}
