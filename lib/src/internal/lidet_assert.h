/* SPDX-License-Identifier: MIT */
/* LIDET_ASSERT: checks of what init already validated; compiled out unless LIDET_DEBUG.
 * A port may define LIDET_ASSERT itself (e.g. to its fault handler) before this header. */
#ifndef LIDET_ASSERT_H
#define LIDET_ASSERT_H

#include "lidet/lidet_opt.h"

#ifndef LIDET_ASSERT
#if LIDET_DEBUG
#include <assert.h>
#define LIDET_ASSERT(c) assert(c)
#else
#define LIDET_ASSERT(c) ((void)0)
#endif
#endif

#endif
