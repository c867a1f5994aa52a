/* SPDX-License-Identifier: MIT */
/**
 * @file fw_out.h
 * @brief The firmware applications' console output without stdio (decimal, hex and key=value fields over
 *        fw_putc) and the instruction counter's calibration, shared by fw_detect.c, fw_packets.c and fw_ground_q.c.
 *        tools/firmware/run_fw.py parses what they print.
 */
#ifndef LIDET_FW_OUT_H
#define LIDET_FW_OUT_H

#include <stdint.h>

#include "lidet/lidet_types.h"

#ifdef __cplusplus
extern "C" {
#endif

/** The class names in lidet_class_t order, as the reports print them. */
extern const char *const fw_class_names[LIDET_N_CLASSES];

void fw_put_s(const char *s);
void fw_put_u(uint32_t v);
void fw_put_u64(uint64_t v);
void fw_put_i(int32_t v);
void fw_put_i64(int64_t v);
/** Eight lower-case hex digits. */
void fw_put_hex(uint32_t v);
/** " key=value" (decimal). */
void fw_put_kv(const char *key, uint32_t v);
void fw_put_kv64(const char *key, uint64_t v);
#if !LIDET_FIXED_POINT
/** A float as a fixed-point decimal with 4 digits ("nan", "big" beyond 1e6): for reading only; comparisons
 *  read the hex bits. Absent from the integer build, which holds no floating point. */
void fw_put_f(float f);
#endif

/**
 * The counter against loops of known length (fw_spin): prints one `calib` line per length, and with `with_long`
 * a `calib_long` line for a loop longer than a 32-bit tick counter holds at 6.4 ticks per instruction (the counter
 * must be extended past its wrap). Returns nonzero when a count is off (exactly; the long loop within 64).
 */
int fw_calibrate(int with_long);

#ifdef __cplusplus
}
#endif

#endif /* LIDET_FW_OUT_H */
