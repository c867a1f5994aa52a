/* SPDX-License-Identifier: MIT */
/* memset for the RISC-V images, in place of picolibc's. Debian's picolibc for riscv64-unknown-elf is built for
 * size: its memset stores one byte per loop of four instructions, and the integer detector clears its range image
 * at every scan (2 bytes a pixel: 57,600 B at 16 x 1800), about 230,000 instructions that way. This one stores
 * aligned 32-bit words, four a loop (about 1.5 instructions per word), with bytes only at the ends; the same bytes
 * written. A firmware whose C library has a word-wise memset (newlib's and picolibc's speed builds do) needs none of
 * this.
 *
 * Built with -ffreestanding (ports/firmware/CMakeLists.txt), so that the compiler does not turn the loops into a
 * call to memset itself. */
#include <stddef.h>
#include <stdint.h>

/* 32-bit words that may alias any object (memset's stores) */
typedef uint32_t u32_alias __attribute__((may_alias));

void *memset(void *dst, int c, size_t n);

void *memset(void *dst, int c, size_t n)
{
    unsigned char *d = (unsigned char *)dst;
    const uint32_t v = 0x01010101u * (uint8_t)c;
    for (; n > 0u && ((uintptr_t)d & 3u) != 0u; --n)
    {
        *d++ = (unsigned char)c;
    }
    for (; n >= 16u; n -= 16u, d += 16)
    {
        u32_alias *w = (u32_alias *)(void *)d;
        w[0] = v;
        w[1] = v;
        w[2] = v;
        w[3] = v;
    }
    for (; n >= 4u; n -= 4u, d += 4)
    {
        *(u32_alias *)(void *)d = v;
    }
    for (; n > 0u; --n)
    {
        *d++ = (unsigned char)c;
    }
    return dst;
}
