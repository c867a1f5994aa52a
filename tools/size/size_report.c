/* SPDX-License-Identifier: MIT */
/* Prints the bytes of every part of the detector (its workspace, PointNet scratch, proposal, detections)
 * and of the standalone stages for the capacities this file is compiled with (tools/size/size_report.sh
 * builds it per configuration). */
#include <stdio.h>

#include "lidet/lidet.h"
#include "lidet/lidet_detector.h"
#include "lidet/lidet_workspace.h"

int main(void)
{
    lidet_workspace_sizes_t s;
    lidet_workspace_sizes(&s);
    printf("proj_state %u\nground_state %u\ncluster_state %u\nimage %u\nground_mask %u\n", (unsigned)s.proj_state,
           (unsigned)s.ground_state, (unsigned)s.cluster_state, (unsigned)s.image, (unsigned)s.ground_mask);
    printf("overlay_proj %u\noverlay_ground %u\noverlay_cluster %u\noverlay %u\nworkspace %u\n", (unsigned)s.overlay_proj,
           (unsigned)s.overlay_ground, (unsigned)s.overlay_cluster, (unsigned)s.overlay, (unsigned)s.total);
    printf("proj_t %u\nground_t %u\ncluster_t %u\nstages_standalone %u\n", (unsigned)lidet_proj_bytes(),
           (unsigned)lidet_ground_bytes(), (unsigned)lidet_cluster_bytes(), (unsigned)s.stages_standalone);
    {
        const lidet_detector_t *d = 0; /* sizeof only: never dereferenced */
        const uint32_t pn_states = (uint32_t)(sizeof d->cls + sizeof d->box);
        const uint32_t parts =
            (uint32_t)(sizeof d->ws + sizeof d->pn_scratch + sizeof d->proposal + sizeof d->det) + pn_states;
        printf("det_workspace %u\ndet_pn_scratch %u\ndet_pn_states %u\n", (unsigned)sizeof d->ws,
               (unsigned)sizeof d->pn_scratch, pn_states);
        printf("det_proposal %u\ndet_detections %u\n", (unsigned)sizeof d->proposal, (unsigned)sizeof d->det);
        printf("det_rest %u\ndetector %u\n", (unsigned)(lidet_detector_bytes() - parts),
               (unsigned)lidet_detector_bytes());
    }
    return 0;
}
