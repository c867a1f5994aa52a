/* SPDX-License-Identifier: MIT */
/* Flat C entry point over the Ouster packet decoder for the Python bindings (tools/lidet_tools/ouster.py calls it
 * through ctypes): a whole capture's payloads decoded in one call, each return tagged with its scan. */
#include <stddef.h>
#include <string.h>

#include "lidet/lidet_ouster.h"

#define GUARD 16u
#define GUARD_BYTE 0xA5u
/* returned when the decoder wrote past the cap it was given (the guard entries changed) */
#define WROTE_PAST_CAP (-100)

#if defined(_WIN32)
#define LIDET_PY_API __declspec(dllexport)
#else
#define LIDET_PY_API __attribute__((visibility("default")))
#endif

/* Decode n_packets payloads (concatenated in `bytes`, lens[i] bytes each) with cfg = profile, header, filter,
 * pixels_per_column, columns_per_frame, columns_per_packet, seam_col, max_step_cols, azimuth_offset_bam, init_id,
 * prod_sn (low 32 bits), prod_sn (high bits), out_cap (the cap given to each call; 0: LIDET_OUSTER_MAX_RETURNS),
 * and the beam azimuth table (millidegrees, pixels_per_column entries; NULL: none). Per return (at most cap):
 * range_mm, azimuth (BAM16), ring, measurement id, timestamp (ns: the payload's time_ns + t_ns), signal,
 * reflectivity, return index, flags, the packet's index, its frame id and the scan number (0 = the scan in
 * progress at the start; +1 at each scan event). Per packet: event (scan_event | reject << 8 | status << 16, the
 * status as int8), scan_end, n_returns. stats: the counts of lidet_ouster_stats_t in order. Returns the number of
 * returns, or a negative status (init), or WROTE_PAST_CAP. */
LIDET_PY_API int64_t lidet_py_ouster_decode(const uint8_t *bytes, const uint32_t *lens, uint32_t n_packets,
                                            const uint32_t *cfg_u32, const int32_t *beam_az_mdeg,
                                            uint32_t cap, uint32_t *range_mm, uint16_t *azimuth,
                                            uint16_t *ring, uint16_t *measurement_id, uint64_t *timestamp_ns,
                                            uint16_t *signal, uint16_t *reflectivity, uint8_t *return_index,
                                            uint8_t *flags, uint32_t *packet, uint32_t *frame_id,
                                            uint32_t *scan, uint32_t *events, uint32_t *scan_end,
                                            uint32_t *n_returns, uint32_t *stats)
{
    /* one payload's returns, plus GUARD entries past the cap given to the decoder, which must stay untouched */
    lidet_return_t out[LIDET_OUSTER_MAX_RETURNS + GUARD];
    lidet_ouster_attr_t attr[LIDET_OUSTER_MAX_RETURNS + GUARD];
    lidet_ouster_cfg_t cfg;
    lidet_ouster_t st;
    lidet_status_t status;
    uint64_t off = 0;
    uint32_t n = 0, p, scan_no = 0, out_cap;
    lidet_ouster_cfg_default(&cfg);
    cfg.profile = (lidet_ouster_profile_t)cfg_u32[0];
    cfg.header = (lidet_ouster_header_t)cfg_u32[1];
    cfg.filter = (lidet_ouster_filter_t)cfg_u32[2];
    cfg.pixels_per_column = (uint16_t)cfg_u32[3];
    cfg.columns_per_frame = (uint16_t)cfg_u32[4];
    cfg.columns_per_packet = (uint16_t)cfg_u32[5];
    cfg.seam_col = (uint16_t)cfg_u32[6];
    cfg.max_step_cols = (uint16_t)cfg_u32[7];
    cfg.azimuth_offset_bam = (uint16_t)cfg_u32[8];
    cfg.init_id = cfg_u32[9];
    cfg.prod_sn = (uint64_t)cfg_u32[10] | ((uint64_t)cfg_u32[11] << 32);
    cfg.beam_azimuth_mdeg = beam_az_mdeg;
    out_cap =
        cfg_u32[12] != 0u && cfg_u32[12] < LIDET_OUSTER_MAX_RETURNS ? cfg_u32[12] : LIDET_OUSTER_MAX_RETURNS;
    status = lidet_ouster_init(&st, &cfg);
    if (status != LIDET_OK)
    {
        return status;
    }
    for (p = 0; p < n_packets; ++p)
    {
        lidet_ouster_result_t res;
        uint32_t i;
        memset(out + out_cap, GUARD_BYTE, GUARD * sizeof out[0]);
        memset(attr + out_cap, GUARD_BYTE, GUARD * sizeof attr[0]);
        status = lidet_ouster_packet(&st, bytes + off, lens[p], out, attr, out_cap, &res);
        for (i = 0; i < GUARD * (uint32_t)sizeof out[0]; ++i)
        {
            if (((const uint8_t *)(out + out_cap))[i] != GUARD_BYTE)
            {
                return WROTE_PAST_CAP;
            }
        }
        for (i = 0; i < GUARD * (uint32_t)sizeof attr[0]; ++i)
        {
            if (((const uint8_t *)(attr + out_cap))[i] != GUARD_BYTE)
            {
                return WROTE_PAST_CAP;
            }
        }
        off += lens[p];
        events[p] =
            (uint32_t)res.scan_event | ((uint32_t)res.reject << 8) | (((uint32_t)status & 0xFFu) << 16);
        scan_end[p] = res.scan_end;
        n_returns[p] = res.n_returns;
        if (status < 0)
        {
            continue;
        }
        for (i = 0; i < res.n_returns && n < cap; ++i, ++n)
        {
            if (res.scan_event != LIDET_OUSTER_SCAN_NONE && i == res.scan_end)
            {
                ++scan_no;
            }
            range_mm[n] = out[i].range_mm;
            azimuth[n] = out[i].azimuth;
            ring[n] = out[i].ring;
            measurement_id[n] = attr[i].measurement_id;
            timestamp_ns[n] = res.time_ns + attr[i].t_ns;
            signal[n] = attr[i].signal;
            reflectivity[n] = attr[i].reflectivity;
            return_index[n] = attr[i].return_index;
            flags[n] = attr[i].flags;
            packet[n] = p;
            frame_id[n] = res.frame_id;
            scan[n] = scan_no;
        }
        if (res.scan_event != LIDET_OUSTER_SCAN_NONE && res.scan_end == res.n_returns)
        {
            ++scan_no;
        }
    }
    memcpy(stats, lidet_ouster_stats(&st), sizeof(lidet_ouster_stats_t));
    return (int64_t)n;
}
