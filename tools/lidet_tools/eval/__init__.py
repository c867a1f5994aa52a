# SPDX-License-Identifier: MIT
"""Evaluation of 3D detections: KITTI protocol (kitti_ap), sensor-frame protocol (boxes_ap), rotated IoU
(iou), the devkit matching engine (engine), synthetic labels (synth) and the lidet-eval CLI (cli)."""
