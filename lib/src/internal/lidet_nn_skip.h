/* SPDX-License-Identifier: MIT */
/* The zero test of the float dense kernels that skip the zero inputs of ReLU layers (lib/src/nn/lidet_nn_f32_cm.c,
 * lidet_nn_f32_rv.c: a zero input adds nothing the ReLU does not erase; the argument is in lidet_nn_f32_cm.c). A header
 * of its own: <string.h> stays out of the kernels that do not skip. Never installed. */
#ifndef LIDET_NN_SKIP_H
#define LIDET_NN_SKIP_H

#include <stdint.h>
#include <string.h>

/* whether v is +0 or -0 (its bits without the sign are 0), and how many of a row's
 * n_in inputs count, those up to its last nonzero one (all of them without a ReLU) */
static inline int lidet__nn_is_zero(float v)
{
    uint32_t u;
    memcpy(&u, &v, sizeof u);
    return (u << 1) == 0u;
}

static inline uint32_t lidet__nn_inputs_used(const float *x, uint32_t n_in, int relu)
{
    uint32_t last = n_in;
    while (relu && last > 0u && lidet__nn_is_zero(x[last - 1u]))
    {
        --last;
    }
    return last;
}

#endif
