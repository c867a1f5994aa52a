/* SPDX-License-Identifier: MIT */
/* Instructions of the projection on a bare-metal core (tools/bench/fw_proj_q/run.sh builds it for the Cortex-M0+
 * instruction set and runs it under QEMU with exact instruction counting, as the firmware images do): the integer
 * projection (lidet_proj_q_run) of the stored scan in mm, by elevation and by ring, next to the float projection
 * writing the same compact image (lidet_proj_run_buffers, soft float on this core). One line on the console. */
#include <stdint.h>

#include "fw_port.h"
#include "fw_scan.h"
#include "lidet/lidet.h"

#define NPIX (LIDET_MAX_ROWS * LIDET_MAX_COLS)

static int16_t g_x[NPIX], g_y[NPIX], g_z[NPIX];
static uint16_t g_r[NPIX];
static int32_t g_idx[NPIX];
static int32_t g_mm[LIDET_MAX_POINTS * 3];
static lidet_proj_q_state_t g_q;
static lidet_proj_state_t g_f;
static const lidet_proj_q_buffers_t g_bq = {g_x, g_y, g_z, g_r, g_idx, 0};
/* the float projection's compact image: x_m NULL, the 4 mm planes, no per-point pixels */
static const lidet_proj_buffers_t g_bf = {0, 0, 0, 0, g_x, g_y, g_z, g_r, 0, g_idx, 0};

static void put_s(const char *s)
{
    while (*s != '\0')
        fw_putc(*s++);
}

static void put_u(uint64_t v)
{
    char b[24];
    int i = 0;
    do
    {
        b[i++] = (char)('0' + v % 10u);
        v /= 10u;
    } while (v != 0u);
    while (i > 0)
        fw_putc(b[--i]);
}

int fw_main(void);

int fw_main(void)
{
    const uint32_t n = fw_scan_n < LIDET_MAX_POINTS ? fw_scan_n : LIDET_MAX_POINTS;
    lidet_proj_q_cfg_t cq;
    lidet_proj_cfg_t cf;
    uint64_t t0, t1, t2, t3;
    uint32_t i, filled;
    for (i = 0; i < 3u * n; ++i) /* mm, rounded half away from zero (not timed) */
    {
        const float v = fw_scan_xyz[i] * 1000.0f;
        g_mm[i] = (int32_t)(v >= 0.0f ? v + 0.5f : v - 0.5f);
    }
    lidet_proj_q_cfg_default(&cq, lidet_sensor_q_find(FW_SENSOR));
    lidet_proj_cfg_default(&cf, lidet_sensor_find(FW_SENSOR));
    if (lidet_proj_q_init(&g_q, &cq) != LIDET_OK || lidet_proj_state_init(&g_f, &cf) != LIDET_OK)
        return 1;
    t0 = fw_insn64();
    lidet_proj_q_run(&g_q, &g_bq, g_mm, n, 3u, 0);
    t1 = fw_insn64();
    filled = g_q.stats.n_pixels_filled;
    lidet_proj_q_run(&g_q, &g_bq, g_mm, n, 3u, fw_scan_has_ring ? fw_scan_ring : 0);
    t2 = fw_insn64();
    lidet_proj_run_buffers(&g_f, &g_bf, fw_scan_xyz, n, 3u, 0);
    t3 = fw_insn64();
    put_s("proj_q core=");
    put_s(fw_core_name);
    put_s(" points=");
    put_u(n);
    put_s(" filled=");
    put_u(filled);
    put_s(" insn_int=");
    put_u(t1 - t0);
    put_s(" insn_int_ring=");
    put_u(t2 - t1);
    put_s(" insn_float_compact=");
    put_u(t3 - t2);
    put_s("\n");
    return 0;
}
