/* SPDX-License-Identifier: MIT */
#include <stdio.h>

#include <lidet/lidet.h>

static lidet_proj_t proj;

int main(void)
{
    const float pts[2 * 4] = {10.0f, 0.0f, -1.0f, 0.0f, 0.0f, 5.0f, 0.0f, 0.0f};
    lidet_proj_cfg_t cfg;
    lidet_proj_cfg_default(&cfg, lidet_sensor_find("vlp16"));
    if (lidet_proj_init(&proj, &cfg) != LIDET_OK || lidet_proj_run(&proj, pts, 2, 4, NULL) != LIDET_OK)
    {
        return 1;
    }
    printf("lidet %s: %u pixels filled\n", lidet_version(), (unsigned)lidet_proj_stats(&proj)->n_pixels_filled);
    return lidet_proj_stats(&proj)->n_pixels_filled == 2 ? 0 : 1;
}
