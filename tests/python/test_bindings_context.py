# SPDX-License-Identifier: MIT
"""The bindings work on explicit scan contexts (no global state), and configurations and statistics
cross the boundary by field name with the layout and the defaults of the C side."""
import re

import numpy as np
import pytest

from lidet_ref import cluster as ref
from lidet_tools import native

pytestmark = pytest.mark.usefixtures("need_lib")


def _scene(seed, car_at, ped_at):
    """Flat ground plus a car-sized and a pedestrian-sized vertical face (points facing the sensor)."""
    rng = np.random.default_rng(seed)
    g = np.c_[rng.uniform(-30, 30, 30000), rng.uniform(-30, 30, 30000), np.full(30000, -1.73)]
    parts = [g]
    for (cx, cy, cz), w, h, n in ((car_at, 1.8, 1.5, 5000), (ped_at, 0.5, 1.7, 1500)):
        c = np.array([cx, cy, cz])
        t = np.array([-cy, cx, 0.0]) / np.hypot(cx, cy)
        u = rng.uniform(-0.5, 0.5, (n, 1)) * w
        v = rng.uniform(-0.5, 0.5, (n, 1)) * h
        parts.append(c + u * t + v * np.array([0.0, 0.0, 1.0]))
    pts = np.concatenate(parts).astype(np.float32)
    ground = np.r_[np.ones(len(g), bool), np.zeros(len(pts) - len(g), bool)]
    return np.c_[pts, np.zeros(len(pts), np.float32)], ground


def test_proposals_read_the_scan_of_their_cluster_call():
    a_pts, a_gnd = _scene(1, (10.0, 0.0, -0.9), (8.0, 4.0, -0.85))
    b_pts, b_gnd = _scene(2, (-12.0, 5.0, -0.9), (6.0, -7.0, -0.85))
    ca = native.cluster(a_pts, "hdl64", ground=a_gnd, with_image=True)
    assert len(ca) == 2
    pa = native.proposals(ca, n_points=32)
    # other scans go through every stage in between, on their own contexts
    native.project(b_pts, "hdl64")
    native.ground(b_pts, "hdl64")
    cb = native.cluster(b_pts, "hdl64", ground=b_gnd)
    pa2 = native.proposals(ca, n_points=32)
    pb = native.proposals(cb, n_points=32)
    for k in ("xyz", "mean", "voxel", "n_src"):
        np.testing.assert_array_equal(getattr(pa, k), getattr(pa2, k))
    assert not np.allclose(pa.mean, pb.mean)
    # and they are the proposals of scan A's clusters (bit-exact against the reference)
    xyz = np.stack([ca.image.x, ca.image.y, ca.image.z], -1).reshape(-1, 3)
    for i in range(len(ca)):
        m = ca.members[ca.first_member[i]:ca.first_member[i] + ca.n_points[i]]
        rx, rmean, _ = ref.make_proposal(xyz[m], ca.mean[i], n_points=32, pixels=m)
        np.testing.assert_array_equal(pa.xyz[i], rx)
        np.testing.assert_array_equal(pa.mean[i], rmean)
    # the first n only; a count past the clusters is refused
    np.testing.assert_array_equal(native.proposals(ca, n_clusters=1, n_points=32).xyz, pa.xyz[:1])
    with pytest.raises(ValueError):
        native.proposals(ca, n_clusters=3)


def test_proposals_need_the_clusters_they_read():
    with pytest.raises(TypeError):
        native.proposals(n_clusters=2)  # the old form read whatever scan the C side held last
    with pytest.raises(TypeError):
        native.proposals(2)


def test_ground_and_project_results_keep_their_scan():
    a_pts, _ = _scene(3, (10.0, 0.0, -0.9), (8.0, 4.0, -0.85))
    b_pts, _ = _scene(4, (-12.0, 5.0, -0.9), (6.0, -7.0, -0.85))
    ia = native.project(a_pts, "vlp16")
    ga = native.ground(a_pts, "vlp16")
    native.ground(b_pts, "vlp16")
    np.testing.assert_array_equal(ia.range, ga.image.range)
    np.testing.assert_array_equal(native.ground(a_pts, "vlp16").mask_pixel, ga.mask_pixel)


def _header_structs(root):
    """typedef struct { ... } name; of the public headers -> list of field names (comments stripped)."""
    out = {}
    for h in (root / "lib" / "include" / "lidet").glob("*.h"):
        text = re.sub(r"/\*.*?\*/", "", h.read_text(), flags=re.S)
        text = re.sub(r"//[^\n]*", "", text)
        for body, name in re.findall(r"typedef struct\s*\{(.*?)\}\s*(\w+)\s*;", text, flags=re.S):
            names = []
            for decl in body.split(";"):
                decl = decl.strip()
                if not decl:
                    continue
                # "type a, b[3]" -> a, b (the first word(s) before the first declarator are the type)
                head, *rest = [p.strip() for p in decl.split(",")]
                names.append(re.sub(r"\[.*", "", head).split()[-1].lstrip("*"))
                names += [re.sub(r"\[.*", "", p).lstrip("*") for p in rest]
            out[name] = names
    return out


def test_struct_layouts_follow_the_headers(root):
    header = _header_structs(root)
    layouts = native.struct_layouts()
    expect = {"lidet_proj_cfg_t", "lidet_proj_stats_t", "lidet_ground_cfg_t", "lidet_ground_stats_t",
              "lidet_cluster_cfg_t", "lidet_cluster_stats_t", "lidet_proposal_cfg_t"}
    assert expect <= set(layouts)
    for name, dt in layouts.items():
        fields = [f for f in header[name] if not (name == "lidet_proj_cfg_t" and f == "sensor")]
        assert list(dt.names) == fields, name  # every field, in header order (the sensor travels apart)
        offs = [dt.fields[f][1] for f in dt.names]
        ends = [o + dt.fields[f][0].itemsize for f, o in zip(dt.names, offs)]
        assert all(e <= o for e, o in zip(ends, offs[1:])) and ends[-1] <= dt.itemsize, name


def test_defaults_and_stats_come_from_c():
    g = native.ground_defaults("vlp16")
    assert list(g) == list(native.struct_layouts()["lidet_ground_cfg_t"].names)
    assert g["sample_step"] == 1 and g["mount_height_m"] == np.float32(0.5)
    assert native.ground_defaults("hdl64")["sample_step"] == 4
    assert native.proj_defaults()["min_range_m"] == np.float32(0.1)
    assert native.proposal_defaults()["seed"] == 0x5EED1234
    pts, _ = _scene(5, (10.0, 0.0, -0.9), (8.0, 4.0, -0.85))
    img = native.project(pts, "hdl64", min_range_m=8.0)
    assert set(img.stats) == set(native.struct_layouts()["lidet_proj_stats_t"].names)
    assert img.stats["n_too_close"] > 0 and img.stats["n_points_in"] == len(pts)
    with pytest.raises(TypeError):
        native.project(pts, "hdl64", min_range=1.0)
    gr = native.ground(pts, "hdl64")
    assert set(gr.stats) == set(native.struct_layouts()["lidet_ground_stats_t"].names)
    assert gr.stats["n_ground"] > 0


def test_pixel_models_rewrite_the_image_as_stored():
    """The measurement hook of docs/journal/memory.md ("What a compact pixel would cost"): an image decoded from
    another pixel storage."""
    from lidet_tools.native._proj import _project_into  # projects on a given context (project() makes its own)
    pts, _ = _scene(6, (10.0, 0.0, -0.9), (8.0, 4.0, -0.85))
    ref_img = native.project(pts, "vlp16")
    ctx = native.ScanContext("s16", 0.004)
    s, ctx = native.proj_init("vlp16", ctx=ctx)
    q = _project_into(ctx, s, pts)
    v = ref_img.valid
    np.testing.assert_array_equal(q.valid, v)
    for a, b in ((q.x, ref_img.x), (q.y, ref_img.y), (q.z, ref_img.z), (q.range, ref_img.range)):
        assert np.max(np.abs(a[v] - b[v])) <= 0.002 + 1e-5
        k = a[v] / 0.004
        assert np.max(np.abs(k - np.round(k))) < 1e-2  # multiples of 4 mm
    ctx = native.ScanContext("recompute")
    s, ctx = native.proj_init("vlp16", ctx=ctx)
    r = _project_into(ctx, s, pts)
    np.testing.assert_array_equal(r.range, ref_img.range)
    el = np.arcsin(np.clip(r.z / np.where(v, r.range, 1), -1, 1))
    rows = np.broadcast_to(r.row_elev[:, None], r.shape)
    assert np.max(np.abs(el[v] - rows[v])) < 1e-5  # every point on its beam
    with pytest.raises(KeyError):
        native.ScanContext("int4")
