/* SPDX-License-Identifier: MIT */
/* Prints the bytes of every part of the integer detector (lidet_detector_q_t) for the capacities and the pixel
 * (LIDET_Q_PIXEL_XYZ) this file is compiled with (tools/size/size_report.sh builds it per configuration). sizeof
 * only: nothing is linked. */
#include <stdio.h>

#include "lidet/lidet_detector_q.h"

int main(void)
{
    const lidet_detector_q_t *d = 0; /* sizeof only: never dereferenced */
    const unsigned states = (unsigned)(sizeof d->proj + sizeof d->ground + sizeof d->cluster);
#if LIDET_Q_PIXEL_XYZ
    const unsigned image = (unsigned)(sizeof d->x_4mm + sizeof d->y_4mm + sizeof d->z_4mm + sizeof d->range_4mm);
    const unsigned mask = (unsigned)sizeof d->mask;
#else
    const unsigned image = (unsigned)sizeof d->range_4mm;
    const unsigned mask = 0u; /* in the ground scratch's sample bytes */
#endif
    const unsigned overlay = (unsigned)sizeof d->scratch, pn = (unsigned)sizeof d->pn_scratch;
    const unsigned total = (unsigned)sizeof(lidet_detector_q_t);
    printf("q_states %u\nq_image %u\nq_mask %u\nq_overlay %u\nq_overlay_proj %u\nq_overlay_ground %u\n", states,
           image, mask, overlay, (unsigned)sizeof d->scratch.point_idx, (unsigned)sizeof d->scratch.ground);
    printf("q_overlay_cluster %u\nq_pn_scratch %u\nq_rest %u\nq_detector %u\n", (unsigned)sizeof d->scratch.cluster,
           pn, total - states - image - mask - overlay - pn, total);
    return 0;
}
