/* SPDX-License-Identifier: MIT */
/**
 * @file lidet_sensor_q.h
 * @brief Sensor profiles of the integer path (lidet_q.h units): the presets of lidet_sensor.h with beam
 *        elevations and field of view in microradians, mount height and maximum range in millimetres.
 *
 * Same presets, same ring order, same conventions as lidet_sensor.h (a table in ring order, or a uniform
 * field of view when beam_elev_urad is NULL: beam i at the centre of the i-th of n_rows equal bins). The
 * integer values are the float presets rounded to the nearest microradian / millimetre; a test keeps C,
 * tools/lidet_tools/sensors.py and the float presets consistent (tests/python/test_proj_q.py).
 */
#ifndef LIDET_SENSOR_Q_H
#define LIDET_SENSOR_Q_H

#include "lidet_types.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Largest |elevation| the integer path accepts for a beam or a field-of-view edge (margin included):
 *  1.1 rad (63 deg), where tan^2 < 4 keeps the projection's products inside int64. */
#define LIDET_Q_MAX_ELEV_URAD 1100000

/** @brief An integer sensor profile. Plain data: fill one yourself for a custom sensor. */
typedef struct
{
    const char *name;              /**< profile name (informational) */
    uint16_t n_rows;               /**< beams = range-image rows, [1, LIDET_MAX_ROWS] */
    uint16_t n_cols;               /**< azimuth steps per revolution, [8, LIDET_MAX_COLS] */
    const int32_t *beam_elev_urad; /**< n_rows elevations in ring order (microradians, distinct, within
                                        +-LIDET_Q_MAX_ELEV_URAD); NULL = uniform between fov_up and
                                        fov_down. Only read by init (copied). */
    int32_t fov_up_urad;           /**< top edge of the uniform field of view (table == NULL only) */
    int32_t fov_down_urad;         /**< bottom edge of the uniform field of view (table == NULL only) */
    int32_t mount_height_mm;       /**< optical centre above the ground plane */
    int32_t max_range_mm;          /**< nominal maximum range (informational) */
} lidet_sensor_q_t;

/**
 * @brief Look up an integer preset by name (the names of lidet_sensor_find: "hdl64", "vlp16", "vlp32c", "hdl32",
 *        "os1-64", ...).
 * @return the preset (static storage), or NULL when unknown or name is NULL.
 */
const lidet_sensor_q_t *lidet_sensor_q_find(const char *name);

/** @brief Integer preset number `index` (0-based, the order of lidet_sensor_at), NULL past the last one. */
const lidet_sensor_q_t *lidet_sensor_q_at(uint32_t index);

/**
 * @brief The beam elevations of a profile in ring order (the table, or the uniform beams
 *        fov_up - round((2 i + 1) (fov_up - fov_down) / (2 n_rows)), rounded half away from zero).
 * @param[in]  s        profile.
 * @param[out] out_urad n_rows entries.
 * @return LIDET_OK; LIDET_ERR_ARG (NULL); LIDET_ERR_CONFIG (n_rows 0, elevations or fov edges beyond
 *         +-LIDET_Q_MAX_ELEV_URAD, fov_up <= fov_down); LIDET_ERR_BUFFER (n_rows > LIDET_MAX_ROWS).
 *         Distinctness is checked by the projection's init.
 */
lidet_status_t lidet_sensor_q_elevations(const lidet_sensor_q_t *s, int32_t *out_urad);

#ifdef __cplusplus
}
#endif

#endif /* LIDET_SENSOR_Q_H */
