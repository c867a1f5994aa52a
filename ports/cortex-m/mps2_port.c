/* SPDX-License-Identifier: MIT */
/* fw_port.h for the MPS2 boards under QEMU: console over Arm semihosting (SYS_WRITE0, one call per line),
 * exit over semihosting (SYS_EXIT), and the instruction counter.
 *
 * Instruction counting (exact): QEMU runs with `-icount shift=S` (FW_ICOUNT_SHIFT, default 8), so its virtual
 * clock advances exactly 2^S ns per executed guest instruction. CMSDK APB timer 0 (0x40000000) counts that
 * virtual clock at the board's 25 MHz (40 ns per tick), i.e. 2^S / 40 = 6.4 ticks per instruction at S = 8.
 * Each read is off by less than one tick, so a difference of two reads is within 2 ticks of 6.4 x N and
 * N = round(ticks * 40 / 2^S) is exact (2 / 6.4 < 0.5). The timer is 32 bits: at most 671 M instructions per
 * measured interval. fw_detect.c checks the conversion against loops of known length at every run. */
#include <stdint.h>

#include "fw_port.h"

#ifndef FW_ICOUNT_SHIFT
#define FW_ICOUNT_SHIFT 8
#endif
#define FW_TIMER_NS 40u /* 25 MHz */

#define TIMER0_CTRL (*(volatile uint32_t *)0x40000000u)
#define TIMER0_VALUE (*(volatile uint32_t *)0x40000004u)
#define TIMER0_RELOAD (*(volatile uint32_t *)0x40000008u)

#define SEMI_SYS_WRITE0 0x04
#define SEMI_SYS_EXIT 0x18
#define ADP_STOPPED_APPLICATION_EXIT 0x20026u /* QEMU exits with 0 */
#define ADP_STOPPED_RUNTIME_ERROR 0x20023u    /* QEMU exits with 1 */

void fw_mps2_counter_start(void);
void fw_mps2_report_fault(uint32_t exc, const uint32_t *frame);

static int semihost(int op, const void *arg)
{
    register int r0 __asm__("r0") = op;
    register const void *r1 __asm__("r1") = arg;
    __asm__ volatile("bkpt 0xab" : "+r"(r0) : "r"(r1) : "memory");
    return r0;
}

static char g_line[160];
static uint32_t g_len;

static void flush(void)
{
    if (g_len > 0u)
    {
        g_line[g_len] = '\0';
        semihost(SEMI_SYS_WRITE0, g_line);
        g_len = 0u;
    }
}

void fw_putc(char c)
{
    g_line[g_len++] = c;
    if (c == '\n' || g_len == sizeof g_line - 1u)
        flush();
}

void fw_exit(int code)
{
    flush();
    for (;;)
        semihost(SEMI_SYS_EXIT, (const void *)(uintptr_t)(code == 0 ? ADP_STOPPED_APPLICATION_EXIT
                                                                      : ADP_STOPPED_RUNTIME_ERROR));
}

void fw_mps2_counter_start(void)
{
    TIMER0_CTRL = 0u;
    TIMER0_RELOAD = 0xFFFFFFFFu;
    TIMER0_VALUE = 0xFFFFFFFFu;
    TIMER0_CTRL = 1u; /* enable, system clock, no interrupt */
}

uint32_t fw_clock(void *ctx)
{
    (void)ctx;
    return ~TIMER0_VALUE; /* counts up */
}

uint32_t fw_ticks_to_insn(uint32_t ticks)
{
    return (uint32_t)(((uint64_t)ticks * FW_TIMER_NS + (1u << (FW_ICOUNT_SHIFT - 1))) >> FW_ICOUNT_SHIFT);
}

int fw_have_counter(void)
{
    return 1;
}

/* 2 n + 1 instructions: n x (subs, bne), bx lr */
__attribute__((naked, noinline)) void fw_spin(uint32_t n)
{
    (void)n;
    __asm__ volatile("1:\n\t"
                     "subs r0, r0, #1\n\t"
                     "bne 1b\n\t"
                     "bx lr\n\t");
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

void fw_mps2_report_fault(uint32_t exc, const uint32_t *frame)
{
    put_s("lidet-fw: FAIL (exception ");
    put_hex(exc);
    put_s(" pc ");
    put_hex(frame[6]);
    put_s(" cfsr ");
    put_hex(*(volatile uint32_t *)0xE000ED28u);
    put_s(" hfsr ");
    put_hex(*(volatile uint32_t *)0xE000ED2Cu);
    put_s(")\n");
    fw_exit(3);
}
