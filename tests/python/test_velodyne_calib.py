# SPDX-License-Identifier: MIT
"""Velodyne calibrations as sensors (docs/VELODYNE_CALIBRATION.md): Velodyne's db.xml / VeloView XML
and velodyne_pointcloud's YAML, read by lidet_tools.sensors.load_velodyne_calibration and by the host CLI
(`--velodyne-calib C`, ports/host/cli_velodyne_calib.c). Hand-made files of both formats give their tables in ring
order; every bad file gives its message naming the entry and field, word for word the same from both loaders; the
CLI's --print-sensor is sensors.description_json's text; a VLP-16 calibration with the vlp16 preset's elevations
detects bit for bit as the preset (CLI, --ring, --fixed and the bindings)."""
import json
import math
import pathlib
import subprocess

import numpy as np
import pytest

from lidet_tools import kitti, sensors

pytest.importorskip("yaml", reason="PyYAML (requirements.txt) reads the YAML calibrations")
pytest.importorskip("defusedxml", reason="defusedxml (requirements.txt) reads the XML calibrations")
import yaml  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parents[2]
DATA = ROOT / "tests" / "data" / "sensors"
SIM = ROOT / "tests" / "data" / "sim_vlp16"
MAX_ROWS, MAX_COLS = sensors.capacity_limits()
#: PyYAML parses with libyaml, as the CLI: even the parser's own messages are the same
LIBYAML = getattr(yaml, "CSafeLoader", None) is not None

# the VLP-16's lasers in their firing order (laser 2k: -15 + 2k deg, 2k+1: +1 + 2k deg)
VLP16_LASER_DEG = [(-15 + 2 * (k // 2)) if k % 2 == 0 else (1 + 2 * (k // 2)) for k in range(16)]


# ---- hand-made files ---------------------------------------------------------------------------------------------

def _px(**f):
    return dict(f)


BASE_PX = [_px(id_="0", rotCorrection_="-1.4", vertCorrection_="-2", distCorrection_="1.5",
               vertOffsetCorrection_="0.3", horizOffsetCorrection_="-0.2"),
           _px(id_="1", rotCorrection_="1.4", vertCorrection_="2"),
           _px(id_="2", rotCorrection_="-4.2", vertCorrection_="-1"),
           _px(id_="3", rotCorrection_="4.2", vertCorrection_="1", focalSlope_="1.25"),
           _px(id_="4", rotCorrection_="0", vertCorrection_="0"),  # not enabled: ignored
           _px(id_="5", rotCorrection_="junk", vertCorrection_="500")]  # not enabled: not even validated
BASE_EN = ["1", "1", "1", "1", "0", "0"]


def _xml(px=None, enabled=BASE_EN, dist_lsb="0.2", count=True, root="boost", head='<?xml version="1.0"?>\n',
         db_extra="", item_extra=None) -> str:
    """A db.xml: px entries (field -> text; a value that is a list gives the field once per element), enabled_ flags
    (None: no enabled_), distLSB_ (None: none), counts (True: right; an int: that; None: none)."""
    px = BASE_PX if px is None else px

    def count_tag(n):
        if count is None:
            return ""
        return f"<count>{n if count is True else count}</count>"
    out = [head]
    if root == "boost":
        out.append('<boost_serialization signature="serialization::archive" version="4">')
    out.append("<DB>" + db_extra)
    if dist_lsb is not None:
        out.append(f"<distLSB_>{dist_lsb}</distLSB_>")
    if enabled is not None:
        out.append(f"<enabled_>{count_tag(len(enabled))}" + "".join(f"<item>{e}</item>" for e in enabled) +
                   "</enabled_>")
    out.append(f"<points_>{count_tag(len(px))}<item_version>1</item_version>")
    for k, p in enumerate(px):
        if p is None:
            out.append("<item></item>")
            continue
        fields = "".join(
            "".join(f"<{t}>{x}</{t}>" for x in (v if isinstance(v, list) else [v])) for t, v in p.items())
        extra = item_extra[k] if item_extra and k in item_extra else ""
        out.append(f"<item><px>{fields}</px>{extra}</item>")
    out.append("</points_></DB>")
    if root == "boost":
        out.append("</boost_serialization>")
    return "\n".join(out) + "\n"


def _with_px(k, **f):
    px = [dict(p) for p in BASE_PX]
    for key, v in f.items():
        if v is None:
            px[k].pop(key, None)
        else:
            px[k][key] = v
    return px


BASE_LASERS = [dict(laser_id="0", rot_correction="-0.0244", vert_correction="-0.0349", dist_correction="0.015",
                    vert_offset_correction="0.003", horiz_offset_correction="-0.002",
                    two_pt_correction_available="false", max_intensity="255"),
               dict(laser_id="1", rot_correction="0.0244", vert_correction="0.0349"),
               dict(laser_id="2", rot_correction="-0.0733", vert_correction="-0.0175"),
               dict(laser_id="3", rot_correction="0.0733", vert_correction="0.0175", focal_slope="1.25")]


def _yaml(lasers=None, num="4", res="0.002", lead="", tail="") -> str:
    """velodyne_pointcloud's YAML, values given as their text (None: the key left out)."""
    lasers = BASE_LASERS if lasers is None else lasers
    out = [lead]
    if num is not None:
        out.append(f"num_lasers: {num}")
    if res is not None:
        out.append(f"distance_resolution: {res}")
    out.append("lasers:")
    for las in lasers:
        if not isinstance(las, dict):
            out.append(f"  - {las}")
            continue
        first = True
        for k, v in las.items():
            out.append(("  - " if first else "    ") + f"{k}: {v}")
            first = False
    return "\n".join(out) + "\n" + tail


def _with_laser(k, **f):
    lasers = [dict(x) for x in BASE_LASERS]
    for key, v in f.items():
        if v is None:
            lasers[k].pop(key, None)
        else:
            lasers[k][key] = v
    return lasers


def _many_px(n, enabled=False):
    return [_px(id_=str(k), rotCorrection_="0", vertCorrection_=f"{-60 + 0.5 * k:g}") for k in range(n)]


#: an alias on the file's last line
ALIAS = _yaml(lead="res: &r 0.002", tail="copy: *r\n")
#: a file cut short (a copy interrupted): num_lasers (written last) lost; the last laser lost
CUT_NUM = _yaml(num=None, tail="num_lasers: 4\n")
CUT_NUM = CUT_NUM[:CUT_NUM.index("    focal_slope")]
CUT_LIST = _yaml()[:_yaml().index("  - laser_id: 3")]
FLOW = "{num_lasers: 2, lasers: [{laser_id: 1, rot_correction: 0, vert_correction: 0.1}, " \
       "{laser_id: 0, rot_correction: 0, vert_correction: -0.1}]}\n"
#: layouts that read as the base file (_xml(), _yaml())
GOOD_XML = [
    _xml(root="DB"),  # <DB> as the root
    _xml(count=None, head=""),  # no counts, no XML declaration
    "\ufeff \n" + _xml(head=""),  # a byte-order mark and white space before (no declaration then)
    _xml(px=_with_px(0, vertCorrection_=" \n\t-2 ")),  # white space around a number
    _xml(px=_with_px(0, vertCorrection_="<![CDATA[-2]]>")),  # CDATA
    _xml(px=_with_px(0, vertCorrection_="-<!-- minus two -->2")),  # a comment inside
    _xml(px=_with_px(0, vertCorrection_="&#45;2")),  # a character reference
    _xml(px=_with_px(0, colors_="<rgb>1</rgb>")),  # unknown elements ignored
    _xml(head='<?xml version="1.0"?>\n<!DOCTYPE boost_serialization SYSTEM "http://127.0.0.1:9/db.dtd">\n'),
    # (an external DTD: never fetched)
    _xml(px=BASE_PX[:4], enabled=None),  # no enabled_: every item
    _xml(px=BASE_PX[:4] + BASE_PX[5:], enabled=["1", "1", "1", "1", "0", "0"]),  # a disabled laser missing
]
GOOD_YAML = [
    _yaml(num=None, tail="num_lasers: 4\n"),  # num_lasers after the list
    _yaml(res=None),  # no distance_resolution: 2 mm
    "%YAML 1.1\n---\n" + _yaml() + "...\n",  # a directive, an explicit document and its end
    "\ufeff# comment\n" + _yaml(),  # a byte-order mark and a comment
    _yaml(lasers=_with_laser(0, vert_correction="!!float -0.0349")),  # tags are ignored
    _yaml(lasers=_with_laser(0, vert_correction="-3.49e-2")),
    _yaml(lasers=_with_laser(0, vert_correction="-.0349", unknown_key="[1, {a: b}]")),  # unknown keys ignored
]


NOT_VALID_XML = "not valid XML ..."
NOT_VALID_YAML = "not valid YAML ..."

# (case id, file content, message after "PATH: "); a message ending in "..." is a prefix
BAD_XML = [
    ("syntax", "<boost_serialization><DB>", NOT_VALID_XML),
    ("truncated", _xml()[:400], NOT_VALID_XML),
    ("entity", '<?xml version="1.0"?>\n<!DOCTYPE b [<!ENTITY a "x">]>\n<boost_serialization/>\n',
     "not valid XML for a calibration (entity declarations are refused)"),
    ("billion-laughs", '<?xml version="1.0"?>\n<!DOCTYPE b [<!ENTITY a "aaaaaaaaaa"><!ENTITY b "&a;&a;&a;&a;&a;">'
                       '<!ENTITY c "&b;&b;&b;&b;&b;">]>\n<boost_serialization><DB>&c;</DB></boost_serialization>\n',
     "not valid XML for a calibration (entity declarations are refused)"),
    ("external-entity", '<?xml version="1.0"?>\n<!DOCTYPE b [<!ENTITY e SYSTEM "/etc/hostname">]>\n'
                        '<boost_serialization><DB><distLSB_>&e;</distLSB_></DB></boost_serialization>\n',
     "not valid XML for a calibration (entity declarations are refused)"),
    ("parameter-entity", '<?xml version="1.0"?>\n<!DOCTYPE b [<!ENTITY % p "x">]>\n<boost_serialization/>\n',
     "not valid XML for a calibration (entity declarations are refused)"),
    ("undefined-entity", "<boost_serialization><DB>&nope;</DB></boost_serialization>", NOT_VALID_XML),
    ("no-db", "<calibration><lasers/></calibration>",
     '"DB": missing (<boost_serialization><DB>...</DB>): not a Velodyne calibration (db.xml)?'),
    ("db-twice", "<boost_serialization><DB/><DB/></boost_serialization>", '"DB": given twice'),
    ("distlsb-text", _xml(dist_lsb="0.2cm"), '"distLSB_": not a number'),
    ("distlsb-zero", _xml(dist_lsb="0"), '"distLSB_": 0 is outside (0, 100] (centimetres)'),
    ("distlsb-inf", _xml(dist_lsb="1e999"), '"distLSB_": not a finite number'),
    ("distlsb-twice", _xml(db_extra="<distLSB_>0.4</distLSB_>"), '"distLSB_": given twice'),
    ("enabled-count", _xml(count=7), '"enabled_.count": 7 but "enabled_" has 6 items'),
    ("enabled-2", _xml(enabled=["1", "2", "1", "1", "0", "0"]), '"enabled_"[1]: expected 0 or 1, got 2'),
    ("enabled-word", _xml(enabled=["1", "yes", "1", "1", "0", "0"]), '"enabled_"[1]: not a number'),
    ("enabled-none", _xml(enabled=["0"] * 6),
     f'"enabled_": 0 lasers enabled, outside [1, {MAX_ROWS}] (LIDET_MAX_ROWS)'),
    ("too-many-enabled", _xml(px=_many_px(MAX_ROWS + 1), enabled=["1"] * (MAX_ROWS + 1)),
     f'"enabled_": {MAX_ROWS + 1} lasers enabled, outside [1, {MAX_ROWS}] (LIDET_MAX_ROWS)'),
    ("too-many", _xml(px=_many_px(MAX_ROWS + 1), enabled=None),
     f'"points_": {MAX_ROWS + 1} lasers, outside [1, {MAX_ROWS}] (LIDET_MAX_ROWS)'),
    ("no-points", _xml().replace("<points_>", "<pts_>").replace("</points_>", "</pts_>"),
     '"points_": missing: not a Velodyne calibration (db.xml)?'),
    ("points-count", _xml(px=BASE_PX[:5], enabled=None, count=6), '"points_.count": 6 but "points_" has 5 items'),
    ("no-px", _xml(px=BASE_PX[:2] + [None] + BASE_PX[3:]), '"points_"[2]: no "px"'),
    ("px-twice", _xml(item_extra={2: "<px><id_>9</id_></px>"}), '"points_"[2].px: given twice'),
    ("id-missing", _xml(px=_with_px(1, id_=None)), '"points_"[1].id_: missing'),
    ("id-text", _xml(px=_with_px(1, id_="one")), '"points_"[1].id_: not a number'),
    ("id-fraction", _xml(px=_with_px(1, id_="1.5")), '"points_"[1].id_: expected an integer, got 1.5'),
    ("id-range", _xml(px=_with_px(1, id_="9")), '"points_"[1].id_: 9 is outside [0, 5]'),
    ("id-negative", _xml(px=_with_px(1, id_="-1"), enabled=None), '"points_"[1].id_: -1 is outside [0, 5]'),
    ("id-twice", _xml(px=_with_px(2, id_="0")), '"points_"[2].id_: 0 given twice (also "points_"[0])'),
    ("vert-missing", _xml(px=_with_px(1, vertCorrection_=None)), '"points_"[1].vertCorrection_: missing'),
    ("vert-text", _xml(px=_with_px(1, vertCorrection_="2 deg")), '"points_"[1].vertCorrection_: not a number'),
    ("vert-empty", _xml(px=_with_px(1, vertCorrection_=" ")), '"points_"[1].vertCorrection_: not a number'),
    ("vert-child", _xml(px=_with_px(1, vertCorrection_="<v>2</v>")), '"points_"[1].vertCorrection_: not a number'),
    ("vert-hex", _xml(px=_with_px(1, vertCorrection_="0x2")), '"points_"[1].vertCorrection_: not a number'),
    ("vert-inf", _xml(px=_with_px(1, vertCorrection_="-1e400")), '"points_"[1].vertCorrection_: not a finite number'),
    ("vert-95", _xml(px=_with_px(1, vertCorrection_="95")),
     '"points_"[1].vertCorrection_: 95 deg is outside (-90, 90)'),
    ("vert-90", _xml(px=_with_px(1, vertCorrection_="-90")),
     '"points_"[1].vertCorrection_: -90 deg is outside (-90, 90)'),
    ("vert-twice", _xml(px=_with_px(1, vertCorrection_=["2", "3"])), '"points_"[1].vertCorrection_: given twice'),
    ("rot-missing", _xml(px=_with_px(3, rotCorrection_=None)), '"points_"[3].rotCorrection_: missing'),
    ("rot-200", _xml(px=_with_px(3, rotCorrection_="200")),
     '"points_"[3].rotCorrection_: 200 deg is outside (-180, 180)'),
    ("optional-text", _xml(px=_with_px(0, distCorrection_="x")), '"points_"[0].distCorrection_: not a number'),
    ("optional-twice", _xml(px=_with_px(0, focalSlope_=["1", "2"])), '"points_"[0].focalSlope_: given twice'),
    ("enabled-without-px", _xml(px=BASE_PX[:3] + BASE_PX[4:], enabled=["1", "1", "1", "1", "1", "0"]),
     '"enabled_"[3]: laser 3 is enabled, but "points_" has no px with id_ 3'),
    ("same-elevation", _xml(px=_with_px(3, vertCorrection_="-2")),
     '"points_"[3].vertCorrection_: the same elevation as "points_"[0] (-2 deg): beams must be distinct'),
    ("same-float32", _xml(px=_with_px(2, vertCorrection_="2.00000000001")),
     '"points_"[2].vertCorrection_: the same elevation as "points_"[1] (2 deg): beams must be distinct'),
]

BAD_YAML = [
    ("syntax", "num_lasers: 4\nlasers: [{laser_id: 0", NOT_VALID_YAML),
    ("indent", "num_lasers: 4\nlasers:\n  - laser_id: 0\n rot_correction: 0\n", NOT_VALID_YAML),
    ("control-char", "num_lasers: 4\x00\n", NOT_VALID_YAML),
    ("latin1", b"num_lasers: 4\nname: \xe9\n", NOT_VALID_YAML),
    ("two-documents", "num_lasers: 1\n---\nnum_lasers: 2\n", "the file must hold one YAML document"),
    ("empty", "", "the file must hold one YAML mapping"),
    ("comment-only", "# nothing\n", "the file must hold one YAML mapping"),
    ("list", "- 1\n- 2\n", "the file must hold one YAML mapping"),
    ("scalar", "lasers\n", "the file must hold one YAML mapping"),
    ("alias", ALIAS, f"YAML aliases are not supported (line {ALIAS.count(chr(10))})"),
    ("complex-key", "? [a, b]\n: 1\n", "a mapping key must be a scalar (line 1)"),
    ("deep", "a: " + "[" * 40 + "]" * 40 + "\n", "nested deeper than 32 levels (line 1)"),
    ("key-twice", _yaml(tail="num_lasers: 4\n"), '"num_lasers": given twice'),
    ("laser-key-twice", _yaml(lasers=_with_laser(2, laser_id="2\n    laser_id: 2")),
     '"lasers"[2].laser_id: given twice'),
    ("no-lasers", "num_lasers: 4\n", '"lasers": missing: not a velodyne_pointcloud calibration?'),
    ("ouster-json", json.dumps({"beam_altitude_angles": [1, 0], "lidar_mode": "1024x10"}),
     '"lasers": missing: not a velodyne_pointcloud calibration?'),
    ("lasers-mapping", "num_lasers: 4\nlasers: {a: 1}\n", '"lasers": expected a list, got a mapping'),
    ("lasers-null", "num_lasers: 4\nlasers:\n", '"lasers": expected a list, got null'),
    ("no-num", _yaml(num=None), '"num_lasers": missing'),
    ("num-string", _yaml(num='"4"'), '"num_lasers": expected an integer, got a string'),
    ("num-fraction", _yaml(num="4.5"), '"num_lasers": expected an integer, got 4.5'),
    ("num-zero", _yaml(num="0"), f'"num_lasers": 0 is outside [1, {MAX_ROWS}] (LIDET_MAX_ROWS)'),
    ("num-large", _yaml(num=str(MAX_ROWS + 1)),
     f'"num_lasers": {MAX_ROWS + 1} is outside [1, {MAX_ROWS}] (LIDET_MAX_ROWS)'),
    ("num-mismatch", _yaml(num="5"), '"num_lasers": 5 but "lasers" has 4 entries'),
    ("truncated", CUT_NUM, '"num_lasers": missing'),
    ("truncated-list", CUT_LIST, '"num_lasers": 4 but "lasers" has 3 entries'),
    ("truncated-flow", FLOW[:-30], NOT_VALID_YAML),
    ("res-string", _yaml(res="2mm"), '"distance_resolution": expected a number, got a string'),
    ("res-zero", _yaml(res="0"), '"distance_resolution": 0 is outside (0, 1] (metres)'),
    ("laser-number", _yaml(lasers=[5] + BASE_LASERS[1:]), '"lasers"[0]: expected a mapping, got a number'),
    ("id-missing", _yaml(lasers=_with_laser(1, laser_id=None)), '"lasers"[1].laser_id: missing'),
    ("id-null", _yaml(lasers=_with_laser(1, laser_id="~")), '"lasers"[1].laser_id: expected an integer, got null'),
    ("id-hex", _yaml(lasers=_with_laser(1, laser_id="0x1")), '"lasers"[1].laser_id: expected an integer, got a string'),
    ("id-range", _yaml(lasers=_with_laser(1, laser_id="4")), '"lasers"[1].laser_id: 4 is outside [0, 3]'),
    ("id-twice", _yaml(lasers=_with_laser(2, laser_id="0")), '"lasers"[2].laser_id: 0 given twice (also "lasers"[0])'),
    ("vert-missing", _yaml(lasers=_with_laser(1, vert_correction=None)), '"lasers"[1].vert_correction: missing'),
    ("vert-string", _yaml(lasers=_with_laser(1, vert_correction="'0.0349'")),
     '"lasers"[1].vert_correction: expected a number, got a string'),
    ("vert-bool", _yaml(lasers=_with_laser(1, vert_correction="true")),
     '"lasers"[1].vert_correction: expected a number, got true'),
    ("vert-list", _yaml(lasers=_with_laser(1, vert_correction="[1]")),
     '"lasers"[1].vert_correction: expected a number, got a list'),
    ("vert-inf", _yaml(lasers=_with_laser(1, vert_correction="-.inf")),
     '"lasers"[1].vert_correction: not a finite number'),
    ("vert-nan", _yaml(lasers=_with_laser(1, vert_correction=".nan")),
     '"lasers"[1].vert_correction: not a finite number'),
    ("vert-overflow", _yaml(lasers=_with_laser(1, vert_correction="1e999")),
     '"lasers"[1].vert_correction: not a finite number'),
    ("vert-range", _yaml(lasers=_with_laser(1, vert_correction="1.6")),
     '"lasers"[1].vert_correction: 1.6 rad (91.6732 deg) is outside (-90, 90) deg'),
    ("vert-degrees", _yaml(lasers=_with_laser(1, vert_correction="-15")),
     '"lasers"[1].vert_correction: -15 rad (-859.437 deg) is outside (-90, 90) deg'),
    ("rot-missing", _yaml(lasers=_with_laser(3, rot_correction=None)), '"lasers"[3].rot_correction: missing'),
    ("rot-range", _yaml(lasers=_with_laser(3, rot_correction="3.2")),
     '"lasers"[3].rot_correction: 3.2 rad (183.346 deg) is outside (-180, 180) deg'),
    ("optional-string", _yaml(lasers=_with_laser(0, dist_correction="x")),
     '"lasers"[0].dist_correction: expected a number, got a string'),
    ("optional-null", _yaml(lasers=_with_laser(2, horiz_offset_correction="")),
     '"lasers"[2].horiz_offset_correction: expected a number, got null'),
    ("same-elevation", _yaml(lasers=_with_laser(3, vert_correction="-0.0349")),
     '"lasers"[3].vert_correction: the same elevation as "lasers"[0] (-0.0349 rad): beams must be distinct'),
    ("same-float32", _yaml(lasers=_with_laser(3, vert_correction="0.03490000000001")),
     '"lasers"[3].vert_correction: the same elevation as "lasers"[1] (0.0349 rad): beams must be distinct'),
]


def _write(tmp_path, name, content, suffix) -> pathlib.Path:
    p = tmp_path / f"{name}{suffix}"
    if isinstance(content, bytes):
        p.write_bytes(content)
    else:
        p.write_text(content)
    return p


def _expect(msg: str, p: pathlib.Path, got: str):
    want = f"{p}: {msg}"
    if msg.endswith("..."):
        assert got.startswith(want[:-3]), got
    else:
        assert got == want


def _load_error(p) -> str:
    with pytest.raises(sensors.SensorFileError) as e:
        sensors.load_velodyne_calibration(p)
    return str(e.value)


# ---- lidet_tools.sensors -------------------------------------------------------------------------------------

def test_vlp16_xml_gives_the_ring_order_table():
    s = sensors.load_velodyne_calibration(DATA / "vlp16_db.xml")
    p = sensors.get_sensor("vlp16")
    assert (s.name, s.rows, s.cols, s.mount_height_m, s.max_range_m) == ("velodyne-16", 16, 1800, 1.0, 100.0)
    assert s.model is None and sensors.model_family(s) == "vlp16" and s.fov_urad is None
    # ring order: lowest beam first, the vlp16 preset's (and lidet's Velodyne decoder's) rings
    np.testing.assert_array_equal(s.beam_elev_deg, np.arange(-15.0, 16.0, 2.0))
    np.testing.assert_array_equal(s.beam_elev_rad, np.radians(np.arange(-15.0, 16.0, 2.0)))
    assert np.array_equal(s.beam_elev_rad.astype(np.float32), p.beam_elev_rad.astype(np.float32))
    assert np.array_equal(s.beam_elev_urad, p.beam_elev_urad)
    # each ring's laser: the even lasers (-15 .. -1 deg) then the odd ones (+1 .. +15 deg)
    v = s.velodyne
    np.testing.assert_array_equal(v.laser_id, [0, 2, 4, 6, 8, 10, 12, 14, 1, 3, 5, 7, 9, 11, 13, 15])
    assert [VLP16_LASER_DEG[k] for k in v.laser_id] == list(range(-15, 16, 2))
    assert v.source == "xml" and v.distance_resolution_m == 0.2 * 0.01
    # the corrections of vlp16_db.xml (invented: laser k's rot is 0.1 ((k % 5) - 2) deg, ...), in metres
    k = v.laser_id
    np.testing.assert_allclose(s.beam_azimuth_rad, np.radians(0.1 * ((k % 5) - 2)), atol=1e-15)
    np.testing.assert_allclose(v.dist_correction_m, 0.005 * (k % 3), atol=1e-15)
    np.testing.assert_allclose(v.vert_offset_m, 0.011 * ((k % 2) * 2 - 1), atol=1e-15)
    np.testing.assert_allclose(v.focal_distance_m, 0.1 * (k % 2), atol=1e-15)
    np.testing.assert_allclose(v.focal_slope, 0.05 * (k % 4), atol=1e-15)


def test_vlp16_yaml_reads_as_the_xml():
    """The same unit in velodyne_pointcloud's YAML (radians, metres, as gen_calibration.py converts db.xml)."""
    a = sensors.load_velodyne_calibration(DATA / "vlp16_db.xml")
    b = sensors.load_velodyne_calibration(DATA / "vlp16.yaml")
    assert (b.name, b.rows, b.cols) == (a.name, a.rows, a.cols) and b.velodyne.source == "yaml"
    assert np.array_equal(a.beam_elev_rad, b.beam_elev_rad)  # the YAML's radians are np.radians(the XML's degrees)
    np.testing.assert_allclose(b.beam_elev_deg, a.beam_elev_deg, rtol=0, atol=1e-13)  # radians x 180 / pi
    assert np.array_equal(a.beam_azimuth_rad, b.beam_azimuth_rad)
    for f in ("laser_id", "dist_correction_m", "dist_correction_x_m", "dist_correction_y_m", "vert_offset_m",
              "horiz_offset_m", "focal_distance_m", "focal_slope"):
        assert np.array_equal(getattr(a.velodyne, f), getattr(b.velodyne, f)), f
    assert a.velodyne.distance_resolution_m == b.velodyne.distance_resolution_m


def test_hdl32e_yaml_block_style():
    s = sensors.load_velodyne_calibration(DATA / "hdl32e.yaml", cols=1085, mount_height_m=1.84)
    p = sensors.get_sensor("hdl32")
    assert (s.rows, s.cols, s.mount_height_m) == (32, 1085, 1.84) and sensors.model_family(s) == "hdl64"
    assert np.array_equal(s.beam_elev_rad, p.beam_elev_rad)  # the preset's table, in its ring order
    np.testing.assert_array_equal(s.velodyne.laser_id, [2 * r for r in range(16)] + [2 * r + 1 for r in range(16)])
    assert not s.beam_azimuth_rad.any() and not s.velodyne.focal_slope.any()
    assert sensors.load_velodyne_calibration(DATA / "hdl32e.yaml").cols == 1800  # the default for 32 lasers


def test_base_files_and_variants(tmp_path):
    """The bad cases' base files load; variants of the layout read the same."""
    x = sensors.load_velodyne_calibration(_write(tmp_path, "base", _xml(), ".xml"))
    np.testing.assert_array_equal(x.beam_elev_deg, [-2.0, -1.0, 1.0, 2.0])
    np.testing.assert_array_equal(x.velodyne.laser_id, [0, 2, 3, 1])
    np.testing.assert_allclose(np.degrees(x.beam_azimuth_rad), [-1.4, -4.2, 4.2, 1.4])
    np.testing.assert_array_equal(x.velodyne.dist_correction_m, [0.015, 0.0, 0.0, 0.0])
    np.testing.assert_array_equal(x.velodyne.focal_slope, [0.0, 0.0, 1.25, 0.0])
    assert x.velodyne.distance_resolution_m == 0.002 and x.name == "velodyne-4"
    y = sensors.load_velodyne_calibration(_write(tmp_path, "base", _yaml(), ".yaml"))
    np.testing.assert_array_equal(y.beam_elev_rad, [-0.0349, -0.0175, 0.0175, 0.0349])
    np.testing.assert_array_equal(y.velodyne.laser_id, [0, 2, 3, 1])
    np.testing.assert_array_equal(y.velodyne.dist_correction_m, [0.015, 0.0, 0.0, 0.0])
    variants = [(t, x) for t in GOOD_XML] + [(t, y) for t in GOOD_YAML]
    for i, (text, want) in enumerate(variants):
        s = sensors.load_velodyne_calibration(_write(tmp_path, f"v{i}", text, ".cal"))
        assert np.array_equal(s.beam_elev_rad, want.beam_elev_rad), i
        assert np.array_equal(s.velodyne.laser_id, want.velodyne.laser_id), i
    s = sensors.load_velodyne_calibration(_write(tmp_path, "nores", _yaml(res=None), ".yaml"))
    assert s.velodyne.distance_resolution_m == sensors.VELODYNE_DISTANCE_RESOLUTION_M == 0.002
    s = sensors.load_velodyne_calibration(_write(tmp_path, "res", _yaml(res="0.004"), ".yaml"))
    assert s.velodyne.distance_resolution_m == 0.004
    s = sensors.load_velodyne_calibration(_write(tmp_path, "flow", FLOW, ".yaml"))
    assert list(s.beam_elev_rad) == [-0.1, 0.1] and list(s.velodyne.laser_id) == [0, 1]


def test_laser_counts_and_default_columns(tmp_path):
    for n, cols in ((1, 1800), (16, 1800), (32, 1800), (64, min(2048, MAX_COLS)), (MAX_ROWS, 1800)):
        x = sensors.load_velodyne_calibration(_write(tmp_path, f"n{n}", _xml(px=_many_px(n), enabled=None), ".xml"))
        assert (x.rows, x.cols) == (n, min(cols, MAX_COLS)) == (n, sensors.velodyne_default_cols(n))
        assert np.all(np.diff(x.beam_elev_rad) > 0)
        assert sensors.model_family(x) == ("hdl64" if n >= 32 else "vlp16")


@pytest.mark.parametrize("case,content,msg", BAD_XML, ids=[c[0] for c in BAD_XML])
def test_bad_xml_names_its_field(tmp_path, case, content, msg):
    p = _write(tmp_path, case, content, ".xml")
    _expect(msg, p, _load_error(p))


@pytest.mark.parametrize("case,content,msg", BAD_YAML, ids=[c[0] for c in BAD_YAML])
def test_bad_yaml_names_its_field(tmp_path, case, content, msg):
    p = _write(tmp_path, case, content, ".yaml")
    _expect(msg, p, _load_error(p))


def test_missing_and_oversized_files_and_arguments(tmp_path):
    with pytest.raises(sensors.SensorFileError, match="cannot read: No such file"):
        sensors.load_velodyne_calibration(tmp_path / "nope.yaml")
    big = tmp_path / "big.xml"
    big.write_bytes(b"<" + b" " * sensors.SENSOR_FILE_MAX_BYTES)
    with pytest.raises(sensors.SensorFileError, match="larger than 16 MiB: not a Velodyne calibration"):
        sensors.load_velodyne_calibration(big)
    f = DATA / "vlp16.yaml"
    assert sensors.load_velodyne_calibration(f, mount_height_m=0.3).mount_height_m == 0.3
    assert sensors.load_velodyne_calibration(f, cols=8).cols == 8
    assert sensors.load_velodyne_calibration(f, cols=np.int64(MAX_COLS)).cols == MAX_COLS
    assert sensors.load_velodyne_calibration(f, name="my-vlp16").name == "my-vlp16"
    for bad in (-0.1, 10.5, float("nan"), "1", True):
        with pytest.raises(ValueError, match="mount_height_m must be metres in"):
            sensors.load_velodyne_calibration(f, mount_height_m=bad)
    for bad in (7, MAX_COLS + 1, 1800.0, "1800", True):
        with pytest.raises(ValueError, match=r"cols must be an integer in \[8, "):
            sensors.load_velodyne_calibration(f, cols=bad)
    for bad in ("my vlp", "", "x" * 64):
        with pytest.raises(ValueError, match="must be 1 to 63 characters"):
            sensors.load_velodyne_calibration(f, name=bad)


def test_format_is_told_by_the_first_character():
    assert sensors.velodyne_calibration_kind(b"\xef\xbb\xbf \n\t<x/>") == "xml"
    assert sensors.velodyne_calibration_kind(b"# <not xml>\nlasers: []") == "yaml"
    assert sensors.velodyne_calibration_kind(b"") == "yaml"


def test_description_json_reads_back(tmp_path):
    """description_json writes a description that load_sensor_file reads back into the same table."""
    for f in ("vlp16_db.xml", "vlp16.yaml", "hdl32e.yaml"):
        s = sensors.load_velodyne_calibration(DATA / f, mount_height_m=1.2)
        out = tmp_path / f"{f}.json"
        sensors.write_sensor_file(s, out)
        b = sensors.load_sensor_file(out)
        assert (b.name, b.rows, b.cols, b.mount_height_m, b.max_range_m) == (s.name, s.rows, s.cols, 1.2, 100.0)
        assert np.array_equal(b.beam_elev_deg, s.beam_elev_deg)
        assert np.array_equal(b.beam_elev_rad.astype(np.float32), s.beam_elev_rad.astype(np.float32))
        assert sensors.description_json(b) == sensors.description_json(s)
    # presets: the shortest degrees that give back their single-precision table
    for name in ("hdl64", "vlp16", "vlp32c", "hdl32"):
        p = sensors.get_sensor(name)
        out = tmp_path / f"{name}.json"
        sensors.write_sensor_file(p, out)
        b = sensors.load_sensor_file(out)
        assert np.array_equal(b.beam_elev_rad.astype(np.float32), p.beam_elev_rad.astype(np.float32)), name


# ---- the CLI (ports/host/cli_velodyne_calib.c) against the Python loader -------------------------------------------

@pytest.fixture(scope="module")
def cli_calib(cli):
    """The CLI, when built with libxml2 and libyaml (else the tests that need it skip, saying so)."""
    for f in ("vlp16_db.xml", "vlp16.yaml"):
        r = subprocess.run([str(cli), "project", "--velodyne-calib", str(DATA / f), "--print-sensor"],
                           capture_output=True, text=True)
        if r.returncode != 0 and "built without" in r.stderr:
            pytest.skip("the CLI was built without libxml2 / libyaml (apt-get install libxml2-dev libyaml-dev): " +
                        r.stderr.strip())
        assert r.returncode == 0, r.stderr
    return cli


def _cli(cli, *args):
    return subprocess.run([str(cli), *map(str, args)], capture_output=True, text=True)


def _cli_error(cli, path) -> str:
    r = _cli(cli, "project", "--velodyne-calib", path, "--print-sensor")
    assert r.returncode == 1 and r.stdout == "", (r.stdout, r.stderr)
    assert r.stderr.startswith("lidet project: ") and r.stderr.endswith("\n") and r.stderr.count("\n") == 1, r.stderr
    return r.stderr[len("lidet project: "):-1]


@pytest.mark.parametrize("case,content,msg", BAD_XML + BAD_YAML,
                         ids=[f"xml-{c[0]}" for c in BAD_XML] + [f"yaml-{c[0]}" for c in BAD_YAML])
def test_cli_bad_file_same_message(cli_calib, tmp_path, case, content, msg):
    p = _write(tmp_path, case, content, ".cal")
    got = _cli_error(cli_calib, p)
    _expect(msg, p, got)
    py = _load_error(p)
    if msg == NOT_VALID_XML or (msg == NOT_VALID_YAML and not LIBYAML):
        return  # the parsers' own words differ (expat / libxml2; PyYAML without libyaml)
    assert got == py  # word for word, the parser's message of a YAML file included (libyaml in both)


def test_cli_missing_file_and_options(cli_calib, tmp_path):
    assert _cli_error(cli_calib, tmp_path / "nope.yaml") == \
        f"{tmp_path / 'nope.yaml'}: cannot read: No such file or directory"
    big = tmp_path / "big.xml"
    big.write_bytes(b"<" + b" " * sensors.SENSOR_FILE_MAX_BYTES)
    assert _cli_error(cli_calib, big) == f"{big}: larger than 16 MiB: not a Velodyne calibration"
    r = _cli(cli_calib, "detect", "x.bin", "--sensor-file", DATA / "vlp16.json", "--velodyne-calib",
             DATA / "vlp16.yaml")
    assert r.returncode == 1 and "give one of --sensor, --sensor-file, --ouster-meta and --velodyne-calib" in r.stderr
    r = _cli(cli_calib, "project", "--sensor", "vlp16", "--cols", "1800", "--print-sensor")
    assert r.returncode == 1 and "--cols goes with --velodyne-calib" in r.stderr
    for bad in ("7", str(MAX_COLS + 1), "1800.5", "x"):
        r = _cli(cli_calib, "project", "--velodyne-calib", DATA / "vlp16.yaml", "--cols", bad, "--print-sensor")
        assert r.returncode == 1 and f"--cols needs an integer in [8, {MAX_COLS}] (LIDET_MAX_COLS), got '{bad}'" \
            in r.stderr, r.stderr


def _good_calibrations(tmp_path):
    out = [DATA / "vlp16_db.xml", DATA / "vlp16.yaml", DATA / "hdl32e.yaml",
           _write(tmp_path, "base", _xml(), ".xml"), _write(tmp_path, "base", _yaml(), ".yaml"),
           _write(tmp_path, "n128", _xml(px=_many_px(MAX_ROWS), enabled=None), ".xml"),
           _write(tmp_path, "n64", _xml(px=_many_px(64), enabled=None, root="DB"), ".xml"),
           *(_write(tmp_path, f"gx{i}", t, ".xml") for i, t in enumerate(GOOD_XML)),
           *(_write(tmp_path, f"gy{i}", t, ".yaml") for i, t in enumerate(GOOD_YAML)),
           _write(tmp_path, "flow", FLOW, ".yaml"),
           _write(tmp_path, "odd", _yaml(lasers=[dict(laser_id=str(k), rot_correction="0",
                                                       vert_correction=repr(math.radians(1 / 3 + k) * (-1) ** k))
                                                  for k in range(5)], num="5"), ".yaml")]
    return out


def test_cli_prints_what_python_writes(cli_calib, tmp_path):
    """`--velodyne-calib C --print-sensor` is sensors.description_json of Python's reading, byte for byte (names,
    columns, each elevation as the shortest decimal of the same double, mount height, range), with and without
    --mount-height and --cols."""
    for f in _good_calibrations(tmp_path):
        for opts, kw in (((), {}), (("--mount-height", "0.5"), {"mount_height_m": 0.5}),
                         (("--cols", "1085"), {"cols": 1085})):
            r = _cli(cli_calib, "project", "--velodyne-calib", f, *opts, "--print-sensor")
            assert r.returncode == 0, r.stderr
            assert r.stdout == sensors.description_json(sensors.load_velodyne_calibration(f, **kw)), (f, opts)


def test_cli_prints_descriptions_and_presets_as_python_writes(cli, tmp_path):
    """The same for lidet's descriptions with a table, Ouster metadata (when the CLI has cJSON) and the table
    presets."""
    for name in ("hdl64", "vlp16", "vlp32c", "hdl32"):
        r = _cli(cli, "project", "--sensor", name, "--print-sensor")
        assert r.returncode == 0 and r.stdout == sensors.description_json(sensors.get_sensor(name)), name
    r = _cli(cli, "project", "--sensor-file", DATA / "vlp16.json", "--print-sensor")
    if r.returncode != 0 and "built without" in r.stderr:
        pytest.skip("the CLI was built without cJSON")
    for option, f, load in (("--sensor-file", DATA / "hdl64.json", sensors.load_sensor_file),
                            ("--sensor-file", DATA / "vlp16.json", sensors.load_sensor_file),
                            ("--ouster-meta", DATA / "ouster_nested.json", sensors.load_ouster_metadata)):
        r = _cli(cli, "project", option, f, "--print-sensor")
        assert r.returncode == 0 and r.stdout == sensors.description_json(load(f)), f


@pytest.mark.usefixtures("need_lib")
def test_cli_projection_equals_bindings(cli_calib, tmp_path):
    """`lidet project --velodyne-calib C --out` puts every point in the pixel the bindings give with Python's Sensor."""
    from lidet_tools import native
    scan = SIM / "velodyne" / "000000.bin"
    pts = kitti.read_bin(scan)
    for f in _good_calibrations(tmp_path):
        out = tmp_path / "pix.bin"
        r = _cli(cli_calib, "project", scan, "--velodyne-calib", f, "--out", out)
        assert r.returncode == 0, r.stderr
        ref = native.project(pts, sensors.load_velodyne_calibration(f)).point_pixel
        assert np.array_equal(np.fromfile(out, np.int32), ref), f


# ---- the detector: a calibration with the vlp16 preset's elevations detects as the preset ------------------------

@pytest.mark.parametrize("calib", ["vlp16_db.xml", "vlp16.yaml"])
def test_cli_calibration_of_the_vlp16_detects_as_the_preset(cli_calib, tmp_path, calib):
    """A scan simulated with the vlp16 preset (tests/data/sim_vlp16: lidet-sim --sensor vlp16), detected with
    --sensor vlp16 and with --velodyne-calib of the hand-made VLP-16 calibration (lasers in firing order, the
    preset's elevations) at the preset's mount height: the same --dump bytes, with elevations and with the
    simulator's rings (--ring: the ring order is the preset's), and the same --fixed boxes."""
    scan, ring = SIM / "velodyne" / "000000.bin", SIM / "ring" / "000000.bin"
    cal = ["--velodyne-calib", DATA / calib, "--mount-height", "0.5"]
    for extra in ([], ["--ring", ring]):
        dumps = []
        for opts in (["--sensor", "vlp16"], cal):
            d = tmp_path / f"d{len(dumps)}.bin"
            r = _cli(cli_calib, "detect", scan, *opts, *extra, "--dump", d, "--json")
            assert r.returncode == 0, r.stderr
            js = json.loads(r.stdout)
            assert js["model"] == "vlp16" and js["detections"] > 0
            dumps.append(d.read_bytes())
        assert dumps[0] == dumps[1], extra
    outs = []
    for opts in (["--sensor", "vlp16"], cal):
        o = tmp_path / f"q{len(outs)}.txt"
        r = _cli(cli_calib, "detect", scan, *opts, "--fixed", "--out", o)
        assert r.returncode == 0, r.stderr
        outs.append(o.read_text())
    assert outs[0] == outs[1] and outs[0]


@pytest.mark.usefixtures("need_lib")
@pytest.mark.parametrize("calib", ["vlp16_db.xml", "vlp16.yaml"])
def test_bindings_calibration_of_the_vlp16_detects_as_the_preset(calib):
    from lidet_tools import native
    pts = kitti.read_bin(SIM / "velodyne" / "000000.bin")
    a = native.detect(pts, "vlp16")
    s = sensors.load_velodyne_calibration(DATA / calib, mount_height_m=0.5)
    assert native.default_family(s) == "vlp16"
    b = native.detect(pts, s)
    assert len(a.score) > 0
    for k in ("cls", "score", "energy_cls", "energy_box", "box", "cluster_id", "outcome", "point_cluster",
              "point_ground"):
        assert np.array_equal(getattr(a, k), getattr(b, k)), k
    assert a.stats == b.stats
