/* SPDX-License-Identifier: MIT */
/* Portable int8 dense kernels of the integer PointNets (internal/lidet_pointnet_q_internal.h); reference:
 * codegen/lidet_ref/pointnet_q.py (dense_acc, requant). Plain C99, integers only: int8 x int8 (or
 * int16 x int8) products summed in int32 (one 32-bit multiply-add per weight on a Cortex-M0+), one 64-bit
 * requantization per output value. Weights [in][out] as the float kernel: the innermost loop runs over the
 * output channels of one weight row (unit stride; compilers vectorise it on hosts, and x86-64 host builds also
 * get an AVX2 variant, LIDET_NN_KERNEL: integer sums are exact, so every variant gives the same bits). */
#include "internal/lidet_nn.h"
#include "internal/lidet_pointnet_q_internal.h"
#include "internal/lidet_q_gpr.h" /* first: no FPU register for 64-bit integers */
#include "internal/lidet_qmath.h"
#include <string.h>

#if defined(__GNUC__)
#define S8_ALWAYS_INLINE static inline __attribute__((always_inline))
#else
#define S8_ALWAYS_INLINE static inline
#endif

/* rows r..r+3 of acc += in rows * W: four rows share each weight load */
static inline void rows4_s8(const int8_t *x, uint32_t n_in, const int8_t *w_t, uint32_t n_out,
                            int32_t *restrict a0)
{
    int32_t *restrict a1 = a0 + n_out;
    int32_t *restrict a2 = a1 + n_out;
    int32_t *restrict a3 = a2 + n_out;
    uint32_t i, o;
    for (i = 0; i < n_in; ++i)
    {
        const int8_t *restrict w = w_t + i * n_out;
        const int32_t x0 = x[i], x1 = x[n_in + i], x2 = x[2u * n_in + i], x3 = x[3u * n_in + i];
        for (o = 0; o < n_out; ++o)
        {
            const int32_t wv = w[o];
            a0[o] += x0 * wv;
            a1[o] += x1 * wv;
            a2[o] += x2 * wv;
            a3[o] += x3 * wv;
        }
    }
}

LIDET_NN_KERNEL void lidet__nn_acc_s8_rows4(const int8_t *in, uint32_t n_rows, uint32_t n_in,
                                            const int8_t *w_t, const int32_t *b, uint32_t n_out, int32_t *acc)
{
    const uint32_t n4 = n_rows & ~3u;
    uint32_t r, o;
    for (r = 0; r < n4; ++r)
    {
        for (o = 0; o < n_out; ++o)
        {
            acc[r * n_out + o] = b[o];
        }
    }
    for (r = 0; r < n4; r += 4u)
    {
        rows4_s8(in + r * n_in, n_in, w_t, n_out, acc + r * n_out);
    }
    if (n4 < n_rows) /* the last rows: the output-inner loop */
    {
        lidet__nn_acc_s8_cols(in + n4 * n_in, n_rows - n4, n_in, w_t, b, n_out, n_out, acc + n4 * n_out,
                              n_out);
    }
}

/* The accumulation has several kernels with the same results (int32 sums of exact products: the order does not
 * matter): lidet__nn_acc_s8_rows4 above (four rows share each weight row, output-inner and unit-stride: what
 * host compilers vectorise, with an AVX2 clone on x86-64), the plain output-inner loop on a column slice (the
 * blocked kernels' leftovers), two register-blocked ones for 32-bit cores, which keep 2 x 2 or 4 x 2 (points x
 * output channels) accumulators in registers and load each weight once per block of points (2.75 instead of 4.5
 * instructions per multiply-add on a Cortex-M3, 3.5 instead of 6 on RV32IM, counted in the compilers' inner
 * loops), the form of the output-inner loop that skips the inputs at a ReLU's zero point, -128
 * (lidet__nn_acc_s8_skip: 5.5 instructions per multiply-add on ARMv6-M, 40-50 % of them skipped), and the list
 * kernel below, the default of the cores without the DSP extension: one point at a time over the list of its
 * inputs off -128, a block of output channels' sums in registers (per multiply-add left: 3.3 instructions on
 * RV32IM, 2.6 on a Cortex-M3, 4.1 on ARMv6-M). Cores with the DSP extension (Cortex-M4, M7, M33 with DSP:
 * __ARM_FEATURE_DSP) take lidet__nn_acc_s8_dsp below, two multiply-adds per SMLAD. LIDET_NN_S8_KERNEL
 * (lidet_opt.h) picks one by name: LIDET_NN_S8_KERNEL_ROWS4 (rows4), _COLS (output-inner; the skipping form for
 * layers of LIDET_NN_S8_SKIP_MIN_ROWS rows or more), _DSP, _R2O2 (2 x 2), _R4O2 (4 x 2) or _LIST; its default is
 * the target's as above. Layers whose model carries the packed int16 copy of the weights (w_pk: the generated
 * models on DSP cores) take the packed kernel and the fused pass further below instead (about 0.75 instead of 1.5
 * instructions per multiply-add). tests/unit/test_nn_s8.c checks that all agree (on the host the DSP kernels run
 * on a C model of the three instructions they use). */

void lidet__nn_acc_s8_r4o2(const int8_t *in, uint32_t n_rows, uint32_t n_in, const int8_t *w_t,
                           const int32_t *b, uint32_t n_out, int32_t *acc)
{
    uint32_t r, i, o;
    for (r = 0; r + 4u <= n_rows; r += 4u)
    {
        const int8_t *x0 = in + r * n_in;
        int32_t *a0 = acc + r * n_out;
        for (o = 0; o + 2u <= n_out; o += 2u)
        {
            int32_t s0 = b[o], s1 = s0, s2 = s0, s3 = s0, t0 = b[o + 1u], t1 = t0, t2 = t0, t3 = t0;
            const int8_t *w = w_t + o, *x = x0;
            for (i = 0; i < n_in; ++i, w += n_out, ++x)
            {
                const int32_t w0 = w[0], w1 = w[1];
                const int32_t v0 = x[0], v1 = x[n_in], v2 = x[2u * n_in], v3 = x[3u * n_in];
                s0 += v0 * w0;
                s1 += v1 * w0;
                s2 += v2 * w0;
                s3 += v3 * w0;
                t0 += v0 * w1;
                t1 += v1 * w1;
                t2 += v2 * w1;
                t3 += v3 * w1;
            }
            a0[o] = s0;
            a0[n_out + o] = s1;
            a0[2u * n_out + o] = s2;
            a0[3u * n_out + o] = s3;
            a0[o + 1u] = t0;
            a0[n_out + o + 1u] = t1;
            a0[2u * n_out + o + 1u] = t2;
            a0[3u * n_out + o + 1u] = t3;
        }
        if (o < n_out)
        {
            lidet__nn_acc_s8_cols(x0, 4u, n_in, w_t + o, b + o, 1u, n_out, a0 + o, n_out);
        }
    }
    if (r < n_rows)
    {
        lidet__nn_acc_s8_cols(in + r * n_in, n_rows - r, n_in, w_t, b, n_out, n_out, acc + r * n_out, n_out);
    }
}

/* The list kernel, for cores without the DSP extension (RV32IM, Cortex-M3, ARMv6-M): one point at a time, a block
 * of output channels' sums in registers over a list of the point's inputs, each entry the offset of its weight row
 * and its value. In layers of LIST_MIN_ROWS rows or more the list holds only the inputs off -128 (a ReLU's zero
 * point: 40-50 % of a hidden layer's), with u = x + 128 and the bias less 128 sum w (lidet__nn_acc_s8_skip's form,
 * made once per call in the first row's accumulators; every row starts from them, the first row last); in smaller
 * layers every input but the zero ones, with x and the bias. Per entry, in the inner loops: RV32IM (GCC's), 16
 * channels: 2 loads, an add, 16 LB, 16 MUL, 16 ADD, the pointer's add and the branch, 53 instructions per 16
 * multiply-adds (3.3; R4O2: 3.5 per multiply-add, none skipped). Cortex-M3 (Thumb-2 assembly), 8 channels: a
 * post-indexed LDRH, LDRSH, an add, 8 LDRSB and 8 MLA, compare and branch, 21 per 8 (2.6; R2O2: 2.75, none
 * skipped). ARMv6-M (Thumb-1 assembly), 8 channels, six sums in high registers and LR: 2 loads and the end's test
 * (the entry of value 0 that ends the list), 8 LDRSB (register offset, the row's offset against the bases of
 * channels 0 and 4, stepped 3 times), 8 MULS, 8 ADD and 2 for the loop, 33 per 8 (4.1; x sign-extended, 34; the
 * skip kernel's loop: 5.5). The last shared layer's rows fold into the running maximum instead of being written
 * (lidet__nn_acc_s8_list_max). Exact integer sums: the same results as the other kernels. */
#define LIST_CHUNK 64u /* inputs per list: 256 bytes of stack */
/* the fewest rows that skip (per scan, ARMv6-M: 2 and 4 rows 0.03 % and 0.005 % more instructions; RV32: 2 and 8
 * 0.04 % more; Cortex-M3: 2 as many, 8 0.8 % more) */
#if defined(__ARM_ARCH_6M__)
#define LIST_MIN_ROWS 3u
#else
#define LIST_MIN_ROWS 4u
#endif
/* 16 channels a pass where the core has the registers (RV32: 31), else 8 (32-bit Arm: 13) */
#if defined(__arm__)
#define LIST_W16 0
#else
#define LIST_W16 1
#endif
/* the 8-channel loop in Thumb-2 assembly (GCC, 32-bit Arm without the DSP extension; optimised builds: it takes 14
 * registers, the frame pointer's among them) */
#if defined(__thumb2__) && !(defined(__ARM_FEATURE_DSP) && __ARM_FEATURE_DSP) && defined(__GNUC__) &&        \
    !defined(__clang__) && defined(__OPTIMIZE__) && LIDET_NN_PK_ASM
#define LIST_T2_ASM 1
#else
#define LIST_T2_ASM 0
#endif
/* the Thumb-1 assembly loops (GCC: its inline assembly is in divided syntax unless -masm-syntax-unified; optimised
 * builds but -Os: they take the 8 low registers and 5 high ones, which GCC 12 finds at -O1, -O2, -O3, not at -Os) */
#if defined(__ARM_ARCH_6M__) && defined(__GNUC__) && !defined(__clang__) && defined(__OPTIMIZE__) &&         \
    !defined(__OPTIMIZE_SIZE__) && LIDET_NN_PK_ASM
#define LIST_T1_ASM 1
#else
#define LIST_T1_ASM 0
#endif

typedef struct
{
    uint16_t off; /* the weight row's offset, i n_out */
    int16_t v;    /* x + 128, or x */
} list_ent_t;

/* the entries of inputs x[0..n) (weight rows from off, n_out apart): value x + add, the zero ones left out */
S8_ALWAYS_INLINE list_ent_t *list_make(const int8_t *x, uint32_t n, uint32_t off, uint32_t n_out, int32_t add,
                                       list_ent_t *l)
{
    const int8_t *const end = x + n;
    for (; x != end; ++x, off += n_out)
    {
        const int32_t v = (int32_t)*x + add;
        if (v != 0)
        {
            l->off = (uint16_t)off;
            l->v = (int16_t)v;
            ++l;
        }
    }
    return l;
}

/* GCC's scheduling before register allocation hoists the 16 loads above the products and spills the sums (RV32: 2
 * loads and 2 stores more per multiply-add): off in the 16-channel loops */
#if defined(__GNUC__) && !defined(__clang__)
#define LIST_NO_SCHED __attribute__((optimize("no-schedule-insns")))
#else
#define LIST_NO_SCHED
#endif

#if LIST_W16
/* a[0..15] = c[0..15] + sum over the entries e of e.v * w[e.off + 0..15] (a may be c; e != end) */
S8_ALWAYS_INLINE void list_run16_body(const list_ent_t *e, const list_ent_t *end, const int8_t *w,
                                      const int32_t *c, int32_t *a, const int fold)
{
    int32_t s0 = c[0], s1 = c[1], s2 = c[2], s3 = c[3], s4 = c[4], s5 = c[5], s6 = c[6], s7 = c[7];
    int32_t s8 = c[8], s9 = c[9], s10 = c[10], s11 = c[11], s12 = c[12], s13 = c[13], s14 = c[14],
            s15 = c[15];
    do
    {
        const int8_t *p = w + e->off;
        const int32_t v = e->v;
        s0 += v * p[0];
        s1 += v * p[1];
        s2 += v * p[2];
        s3 += v * p[3];
        s4 += v * p[4];
        s5 += v * p[5];
        s6 += v * p[6];
        s7 += v * p[7];
        s8 += v * p[8];
        s9 += v * p[9];
        s10 += v * p[10];
        s11 += v * p[11];
        s12 += v * p[12];
        s13 += v * p[13];
        s14 += v * p[14];
        s15 += v * p[15];
    } while (++e != end);
    if (fold) /* into the running maximum */
    {
        a[0] = a[0] > s0 ? a[0] : s0;
        a[1] = a[1] > s1 ? a[1] : s1;
        a[2] = a[2] > s2 ? a[2] : s2;
        a[3] = a[3] > s3 ? a[3] : s3;
        a[4] = a[4] > s4 ? a[4] : s4;
        a[5] = a[5] > s5 ? a[5] : s5;
        a[6] = a[6] > s6 ? a[6] : s6;
        a[7] = a[7] > s7 ? a[7] : s7;
        a[8] = a[8] > s8 ? a[8] : s8;
        a[9] = a[9] > s9 ? a[9] : s9;
        a[10] = a[10] > s10 ? a[10] : s10;
        a[11] = a[11] > s11 ? a[11] : s11;
        a[12] = a[12] > s12 ? a[12] : s12;
        a[13] = a[13] > s13 ? a[13] : s13;
        a[14] = a[14] > s14 ? a[14] : s14;
        a[15] = a[15] > s15 ? a[15] : s15;
    }
    else
    {
        a[0] = s0;
        a[1] = s1;
        a[2] = s2;
        a[3] = s3;
        a[4] = s4;
        a[5] = s5;
        a[6] = s6;
        a[7] = s7;
        a[8] = s8;
        a[9] = s9;
        a[10] = s10;
        a[11] = s11;
        a[12] = s12;
        a[13] = s13;
        a[14] = s14;
        a[15] = s15;
    }
}

LIST_NO_SCHED static void list_run16(const list_ent_t *e, const list_ent_t *end, const int8_t *w,
                                     const int32_t *c, int32_t *a)
{
    list_run16_body(e, end, w, c, a, 0);
}

/* the same, a[k] the larger of itself and the sum (the last shared layer's maximum) */
LIST_NO_SCHED static void list_run16_max(const list_ent_t *e, const list_ent_t *end, const int8_t *w,
                                         const int32_t *c, int32_t *a)
{
    list_run16_body(e, end, w, c, a, 1);
}

#endif

#if LIST_T1_ASM
#if defined(__ARM_ASM_SYNTAX_UNIFIED__)
#define LIST_T1_SYNTAX_END ""
#else
#define LIST_T1_SYNTAX_END ".syntax divided\n\t"
#endif
/* ARMv6-M's 8-channel loop (list_run8_body), EXT after the value's load */
#define LIST_T1_RUN8(EXT)                                                                                    \
    __asm__ volatile(                                                                                        \
        ".syntax unified\n\t"                                                                                \
        "mov lr, %[s4]\n\t"                                                                                  \
        "1:\n\t"                                                                                             \
        "ldrh %[u], [%[e], #2]\n\t" EXT "cmp %[u], #0\n\t"                                                   \
        "beq 2f\n\t"                                                                                         \
        "ldrh %[off], [%[e], #0]\n\t"                                                                        \
        "ldrsb %[s4], [%[w0], %[off]]\n\t"                                                                   \
        "muls %[s4], %[u], %[s4]\n\t"                                                                        \
        "add %[s0], %[s4]\n\t"                                                                               \
        "ldrsb %[s4], [%[w4], %[off]]\n\t"                                                                   \
        "muls %[s4], %[u], %[s4]\n\t"                                                                        \
        "add lr, %[s4]\n\t"                                                                                  \
        "adds %[off], %[off], #1\n\t"                                                                        \
        "ldrsb %[s4], [%[w0], %[off]]\n\t"                                                                   \
        "muls %[s4], %[u], %[s4]\n\t"                                                                        \
        "add %[s1], %[s4]\n\t"                                                                               \
        "ldrsb %[s4], [%[w4], %[off]]\n\t"                                                                   \
        "muls %[s4], %[u], %[s4]\n\t"                                                                        \
        "add %[s5], %[s4]\n\t"                                                                               \
        "adds %[off], %[off], #1\n\t"                                                                        \
        "ldrsb %[s4], [%[w0], %[off]]\n\t"                                                                   \
        "muls %[s4], %[u], %[s4]\n\t"                                                                        \
        "add %[s2], %[s4]\n\t"                                                                               \
        "ldrsb %[s4], [%[w4], %[off]]\n\t"                                                                   \
        "muls %[s4], %[u], %[s4]\n\t"                                                                        \
        "adds %[s6], %[s6], %[s4]\n\t"                                                                       \
        "adds %[off], %[off], #1\n\t"                                                                        \
        "ldrsb %[s4], [%[w0], %[off]]\n\t"                                                                   \
        "muls %[s4], %[u], %[s4]\n\t"                                                                        \
        "add %[s3], %[s4]\n\t"                                                                               \
        "ldrsb %[s4], [%[w4], %[off]]\n\t"                                                                   \
        "muls %[s4], %[u], %[s4]\n\t"                                                                        \
        "adds %[s7], %[s7], %[s4]\n\t"                                                                       \
        "adds %[e], %[e], #4\n\t"                                                                            \
        "b 1b\n\t"                                                                                           \
        "2:\n\t"                                                                                             \
        "mov %[s4], lr\n\t" LIST_T1_SYNTAX_END                                                               \
        : [s0] "+h"(s0), [s1] "+h"(s1), [s2] "+h"(s2), [s3] "+h"(s3), [s5] "+h"(s5), [s4] "+l"(s4),          \
          [s6] "+l"(s6), [s7] "+l"(s7), [e] "+l"(e), [u] "=&l"(u), [off] "=&l"(off)                          \
        : [w0] "l"(w), [w4] "l"(w4)                                                                          \
        : "cc", "memory", "lr")
/* ARMv6-M's 4-channel loop (list_run4), EXT after the value's load */
#define LIST_T1_RUN4(EXT)                                                                                    \
    __asm__ volatile(".syntax unified\n\t"                                                                   \
                     "1:\n\t"                                                                                \
                     "ldrh %[off], [%[e], #0]\n\t"                                                           \
                     "ldrh %[u], [%[e], #2]\n\t" EXT "ldrsb %[t], [%[w0], %[off]]\n\t"                       \
                     "muls %[t], %[u], %[t]\n\t"                                                             \
                     "add %[s0], %[t]\n\t"                                                                   \
                     "ldrsb %[t], [%[w1], %[off]]\n\t"                                                       \
                     "muls %[t], %[u], %[t]\n\t"                                                             \
                     "add %[s1], %[t]\n\t"                                                                   \
                     "ldrsb %[t], [%[w2], %[off]]\n\t"                                                       \
                     "muls %[t], %[u], %[t]\n\t"                                                             \
                     "add %[s2], %[t]\n\t"                                                                   \
                     "ldrsb %[t], [%[w3], %[off]]\n\t"                                                       \
                     "muls %[t], %[u], %[t]\n\t"                                                             \
                     "add %[s3], %[t]\n\t"                                                                   \
                     "adds %[e], %[e], #4\n\t"                                                               \
                     "cmp %[e], %[end]\n\t"                                                                  \
                     "bne 1b\n\t" LIST_T1_SYNTAX_END                                                         \
                     : [s0] "+h"(s0), [s1] "+h"(s1), [s2] "+h"(s2), [s3] "+h"(s3), [e] "+l"(e),              \
                       [t] "=&l"(t), [u] "=&l"(u), [off] "=&l"(off)                                          \
                     : [w0] "l"(w0), [w1] "l"(w1), [w2] "l"(w2), [w3] "l"(w3), [end] "h"(end)                \
                     : "cc", "memory")
#endif

/* the same for 8 channels (ARMv6-M: the list ends in an entry of v = 0 at end, u being 1..255) */
S8_ALWAYS_INLINE void list_run8_body(const list_ent_t *e, const list_ent_t *end, const int8_t *w,
                                     const int32_t *c, int32_t *a, const int fold, const int sgn)
{
    int32_t s0 = c[0], s1 = c[1], s2 = c[2], s3 = c[3], s4 = c[4], s5 = c[5], s6 = c[6], s7 = c[7];
#if LIST_T1_ASM
    const int8_t *const w4 = w + 4;
    uint32_t u, off;
    (void)end;
    /* channels k and k + 4 from the bases w and w + 4, the offset stepped by one between; five sums in high
     * registers (GCC gives no more), two in low ones and s4 in LR (its own register the product's meanwhile); no
     * register left for the end: the loop stops on the entry of u = 0 (per entry 33 instructions, 1 fewer than two
     * passes of list_run4, and half the passes) */
    if (sgn) /* x: a halfword sign-extended */
    {
        LIST_T1_RUN8("sxth %[u], %[u]\n\t");
    }
    else
    {
        LIST_T1_RUN8("");
    }
#elif LIST_T2_ASM
    uint32_t v, p, t;
    (void)sgn;
    /* the 14 registers: 8 sums, the entry, its end, the weights, the value, the row and the weight (GCC: 24
     * instructions per entry, the end reloaded from the stack) */
    __asm__ volatile(
        "1:\n\t"
        "ldrh %[p], [%[e]], #4\n\t"
        "ldrsh %[v], [%[e], #-2]\n\t"
        "add %[p], %[w], %[p]\n\t"
        "ldrsb %[t], [%[p]]\n\t"
        "mla %[s0], %[v], %[t], %[s0]\n\t"
        "ldrsb %[t], [%[p], #1]\n\t"
        "mla %[s1], %[v], %[t], %[s1]\n\t"
        "ldrsb %[t], [%[p], #2]\n\t"
        "mla %[s2], %[v], %[t], %[s2]\n\t"
        "ldrsb %[t], [%[p], #3]\n\t"
        "mla %[s3], %[v], %[t], %[s3]\n\t"
        "ldrsb %[t], [%[p], #4]\n\t"
        "mla %[s4], %[v], %[t], %[s4]\n\t"
        "ldrsb %[t], [%[p], #5]\n\t"
        "mla %[s5], %[v], %[t], %[s5]\n\t"
        "ldrsb %[t], [%[p], #6]\n\t"
        "mla %[s6], %[v], %[t], %[s6]\n\t"
        "ldrsb %[t], [%[p], #7]\n\t"
        "mla %[s7], %[v], %[t], %[s7]\n\t"
        "cmp %[e], %[end]\n\t"
        "bne 1b\n\t"
        : [s0] "+r"(s0), [s1] "+r"(s1), [s2] "+r"(s2), [s3] "+r"(s3), [s4] "+r"(s4), [s5] "+r"(s5),
          [s6] "+r"(s6), [s7] "+r"(s7), [e] "+r"(e), [v] "=&r"(v), [p] "=&r"(p), [t] "=&r"(t)
        : [w] "r"(w), [end] "r"(end)
        : "cc", "memory");
#else
    (void)sgn;
    do
    {
        const int8_t *p = w + e->off;
        const int32_t v = e->v;
        s0 += v * p[0];
        s1 += v * p[1];
        s2 += v * p[2];
        s3 += v * p[3];
        s4 += v * p[4];
        s5 += v * p[5];
        s6 += v * p[6];
        s7 += v * p[7];
    } while (++e != end);
#endif
    if (fold) /* into the running maximum */
    {
        a[0] = a[0] > s0 ? a[0] : s0;
        a[1] = a[1] > s1 ? a[1] : s1;
        a[2] = a[2] > s2 ? a[2] : s2;
        a[3] = a[3] > s3 ? a[3] : s3;
        a[4] = a[4] > s4 ? a[4] : s4;
        a[5] = a[5] > s5 ? a[5] : s5;
        a[6] = a[6] > s6 ? a[6] : s6;
        a[7] = a[7] > s7 ? a[7] : s7;
    }
    else
    {
        a[0] = s0;
        a[1] = s1;
        a[2] = s2;
        a[3] = s3;
        a[4] = s4;
        a[5] = s5;
        a[6] = s6;
        a[7] = s7;
    }
}

LIST_NO_SCHED static void list_run8(const list_ent_t *e, const list_ent_t *end, const int8_t *w,
                                    const int32_t *c, int32_t *a)
{
    list_run8_body(e, end, w, c, a, 0, 0);
}

#if LIST_T1_ASM
/* the same for values x (not u): ARMv6-M's rows that do not skip */
static void list_run8_s(const list_ent_t *e, const list_ent_t *end, const int8_t *w, const int32_t *c,
                        int32_t *a)
{
    list_run8_body(e, end, w, c, a, 0, 1);
}
#endif

/* the same, a[k] the larger of itself and the sum (the last shared layer's maximum) */
LIST_NO_SCHED static void list_run8_max(const list_ent_t *e, const list_ent_t *end, const int8_t *w,
                                        const int32_t *c, int32_t *a)
{
    list_run8_body(e, end, w, c, a, 1, 0);
}

/* the same for 4 channels (e != end; on ARMv6-M sgn: the entries' v are x, else u = x + 128) */
S8_ALWAYS_INLINE void list_run4(const list_ent_t *e, const list_ent_t *end, const int8_t *w, const int32_t *c,
                                int32_t *a, const int fold, const int sgn)
{
    int32_t s0 = c[0], s1 = c[1], s2 = c[2], s3 = c[3];
#if LIST_T1_ASM
    const int8_t *const w0 = w, *const w1 = w + 1, *const w2 = w + 2, *const w3 = w + 3;
    uint32_t t, u, off;
    /* the sums in high registers (ADD takes them), the 4 channels' bases, the offset, the value and the product in
     * the 8 low ones */
    if (sgn) /* x: a halfword sign-extended */
    {
        LIST_T1_RUN4("sxth %[u], %[u]\n\t");
    }
    else
    {
        LIST_T1_RUN4("");
    }
#else
    (void)sgn;
    do
    {
        const int8_t *p = w + e->off;
        const int32_t v = e->v;
        s0 += v * p[0];
        s1 += v * p[1];
        s2 += v * p[2];
        s3 += v * p[3];
    } while (++e != end);
#endif
    if (fold) /* into the running maximum */
    {
        a[0] = a[0] > s0 ? a[0] : s0;
        a[1] = a[1] > s1 ? a[1] : s1;
        a[2] = a[2] > s2 ? a[2] : s2;
        a[3] = a[3] > s3 ? a[3] : s3;
    }
    else
    {
        a[0] = s0;
        a[1] = s1;
        a[2] = s2;
        a[3] = s3;
    }
}

/* one row: a[o] = c[o] + sum over the entries of v w[off + o], o < n_out (a may be c); fold: a[o] the larger of
 * itself and that */
S8_ALWAYS_INLINE void list_row_body(const list_ent_t *e, const list_ent_t *end, const int8_t *w_t,
                                    const int32_t *c, uint32_t n_out, int32_t *a, const int fold,
                                    const int sgn)
{
    uint32_t o = 0;
    if (e == end) /* nothing to add */
    {
        for (; o < n_out; ++o)
        {
            a[o] = fold && a[o] > c[o] ? a[o] : c[o];
        }
        return;
    }
#if LIST_W16
    for (; o + 16u <= n_out; o += 16u)
    {
        if (fold)
        {
            list_run16_max(e, end, w_t + o, c + o, a + o);
        }
        else
        {
            list_run16(e, end, w_t + o, c + o, a + o);
        }
    }
#endif
    for (; o + 8u <= n_out; o += 8u)
    {
#if LIST_T1_ASM
        if (sgn)
        {
            list_run8_s(e, end, w_t + o, c + o, a + o);
            continue;
        }
#endif
        if (fold)
        {
            list_run8_max(e, end, w_t + o, c + o, a + o);
        }
        else
        {
            list_run8(e, end, w_t + o, c + o, a + o);
        }
    }
    for (; o + 4u <= n_out; o += 4u)
    {
        list_run4(e, end, w_t + o, c + o, a + o, fold, sgn);
    }
    for (; o < n_out; ++o)
    {
        const list_ent_t *f;
        int32_t s = c[o];
        for (f = e; f != end; ++f)
        {
            s += f->v * (int32_t)w_t[f->off + o];
        }
        a[o] = fold && a[o] > s ? a[o] : s;
    }
}

static void list_row(const list_ent_t *e, const list_ent_t *end, const int8_t *w_t, const int32_t *c,
                     uint32_t n_out, int32_t *a)
{
    list_row_body(e, end, w_t, c, n_out, a, 0, 0);
}

#if LIST_T1_ASM
/* the same for values x: the rows that do not skip */
static void list_row_s(const list_ent_t *e, const list_ent_t *end, const int8_t *w_t, const int32_t *c,
                       uint32_t n_out, int32_t *a)
{
    list_row_body(e, end, w_t, c, n_out, a, 0, 1);
}
#endif

static void list_row_max(const list_ent_t *e, const list_ent_t *end, const int8_t *w_t, const int32_t *c,
                         uint32_t n_out, int32_t *a)
{
    list_row_body(e, end, w_t, c, n_out, a, 1, 0);
}

#if LIST_W16
/* a[0..15] = b[0..15] - 128 sum_i w[i n_out + 0..15], i < n_in: the skipping rows' starting sums (a load and an add
 * per weight) */
LIST_NO_SCHED static void list_bias16(const int8_t *w, uint32_t n_in, uint32_t n_out, const int32_t *b,
                                      int32_t *a)
{
    int32_t s0 = 0, s1 = 0, s2 = 0, s3 = 0, s4 = 0, s5 = 0, s6 = 0, s7 = 0;
    int32_t s8 = 0, s9 = 0, s10 = 0, s11 = 0, s12 = 0, s13 = 0, s14 = 0, s15 = 0;
    const int8_t *const end = w + n_in * n_out;
    for (; w != end; w += n_out)
    {
        s0 += w[0];
        s1 += w[1];
        s2 += w[2];
        s3 += w[3];
        s4 += w[4];
        s5 += w[5];
        s6 += w[6];
        s7 += w[7];
        s8 += w[8];
        s9 += w[9];
        s10 += w[10];
        s11 += w[11];
        s12 += w[12];
        s13 += w[13];
        s14 += w[14];
        s15 += w[15];
    }
    a[0] = b[0] - s0 * 128;
    a[1] = b[1] - s1 * 128;
    a[2] = b[2] - s2 * 128;
    a[3] = b[3] - s3 * 128;
    a[4] = b[4] - s4 * 128;
    a[5] = b[5] - s5 * 128;
    a[6] = b[6] - s6 * 128;
    a[7] = b[7] - s7 * 128;
    a[8] = b[8] - s8 * 128;
    a[9] = b[9] - s9 * 128;
    a[10] = b[10] - s10 * 128;
    a[11] = b[11] - s11 * 128;
    a[12] = b[12] - s12 * 128;
    a[13] = b[13] - s13 * 128;
    a[14] = b[14] - s14 * 128;
    a[15] = b[15] - s15 * 128;
}

#endif

#if !LIST_T1_ASM
/* the same for 8 channels */
LIST_NO_SCHED static void list_bias8(const int8_t *w, uint32_t n_in, uint32_t n_out, const int32_t *b,
                                     int32_t *a)
{
    int32_t s0 = 0, s1 = 0, s2 = 0, s3 = 0, s4 = 0, s5 = 0, s6 = 0, s7 = 0;
    const int8_t *const end = w + n_in * n_out;
    for (; w != end; w += n_out)
    {
        s0 += w[0];
        s1 += w[1];
        s2 += w[2];
        s3 += w[3];
        s4 += w[4];
        s5 += w[5];
        s6 += w[6];
        s7 += w[7];
    }
    a[0] = b[0] - s0 * 128;
    a[1] = b[1] - s1 * 128;
    a[2] = b[2] - s2 * 128;
    a[3] = b[3] - s3 * 128;
    a[4] = b[4] - s4 * 128;
    a[5] = b[5] - s5 * 128;
    a[6] = b[6] - s6 * 128;
    a[7] = b[7] - s7 * 128;
}
#endif

/* acc[0..n_out) = b - 128 sum_i w[i n_out + o] */
static void list_bias(const int8_t *w_t, uint32_t n_in, const int32_t *b, uint32_t n_out, int32_t *acc,
                      list_ent_t *list)
{
    uint32_t o = 0, i0;
#if LIST_T1_ASM
    /* 128 sum w with the list kernel (u = 128 for every input), then b less it */
    for (; o < n_out; ++o)
    {
        acc[o] = 0;
    }
    for (i0 = 0; i0 < n_in; i0 += LIST_CHUNK)
    {
        const uint32_t n = n_in - i0 < LIST_CHUNK ? n_in - i0 : LIST_CHUNK;
        uint32_t i;
        for (i = 0; i < n; ++i)
        {
            list[i].off = (uint16_t)((i0 + i) * n_out);
            list[i].v = 128;
        }
        list[n].v = 0; /* the end's mark */
        list_row(list, list + n, w_t, acc, n_out, acc);
    }
    for (o = 0; o < n_out; ++o)
    {
        acc[o] = b[o] - acc[o];
    }
#else
    (void)list;
#if LIST_W16
    for (; o + 16u <= n_out; o += 16u)
    {
        list_bias16(w_t + o, n_in, n_out, b + o, acc + o);
    }
#endif
    for (; o + 8u <= n_out; o += 8u)
    {
        list_bias8(w_t + o, n_in, n_out, b + o, acc + o);
    }
    for (; o < n_out; ++o)
    {
        int32_t c = b[o];
        for (i0 = 0; i0 < n_in; ++i0)
        {
            c -= 128 * (int32_t)w_t[i0 * n_out + o];
        }
        acc[o] = c;
    }
#endif
}

/* lidet__nn_acc_s8_list, or (vmax != NULL, skipping rows only) each row's sums folded into vmax, acc scratch;
 * b_list: the skipping rows' starting sums b - 128 sum w (NULL: summed here into the first row's accumulators) */
static void acc_list(const int8_t *in, uint32_t n_rows, uint32_t n_in, const int8_t *w_t, const int32_t *b,
                     const int32_t *b_list, uint32_t n_out, int32_t *acc, int32_t *vmax)
{
    list_ent_t list[LIST_CHUNK + 1u]; /* and the end's mark */
    const int skip = n_rows >= LIST_MIN_ROWS;
    const int32_t *start = b_list != 0 ? b_list : acc;
    uint32_t r, i0;
    if (skip && b_list == 0) /* the first row's accumulators: b - 128 sum w */
    {
        list_bias(w_t, n_in, b, n_out, acc, list);
    }
    for (r = n_rows; r-- > 0u;) /* the last row first: row 0 keeps the starting sums until the end */
    {
        const int8_t *x = in + r * n_in;
        /* folded: the sums of a row of several lists in row 1 (free: no row is written) */
        int32_t *a = vmax != 0 ? acc + n_out : acc + r * n_out;
        for (i0 = 0; i0 < n_in; i0 += LIST_CHUNK)
        {
            const uint32_t n = n_in - i0 < LIST_CHUNK ? n_in - i0 : LIST_CHUNK;
            const int last = i0 + n == n_in;
            list_ent_t *const end = skip ? list_make(x + i0, n, i0 * n_out, n_out, 128, list)
                                         : list_make(x + i0, n, i0 * n_out, n_out, 0, list);
#if LIST_T1_ASM
            end->v = 0; /* the end's mark */
#endif
            const int32_t *const c = i0 == 0u ? (skip ? start : b) : a;
            if (vmax != 0 && last)
            {
                list_row_max(list, end, w_t, c, n_out, vmax);
            }
#if LIST_T1_ASM
            else if (!skip)
            {
                list_row_s(list, end, w_t, c, n_out, a);
            }
#endif
            else
            {
                list_row(list, end, w_t, c, n_out, a);
            }
        }
    }
}

/* whether the list kernel takes the layer: its entries' offsets in 16 bits */
static int list_fits(uint32_t n_in, uint32_t n_out)
{
    return n_in * n_out <= 65536u;
}

void lidet__nn_acc_s8_list(const int8_t *in, uint32_t n_rows, uint32_t n_in, const int8_t *w_t,
                           const int32_t *b, const int32_t *b_list, uint32_t n_out, int32_t *acc)
{
    if (n_rows == 0u)
    {
        return;
    }
    if (!list_fits(n_in, n_out))
    {
#if LIST_T1_ASM
        lidet__nn_acc_s8_cols(in, n_rows, n_in, w_t, b, n_out, n_out, acc, n_out);
#else
        lidet__nn_acc_s8_r4o2(in, n_rows, n_in, w_t, b, n_out, acc);
#endif
        return;
    }
    acc_list(in, n_rows, n_in, w_t, b, b_list, n_out, acc, 0);
}

int lidet__nn_acc_s8_list_max(const int8_t *in, uint32_t n_rows, uint32_t n_in, const int8_t *w_t,
                              const int32_t *b, const int32_t *b_list, uint32_t n_out, int32_t *acc,
                              int32_t *vmax)
{
    if (n_rows < LIST_MIN_ROWS || n_rows < 2u || !list_fits(n_in, n_out))
    {
        return 0;
    }
    acc_list(in, n_rows, n_in, w_t, b, b_list, n_out, acc, vmax);
    return 1;
}

/* The DSP kernel: 2 x 2 (points x output channels) accumulators, 4 inputs per step. One 32-bit load brings 4 int8
 * inputs of a point; SXTB16 widens bytes 0 and 2 (and, rotated by 8, bytes 1 and 3) into two int16 halves:
 * inputs (i, i + 2) and (i + 1, i + 3). The weights lie [in][out]: one halfword load brings channels o, o + 1 of
 * one input, two of them (inputs i and i + 2) make a word whose SXTB16 is channel o's (w_i, w_i+2) and, rotated,
 * channel o + 1's. SMLAD adds both halves' products to an accumulator: 8 SMLAD for 16 multiply-adds, with 6
 * instructions for the inputs and 10 for the weights. Exact int32 sums, so the results equal the other kernels'.
 * Off the DSP cores the three instructions are modelled in C (the host test runs it). */
#if defined(__ARM_FEATURE_DSP) && __ARM_FEATURE_DSP
#include <arm_acle.h>
#define S8_SXTB16(v) ((uint32_t)__sxtb16((int32_t)(v)))
/* SXTB16 with its rotate operand: one instruction (GCC does not fold a separate ROR into it) */
static inline uint32_t S8_SXTB16_ROR8(uint32_t v)
{
    uint32_t r;
    __asm__("sxtb16 %0, %1, ror #8" : "=r"(r) : "r"(v));
    return r;
}
#define S8_SMLAD(a, b, acc) __smlad((int32_t)(a), (int32_t)(b), (acc))
#else
static inline uint32_t s8_half(int32_t v)
{
    return (uint32_t)v & 0xFFFFu;
}
static inline uint32_t S8_SXTB16(uint32_t v)
{
    return s8_half((int8_t)(v & 0xFFu)) | (s8_half((int8_t)((v >> 16) & 0xFFu)) << 16);
}
static inline uint32_t S8_SXTB16_ROR8(uint32_t v)
{
    return S8_SXTB16((v >> 8) | (v << 24));
}
/* The halves sign-extended by shifts (arithmetic, lidet_opt.h), not through int16_t: from int16 x int16 products
 * summed into int32, GCC 12.2 for aarch64 at -O3 makes pk_pair's loop a vectorised widening reduction that drops
 * half the products (clang and -fno-tree-loop-vectorize sum right; test_nn_s8 under qemu-aarch64 found it,
 * tests/aarch64.cmake). Same sums, no int16 in the loop. */
static inline int32_t S8_SMLAD(uint32_t a, uint32_t b, int32_t acc)
{
    const int32_t alo = (int32_t)(a << 16) >> 16, ahi = (int32_t)a >> 16;
    const int32_t blo = (int32_t)(b << 16) >> 16, bhi = (int32_t)b >> 16;
    return acc + alo * blo + ahi * bhi;
}
#endif

/* 4 int8 inputs, little endian (a 32-bit load where the core allows unaligned ones) */
static inline uint32_t s8_load4(const int8_t *p)
{
    return (uint32_t)(uint8_t)p[0] | ((uint32_t)(uint8_t)p[1] << 8) | ((uint32_t)(uint8_t)p[2] << 16) |
           ((uint32_t)(uint8_t)p[3] << 24);
}

/* 2 int8 weights as 16 bits, little endian (a halfword load) */
static inline uint32_t s8_load2(const int8_t *p)
{
    return (uint32_t)(uint8_t)p[0] | ((uint32_t)(uint8_t)p[1] << 8);
}

/* 2 x 2 (points x output channels) accumulators in registers; the first n_simd inputs (a multiple of 4) 4 at a
 * time with SMLAD (the DSP kernels below; 0 elsewhere: a constant, so the loop vanishes; inlined into each, so each
 * is compiled for its own case), the rest one at a time. */

/* 4 inputs of points x0, x1 against channels o, o + 1: [in][out] weights at w (row stride n_out) */
S8_ALWAYS_INLINE void step4_io(const int8_t *x0, const int8_t *x1, const int8_t *w, uint32_t n_out,
                               int32_t *s)
{
    const uint32_t u0 = s8_load4(x0), u1 = s8_load4(x1);
    const uint32_t p02 = S8_SXTB16(u0), p13 = S8_SXTB16_ROR8(u0);
    const uint32_t q02 = S8_SXTB16(u1), q13 = S8_SXTB16_ROR8(u1);
    /* channels o, o + 1 of inputs i and i + 2: bytes (w_i,o, w_i,o+1, w_i+2,o, w_i+2,o+1) */
    uint32_t c = s8_load2(w) | (s8_load2(w + 2u * n_out) << 16), h = S8_SXTB16(c);
    s[0] = S8_SMLAD(p02, h, s[0]);
    s[2] = S8_SMLAD(q02, h, s[2]);
    h = S8_SXTB16_ROR8(c);
    s[1] = S8_SMLAD(p02, h, s[1]);
    s[3] = S8_SMLAD(q02, h, s[3]);
    /* inputs i + 1 and i + 3 */
    c = s8_load2(w + n_out) | (s8_load2(w + 3u * n_out) << 16);
    h = S8_SXTB16(c);
    s[0] = S8_SMLAD(p13, h, s[0]);
    s[2] = S8_SMLAD(q13, h, s[2]);
    h = S8_SXTB16_ROR8(c);
    s[1] = S8_SMLAD(p13, h, s[1]);
    s[3] = S8_SMLAD(q13, h, s[3]);
}

S8_ALWAYS_INLINE void acc_s8_2x2(const int8_t *in, uint32_t n_rows, uint32_t n_in, const int8_t *w_t,
                                 const int32_t *b, uint32_t n_out, int32_t *acc, uint32_t n_simd)
{
    uint32_t r, i, o;
    for (r = 0; r + 2u <= n_rows; r += 2u)
    {
        const int8_t *x0 = in + r * n_in, *x1 = x0 + n_in;
        int32_t *a0 = acc + r * n_out, *a1 = a0 + n_out;
        for (o = 0; o + 2u <= n_out; o += 2u)
        {
            const int8_t *w = w_t + o;
            int32_t s[4];
            s[0] = s[2] = b[o];
            s[1] = s[3] = b[o + 1u];
            for (i = 0; i < n_simd; i += 4u, w += 4u * n_out)
            {
                step4_io(x0 + i, x1 + i, w, n_out, s);
            }
            for (i = n_simd; i < n_in; ++i, w += n_out)
            {
                const int32_t w0 = w[0], w1 = w[1], v0 = x0[i], v1 = x1[i];
                s[0] += v0 * w0;
                s[1] += v0 * w1;
                s[2] += v1 * w0;
                s[3] += v1 * w1;
            }
            a0[o] = s[0];
            a0[o + 1u] = s[1];
            a1[o] = s[2];
            a1[o + 1u] = s[3];
        }
        if (o < n_out) /* an odd last channel */
        {
            lidet__nn_acc_s8_cols(x0, 2u, n_in, w_t + o, b + o, 1u, n_out, a0 + o, n_out);
        }
    }
    if (r < n_rows) /* an odd last row */
    {
        lidet__nn_acc_s8_cols(in + r * n_in, n_rows - r, n_in, w_t, b, n_out, n_out, acc + r * n_out, n_out);
    }
}

void lidet__nn_acc_s8_r2o2(const int8_t *in, uint32_t n_rows, uint32_t n_in, const int8_t *w_t,
                           const int32_t *b, uint32_t n_out, int32_t *acc)
{
    acc_s8_2x2(in, n_rows, n_in, w_t, b, n_out, acc, 0u);
}

void lidet__nn_acc_s8_dsp(const int8_t *in, uint32_t n_rows, uint32_t n_in, const int8_t *w_t,
                          const int32_t *b, uint32_t n_out, int32_t *acc)
{
    acc_s8_2x2(in, n_rows, n_in, w_t, b, n_out, acc, n_in & ~3u);
}

/* The packed DSP kernel: the weights widened to int16 and ordered as the loop reads them
 * (lidet_pointnet_q_layer_t.w_pk, lidet__nn_pack_s8_pk), two points' inputs widened once per pass into a
 * stack buffer. Per 4 inputs of a pair of points and a pair of channels: 4 words of inputs, 4 of weights and 8
 * SMLAD; no SXTB16 in the inner loop (the former [out][in] int8 layout widened inputs and weights there:
 * 23 instructions per 16 multiply-adds on a Cortex-M4, against about 14 here). */
#define PK_CHUNK_GROUPS 16u /* 64 inputs per pass: 256 bytes of widened inputs on the stack */

/* groups g0..g0+n_g of points x0 and x1 (x1 NULL: one point, [A, B] per group; else [A0, A1, B0, B1]),
 * A = (x_i, x_i+2), B = (x_i+1, x_i+3) as SXTB16 widens them */
static void pk_widen(const int8_t *x0, const int8_t *x1, uint32_t n_g, uint32_t *xw)
{
    uint32_t g;
    for (g = 0; g < n_g; ++g)
    {
        const uint32_t u = s8_load4(x0 + 4u * g);
        if (x1 == 0)
        {
            xw[2u * g] = S8_SXTB16(u);
            xw[2u * g + 1u] = S8_SXTB16_ROR8(u);
        }
        else
        {
            const uint32_t v = s8_load4(x1 + 4u * g);
            xw[4u * g] = S8_SXTB16(u);
            xw[4u * g + 1u] = S8_SXTB16(v);
            xw[4u * g + 2u] = S8_SXTB16_ROR8(u);
            xw[4u * g + 3u] = S8_SXTB16_ROR8(v);
        }
    }
}

/* s[0..3] (point 0 channel 0, point 0 channel 1, point 1 channel 0, point 1 channel 1) += n_g >= 1 groups;
 * returns w past them. On the DSP cores in assembly (LIDET_NN_PK_ASM, lidet_opt.h; 0: the C loop below): GCC
 * neither pairs the loads into LDRD nor keeps the four sums in registers across the loop's back edge without
 * copies (19 instructions per group, 13 here) */
S8_ALWAYS_INLINE const uint32_t *pk_pair(const uint32_t *xw, uint32_t n_g, const uint32_t *w, int32_t *s)
{
    int32_t s00 = s[0], s01 = s[1], s10 = s[2], s11 = s[3];
    const uint32_t *const end = xw + 4u * n_g;
#if defined(__ARM_FEATURE_DSP) && __ARM_FEATURE_DSP && defined(__GNUC__) && LIDET_NN_PK_ASM
    uint32_t a0, a1, c0, c1;
    /* one group: inputs A of both points and the two channels' A weights, 4 SMLAD, then the same for B */
#define PK_PAIR_GROUP                                                                                        \
    "ldrd %[a0], %[a1], [%[x]], #8\n\t"                                                                      \
    "ldrd %[c0], %[c1], [%[w]], #8\n\t"                                                                      \
    "smlad %[s00], %[a0], %[c0], %[s00]\n\t"                                                                 \
    "smlad %[s01], %[a0], %[c1], %[s01]\n\t"                                                                 \
    "smlad %[s10], %[a1], %[c0], %[s10]\n\t"                                                                 \
    "smlad %[s11], %[a1], %[c1], %[s11]\n\t"                                                                 \
    "ldrd %[a0], %[a1], [%[x]], #8\n\t"                                                                      \
    "ldrd %[c0], %[c1], [%[w]], #8\n\t"                                                                      \
    "smlad %[s00], %[a0], %[c0], %[s00]\n\t"                                                                 \
    "smlad %[s01], %[a0], %[c1], %[s01]\n\t"                                                                 \
    "smlad %[s10], %[a1], %[c0], %[s10]\n\t"                                                                 \
    "smlad %[s11], %[a1], %[c1], %[s11]\n\t"
#define PK_PAIR_OPERANDS                                                                                     \
    : [s00] "+r"(s00), [s01] "+r"(s01), [s10] "+r"(s10), [s11] "+r"(s11), [x] "+r"(xw), [w] "+r"(w),          \
      [a0] "=&r"(a0), [a1] "=&r"(a1), [c0] "=&r"(c0), [c1] "=&r"(c1)                                          \
    : [end] "r"(end)                                                                                         \
    : "cc", "memory"
    /* one asm statement (two let GCC put the sums in other registers in each, with moves between): an odd group
     * first (the groups' bytes, 16 each, tested in a0 before it is loaded), then two groups per pass, one compare
     * and branch per 32 multiply-adds */
    __asm__ volatile("sub %[a0], %[end], %[x]\n\t"
                     "tst %[a0], #16\n\t"
                     "beq 2f\n\t" PK_PAIR_GROUP "2:\n\t"
                     "cmp %[x], %[end]\n\t"
                     "beq 3f\n\t"
                     "1:\n\t" PK_PAIR_GROUP PK_PAIR_GROUP "cmp %[x], %[end]\n\t"
                     "bne 1b\n\t"
                     "3:\n\t" PK_PAIR_OPERANDS);
#undef PK_PAIR_GROUP
#undef PK_PAIR_OPERANDS
#else
    do
    {
        const uint32_t a0 = xw[0], a1 = xw[1], c0 = w[0], c1 = w[1];
        const uint32_t b0 = xw[2], b1 = xw[3], d0 = w[2], d1 = w[3];
        s00 = S8_SMLAD(a0, c0, s00);
        s01 = S8_SMLAD(a0, c1, s01);
        s10 = S8_SMLAD(a1, c0, s10);
        s11 = S8_SMLAD(a1, c1, s11);
        s00 = S8_SMLAD(b0, d0, s00);
        s01 = S8_SMLAD(b0, d1, s01);
        s10 = S8_SMLAD(b1, d0, s10);
        s11 = S8_SMLAD(b1, d1, s11);
        xw += 4;
        w += 4;
    } while (xw != end);
#endif
    s[0] = s00;
    s[1] = s01;
    s[2] = s10;
    s[3] = s11;
    return w;
}

/* one point: s[0], s[1] (channels 0, 1) += n_g >= 1 groups; returns w past them */
S8_ALWAYS_INLINE const uint32_t *pk_one(const uint32_t *xw, uint32_t n_g, const uint32_t *w, int32_t *s)
{
    int32_t s0 = s[0], s1 = s[1];
    const uint32_t *const end = xw + 2u * n_g;
#if defined(__ARM_FEATURE_DSP) && __ARM_FEATURE_DSP && defined(__GNUC__) && LIDET_NN_PK_ASM
    uint32_t a, b, c0, c1;
    __asm__ volatile("1:\n\t"
                     "ldrd %[a], %[b], [%[x]], #8\n\t"
                     "ldrd %[c0], %[c1], [%[w]], #8\n\t"
                     "smlad %[s0], %[a], %[c0], %[s0]\n\t"
                     "smlad %[s1], %[a], %[c1], %[s1]\n\t"
                     "ldrd %[c0], %[c1], [%[w]], #8\n\t"
                     "smlad %[s0], %[b], %[c0], %[s0]\n\t"
                     "smlad %[s1], %[b], %[c1], %[s1]\n\t"
                     "cmp %[x], %[end]\n\t"
                     "bne 1b\n\t"
                     : [s0] "+r"(s0), [s1] "+r"(s1), [x] "+r"(xw), [w] "+r"(w), [a] "=&r"(a), [b] "=&r"(b),
                       [c0] "=&r"(c0), [c1] "=&r"(c1)
                     : [end] "r"(end)
                     : "cc", "memory");
#else
    do
    {
        const uint32_t a = xw[0], b = xw[1];
        s0 = S8_SMLAD(a, w[0], s0);
        s1 = S8_SMLAD(a, w[1], s1);
        s0 = S8_SMLAD(b, w[2], s0);
        s1 = S8_SMLAD(b, w[3], s1);
        xw += 2;
        w += 4;
    } while (xw != end);
#endif
    s[0] = s0;
    s[1] = s1;
    return w;
}

/* The quad layout of four points' widened inputs: per group [A0 A1 A2 A3 B0 B1 B2 B3] (A, B as pk_widen's), then
 * PK_END, which no widened word equals (its halves are sign-extended bytes: 0x8000 is none), and one word more:
 * pk_quad's loop stops on it without a register for its end */
#define PK_END 0x80000000u

/* groups 0..n_g of the four points x0, x0 + n_in, x0 + 2 n_in, x0 + 3 n_in into xw (8 n_g + 2 words) */
static void pk_widen4(const int8_t *x0, uint32_t n_in, uint32_t n_g, uint32_t *xw)
{
    uint32_t g;
    for (g = 0; g < n_g; ++g, xw += 8)
    {
        const uint32_t u0 = s8_load4(x0 + 4u * g), u1 = s8_load4(x0 + n_in + 4u * g);
        const uint32_t u2 = s8_load4(x0 + 2u * n_in + 4u * g), u3 = s8_load4(x0 + 3u * n_in + 4u * g);
        xw[0] = S8_SXTB16(u0);
        xw[1] = S8_SXTB16(u1);
        xw[2] = S8_SXTB16(u2);
        xw[3] = S8_SXTB16(u3);
        xw[4] = S8_SXTB16_ROR8(u0);
        xw[5] = S8_SXTB16_ROR8(u1);
        xw[6] = S8_SXTB16_ROR8(u2);
        xw[7] = S8_SXTB16_ROR8(u3);
    }
    xw[0] = PK_END;
    xw[1] = 0u;
}

/* four points: s[2 j + k] (point j, channel k) += n_g >= 1 groups of the quad layout; returns w past them. On the
 * DSP cores in assembly: per group 6 LDRD and 16 SMLAD for 64 multiply-adds (the pair kernel: 8 LDRD and 16
 * SMLAD), and the loop's test on the next group's first word (PK_END) */
S8_ALWAYS_INLINE const uint32_t *pk_quad(const uint32_t *xw, uint32_t n_g, const uint32_t *w, int32_t *s)
{
    int32_t s00 = s[0], s01 = s[1], s10 = s[2], s11 = s[3], s20 = s[4], s21 = s[5], s30 = s[6], s31 = s[7];
#if defined(__ARM_FEATURE_DSP) && __ARM_FEATURE_DSP && defined(__GNUC__) && LIDET_NN_PK_ASM
    uint32_t a0, a1, c0, c1;
    (void)n_g;
/* one group: A (inputs i, i + 2) of points 0, 1 and 2, 3 against the channels' A weights, then B */
#define PK_QUAD_P01                                                                                          \
    "smlad %[s00], %[a0], %[c0], %[s00]\n\t"                                                                 \
    "smlad %[s01], %[a0], %[c1], %[s01]\n\t"                                                                 \
    "smlad %[s10], %[a1], %[c0], %[s10]\n\t"                                                                 \
    "smlad %[s11], %[a1], %[c1], %[s11]\n\t"
#define PK_QUAD_P23                                                                                          \
    "smlad %[s20], %[a0], %[c0], %[s20]\n\t"                                                                 \
    "smlad %[s21], %[a0], %[c1], %[s21]\n\t"                                                                 \
    "smlad %[s30], %[a1], %[c0], %[s30]\n\t"                                                                 \
    "smlad %[s31], %[a1], %[c1], %[s31]\n\t"
    __asm__ volatile("ldrd %[a0], %[a1], [%[x]], #8\n\t"
                     "1:\n\t"
                     "ldrd %[c0], %[c1], [%[w]], #8\n\t" PK_QUAD_P01
                     "ldrd %[a0], %[a1], [%[x]], #8\n\t" PK_QUAD_P23 "ldrd %[c0], %[c1], [%[w]], #8\n\t"
                     "ldrd %[a0], %[a1], [%[x]], #8\n\t" PK_QUAD_P01
                     "ldrd %[a0], %[a1], [%[x]], #8\n\t" PK_QUAD_P23 "ldrd %[a0], %[a1], [%[x]], #8\n\t"
                     "cmp %[a0], #0x80000000\n\t"
                     "bne 1b\n\t"
                     : [s00] "+r"(s00), [s01] "+r"(s01), [s10] "+r"(s10), [s11] "+r"(s11), [s20] "+r"(s20),
                       [s21] "+r"(s21), [s30] "+r"(s30), [s31] "+r"(s31), [x] "+r"(xw), [w] "+r"(w),
                       [a0] "=&r"(a0), [a1] "=&r"(a1), [c0] "=&r"(c0), [c1] "=&r"(c1)
                     :
                     : "cc", "memory");
#undef PK_QUAD_P01
#undef PK_QUAD_P23
#else
    const uint32_t *const end = xw + 8u * n_g;
    do
    {
        const uint32_t c0 = w[0], c1 = w[1], d0 = w[2], d1 = w[3];
        s00 = S8_SMLAD(xw[0], c0, s00);
        s01 = S8_SMLAD(xw[0], c1, s01);
        s10 = S8_SMLAD(xw[1], c0, s10);
        s11 = S8_SMLAD(xw[1], c1, s11);
        s20 = S8_SMLAD(xw[2], c0, s20);
        s21 = S8_SMLAD(xw[2], c1, s21);
        s30 = S8_SMLAD(xw[3], c0, s30);
        s31 = S8_SMLAD(xw[3], c1, s31);
        s00 = S8_SMLAD(xw[4], d0, s00);
        s01 = S8_SMLAD(xw[4], d1, s01);
        s10 = S8_SMLAD(xw[5], d0, s10);
        s11 = S8_SMLAD(xw[5], d1, s11);
        s20 = S8_SMLAD(xw[6], d0, s20);
        s21 = S8_SMLAD(xw[6], d1, s21);
        s30 = S8_SMLAD(xw[7], d0, s30);
        s31 = S8_SMLAD(xw[7], d1, s31);
        xw += 8;
        w += 4;
    } while (xw != end);
#endif
    s[0] = s00;
    s[1] = s01;
    s[2] = s10;
    s[3] = s11;
    s[4] = s20;
    s[5] = s21;
    s[6] = s30;
    s[7] = s31;
    return w;
}

/* the channel pairs of one pass (ng groups from group g0 of n_g; first: the sums start from the bias, else
 * from a0 / a1) for two points (a1 != NULL) or one */
static void pk_pass(const uint32_t *xw, uint32_t ng, uint32_t n_g, uint32_t g0, const uint32_t *w_pk,
                    const int32_t *b, uint32_t n_pairs, int32_t *a0, int32_t *a1)
{
    const uint32_t skip = 4u * (n_g - ng); /* to the next channel pair's words of this pass */
    const int32_t *i0 = g0 == 0u ? b : a0, *i1 = g0 == 0u ? b : a1;
    const uint32_t *w = w_pk + 4u * g0;
    uint32_t o;
    if (a1 != 0)
    {
        for (o = 0; o < 2u * n_pairs; o += 2u)
        {
            int32_t s[4];
            s[0] = i0[o];
            s[1] = i0[o + 1u];
            s[2] = i1[o];
            s[3] = i1[o + 1u];
            w = pk_pair(xw, ng, w, s) + skip;
            a0[o] = s[0];
            a0[o + 1u] = s[1];
            a1[o] = s[2];
            a1[o + 1u] = s[3];
        }
    }
    else
    {
        for (o = 0; o < 2u * n_pairs; o += 2u)
        {
            int32_t s[2];
            s[0] = i0[o];
            s[1] = i0[o + 1u];
            w = pk_one(xw, ng, w, s) + skip;
            a0[o] = s[0];
            a0[o + 1u] = s[1];
        }
    }
}

void lidet__nn_pack_s8_pk(const int8_t *w_t, uint32_t n_in, uint32_t n_out, uint32_t *w_pk)
{
    const uint32_t n_g = n_in / 4u;
    uint32_t c, g, k;
    for (c = 0; c + 1u < n_out; c += 2u)
    {
        for (g = 0; g < n_g; ++g)
        {
            for (k = 0; k < 4u; ++k) /* c0 A, c1 A, c0 B, c1 B */
            {
                const uint32_t o = c + (k & 1u), i = 4u * g + (k >> 1);
                const uint32_t lo = (uint32_t)(uint16_t)(int16_t)w_t[i * n_out + o];
                const uint32_t hi = (uint32_t)(uint16_t)(int16_t)w_t[(i + 2u) * n_out + o];
                *w_pk++ = lo | (hi << 16);
            }
        }
    }
}

void lidet__nn_acc_s8_pk(const int8_t *in, uint32_t n_rows, uint32_t n_in, const uint32_t *w_pk,
                         const int8_t *w_t, const int32_t *b, uint32_t n_out, int32_t *acc)
{
    uint32_t xw[4u * PK_CHUNK_GROUPS];
    const uint32_t n_g = n_in / 4u, n_pairs = n_out / 2u;
    uint32_t r, g0;
    if (n_in % 4u != 0u || n_in == 0u || n_pairs == 0u)
    {
        lidet__nn_acc_s8(in, n_rows, n_in, w_t, b, 0, n_out, acc);
        return;
    }
    for (r = 0; r < n_rows; r += 2u)
    {
        const int two = r + 1u < n_rows;
        const int8_t *x0 = in + r * n_in;
        int32_t *a0 = acc + r * n_out;
        for (g0 = 0; g0 < n_g; g0 += PK_CHUNK_GROUPS)
        {
            const uint32_t ng = n_g - g0 < PK_CHUNK_GROUPS ? n_g - g0 : PK_CHUNK_GROUPS;
            pk_widen(x0 + 4u * g0, two ? x0 + n_in + 4u * g0 : 0, ng, xw);
            pk_pass(xw, ng, n_g, g0, w_pk, b, n_pairs, a0, two ? a0 + n_out : 0);
        }
        if (n_out & 1u) /* an odd last channel: the [in][out] weights */
        {
            lidet__nn_acc_s8_cols(x0, two ? 2u : 1u, n_in, w_t + n_out - 1u, b + n_out - 1u, 1u, n_out,
                                  a0 + n_out - 1u, n_out);
        }
    }
}

void lidet__nn_acc_s8(const int8_t *in, uint32_t n_rows, uint32_t n_in, const int8_t *w_t, const int32_t *b,
                      const int32_t *b_list, uint32_t n_out, int32_t *acc)
{
#if LIDET_NN_S8_KERNEL != LIDET_NN_S8_KERNEL_LIST
    (void)b_list;
#endif
#if LIDET_NN_S8_KERNEL == LIDET_NN_S8_KERNEL_DSP
    lidet__nn_acc_s8_dsp(in, n_rows, n_in, w_t, b, n_out, acc);
#elif LIDET_NN_S8_KERNEL == LIDET_NN_S8_KERNEL_R2O2
    lidet__nn_acc_s8_r2o2(in, n_rows, n_in, w_t, b, n_out, acc);
#elif LIDET_NN_S8_KERNEL == LIDET_NN_S8_KERNEL_R4O2
    lidet__nn_acc_s8_r4o2(in, n_rows, n_in, w_t, b, n_out, acc);
#elif LIDET_NN_S8_KERNEL == LIDET_NN_S8_KERNEL_LIST
    lidet__nn_acc_s8_list(in, n_rows, n_in, w_t, b, b_list, n_out, acc);
#elif LIDET_NN_S8_KERNEL == LIDET_NN_S8_KERNEL_COLS
    if (n_rows >= LIDET_NN_S8_SKIP_MIN_ROWS)
    {
        lidet__nn_acc_s8_skip(in, n_rows, n_in, w_t, b, n_out, acc);
    }
    else
    {
        lidet__nn_acc_s8_cols(in, n_rows, n_in, w_t, b, n_out, n_out, acc, n_out);
    }
#elif LIDET_NN_S8_KERNEL == LIDET_NN_S8_KERNEL_ROWS4
    lidet__nn_acc_s8_rows4(in, n_rows, n_in, w_t, b, n_out, acc);
#else
#error "LIDET_NN_S8_KERNEL: one of LIDET_NN_S8_KERNEL_ROWS4, _COLS, _DSP, _R2O2, _R4O2, _LIST (lidet_opt.h)"
#endif
}

/* a += u0 w0 + u1 w1 over n channels: a function of its own, so that the few registers of a Cortex-M0+ hold the
 * loop's values (in the caller's loop GCC spilled one to the stack on every channel) */
#if defined(__GNUC__)
__attribute__((noinline))
#endif
static void
skip_pair(int32_t *a, const int8_t *w0, const int8_t *w1, int32_t u0, int32_t u1, uint32_t n)
{
    /* an index from -n up to 0 off the rows' ends: the loop's test is the increment's flags, no register for n */
    const int8_t *e0 = w0 + n, *e1 = w1 + n;
    int32_t k = -(int32_t)n;
    if (n == 0u)
    {
        return;
    }
    do
    {
        *a++ += u0 * (int32_t)e0[k] + u1 * (int32_t)e1[k];
    } while (++k != 0);
}

/* a += u w over n channels: one input's weight row (the output-inner kernels' odd input) */
static inline void acc_row(int32_t *a, const int8_t *w, int32_t u, uint32_t n)
{
    uint32_t o;
    for (o = 0; o < n; ++o)
    {
        a[o] += u * (int32_t)w[o];
    }
}

/* the output-inner kernel on channels [0, n_out) of a layer whose weight rows are w_stride long and whose
 * accumulator rows are a_stride long (a column slice, for the blocked kernels' leftovers) */
void lidet__nn_acc_s8_cols(const int8_t *in, uint32_t n_rows, uint32_t n_in, const int8_t *w_t,
                           const int32_t *b, uint32_t n_out, uint32_t w_stride, int32_t *acc,
                           uint32_t a_stride)
{
    uint32_t r, i, o;
    for (r = 0; r < n_rows; ++r)
    {
        int32_t *a = acc + r * a_stride;
        const int8_t *x = in + r * n_in;
        for (o = 0; o < n_out; ++o)
        {
            a[o] = b[o];
        }
        for (i = 0; i + 2u <= n_in; i += 2u)
        {
            const int32_t x0 = x[i], x1 = x[i + 1u];
            const int8_t *w0 = w_t + i * w_stride;
            const int8_t *w1 = w0 + w_stride;
#if LIDET_NN_S8_KERNEL == LIDET_NN_S8_KERNEL_COLS ||                                                         \
    (LIDET_NN_S8_KERNEL == LIDET_NN_S8_KERNEL_LIST && LIST_T1_ASM)
            skip_pair(a, w0, w1, x0, x1, n_out); /* the loop without a register for n (ARMv6-M) */
#else
            for (o = 0; o < n_out; ++o)
            {
                a[o] += x0 * (int32_t)w0[o] + x1 * (int32_t)w1[o];
            }
#endif
        }
        for (; i < n_in; ++i)
        {
            acc_row(a, w_t + i * w_stride, x[i], n_out);
        }
    }
}

/* The output-inner loop without the products of inputs at -128, the zero point after a ReLU (a ReLU layer's real 0:
 * 40-50 % of a hidden layer's inputs on the simulated VLP-16 scan's proposals). With u = x + 128,
 * b + sum x w = (b - 128 sum w) + sum u w, and u = 0 adds nothing: the first row's accumulators take b - 128 sum w
 * (one pass over the weights, the cost of one row: hence only for layers of many rows), every row starts from it
 * (the last row first) and adds its nonzero u two at a time. Exact integer sums: the same results as the other kernels. */
void lidet__nn_acc_s8_skip(const int8_t *in, uint32_t n_rows, uint32_t n_in, const int8_t *w_t,
                           const int32_t *b, uint32_t n_out, int32_t *acc)
{
    uint32_t r, i, o;
    if (n_rows == 0u)
    {
        return;
    }
    for (o = 0; o < n_out; ++o)
    {
        acc[o] = b[o];
    }
    for (i = 0; i + 2u <= n_in; i += 2u) /* two weight rows a pass, as the rows below take them */
    {
        skip_pair(acc, w_t + i * n_out, w_t + (i + 1u) * n_out, -128, -128, n_out);
    }
    if (i < n_in)
    {
        acc_row(acc, w_t + i * n_out, -128, n_out);
    }
    for (r = n_rows; r-- > 0u;) /* the last row first: row 0 keeps the starting sums until the end */
    {
        int32_t *a = acc + r * n_out;
        const int8_t *x = in + r * n_in;
        const int8_t *w0 = 0; /* the weight row of a nonzero u waiting for a second one */
        int32_t u0 = 0;
        if (r > 0u)
        {
            for (o = 0; o < n_out; ++o)
            {
                a[o] = acc[o];
            }
        }
        for (i = 0; i < n_in; ++i)
        {
            const int32_t u1 = (int32_t)x[i] + 128;
            const int8_t *w1;
            if (u1 == 0)
            {
                continue;
            }
            w1 = w_t + i * n_out;
            if (w0 == 0)
            {
                w0 = w1;
                u0 = u1;
                continue;
            }
            skip_pair(a, w0, w1, u0, u1, n_out);
            w0 = 0;
        }
        if (w0 != 0)
        {
            acc_row(a, w0, u0, n_out);
        }
    }
}

void lidet__nn_acc_s16_by_out(const int16_t *in, uint32_t n_rows, uint32_t n_in, const int8_t *w_t,
                              const int32_t *b, uint32_t n_out, int32_t *acc)
{
    uint32_t r, i, o;
    for (r = 0; r < n_rows; ++r)
    {
        const int16_t *x = in + r * n_in;
        int32_t *a = acc + r * n_out;
        if (n_in == 3u) /* the first layer's x, y, z: the inputs in registers too */
        {
            const int32_t x0 = x[0], x1 = x[1], x2 = x[2];
            for (o = 0; o < n_out; ++o)
            {
                a[o] = b[o] + x0 * (int32_t)w_t[o] + x1 * (int32_t)w_t[n_out + o] +
                       x2 * (int32_t)w_t[2u * n_out + o];
            }
            continue;
        }
        for (o = 0; o < n_out; ++o)
        {
            int32_t s = b[o];
            for (i = 0; i < n_in; ++i)
            {
                s += (int32_t)x[i] * (int32_t)w_t[i * n_out + o];
            }
            a[o] = s;
        }
    }
}

LIDET_NN_KERNEL void lidet__nn_acc_s16(const int16_t *in, uint32_t n_rows, uint32_t n_in, const int8_t *w_t,
                                       const int32_t *b, uint32_t n_out, int32_t *acc)
{
    uint32_t r, i, o;
#if !LIDET_NN_SIMD
    lidet__nn_acc_s16_by_out(in, n_rows, n_in, w_t, b, n_out, acc);
    return;
#endif
    for (r = 0; r < n_rows; ++r)
    {
        int32_t *a = acc + r * n_out;
        const int16_t *x = in + r * n_in;
        for (o = 0; o < n_out; ++o)
        {
            a[o] = b[o];
        }
        for (i = 0; i < n_in; ++i)
        {
            const int32_t x0 = x[i];
            const int8_t *w0 = w_t + i * n_out;
            for (o = 0; o < n_out; ++o)
            {
                a[o] += x0 * (int32_t)w0[o];
            }
        }
    }
}

/* round_half_up(acc * m / 2^s) = (acc * m + 2^(s-1)) >> s, m in [0, 2^31), s in [1, 62], without the 64-bit
 * add and shift where s > 32 (the generated models' usual case): with acc * m = hi 2^32 + lo (0 <= lo < 2^32),
 * (hi 2^32 + lo + 2^(s-1)) >> s = (hi + 2^(s-33)) >> (s - 32), exactly, as lo / 2^32 < 1 cannot carry an
 * integer across a multiple of 2^(s-32); |hi| < 2^30, so the 32-bit add does not overflow. s = 32: hi plus the
 * carry of lo + 2^31. On a 32-bit core: one long multiply, then 32-bit arithmetic (about 14 instructions per
 * value on a Cortex-M4 instead of 40). The same results as lidet__q_rshift_round (tests/unit/test_nn_s8.c). */
static inline int64_t requant_round(int32_t acc, int32_t m, uint32_t s)
{
    const int64_t p = (int64_t)acc * m;
    if (s > 32u)
    {
        const int32_t hi = (int32_t)(p >> 32);
        return (int64_t)((hi + ((int32_t)1 << (s - 33u))) >> (s - 32u));
    }
    if (s == 32u)
    {
        return (int64_t)(int32_t)(p >> 32) + (int64_t)(((uint32_t)p) >> 31);
    }
    return lidet__q_rshift_round(p, s);
}

#if defined(__ARM_FEATURE_SAT) && __ARM_FEATURE_SAT
#include <arm_acle.h>
#endif
/* v clamped to [lo, 127] (lo >= -128): SSAT where the core has it */
static inline int8_t clamp_s8(int32_t v, int32_t lo)
{
#if defined(__ARM_FEATURE_SAT) && __ARM_FEATURE_SAT
    v = __ssat(v, 8);
#else
    v = v > 127 ? 127 : (v < -128 ? -128 : v);
#endif
    return (int8_t)(v < lo ? lo : v);
}

/* one value of lidet__nn_requant_s8 (the same rule and fast path as lidet__nn_requant_s8_by_channel) */
S8_ALWAYS_INLINE int8_t rq_one(int32_t a, int32_t m, uint32_t s, int32_t zp, int32_t lo)
{
    if (s > 32u)
    {
        const uint32_t k = s - 32u;
        const int32_t hi = lidet__q_smulhi32(a, m);
        return clamp_s8(((hi + ((int32_t)1 << (k - 1u))) >> k) + zp, lo);
    }
    {
        int64_t v = requant_round(a, m, s) + zp;
        v = v < lo ? lo : (v > 127 ? 127 : v);
        return (int8_t)v;
    }
}

/* The same values channel by channel: the channel's multiplier, shift and rounding constant stay in registers
 * and the usual case (shift > 32, requant_round's fast path) stays in 32 bits (|v| < 2^30), about 10
 * instructions per value on a Cortex-M4 instead of 24. Cores without SIMD use it; hosts keep the row-major
 * loop, which vectorises (tests/unit/test_nn_s8.c runs both against the int64 rule). After a ReLU (lo >= zp) an
 * accumulator <= 0 gives lo without its multiply: m >= 0, so acc m <= 0 and its rounding (half up) <= 0, v <= zp,
 * clamped to lo; on the shared layers about half the values, whose multiply costs most where the core has no 32 x
 * 32 -> 64 one (ARMv6-M: lidet__q_smulhi32 from 16-bit halves). */
void lidet__nn_requant_s8_by_channel(const int32_t *acc, uint32_t n_rows, uint32_t n_out, const int32_t *mult,
                                     const uint8_t *shift, int32_t zp, int32_t lo, int8_t *out)
{
    uint32_t r, o;
#if defined(__ARM_FEATURE_DSP) && __ARM_FEATURE_DSP
    const int relu = 0; /* Cortex-M4: 28 000 instructions more per scan with it (its layers mostly fused) */
#else
    const int relu = lo >= zp;
#endif
    if (n_rows == 1u)
    {
        /* one vector (the pooled features, the PVLE and head layers): channel after channel, no row loop */
        for (o = 0; o < n_out; ++o)
        {
            out[o] = relu && acc[o] <= 0 ? (int8_t)lo : rq_one(acc[o], mult[o], shift[o], zp, lo);
        }
        return;
    }
    for (o = 0; o < n_out; ++o)
    {
        const int32_t m = mult[o];
        const uint32_t s = shift[o];
        const int32_t *a = acc + o;
        int8_t *d = out + o;
        if (s > 32u && relu)
        {
            const uint32_t k = s - 32u;
            const int32_t half = (int32_t)1 << (k - 1u);
            for (r = 0; r < n_rows; ++r, a += n_out, d += n_out)
            {
                const int32_t v = *a;
                *d = v <= 0 ? (int8_t)lo : clamp_s8(((lidet__q_smulhi32(v, m) + half) >> k) + zp, lo);
            }
        }
        else if (s > 32u)
        {
            const uint32_t k = s - 32u;
            const int32_t half = (int32_t)1 << (k - 1u);
            for (r = 0; r < n_rows; ++r, a += n_out, d += n_out)
            {
                const int32_t hi = lidet__q_smulhi32(*a, m);
                *d = clamp_s8(((hi + half) >> k) + zp, lo);
            }
        }
        else
        {
            for (r = 0; r < n_rows; ++r, a += n_out, d += n_out)
            {
                int64_t v = requant_round(*a, m, s) + zp;
                v = v < lo ? lo : (v > 127 ? 127 : v);
                *d = (int8_t)v;
            }
        }
    }
}

LIDET_NN_KERNEL void lidet__nn_requant_s8(const int32_t *acc, uint32_t n_rows, uint32_t n_out,
                                          const int32_t *mult, const uint8_t *shift, int32_t zp, int32_t lo,
                                          int8_t *out)
{
    uint32_t r, o;
#if !LIDET_NN_SIMD
    lidet__nn_requant_s8_by_channel(acc, n_rows, n_out, mult, shift, zp, lo, out);
    return;
#endif
    for (r = 0; r < n_rows; ++r)
    {
        for (o = 0; o < n_out; ++o)
        {
            int64_t v = requant_round(acc[r * n_out + o], mult[o], shift[o]) + zp;
            v = v < lo ? lo : (v > 127 ? 127 : v);
            out[r * n_out + o] = (int8_t)v;
        }
    }
}

void lidet__nn_requant_q16(const int32_t *acc, uint32_t n_out, const int32_t *mult, const uint8_t *shift,
                           int32_t *out)
{
    uint32_t o;
    for (o = 0; o < n_out; ++o)
    {
        const int64_t v = requant_round(acc[o], mult[o], shift[o]);
        out[o] = v < INT32_MIN ? INT32_MIN : (v > INT32_MAX ? INT32_MAX : (int32_t)v);
    }
}

LIDET_NN_KERNEL void lidet__nn_max_rows_s32(const int32_t *acc, uint32_t n_rows, uint32_t n, int32_t *vmax)
{
    uint32_t r, o;
    for (r = 0; r < n_rows; ++r)
    {
        const int32_t *a = acc + r * n;
        for (o = 0; o < n; ++o)
        {
            vmax[o] = a[o] > vmax[o] ? a[o] : vmax[o];
        }
    }
}

/* rq_one for a shift 32 + k, k in [1, 16], and lo = -128 (the generated models' usual case): the zero point
 * added before the shift, exactly (floor((v + zp 2^k) / 2^k) = floor(v / 2^k) + zp; |hi| < 2^30 and
 * |zp| 2^k <= 2^23, so no overflow), the clamp at -128 SSAT's own. c = rq_fast_c(k, zp) */
static inline int32_t rq_fast_c(uint32_t k, int32_t zp)
{
    return (2 * zp + 1) * ((int32_t)1 << (k - 1u)); /* 2^(k-1) + zp 2^k */
}

S8_ALWAYS_INLINE int8_t rq_fast(int32_t a, int32_t m, uint32_t k, int32_t c)
{
    const int32_t v = (lidet__q_smulhi32(a, m) + c) >> k;
#if defined(__ARM_FEATURE_SAT) && __ARM_FEATURE_SAT
    return (int8_t)__ssat(v, 8); /* SSAT's own -128 (GCC does not drop clamp_s8's second compare after it) */
#else
    return clamp_s8(v, -128);
#endif
}

/* the fused pass's rows: mode PKF_RQ requantizes with rq_one, PKF_RQ_FAST with rq_fast (every channel's shift in
 * [33, 48] and lo = -128, checked by the caller; each channel's k and rq_fast_c made where its pair of channels
 * is requantized: four points share them, so a table of them made once per call, 240 bytes of stack, no longer
 * paid), PKF_MAX folds into vmax (a constant where inlined: each mode is compiled on its own, without the others'
 * branches) */
enum
{
    PKF_RQ,
    PKF_RQ_FAST,
    PKF_MAX
};

/* one pair of points (two: x0 and the row after it), or the last point alone; two and mode are constants where
 * inlined, so the pairs' loop carries no test for the odd last row */
S8_ALWAYS_INLINE void pk_fused_block(const int8_t *x0, uint32_t n_in, const uint32_t *w_pk, const int32_t *b,
                                     uint32_t n_out, const int32_t *mult, const uint8_t *shift, int32_t zp,
                                     int32_t lo, int8_t *d, int32_t *vmax, uint32_t *xw, const int two,
                                     const int mode)
{
    const uint32_t n_g = n_in / 4u;
    const uint32_t *w = w_pk;
    uint32_t o;
    pk_widen(x0, two ? x0 + n_in : 0, n_g, xw);
    for (o = 0; o < n_out; o += 2u)
    {
        int32_t s[4];
        s[0] = s[2] = b[o];
        s[1] = s[3] = b[o + 1u];
        w = two ? pk_pair(xw, n_g, w, s) : pk_one(xw, n_g, w, s);
        if (mode == PKF_RQ_FAST)
        {
            const int32_t m0 = mult[o], m1 = mult[o + 1u];
            const uint32_t k0 = shift[o] - 32u, k1 = shift[o + 1u] - 32u;
            const int32_t c0 = rq_fast_c(k0, zp), c1 = rq_fast_c(k1, zp);
            d[o] = rq_fast(s[0], m0, k0, c0);
            d[o + 1u] = rq_fast(s[1], m1, k1, c1);
            if (two)
            {
                d[n_out + o] = rq_fast(s[2], m0, k0, c0);
                d[n_out + o + 1u] = rq_fast(s[3], m1, k1, c1);
            }
        }
        else if (mode == PKF_RQ)
        {
            const int32_t m0 = mult[o], m1 = mult[o + 1u];
            const uint32_t h0 = shift[o], h1 = shift[o + 1u];
            d[o] = rq_one(s[0], m0, h0, zp, lo);
            d[o + 1u] = rq_one(s[1], m1, h1, zp, lo);
            if (two)
            {
                d[n_out + o] = rq_one(s[2], m0, h0, zp, lo);
                d[n_out + o + 1u] = rq_one(s[3], m1, h1, zp, lo);
            }
        }
        else
        {
            int32_t v0 = vmax[o], v1 = vmax[o + 1u];
            v0 = s[0] > v0 ? s[0] : v0;
            v1 = s[1] > v1 ? s[1] : v1;
            if (two)
            {
                v0 = s[2] > v0 ? s[2] : v0;
                v1 = s[3] > v1 ? s[3] : v1;
            }
            vmax[o] = v0;
            vmax[o + 1u] = v1;
        }
    }
}

/* four points (x0 and the three rows after it): pk_fused_block's work for two pairs, the channel pair's
 * constants and loop once for the four */
S8_ALWAYS_INLINE void pk_fused_quad(const int8_t *x0, uint32_t n_in, const uint32_t *w_pk, const int32_t *b,
                                    uint32_t n_out, const int32_t *mult, const uint8_t *shift, int32_t zp,
                                    int32_t lo, int8_t *d, int32_t *vmax, uint32_t *xw, const int mode)
{
    const uint32_t n_g = n_in / 4u;
    const uint32_t *w = w_pk;
    uint32_t o;
    pk_widen4(x0, n_in, n_g, xw);
    if (mode == PKF_MAX)
    {
        /* pointers walked, not indexed: fewer of the loop's values reloaded around the kernel's 14 registers */
        const int32_t *bp = b, *const bend = b + n_out;
        int32_t *vp = vmax;
        for (; bp != bend; bp += 2, vp += 2)
        {
            int32_t s[8], v0, v1;
            s[0] = s[2] = s[4] = s[6] = bp[0];
            s[1] = s[3] = s[5] = s[7] = bp[1];
            w = pk_quad(xw, n_g, w, s);
            v0 = vp[0];
            v1 = vp[1];
            v0 = s[0] > v0 ? s[0] : v0;
            v1 = s[1] > v1 ? s[1] : v1;
            v0 = s[2] > v0 ? s[2] : v0;
            v1 = s[3] > v1 ? s[3] : v1;
            v0 = s[4] > v0 ? s[4] : v0;
            v1 = s[5] > v1 ? s[5] : v1;
            v0 = s[6] > v0 ? s[6] : v0;
            v1 = s[7] > v1 ? s[7] : v1;
            vp[0] = v0;
            vp[1] = v1;
        }
        return;
    }
    for (o = 0; o < n_out; o += 2u)
    {
        int32_t s[8];
        s[0] = s[2] = s[4] = s[6] = b[o];
        s[1] = s[3] = s[5] = s[7] = b[o + 1u];
        w = pk_quad(xw, n_g, w, s);
        if (mode == PKF_RQ_FAST)
        {
            const int32_t m0 = mult[o], m1 = mult[o + 1u];
            const uint32_t k0 = shift[o] - 32u, k1 = shift[o + 1u] - 32u;
            const int32_t c0 = rq_fast_c(k0, zp), c1 = rq_fast_c(k1, zp);
            int8_t *const d1 = d + n_out, *const d2 = d1 + n_out, *const d3 = d2 + n_out;
            d[o] = rq_fast(s[0], m0, k0, c0);
            d[o + 1u] = rq_fast(s[1], m1, k1, c1);
            d1[o] = rq_fast(s[2], m0, k0, c0);
            d1[o + 1u] = rq_fast(s[3], m1, k1, c1);
            d2[o] = rq_fast(s[4], m0, k0, c0);
            d2[o + 1u] = rq_fast(s[5], m1, k1, c1);
            d3[o] = rq_fast(s[6], m0, k0, c0);
            d3[o + 1u] = rq_fast(s[7], m1, k1, c1);
        }
        else if (mode == PKF_RQ)
        {
            const int32_t m0 = mult[o], m1 = mult[o + 1u];
            const uint32_t h0 = shift[o], h1 = shift[o + 1u];
            int8_t *const d1 = d + n_out, *const d2 = d1 + n_out, *const d3 = d2 + n_out;
            d[o] = rq_one(s[0], m0, h0, zp, lo);
            d[o + 1u] = rq_one(s[1], m1, h1, zp, lo);
            d1[o] = rq_one(s[2], m0, h0, zp, lo);
            d1[o + 1u] = rq_one(s[3], m1, h1, zp, lo);
            d2[o] = rq_one(s[4], m0, h0, zp, lo);
            d2[o + 1u] = rq_one(s[5], m1, h1, zp, lo);
            d3[o] = rq_one(s[6], m0, h0, zp, lo);
            d3[o + 1u] = rq_one(s[7], m1, h1, zp, lo);
        }
    }
}

S8_ALWAYS_INLINE void pk_fused_rows(const int8_t *in, uint32_t n_rows, uint32_t n_in, const uint32_t *w_pk,
                                    const int32_t *b, uint32_t n_out, const int32_t *mult,
                                    const uint8_t *shift, int32_t zp, int32_t lo, int8_t *out, int32_t *vmax,
                                    const int mode)
{
    uint32_t xw[8u * PK_CHUNK_GROUPS + 2u];
    uint32_t r;
    for (r = 0; r + 3u < n_rows; r += 4u)
    {
        pk_fused_quad(in + r * n_in, n_in, w_pk, b, n_out, mult, shift, zp, lo,
                      mode != PKF_MAX ? out + r * n_out : 0, vmax, xw, mode);
    }
    if (r + 1u < n_rows)
    {
        pk_fused_block(in + r * n_in, n_in, w_pk, b, n_out, mult, shift, zp, lo,
                       mode != PKF_MAX ? out + r * n_out : 0, vmax, xw, 1, mode);
        r += 2u;
    }
    if (r < n_rows)
    {
        pk_fused_block(in + r * n_in, n_in, w_pk, b, n_out, mult, shift, zp, lo,
                       mode != PKF_MAX ? out + r * n_out : 0, vmax, xw, 0, mode);
    }
}

int lidet__nn_acc_s8_pk_fused(const int8_t *in, uint32_t n_rows, uint32_t n_in, const uint32_t *w_pk,
                              const int32_t *b, uint32_t n_out, const int32_t *mult, const uint8_t *shift,
                              int32_t zp, int32_t lo, int8_t *out, int32_t *vmax)
{
    uint32_t o;
    int fast = lo == -128;
    if (w_pk == 0 || n_in % 4u != 0u || n_in == 0u || n_in > 4u * PK_CHUNK_GROUPS || n_out % 2u != 0u ||
        n_out == 0u || (out == 0) == (vmax == 0))
    {
        return 0;
    }
    if (vmax != 0)
    {
        pk_fused_rows(in, n_rows, n_in, w_pk, b, n_out, mult, shift, zp, lo, out, vmax, PKF_MAX);
        return 1;
    }
    for (o = 0; o < n_out && fast; ++o)
    {
        fast = shift[o] - 33u < 16u; /* shift in [33, 48] */
    }
    if (fast)
    {
        pk_fused_rows(in, n_rows, n_in, w_pk, b, n_out, mult, shift, zp, lo, out, vmax, PKF_RQ_FAST);
    }
    else
    {
        pk_fused_rows(in, n_rows, n_in, w_pk, b, n_out, mult, shift, zp, lo, out, vmax, PKF_RQ);
    }
    return 1;
}

#if LIDET_NN_S16_3_TABLE
/* lidet__nn_acc_s16_3_requant's usual case (every channel's shift in [33, 48], lo = -128) on the DSP cores,
 * point by point: each channel's constants made once per call into a table (S16_3_TAB_MAX channels: 576 bytes of
 * stack), read by one load of six words per output (the channel-outer loop made them per call and channel, with
 * its pointers spilled: about 19 instructions per output, here about 12). Returns 0 where it does not apply. */
#define S16_3_TAB_MAX 24u
typedef struct
{
    uint32_t w01;     /* channel's weights of x (low half) and y (high half) */
    int32_t bo, m, c; /* bias, multiplier, rq_fast_c */
    int32_t w2;       /* weight of z */
    uint32_t k;       /* shift - 32 */
} s16_3_ch_t;

int lidet__nn_s16_3_table(const int8_t *w_t, const int32_t *b, uint32_t n_out, const int32_t *mult,
                          const uint8_t *shift, int32_t zp, int32_t lo, void *tab, uint32_t tab_bytes)
{
    s16_3_ch_t *const t = (s16_3_ch_t *)tab;
    uint32_t o;
    if (lo != -128 || n_out * (uint32_t)sizeof(s16_3_ch_t) > tab_bytes)
    {
        return 0;
    }
    for (o = 0; o < n_out; ++o)
    {
        const uint32_t k = (uint32_t)shift[o] - 32u;
        if (k - 1u >= 16u)
        {
            return 0; /* a shift outside [33, 48] */
        }
        t[o].w01 = ((uint32_t)(int32_t)w_t[o] & 0xFFFFu) | ((uint32_t)(int32_t)w_t[n_out + o] << 16);
        t[o].bo = b[o];
        t[o].m = mult[o];
        t[o].c = rq_fast_c(k, zp);
        t[o].w2 = w_t[2u * n_out + o];
        t[o].k = k;
    }
    return 1;
}

void lidet__nn_s16_3_table_run(const int16_t *in, uint32_t n_rows, const void *tab, uint32_t n_out,
                               int8_t *out)
{
    const s16_3_ch_t *const t = (const s16_3_ch_t *)tab;
    uint32_t r;
    for (r = 0; r < n_rows; ++r, in += 3, out += n_out)
    {
        const s16_3_ch_t *e = t, *const end = t + n_out;
        int8_t *d = out;
        uint32_t xy;
        const int32_t z = in[2];
        memcpy(&xy, in, sizeof xy); /* x and y in one (possibly unaligned) little-endian word */
#if defined(__GNUC__) && LIDET_NN_PK_ASM
        /* one LDM of the channel's six words (its registers fixed here: LDM fills them in ascending order), then
         * rq_fast's instructions (GCC loaded the words one by one) */
        register uint32_t w01 __asm__("r2"), bo __asm__("r3"), m __asm__("r4"), c __asm__("r5");
        register uint32_t w2 __asm__("r6"), k __asm__("r8");
        uint32_t lo32;
        __asm__ volatile("1:\n\t"
                         "ldmia %[e]!, {r2, r3, r4, r5, r6, r8}\n\t"
                         "smlad %[bo], %[xy], %[w01], %[bo]\n\t"
                         "mla %[bo], %[z], %[w2], %[bo]\n\t"
                         "smull %[lo], %[bo], %[m], %[bo]\n\t"
                         "add %[bo], %[bo], %[c]\n\t"
                         "asr %[bo], %[bo], %[k]\n\t"
                         "ssat %[bo], #8, %[bo]\n\t"
                         "strb %[bo], [%[d]], #1\n\t"
                         "cmp %[e], %[end]\n\t"
                         "bne 1b\n\t"
                         : [e] "+r"(e), [d] "+r"(d), [w01] "=&r"(w01), [bo] "=&r"(bo), [m] "=&r"(m),
                           [c] "=&r"(c), [w2] "=&r"(w2), [k] "=&r"(k), [lo] "=&r"(lo32)
                         : [end] "r"(end), [xy] "r"(xy), [z] "r"(z)
                         : "cc", "memory");
#else
        for (; e != end; ++e, ++d)
        {
            *d = rq_fast(S8_SMLAD(xy, e->w01, e->bo) + z * e->w2, e->m, e->k, e->c);
        }
#endif
    }
}

/* the table on the stack, made for this call */
static int acc_s16_3_tab(const int16_t *in, uint32_t n_rows, const int8_t *w_t, const int32_t *b,
                         uint32_t n_out, const int32_t *mult, const uint8_t *shift, int32_t zp, int32_t lo,
                         int8_t *out)
{
    s16_3_ch_t t[S16_3_TAB_MAX];
    if (!lidet__nn_s16_3_table(w_t, b, n_out, mult, shift, zp, lo, t, sizeof t))
    {
        return 0;
    }
    lidet__nn_s16_3_table_run(in, n_rows, t, n_out, out);
    return 1;
}
#else
int lidet__nn_s16_3_table(const int8_t *w_t, const int32_t *b, uint32_t n_out, const int32_t *mult,
                          const uint8_t *shift, int32_t zp, int32_t lo, void *tab, uint32_t tab_bytes)
{
    (void)w_t;
    (void)b;
    (void)n_out;
    (void)mult;
    (void)shift;
    (void)zp;
    (void)lo;
    (void)tab;
    (void)tab_bytes;
    return 0; /* DSP cores only */
}

void lidet__nn_s16_3_table_run(const int16_t *in, uint32_t n_rows, const void *tab, uint32_t n_out,
                               int8_t *out)
{
    (void)in;
    (void)n_rows;
    (void)tab;
    (void)n_out;
    (void)out;
}
#endif

void lidet__nn_acc_s16_3_requant(const int16_t *in, uint32_t n_rows, const int8_t *w_t, const int32_t *b,
                                 uint32_t n_out, const int32_t *mult, const uint8_t *shift, int32_t zp,
                                 int32_t lo, int8_t *out)
{
    uint32_t r, o;
    /* after a ReLU an accumulator <= 0 gives lo (as in lidet__nn_requant_s8_by_channel), where the multiply is long
     * (ARMv6-M); a test per value costs more than the multiply it saves elsewhere (RV32IM, M3: 0.3-0.4 % more) */
    const int relu = !LIDET_Q_HAVE_MUL64 && lo >= zp;
#if LIDET_NN_S16_3_TABLE
    if (acc_s16_3_tab(in, n_rows, w_t, b, n_out, mult, shift, zp, lo, out))
    {
        return;
    }
#endif
    /* channel by channel: the channel's weights, bias and requantization stay in registers over the rows */
    for (o = 0; o < n_out; ++o)
    {
        const int32_t w0 = w_t[o], w1 = w_t[n_out + o], w2 = w_t[2u * n_out + o], bo = b[o], m = mult[o];
        const uint32_t sh = shift[o];
        const int16_t *x = in;
        int8_t *d = out + o;
        if (sh > 32u && sh <= 48u && lo == -128)
        {
            /* the usual case (rq_fast) */
            const uint32_t k = sh - 32u;
            const int32_t c = rq_fast_c(k, zp);
#if defined(__ARM_FEATURE_DSP) && __ARM_FEATURE_DSP && !defined(__ARM_BIG_ENDIAN)
            /* x and y in one (possibly unaligned) little-endian word: one SMLAD for both products */
            const uint32_t w01 = ((uint32_t)w0 & 0xFFFFu) | ((uint32_t)w1 << 16);
            for (r = 0; r + 2u <= n_rows; r += 2u, x += 6, d += 2u * n_out)
            {
                /* two rows a pass: the loop's own instructions once for both */
                uint32_t xy0, xy1;
                memcpy(&xy0, x, sizeof xy0);
                memcpy(&xy1, x + 3, sizeof xy1);
                d[0] = rq_fast(S8_SMLAD(xy0, w01, bo) + x[2] * w2, m, k, c);
                d[n_out] = rq_fast(S8_SMLAD(xy1, w01, bo) + x[5] * w2, m, k, c);
            }
            if (r < n_rows)
            {
                uint32_t xy;
                memcpy(&xy, x, sizeof xy);
                *d = rq_fast(S8_SMLAD(xy, w01, bo) + x[2] * w2, m, k, c);
            }
#else
            for (r = 0; r < n_rows; ++r, x += 3, d += n_out)
            {
                const int32_t a = bo + x[0] * w0 + x[1] * w1 + x[2] * w2;
                *d = relu && a <= 0 ? (int8_t)lo
                                    : rq_fast(a, m, k, c); /* as lidet__nn_requant_s8_by_channel */
            }
#endif
        }
        else
        {
            for (r = 0; r < n_rows; ++r, x += 3, d += n_out)
            {
                const int32_t a = bo + x[0] * w0 + x[1] * w1 + x[2] * w2;
                *d = relu && a <= 0 ? (int8_t)lo : rq_one(a, m, sh, zp, lo);
            }
        }
    }
}
