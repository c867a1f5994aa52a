# SPDX-License-Identifier: MIT
"""The tracker on real consecutive scans (SemanticKITTI 00, scans 0-5 of ../shared/data/real; skips without them):
the labelled instances of scans 0-2 keep one track id each, and most tracks of the last labelled scan live on."""
import pytest

from lidet_tools.track import real


def test_semantickitti_ids_hold(real_dir, need_lib):
    if not (real_dir / "semantickitti" / "velodyne" / "00_000005.bin").exists():
        pytest.skip("SemanticKITTI 00 scans 0-5 not in the real data folder")
    res = real.run(real_dir)
    assert res["detections_per_scan"] and min(res["detections_per_scan"]) > 5
    r = res["trackers"]["lidet"]
    assert r["num_matches"] >= 8          # objects of scans 1-2 followed by confirmed tracks
    assert r["num_switches"] == 0
    assert r["tracks_per_scan"][0] == 0   # nothing confirmed after one scan (confirm_hits 2)
    kept = r["ids_kept_scans_3_5"]
    assert kept["still_there_scan_5"] >= kept["tracks_scan_2"] // 2
