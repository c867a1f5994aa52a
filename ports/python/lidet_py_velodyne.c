/* SPDX-License-Identifier: MIT */
/* Flat C entry point over the Velodyne packet decoder for the Python bindings (tests/python/test_velodyne_decode.py
 * calls it through ctypes): a whole capture's payloads decoded in one call, each return tagged with its scan. */
#include <stddef.h>
#include <string.h>

#include "lidet/lidet_velodyne.h"

#if defined(_WIN32)
#define LIDET_PY_API __declspec(dllexport)
#else
#define LIDET_PY_API __attribute__((visibility("default")))
#endif

/* Decode n_packets payloads (concatenated in `bytes`, lens[i] bytes each) with cfg = model, filter, seam_cdeg,
 * max_step_cdeg, force_model, ring_top_first and, when calib is not NULL, the calibration calib = n_lasers, then per
 * laser id vert_mdeg, rot_cdeg, dist_mm (int32; at most LIDET_VELODYNE_MAX_LASERS lasers). Per return (at most
 * cap): range_mm, azimuth (BAM16), ring, t_ns, azimuth_cdeg, intensity, flags, the packet's index, the scan number
 * (0 = the scan in progress at the start; +1 at each scan event) and, when xyz is not NULL, x y z (float, metres,
 * the decoder's elevations: lidet_velodyne_decoder_xyz). Per packet: event (scan_event | reject << 8), scan_end.
 * stats: the 18 counts of lidet_velodyne_stats_t in order. Returns the number of returns, or a negative status. */
LIDET_PY_API int64_t lidet_py_velodyne_decode(const uint8_t *bytes, const uint32_t *lens, uint32_t n_packets,
                                              const uint32_t *cfg_u32, const int32_t *calib, uint32_t cap,
                                              uint32_t *range_mm, uint16_t *azimuth, uint16_t *ring,
                                              uint32_t *t_ns, uint16_t *azimuth_cdeg, uint8_t *intensity,
                                              uint8_t *flags, uint32_t *packet, uint32_t *scan, float *xyz,
                                              uint32_t *events, uint32_t *scan_end, uint32_t *stats)
{
    lidet_velodyne_cfg_t cfg;
    lidet_velodyne_calib_t cal;
    lidet_velodyne_t st;
    lidet_return_t out[LIDET_VELODYNE_MAX_RETURNS];
    lidet_velodyne_attr_t attr[LIDET_VELODYNE_MAX_RETURNS];
    lidet_status_t status;
    uint64_t off = 0;
    uint32_t n = 0, p, scan_no = 0;
    lidet_velodyne_cfg_default(&cfg);
    cfg.model = (lidet_velodyne_model_t)cfg_u32[0];
    cfg.filter = (lidet_velodyne_filter_t)cfg_u32[1];
    cfg.seam_cdeg = (uint16_t)cfg_u32[2];
    cfg.max_step_cdeg = (uint16_t)cfg_u32[3];
    cfg.force_model = (uint8_t)cfg_u32[4];
    cfg.ring_top_first = (uint8_t)cfg_u32[5];
    if (calib != NULL)
    {
        uint32_t k;
        memset(&cal, 0, sizeof cal);
        cal.n_lasers = (uint32_t)calib[0];
        if (cal.n_lasers > LIDET_VELODYNE_MAX_LASERS)
        {
            return LIDET_ERR_CONFIG;
        }
        for (k = 0; k < cal.n_lasers; ++k)
        {
            cal.laser[k].vert_mdeg = calib[1u + 3u * k];
            cal.laser[k].rot_cdeg = (int16_t)calib[2u + 3u * k];
            cal.laser[k].dist_mm = (int16_t)calib[3u + 3u * k];
        }
        cfg.calib = &cal;
    }
    status = lidet_velodyne_init(&st, &cfg);
    if (status != LIDET_OK)
    {
        return status;
    }
    for (p = 0; p < n_packets; ++p)
    {
        lidet_velodyne_result_t res;
        uint32_t i;
        status =
            lidet_velodyne_packet(&st, bytes + off, lens[p], out, attr, LIDET_VELODYNE_MAX_RETURNS, &res);
        off += lens[p];
        events[p] = (uint32_t)res.scan_event | ((uint32_t)res.reject << 8);
        scan_end[p] = res.scan_end;
        if (status < 0)
        {
            continue;
        }
        if (xyz != NULL && res.n_returns > 0u && n + res.n_returns <= cap)
        {
            (void)lidet_velodyne_decoder_xyz(&st, out, res.n_returns, xyz + 3u * (uint64_t)n, 3u);
        }
        for (i = 0; i < res.n_returns && n < cap; ++i, ++n)
        {
            if (res.scan_event != LIDET_VELODYNE_SCAN_NONE && i == res.scan_end)
            {
                ++scan_no;
            }
            range_mm[n] = out[i].range_mm;
            azimuth[n] = out[i].azimuth;
            ring[n] = out[i].ring;
            t_ns[n] = attr[i].t_ns;
            azimuth_cdeg[n] = attr[i].azimuth_cdeg;
            intensity[n] = attr[i].intensity;
            flags[n] = attr[i].flags;
            packet[n] = p;
            scan[n] = scan_no;
        }
        if (res.scan_event != LIDET_VELODYNE_SCAN_NONE && res.scan_end == res.n_returns)
        {
            ++scan_no;
        }
    }
    memcpy(stats, lidet_velodyne_stats(&st), sizeof(lidet_velodyne_stats_t));
    return (int64_t)n;
}
