/* SPDX-License-Identifier: MIT */
/* fw_port.h for the MPS2 boards under QEMU: console over Arm semihosting (SYS_WRITE0, one call per line),
 * exit over semihosting (SYS_EXIT), and the instruction counter.
 *
 * Instruction counting (exact): QEMU runs with `-icount shift=S` (FW_ICOUNT_SHIFT, default 8), so its virtual
 * clock advances exactly 2^S ns per executed guest instruction. CMSDK APB timer 0 (0x40000000) counts that
 * virtual clock at the board's 25 MHz (40 ns per tick): 2^S / 40 = 6.4 ticks per instruction at S = 8. Its
 * wrap interrupt (IRQ 8, every 671 M instructions) extends it to 64 bits. fw_clock returns the instructions
 * since the counter started: round((T - T0) x 40 / 2^S) with T the 64-bit tick count. Each read is within
 * one tick of 6.4 x N (plus a constant), so the error is at most 2 / 6.4 < 0.5 instruction and the rounding
 * gives N exactly; differences of fw_clock values are then exact instruction counts (up to 4.29 G apart).
 * The wrap handler's own ~20 instructions every 671 M are counted where they happen, as every instruction is.
 * fw_detect.c checks the counter against loops of known length at every run. */
#include <stdint.h>

#include "fw_port.h"

#ifndef FW_ICOUNT_SHIFT
#define FW_ICOUNT_SHIFT 8
#endif
#define FW_TIMER_NS 40u /* 25 MHz */

#define TIMER0_CTRL (*(volatile uint32_t *)0x40000000u)
#define TIMER0_VALUE (*(volatile uint32_t *)0x40000004u)
#define TIMER0_RELOAD (*(volatile uint32_t *)0x40000008u)
#define TIMER0_INT (*(volatile uint32_t *)0x4000000Cu) /* read: status, write 1: clear */
#define TIMER0_IRQ 8u
#define NVIC_ISER0 (*(volatile uint32_t *)0xE000E100u)

#define SEMI_SYS_WRITE0 0x04
#define SEMI_SYS_EXIT 0x18
#define ADP_STOPPED_APPLICATION_EXIT 0x20026u /* QEMU exits with 0 */
#define ADP_STOPPED_RUNTIME_ERROR 0x20023u    /* QEMU exits with 1 */

void fw_mps2_counter_start(void);
void fw_mps2_timer0_irq(void);
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

static volatile uint32_t g_wraps; /* timer 0 wrap-arounds (high word of the tick count) */
static uint64_t g_t0;               /* tick count when the counter started */

void fw_mps2_timer0_irq(void)
{
    TIMER0_INT = 1u;
    ++g_wraps;
}

/* 64-bit tick count; interrupts masked so that a wrap between the two halves is seen as pending */
static uint64_t ticks64(void)
{
    uint32_t hi, lo;
    __asm__ volatile("cpsid i" ::: "memory");
    hi = g_wraps;
    lo = ~TIMER0_VALUE; /* counts up */
    if ((TIMER0_INT & 1u) != 0u && lo < 0x80000000u)
        ++hi; /* wrapped, handler not run yet */
    __asm__ volatile("cpsie i" ::: "memory");
    return ((uint64_t)hi << 32) | lo;
}

void fw_mps2_counter_start(void)
{
    TIMER0_CTRL = 0u;
    TIMER0_RELOAD = 0xFFFFFFFFu;
    TIMER0_VALUE = 0xFFFFFFFFu;
    TIMER0_INT = 1u;
    NVIC_ISER0 = 1u << TIMER0_IRQ;
    TIMER0_CTRL = 1u | 8u; /* enable, system clock, interrupt at wrap */
    g_t0 = ticks64();
}

uint64_t fw_insn64(void)
{
    return ((ticks64() - g_t0) * FW_TIMER_NS + (1u << (FW_ICOUNT_SHIFT - 1))) >> FW_ICOUNT_SHIFT;
}

uint32_t fw_clock(void *ctx)
{
    (void)ctx;
    return (uint32_t)fw_insn64();
}

int fw_have_counter(void)
{
    return 1;
}

/* 2 n + 1 instructions: n x (subs, bne), bx lr */
__attribute__((naked, noinline)) void fw_spin(uint32_t n)
{
    (void)n;
    __asm__ volatile(".syntax unified\n\t"
                     "1:\n\t"
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
