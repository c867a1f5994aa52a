/* SPDX-License-Identifier: MIT */
/* What the bindings' integer-detector files share (host only, not exported). */
#ifndef LIDET_PY_DETQ_H
#define LIDET_PY_DETQ_H

#include "lidet/lidet_detector_q.h"

/* The entries of icfg (lidet_py_detq_run's layout, lidet_py_det_q.c); every caller passes all of them */
#define LIDET_PY_DETQ_ICFG 25

/* Configure det from the defaults of `sensor` and icfg (LIDET_PY_DETQ_ICFG entries: crop_half_bam, max_range_mm,
 * nms_iou_q15, max_proposals (0 = the default), gate1, gate2, max_boxes (0 = the default), ..., stream_sectors (1: on;
 * else off), the stream's chunk (> 0: the returns streamed that many at a time, lidet_detector_q_stream_*; else one
 * run), the sensor's mount height in mm (-1: the preset's; [0, 10 000])) with the int8 models cls_name / box_name of
 * lidet::weights, initialise it and run it on n points (stride int32 each, mm), or on n returns when returns is not
 * NULL; point_pixel (n int32, or NULL; not with a stream): each point's pixel. Returns the run's status
 * (LIDET_ERR_NOT_FOUND: sensor or model; LIDET_ERR_CONFIG: a mount height out of range). */
int lidet_py__detq_init_run(lidet_detector_q_t *det, const char *sensor, const char *cls_name,
                            const char *box_name, const int32_t *icfg, const int32_t *pts_mm, uint32_t n,
                            uint32_t stride, const lidet_return_t *returns, int32_t *point_pixel);

#endif
