/* SPDX-License-Identifier: MIT */
/* Flat C entry points over the integer math of the fixed-point path for the Python bindings
 * (tools/lidet_tools/native/_qmath.py: qmath); tests compare them with codegen/lidet_ref/qmath.py. */
#include <stddef.h>

#include "lidet/lidet.h"
#include "internal/lidet_ground_q_internal.h"
#include "internal/lidet_qmath.h"

#if defined(_WIN32)
#define LIDET_PY_API __declspec(dllexport)
#else
#define LIDET_PY_API __attribute__((visibility("default")))
#endif

/* op 0: sin(a), 1: cos(a), 2: atan2(a, b), 3: isqrt(a:b as uint64 hi:lo), 4: sqrt_round(a:b), 5: urad_to_bam(a),
 * 6: the ground stage's R of x^2 + y^2 = a (uint32) */
LIDET_PY_API int lidet_py_qmath(uint32_t op, const int32_t *a, const int32_t *b, uint32_t n, int64_t *out)
{
    uint32_t i;
    if (a == NULL || out == NULL || (op >= 2u && op <= 4u && b == NULL) || op > 6u)
    {
        return LIDET_ERR_ARG;
    }
    for (i = 0; i < n; ++i)
    {
        uint64_t wide = op == 3u || op == 4u ? ((uint64_t)(uint32_t)a[i] << 32) | (uint32_t)b[i] : 0u;
        switch (op)
        {
        case 0u: out[i] = lidet__q_sin((uint32_t)a[i]); break;
        case 1u: out[i] = lidet__q_cos((uint32_t)a[i]); break;
        case 2u: out[i] = lidet__q_atan2(a[i], b[i]); break;
        case 3u: out[i] = lidet__q_isqrt64(wide); break;
        case 4u: out[i] = lidet__q_sqrt_round64(wide); break;
        case 5u: out[i] = lidet__q_urad_to_bam(a[i]); break;
        default: out[i] = lidet__ground_q_r((uint32_t)a[i]); break;
        }
    }
    return LIDET_OK;
}
