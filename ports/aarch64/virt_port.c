/* SPDX-License-Identifier: MIT */
/* fw_port.h for QEMU's Arm `virt` machine run as a bare-metal aarch64 board (-cpu cortex-a72): console on the PL011
 * UART (0x09000000), exit through Arm semihosting (SYS_EXIT; QEMU runs with -semihosting-config enable=on and ends
 * with the given status), and the instruction counter.
 *
 * Instruction counting (exact): PMU event counter 0 counts event 0x08, INST_RETIRED (virt_start.S programs
 * PMEVTYPER0_EL0, PMCNTENSET_EL0 and PMCR_EL0). QEMU implements that event only with precise instruction counting,
 * `-icount shift=N` (its count is QEMU's instruction counter itself: one per executed guest instruction, whatever
 * N; the images run with shift=0); without -icount the counter stays at 0 and the calibration fails. A difference
 * of two reads is the instructions in between, including the MRS itself. The counter is 32 bits wide (Cortex-A72:
 * PMUv3): fw_insn64 extends it in software, which holds while it is read at least once every 2^32 instructions
 * (the detector's clock hook reads it between stages; a whole scan is a few hundred million). fw_detect.c checks
 * the counter against loops of known length at every run. */
#include <stdint.h>

#include "fw_port.h"

#define UART_DR (*(volatile uint32_t *)0x09000000u)
#define UART_FR (*(volatile uint32_t *)0x09000018u)
#define UART_CR (*(volatile uint32_t *)0x09000030u)
#define UART_FR_TXFF 0x20u
#define UART_CR_UARTEN 0x001u
#define UART_CR_TXE 0x100u

#define SEMI_SYS_EXIT 0x18u
#define ADP_STOPPED_APPLICATION_EXIT 0x20026u /* with the status in the second word: QEMU exits with it */

void fw_a64_report_trap(uint64_t kind, uint64_t esr, uint64_t elr, uint64_t far);

void fw_putc(char c)
{
    if ((UART_CR & (UART_CR_UARTEN | UART_CR_TXE)) != (UART_CR_UARTEN | UART_CR_TXE))
        UART_CR = UART_CR_UARTEN | UART_CR_TXE;
    while ((UART_FR & UART_FR_TXFF) != 0u)
    {
    }
    UART_DR = (uint8_t)c;
}

void fw_exit(int code)
{
    /* AArch64 SYS_EXIT takes a parameter block: the reason and the exit status */
    static volatile uint64_t block[2];
    block[0] = ADP_STOPPED_APPLICATION_EXIT;
    block[1] = (uint64_t)(uint32_t)code;
    for (;;)
    {
        register uint64_t x0 __asm__("x0") = SEMI_SYS_EXIT;
        register volatile uint64_t *x1 __asm__("x1") = block;
        __asm__ volatile("hlt #0xf000" : "+r"(x0) : "r"(x1) : "memory");
    }
}

uint32_t fw_clock(void *ctx)
{
    uint64_t v;
    (void)ctx;
    __asm__ volatile("mrs %0, pmevcntr0_el0" : "=r"(v));
    return (uint32_t)v;
}

static uint32_t g_hi, g_last; /* wraps of the 32-bit counter seen so far, its last value read */

uint64_t fw_insn64(void)
{
    const uint32_t lo = fw_clock(0);
    if (lo < g_last)
        ++g_hi;
    g_last = lo;
    return ((uint64_t)g_hi << 32) | lo;
}

int fw_have_counter(void)
{
    return 1;
}

/* fw_spin is in virt_start.S: 2 n + 1 instructions (n x (subs, b.ne), ret) */
uint32_t fw_spin_insn(uint32_t n)
{
    return 2u * n + 1u;
}

static void put_s(const char *s)
{
    while (*s != '\0')
        fw_putc(*s++);
}

static void put_hex(uint64_t v)
{
    int k;
    for (k = 60; k >= 0; k -= 4)
        fw_putc("0123456789abcdef"[(v >> k) & 15u]);
}

/* an exception (virt_start.S: the vector's index, ESR_EL1, ELR_EL1, FAR_EL1) */
void fw_a64_report_trap(uint64_t kind, uint64_t esr, uint64_t elr, uint64_t far)
{
    put_s("lidet-fw: FAIL (exception vector ");
    put_hex(kind);
    put_s(" esr ");
    put_hex(esr);
    put_s(" elr ");
    put_hex(elr);
    put_s(" far ");
    put_hex(far);
    put_s(")\n");
    fw_exit(3);
}
