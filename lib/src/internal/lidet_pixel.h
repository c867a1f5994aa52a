/* SPDX-License-Identifier: MIT */
/* Reading a pixel of either image format (lidet_proj.h: lidet_range_image_t): a float image (x_m set,
 * the reference) or a compact one (x_m NULL; int16 x, y, z and uint16 range in 4 mm steps, a detector
 * workspace's). Stages read coordinates through these where they read them, so one stage source serves
 * both; a compact value decodes as (float)v * LIDET_PIXEL_M (exact in float for |v| < 2^24, then one
 * rounding of the product). Hot loops that would pay the format test per read take it as a constant
 * argument of a static inline function instead (the test then folds away); the flood fill is compiled
 * once per range type (lidet_cluster_grow_body.h) and reads 4 mm steps undecoded. */
#ifndef LIDET_PIXEL_INTERNAL_H
#define LIDET_PIXEL_INTERNAL_H

#include "lidet/lidet_proj.h"

static inline float lidet__pix_m(int32_t v)
{
    return (float)v * LIDET_PIXEL_M;
}

static inline int lidet__img_compact(const lidet_range_image_t *img)
{
    return img->x_m == 0;
}

/* the image has every plane of its format */
static inline int lidet__img_complete(const lidet_range_image_t *img)
{
    return img->x_m != 0 ? (img->y_m != 0 && img->z_m != 0 && img->range_m != 0)
                         : (img->x_4mm != 0 && img->y_4mm != 0 && img->z_4mm != 0 && img->range_4mm != 0);
}

static inline float lidet__img_x(const lidet_range_image_t *img, uint32_t p)
{
    return img->x_m != 0 ? img->x_m[p] : lidet__pix_m(img->x_4mm[p]);
}

static inline float lidet__img_y(const lidet_range_image_t *img, uint32_t p)
{
    return img->x_m != 0 ? img->y_m[p] : lidet__pix_m(img->y_4mm[p]);
}

static inline float lidet__img_z(const lidet_range_image_t *img, uint32_t p)
{
    return img->x_m != 0 ? img->z_m[p] : lidet__pix_m(img->z_4mm[p]);
}

static inline float lidet__img_range(const lidet_range_image_t *img, uint32_t p)
{
    return img->x_m != 0 ? img->range_m[p] : lidet__pix_m(img->range_4mm[p]);
}

/* the range of pixel p; `compact` a constant at the call in hot loops (lidet__img_compact(img)) */
static inline float lidet__img_range_c(const lidet_range_image_t *img, uint32_t p, int compact)
{
    return compact ? lidet__pix_m(img->range_4mm[p]) : img->range_m[p];
}

/* x, y, z of pixel p; `compact` a constant at the call in hot loops (lidet__img_compact(img)) */
static inline void lidet__img_xyz(const lidet_range_image_t *img, uint32_t p, int compact, float *x, float *y,
                                  float *z)
{
    if (!compact)
    {
        *x = img->x_m[p];
        *y = img->y_m[p];
        *z = img->z_m[p];
    }
    else
    {
        *x = lidet__pix_m(img->x_4mm[p]);
        *y = lidet__pix_m(img->y_4mm[p]);
        *z = lidet__pix_m(img->z_4mm[p]);
    }
}

#endif
