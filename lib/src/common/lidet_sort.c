/* SPDX-License-Identifier: MIT */
/* Heapsort of (key, index) pairs (internal/lidet_sort.h). */
#include "internal/lidet_sort.h"

static int before(const uint32_t *key, const uint16_t *idx, uint32_t a, uint32_t b)
{
    return key[a] < key[b] || (key[a] == key[b] && idx[a] < idx[b]);
}

static void swap2(uint32_t *key, uint16_t *idx, uint32_t a, uint32_t b)
{
    const uint32_t k = key[a];
    const uint16_t i = idx[a];
    key[a] = key[b];
    idx[a] = idx[b];
    key[b] = k;
    idx[b] = i;
}

static void sift(uint32_t *key, uint16_t *idx, uint32_t root, uint32_t n)
{
    for (;;)
    {
        uint32_t c = 2u * root + 1u;
        if (c >= n)
        {
            return;
        }
        if (c + 1u < n && before(key, idx, c, c + 1u))
        {
            ++c;
        }
        if (!before(key, idx, root, c))
        {
            return;
        }
        swap2(key, idx, root, c);
        root = c;
    }
}

void lidet__sort_u32_u16(uint32_t *key, uint16_t *idx, uint32_t n)
{
    uint32_t i;
    if (n < 2u)
    {
        return;
    }
    for (i = n / 2u; i-- > 0u;)
    {
        sift(key, idx, i, n);
    }
    for (i = n - 1u; i > 0u; --i)
    {
        swap2(key, idx, 0, i);
        sift(key, idx, 0, i);
    }
}

uint32_t lidet__nearest_first(uint32_t *key, uint16_t *idx, uint32_t n, uint32_t max, uint8_t *outcome,
                              uint8_t code, uint32_t *n_over)
{
    uint32_t i;
    lidet__sort_u32_u16(key, idx, n);
    if (n <= max)
    {
        return n;
    }
    for (i = max; i < n; ++i)
    {
        outcome[idx[i]] = code;
    }
    *n_over = n - max;
    return max;
}
