/* SPDX-License-Identifier: MIT */
/* String helper shared by the float and the integer sensor presets (no libc string calls in lib/). */
#ifndef LIDET_STR_H
#define LIDET_STR_H

/** 1 when the NUL-terminated strings a and b are equal */
static inline int lidet__str_equal(const char *a, const char *b)
{
    while (*a != '\0' && *a == *b)
    {
        ++a;
        ++b;
    }
    return *a == *b;
}

#endif
