# SPDX-License-Identifier: MIT
"""Python bindings over the C library (ctypes + numpy), so tools and training see exactly what the
firmware computes: the float stages, the PointNets and the detector, and their integer (fixed-point) twins
(`project` / `project_q`, `ground` / `ground_q`, `cluster` / `cluster_q`, `pn_classify` / `pnq_classify`,
`detect` / `detect_q`, ...) with the integer math (`qmath`), all in this one namespace.

The shared library `liblidet_py.so` is built by CMake (ports/python). It is found, in order, at
`$LIDET_LIB`, under `$LIDET_BUILD_DIR/ports/python/`, or under `<repo>/build/ports/python/`
(`make build` puts it there).

Every float stage call works on an explicit scan context: a C object holding one scan's stage states. `project`,
`ground` and `cluster` each run on a fresh one, and what they return keeps it (`Clusters` keeps the
scan it clustered), so `proposals(clusters)` always reads the scan of that `cluster` call, whatever
ran in between. Configurations and statistics cross the boundary as the C structs themselves, by
field name: the layout (names, offsets, sizes) comes from the C side (`lidet_py_field`), and every
default from the C `*_cfg_default` functions.

The code is split by stage, float and integer side by side as in lib/src/: _lib (loading, status names and
LidetError, struct layouts and records, argument types, the scan context, capacities), _qmath, _proj, _ground,
_cluster, _pointnet, _detector. Each area types the entry points it calls on first use (`_lib.entry_points`).
"""
from ._lib import (MAX_STRIDE, PIXEL_MODELS, LidetError, ScanContext, capacity, lib, status_names,
                   struct_layouts)
from ._qmath import isqrt32, qmath
from ._proj import (PROJ_Q_STATS, RETURN_DTYPE, CompactImage, RangeImage, as_returns, c_sensors, proj_defaults,
                    proj_init, project, project_compact, project_q, sensors_q, to_mm)
from ._ground import (PLANE_SOURCE, GroundQResult, GroundResult, far2_on, ground, ground_defaults,
                      ground_fit_plane, ground_float_compact, ground_pair, ground_q, ground_q_defaults,
                      ground_q_fields, ground_q_time)
from ._cluster import (CLUSTER_Q_FIELDS, PROPOSAL_Q_FIELDS, Clusters, ClustersOnImage, CompactScan, Proposals,
                       cluster, cluster_defaults, cluster_f_compact, cluster_q, cluster_q_defaults, compact_scan,
                       plane_sectors, planes_to_q, proposal_defaults, proposal_indices, proposals)
from ._pointnet import (PnModel, pn_box, pn_classify, pn_forward, pn_models, pn_time, pnq_box, pnq_classify,
                        pnq_energy, pnq_forward, pnq_models, pnq_time)
from ._detector import (CLASSES, DETQ_STATS, OUTCOME, Detections, LidetFrameWarning, bev_iou_float, bev_iou_q,
                        candidates_float, candidates_q, default_family, detect, detect_q, detector_q_bytes,
                        frame_warning, post_q)

__all__ = [
    "MAX_STRIDE", "PIXEL_MODELS", "LidetError", "ScanContext", "capacity", "lib", "status_names", "struct_layouts",
    "isqrt32", "qmath",
    "PROJ_Q_STATS", "RETURN_DTYPE", "CompactImage", "RangeImage", "as_returns", "c_sensors", "proj_defaults",
    "proj_init", "project", "project_compact", "project_q", "sensors_q", "to_mm",
    "PLANE_SOURCE", "GroundQResult", "GroundResult", "far2_on", "ground", "ground_defaults", "ground_fit_plane",
    "ground_float_compact", "ground_pair", "ground_q", "ground_q_defaults", "ground_q_fields", "ground_q_time",
    "CLUSTER_Q_FIELDS", "PROPOSAL_Q_FIELDS", "Clusters", "ClustersOnImage", "CompactScan", "Proposals", "cluster",
    "cluster_defaults", "cluster_f_compact", "cluster_q", "cluster_q_defaults", "compact_scan", "plane_sectors",
    "planes_to_q", "proposal_defaults", "proposal_indices", "proposals",
    "PnModel", "pn_box", "pn_classify", "pn_forward", "pn_models", "pn_time", "pnq_box", "pnq_classify",
    "pnq_energy", "pnq_forward", "pnq_models", "pnq_time",
    "CLASSES", "DETQ_STATS", "OUTCOME", "Detections", "LidetFrameWarning", "bev_iou_float", "bev_iou_q",
    "candidates_float", "candidates_q", "default_family", "detect", "detect_q", "detector_q_bytes", "frame_warning",
    "post_q",
]
