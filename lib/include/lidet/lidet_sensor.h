/* SPDX-License-Identifier: MIT */
/**
 * @file lidet_sensor.h
 * @brief Sensor profiles: beam elevation tables, columns per revolution, mount height.
 *
 * A profile describes a spinning LiDAR: `n_rows` beams with the elevation of each beam listed in
 * the sensor's *ring order* (the ring index its driver reports; any order is accepted, the
 * projection sorts them top to bottom into image rows), `n_cols` azimuth steps per revolution,
 * and the height of the sensor's optical centre above the ground (used by the ground stage).
 * Instead of a table, a uniform field of view may be given (`beam_elev_rad == NULL`): beam i then
 * sits at the centre of the i-th of n_rows equal bins between fov_up_rad and fov_down_rad, which
 * makes the nearest-beam rule equal to the classic uniform formula.
 *
 * Presets (lidet_sensor_find): "hdl64" (KITTI HDL-64E, table measured on real KITTI scans, 2048
 * cols, 1.73 m), "vlp16" (+-15 deg, 1800 cols, 0.5 m robot mount), "vlp32c" (its real
 * non-uniform table, 1800 cols), "os1-64" and "os1-128" (+-22.5 deg uniform, 2048 cols), "hdl32" (HDL-32E,
 * -30.67 .. +10.67 deg, 1085 cols: nuScenes' 20 Hz, 1.84 m), and the Ouster presets at 1024 cols "os0-32",
 * "os0-64", "os0-128" (+-45 deg), "os1-32" (+-22.5 deg), "os2-32", "os2-64", "os2-128" (+-11.25 deg), uniform,
 * 1.0 m. lidet_sensor_at(i) lists them in this order (docs/SENSORS.md).
 * tools/lidet_tools/sensors.py mirrors these tables (tests keep the two identical).
 */
#ifndef LIDET_SENSOR_H
#define LIDET_SENSOR_H

#include "lidet_types.h"

#ifdef __cplusplus
extern "C" {
#endif

/** @brief A sensor profile. Plain data: fill one yourself for a custom sensor. */
typedef struct
{
    const char *name;           /**< profile name (informational) */
    uint16_t n_rows;            /**< beams = range-image rows, [1, LIDET_MAX_ROWS] */
    uint16_t n_cols;            /**< azimuth steps per revolution, [8, LIDET_MAX_COLS] */
    const float *beam_elev_rad; /**< n_rows elevations in ring order (radians, distinct, within
                                     (-pi/2, pi/2)); NULL = uniform between fov_up and fov_down.
                                     Only read by lidet_proj_init (copied), may be freed after. */
    float fov_up_rad;           /**< top edge of the uniform field of view (table == NULL only) */
    float fov_down_rad;         /**< bottom edge of the uniform field of view (table == NULL only) */
    float mount_height_m;       /**< optical centre above the ground plane, metres */
    float max_range_m;          /**< nominal maximum range (informational, used by tools) */
} lidet_sensor_t;

/**
 * @brief Look up a preset by name ("hdl64", "vlp16", "os1-64", ...; the file comment).
 * @param[in] name NUL-terminated profile name; may be NULL.
 * @return the preset (static storage, never modify it), or NULL when unknown.
 */
const lidet_sensor_t *lidet_sensor_find(const char *name);

/**
 * @brief Enumerate presets.
 * @param[in] index 0-based.
 * @return preset number `index`, or NULL past the last one.
 */
const lidet_sensor_t *lidet_sensor_at(uint32_t index);

#ifdef __cplusplus
}
#endif

#endif /* LIDET_SENSOR_H */
