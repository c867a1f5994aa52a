/* SPDX-License-Identifier: MIT */
/* Compiled by tests/opt/check_opt.cmake, in C and in C++, with one option of lidet_opt.h set at a time: every
 * public header, so that an out-of-range value fails with lidet_opt.h's #error and a valid one compiles. */
#include "lidet/lidet.h"
#include "lidet/lidet_detector_q.h"
#include "lidet/lidet_workspace.h"

int lidet_opt_probe(void);
int lidet_opt_probe(void)
{
    return (int)(sizeof(lidet_detector_t) > 0u) + (int)(sizeof(lidet_detector_q_t) > 0u);
}
