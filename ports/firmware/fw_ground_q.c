/* SPDX-License-Identifier: MIT */
/* A measurement image (LIDET_FW_APP=ground_q): the scan in flash projected into a compact image (the float
 * projection's compact path, as a detector workspace), then the integer ground stage (lidet_ground_q) and the
 * float ground stage on that same image, each between two reads of the instruction counter; then the integer
 * stage again with parts switched off, one after the other (no refinement; + one hypothesis per cell; + no veto),
 * for where its instructions go. One line:
 *   ground_q core=C status_q=S status_f=S insn_q=N insn_f=N insn_q_norefine=N insn_q_1hyp=N insn_q_noveto=N
 *            ground_q=N ground_f=N same=N pixels=N
 * (same: pixels whose labels agree). Build and run (Cortex-M0+ code on QEMU's AN385, docs/journal/fixed-point.md,
 * "Cost on a Cortex-M (the ground_q image)"):
 *   cmake -S ports/firmware -B build-fw/gq-m0 -DLIDET_FW_BOARD=mps2-an385-m0plus -DLIDET_FW_APP=ground_q \
 *         -DCMAKE_TOOLCHAIN_FILE=$PWD/cmake/toolchains/arm-none-eabi.cmake && cmake --build build-fw/gq-m0
 *   qemu-system-arm -M mps2-an385 -icount shift=8 -display none -monitor none -kernel build-fw/gq-m0/lidet_fw.elf \
 *         -semihosting-config enable=on,target=native -serial null */
#include <stdint.h>
#include <string.h>

#include "fw_out.h"
#include "fw_port.h"
#include "fw_scan.h"
#include "lidet/lidet.h"

static lidet_proj_state_t g_proj;
static int16_t g_x[LIDET_MAX_ROWS * LIDET_MAX_COLS], g_y[LIDET_MAX_ROWS * LIDET_MAX_COLS];
static int16_t g_z[LIDET_MAX_ROWS * LIDET_MAX_COLS];
static uint16_t g_r[LIDET_MAX_ROWS * LIDET_MAX_COLS];
static int32_t g_idx[LIDET_MAX_ROWS * LIDET_MAX_COLS];
static lidet_ground_q_t g_q;
static lidet_ground_t g_f;

static void field(const char *name, int64_t v)
{
    fw_put_s(" ");
    fw_put_s(name);
    fw_put_s("=");
    fw_put_i64(v);
}

int fw_main(void)
{
    const lidet_sensor_t *sensor = lidet_sensor_find(FW_SENSOR);
    lidet_proj_cfg_t pc;
    lidet_proj_buffers_t b;
    lidet_range_image_t img;
    lidet_ground_q_cfg_t qc;
    lidet_ground_cfg_t fc;
    uint64_t t0, t1, t2, t3, insn_q, part[3];
    uint32_t p, same = 0, npix, n_ground_q;
    int rq, rf;
    if (sensor == 0)
        return 1;
    lidet_proj_cfg_default(&pc, sensor);
    memset(&b, 0, sizeof b);
    b.x_4mm = g_x;
    b.y_4mm = g_y;
    b.z_4mm = g_z;
    b.range_4mm = g_r;
    b.point_idx = g_idx;
    if (lidet_proj_state_init(&g_proj, &pc) != LIDET_OK ||
        lidet_proj_run_buffers(&g_proj, &b, fw_scan_xyz, fw_scan_n, 3, fw_scan_has_ring ? fw_scan_ring : 0) < 0)
    {
        fw_put_s("ground_q: FAIL (projection)\n");
        return 1;
    }
    lidet_proj_image_of(&g_proj, &b, &img);
    lidet_ground_q_cfg_default(&qc, sensor->n_rows, (int32_t)(sensor->mount_height_m * 1000.0f + 0.5f));
    lidet_ground_cfg_default(&fc, sensor);
    if (lidet_ground_q_init(&g_q, &qc) != LIDET_OK || lidet_ground_init(&g_f, &fc) != LIDET_OK)
    {
        fw_put_s("ground_q: FAIL (init)\n");
        return 1;
    }
    t0 = fw_insn64();
    rq = lidet_ground_q_run(&g_q, &img);
    t1 = fw_insn64();
    t2 = fw_insn64();
    rf = lidet_ground_run(&g_f, &img);
    t3 = fw_insn64();
    npix = (uint32_t)img.n_rows * img.n_cols;
    for (p = 0; p < npix; ++p)
        same += g_q.mask[p] == g_f.mask[p];
    n_ground_q = g_q.state.stats.n_ground;
    insn_q = t1 - t0;
    {
        int v;
        for (v = 0; v < 3; ++v)
        {
            lidet_ground_q_cfg_t c2 = qc;
            c2.refine_iters = 0u;
            c2.ransac_iters = v >= 1 ? 1u : c2.ransac_iters;
            c2.veto_slope_q16 = v >= 2 ? 0u : c2.veto_slope_q16;
            if (lidet_ground_q_init(&g_q, &c2) != LIDET_OK)
                return 1;
            t0 = fw_insn64();
            (void)lidet_ground_q_run(&g_q, &img);
            t1 = fw_insn64();
            part[v] = t1 - t0;
        }
    }
    fw_put_s("ground_q core=");
    fw_put_s(fw_core_name);
    field("status_q", rq);
    field("status_f", rf);
    field("insn_q", (int64_t)insn_q);
    field("insn_f", (int64_t)(t3 - t2));
    field("insn_q_norefine", (int64_t)part[0]);
    field("insn_q_1hyp", (int64_t)part[1]);
    field("insn_q_noveto", (int64_t)part[2]);
    field("ground_q", n_ground_q);
    field("ground_f", g_f.state.stats.n_ground);
    field("same", same);
    field("pixels", npix);
    fw_put_s("\n");
    return rq < 0 || rf < 0;
}
