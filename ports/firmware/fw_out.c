/* SPDX-License-Identifier: MIT */
/* Console output without stdio and the counter's calibration for the firmware applications (fw_out.h). */
#include "fw_out.h"

#include "fw_port.h"

const char *const fw_class_names[LIDET_N_CLASSES] = {"Car", "Cyclist", "Pedestrian"};

void fw_put_s(const char *s)
{
    while (*s != '\0')
        fw_putc(*s++);
}

void fw_put_u64(uint64_t v)
{
    char b[21];
    int n = 0;
    do
    {
        b[n++] = (char)('0' + (unsigned)(v % 10u));
        v /= 10u;
    } while (v != 0u);
    while (n > 0)
        fw_putc(b[--n]);
}

void fw_put_u(uint32_t v)
{
    char b[11];
    int n = 0;
    do
    {
        b[n++] = (char)('0' + v % 10u);
        v /= 10u;
    } while (v != 0u);
    while (n > 0)
        fw_putc(b[--n]);
}

void fw_put_i64(int64_t v)
{
    if (v < 0)
    {
        fw_putc('-');
        fw_put_u64((uint64_t)(-(v + 1)) + 1u);
    }
    else
        fw_put_u64((uint64_t)v);
}

void fw_put_i(int32_t v)
{
    if (v < 0)
    {
        fw_putc('-');
        fw_put_u((uint32_t)(-(v + 1)) + 1u);
    }
    else
        fw_put_u((uint32_t)v);
}

void fw_put_hex(uint32_t v)
{
    int k;
    for (k = 28; k >= 0; k -= 4)
        fw_putc("0123456789abcdef"[(v >> k) & 15u]);
}

void fw_put_kv(const char *key, uint32_t v)
{
    fw_putc(' ');
    fw_put_s(key);
    fw_putc('=');
    fw_put_u(v);
}

void fw_put_kv64(const char *key, uint64_t v)
{
    fw_putc(' ');
    fw_put_s(key);
    fw_putc('=');
    fw_put_u64(v);
}

#if !LIDET_FIXED_POINT
void fw_put_f(float f)
{
    uint32_t whole, frac;
    if (!(f == f))
    {
        fw_put_s("nan");
        return;
    }
    if (f < 0.0f)
    {
        fw_putc('-');
        f = -f;
    }
    if (f >= 1.0e6f)
    {
        fw_put_s("big");
        return;
    }
    whole = (uint32_t)f;
    frac = (uint32_t)((f - (float)whole) * 10000.0f + 0.5f);
    if (frac >= 10000u)
    {
        ++whole;
        frac -= 10000u;
    }
    fw_put_u(whole);
    fw_putc('.');
    fw_putc((char)('0' + frac / 1000u));
    fw_putc((char)('0' + frac / 100u % 10u));
    fw_putc((char)('0' + frac / 10u % 10u));
    fw_putc((char)('0' + frac % 10u));
}
#endif

/* measure() is one function whatever n is (n arrives in a register), so the instructions around the loop are the
 * same in every call; the difference of two loops removes them (and the clock calls), so measured must equal
 * expected exactly. */
static __attribute__((noinline)) uint32_t measure(uint32_t n)
{
    const uint32_t t0 = fw_clock(0);
    fw_spin(n);
    return fw_clock(0) - t0;
}

static int check(const char *tag, uint32_t n, uint32_t base, uint32_t len0, uint32_t slack)
{
    const uint32_t measured = measure(n) - base;
    const uint32_t expected = fw_spin_insn(n) - fw_spin_insn(len0);
    fw_put_s(tag);
    fw_put_kv("n", n);
    fw_put_kv("expected", expected);
    fw_put_kv("measured", measured);
    fw_putc('\n');
    return measured < expected || measured - expected > slack;
}

int fw_calibrate(int with_long)
{
    static volatile uint32_t lens[4] = {1u, 1000u, 12345u, 1000000u}; /* volatile: no constant folding */
    static volatile uint32_t long_n = 350000000u;
    const uint32_t base = measure(lens[0]);
    uint32_t k;
    int bad = 0;
    for (k = 1; k < 4u; ++k)
        bad |= check("calib", lens[k], base, lens[0], 0u);
    if (with_long) /* the wrap handler's few instructions count here too */
        bad |= check("calib_long", long_n, base, lens[0], 64u);
    return bad;
}
