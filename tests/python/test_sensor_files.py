# SPDX-License-Identifier: MIT
"""Sensors from files (docs/SENSORS.md): lidet's description format and Ouster's metadata, read by
lidet_tools.sensors (load_sensor_file, load_ouster_metadata) and by the host CLI (--sensor-file, --ouster-meta,
ports/host/cli_sensor.c). Every bad file gives its message naming the field, the same from both loaders; both give
the same table for the same file; a description repeating a preset's table detects bit for bit as the preset
(CLI and bindings); Ouster's own files of ../shared/data/packets load (skipped when that folder is absent)."""
import json
import pathlib
import subprocess

import numpy as np
import pytest

from lidet_tools import kitti, sensors

ROOT = pathlib.Path(__file__).resolve().parents[2]
DATA = ROOT / "tests" / "data" / "sensors"
OUSTER = ROOT.parent / "shared" / "data" / "packets" / "ouster"
MAX_ROWS, MAX_COLS = sensors.capacity_limits()
KNOWN = ", ".join(sensors.SENSOR_FILE_FIELDS)
NAME_RULE = "must be 1 to 63 characters from A-Z a-z 0-9 . _ + -"

BASE = {"format": "lidet-sensor", "version": 1, "name": "t4", "cols": 1024,
        "beam_elevation_deg": [2.0, 0.0, -2.0, -4.0], "mount_height_m": 1.0, "max_range_m": 100}
FOV = {"format": "lidet-sensor", "version": 1, "name": "u", "cols": 1024, "fov_up_deg": 10, "fov_down_deg": -30,
       "rows": 32, "mount_height_m": 1.0, "max_range_m": 100}
OBASE = {"beam_altitude_angles": [10.0, 5.0, 0.0, -5.0], "beam_azimuth_angles": [1.5, -1.5, 1.5, -1.5],
         "lidar_mode": "1024x10", "prod_line": "OS-1-4"}


def _with(base, **kv):
    d = dict(base)
    for k, v in kv.items():
        if v is _DROP:
            d.pop(k, None)
        else:
            d[k] = v
    return d


_DROP = object()
# json.dumps writes no 1e999: a placeholder string replaced in the text
_INF = "__INF__"


def _text(d) -> str:
    if isinstance(d, str):
        return d
    return json.dumps(d).replace(f'"{_INF}"', "1e999")


# (case id, file content (dict or raw text), message after "PATH: "); a message ending in "..." is a prefix
BAD_DESCRIPTIONS = [
    ("syntax", '{"format": "lidet-sensor",', "not valid JSON ..."),
    ("nan", '{"format": "lidet-sensor", "version": 1, "mount_height_m": NaN}', "not valid JSON ..."),
    ("array", "[1, 2]", "the file must hold one JSON object"),
    ("duplicate", '{"format": "lidet-sensor", "version": 1, "version": 1}', '"version": given twice'),
    ("format-missing", _with(BASE, format=_DROP), '"format": missing (expected "lidet-sensor")'),
    ("format-wrong", _with(BASE, format="lidet-sensors"), '"format": expected "lidet-sensor"'),
    ("format-number", _with(BASE, format=1), '"format": expected "lidet-sensor"'),
    ("ouster-given", OBASE, '"format": missing (expected "lidet-sensor"): this looks like Ouster metadata, read it '
                            'with --ouster-meta (load_ouster_metadata)'),
    ("version-missing", _with(BASE, version=_DROP), '"version": missing'),
    ("version-2", _with(BASE, version=2), '"version": 2 is not supported (this build reads version 1)'),
    ("version-string", _with(BASE, version="1"), '"version": expected an integer, got a string'),
    ("version-fraction", _with(BASE, version=1.5), '"version": expected an integer, got 1.5'),
    ("unknown-field", _with(BASE, colums=1024), f'"colums": unknown field (known: {KNOWN})'),
    ("name-missing", _with(BASE, name=_DROP), '"name": missing'),
    ("name-number", _with(BASE, name=5), '"name": expected a string, got a number'),
    ("name-space", _with(BASE, name="my sensor"), f'"name": {NAME_RULE}'),
    ("name-empty", _with(BASE, name=""), f'"name": {NAME_RULE}'),
    ("name-long", _with(BASE, name="a" * 64), f'"name": {NAME_RULE}'),
    ("name-utf8", _with(BASE, name="capteur-\u00e9"), f'"name": {NAME_RULE}'),
    ("cols-missing", _with(BASE, cols=_DROP), '"cols": missing'),
    ("cols-small", _with(BASE, cols=4), f'"cols": 4 is outside [8, {MAX_COLS}] (LIDET_MAX_COLS)'),
    ("cols-large", _with(BASE, cols=MAX_COLS + 1),
     f'"cols": {MAX_COLS + 1} is outside [8, {MAX_COLS}] (LIDET_MAX_COLS)'),
    ("cols-huge", _with(BASE, cols=10 ** 30), f'"cols": 1e+30 is outside [8, {MAX_COLS}] (LIDET_MAX_COLS)'),
    ("cols-fraction", _with(BASE, cols=1024.5), '"cols": expected an integer, got 1024.5'),
    ("cols-bool", _with(BASE, cols=True), '"cols": expected an integer, got true'),
    ("cols-string", _with(BASE, cols="1024"), '"cols": expected an integer, got a string'),
    ("cols-inf", _with(BASE, cols=_INF), '"cols": not a finite number'),
    ("table-and-fov", _with(BASE, fov_up_deg=10),
     '"beam_elevation_deg": give the beam table or "fov_up_deg", "fov_down_deg" and "rows", not both'),
    ("no-beams", _with(BASE, beam_elevation_deg=_DROP),
     '"beam_elevation_deg": missing (or give "fov_up_deg", "fov_down_deg" and "rows")'),
    ("table-number", _with(BASE, beam_elevation_deg=5),
     '"beam_elevation_deg": expected an array of numbers, got a number'),
    ("table-object", _with(BASE, beam_elevation_deg={"0": 1}),
     '"beam_elevation_deg": expected an array of numbers, got an object'),
    ("table-empty", _with(BASE, beam_elevation_deg=[]),
     f'"beam_elevation_deg": 0 beams, outside [1, {MAX_ROWS}] (LIDET_MAX_ROWS)'),
    ("table-long", _with(BASE, beam_elevation_deg=[80 - 0.5 * i for i in range(MAX_ROWS + 1)]),
     f'"beam_elevation_deg": {MAX_ROWS + 1} beams, outside [1, {MAX_ROWS}] (LIDET_MAX_ROWS)'),
    ("table-string", _with(BASE, beam_elevation_deg=[2.0, "0", -2.0]),
     '"beam_elevation_deg"[1]: expected a number, got a string'),
    ("table-null", _with(BASE, beam_elevation_deg=[2.0, 0.0, None]),
     '"beam_elevation_deg"[2]: expected a number, got null'),
    ("table-90", _with(BASE, beam_elevation_deg=[90, 0.0]), '"beam_elevation_deg"[0]: 90 deg is outside (-90, 90)'),
    ("table-below", _with(BASE, beam_elevation_deg=[1.0, -95.5]),
     '"beam_elevation_deg"[1]: -95.5 deg is outside (-90, 90)'),
    ("table-inf", _with(BASE, beam_elevation_deg=[1.0, 0.0, _INF]), '"beam_elevation_deg"[2]: not a finite number'),
    ("table-twice", _with(BASE, beam_elevation_deg=[2.0, 0.0, 2.0, -4.0]),
     '"beam_elevation_deg"[2]: the same elevation as [0] (2 deg): beams must be distinct'),
    ("table-float32", _with(BASE, beam_elevation_deg=[1.0, 0.0, 1.0 + 1e-9]),
     '"beam_elevation_deg"[2]: the same elevation as [0] (1 deg): beams must be distinct'),
    ("rows-mismatch", _with(BASE, rows=5), '"rows": 5 does not match the 4 entries of "beam_elevation_deg"'),
    ("rows-table-bad", _with(BASE, rows=0), f'"rows": 0 is outside [1, {MAX_ROWS}] (LIDET_MAX_ROWS)'),
    ("fov-no-down", _with(FOV, fov_down_deg=_DROP), '"fov_down_deg": missing'),
    ("fov-no-up", _with(FOV, fov_up_deg=_DROP), '"fov_up_deg": missing'),
    ("fov-no-rows", _with(FOV, rows=_DROP), '"rows": missing (needed with "fov_up_deg" and "fov_down_deg")'),
    ("fov-up-90", _with(FOV, fov_up_deg=90), '"fov_up_deg": 90 deg is outside (-90, 90)'),
    ("fov-down-string", _with(FOV, fov_down_deg="-30"), '"fov_down_deg": expected a number, got a string'),
    ("fov-inverted", _with(FOV, fov_up_deg=-30, fov_down_deg=10),
     '"fov_up_deg": -30 deg is not above "fov_down_deg" (10 deg)'),
    ("fov-rows-0", _with(FOV, rows=0), f'"rows": 0 is outside [1, {MAX_ROWS}] (LIDET_MAX_ROWS)'),
    ("fov-rows-large", _with(FOV, rows=MAX_ROWS + 1),
     f'"rows": {MAX_ROWS + 1} is outside [1, {MAX_ROWS}] (LIDET_MAX_ROWS)'),
    ("fov-narrow", _with(FOV, fov_up_deg=45.0000001, fov_down_deg=45.0),
     '"rows": 32 beams between "fov_down_deg" and "fov_up_deg" are not distinct in single precision'),
    ("mount-missing", _with(BASE, mount_height_m=_DROP), '"mount_height_m": missing'),
    ("mount-negative", _with(BASE, mount_height_m=-1), '"mount_height_m": -1 is outside [0, 10]'),
    ("mount-string", _with(BASE, mount_height_m="1"), '"mount_height_m": expected a number, got a string'),
    ("mount-inf", _with(BASE, mount_height_m=_INF), '"mount_height_m": not a finite number'),
    ("range-missing", _with(BASE, max_range_m=_DROP), '"max_range_m": missing'),
    ("range-zero", _with(BASE, max_range_m=0), '"max_range_m": 0 is outside (0, 1000]'),
    ("range-array", _with(BASE, max_range_m=[100]), '"max_range_m": expected a number, got an array'),
    ("model-number", _with(BASE, model=5), '"model": expected a string, got a number'),
    ("model-space", _with(BASE, model="hdl 64"), f'"model": {NAME_RULE}'),
]

NESTED = json.loads((DATA / "ouster_nested.json").read_text())

BAD_OUSTER = [
    ("syntax", '{"beam_altitude_angles": [1, 2}', "not valid JSON ..."),
    ("duplicate", '{"beam_intrinsics": {"beam_altitude_angles": [1], "beam_altitude_angles": [2]}}',
     '"beam_altitude_angles": given twice'),
    ("lidet-description", BASE,
     '"format": this is a lidet sensor description, read it with --sensor-file (load_sensor_file)'),
    ("digest", {"packet_hash": {"RANGE": "0"}, "scans": []},
     '"packet_hash": this is an ouster-sdk packet digest (hashes of decoded fields), not sensor metadata'),
    ("section-array", _with(OBASE, beam_intrinsics=[]), '"beam_intrinsics": expected an object, got an array'),
    ("section-string", _with(OBASE, sensor_info="OS-1"), '"sensor_info": expected an object, got a string'),
    ("no-altitudes", _with(OBASE, beam_altitude_angles=_DROP),
     '"beam_altitude_angles": missing (neither in "beam_intrinsics" nor at the top level): not Ouster sensor '
     "metadata?"),
    ("altitude-string", _with(OBASE, beam_altitude_angles=["10", 5.0]),
     '"beam_altitude_angles"[0]: expected a number, got a string'),
    ("altitude-nested-95", _with(OBASE, beam_intrinsics={"beam_altitude_angles": [95, 0]}),
     '"beam_intrinsics.beam_altitude_angles"[0]: 95 deg is outside (-90, 90)'),
    ("altitude-twice", _with(OBASE, beam_altitude_angles=[10.0, 5.0, 10.0, 0.0]),
     '"beam_altitude_angles"[2]: the same elevation as [0] (10 deg): beams must be distinct'),
    ("azimuth-count", _with(OBASE, beam_azimuth_angles=[1.0, 2.0, 3.0]),
     '"beam_azimuth_angles": 3 entries for 4 beams'),
    ("azimuth-200", _with(OBASE, beam_azimuth_angles=[1.0, 200.0, 1.0, 1.0]),
     '"beam_azimuth_angles"[1]: 200 deg is outside (-180, 180)'),
    ("azimuth-object", _with(OBASE, beam_azimuth_angles={}),
     '"beam_azimuth_angles": expected an array of numbers, got an object'),
    ("pixels-mismatch", _with(OBASE, data_format={"pixels_per_column": 64}),
     '"data_format.pixels_per_column": 64 but "beam_altitude_angles" has 4 entries'),
    ("mode-word", _with(OBASE, lidar_mode="fast"), '"lidar_mode": expected "<columns>x<rate>" such as "1024x10"'),
    ("mode-number", _with(OBASE, lidar_mode=1024), '"lidar_mode": expected "<columns>x<rate>" such as "1024x10"'),
    ("mode-rate", _with(OBASE, lidar_mode="1024x1000"), '"lidar_mode": expected "<columns>x<rate>" such as "1024x10"'),
    ("no-columns", _with(OBASE, lidar_mode=_DROP), '"lidar_mode": missing (and no "columns_per_frame")'),
    ("mode-vs-columns", _with(OBASE, data_format={"columns_per_frame": 2048}),
     '"lidar_mode": 1024 columns, but "data_format.columns_per_frame" is 2048'),
    ("mode-too-wide", _with(OBASE, lidar_mode="4096x5"),
     f'"lidar_mode": 4096 columns, outside [8, {MAX_COLS}] (LIDET_MAX_COLS)'),
    ("columns-too-wide", _with(OBASE, lidar_mode=_DROP, lidar_data_format={"columns_per_frame": MAX_COLS * 2}),
     f'"lidar_data_format.columns_per_frame": {MAX_COLS * 2} is outside [8, {MAX_COLS}] (LIDET_MAX_COLS)'),
    ("origin-string", _with(OBASE, lidar_origin_to_beam_origin_mm="15.8"),
     '"lidar_origin_to_beam_origin_mm": expected a number, got a string'),
    ("prod-number", _with(OBASE, prod_line=5), '"prod_line": expected a string, got a number'),
    ("prod-nested-null", _with(OBASE, sensor_info={"prod_line": None}),
     '"sensor_info.prod_line": expected a string, got null'),
]


def _write(tmp_path, name, content) -> pathlib.Path:
    p = tmp_path / f"{name}.json"
    p.write_text(_text(content))
    return p


def _expect(msg: str, p: pathlib.Path, got: str):
    want = f"{p}: {msg}"
    if msg.endswith("..."):
        assert got.startswith(want[:-3]), got
    else:
        assert got == want


def _same_sensor(a: sensors.Sensor, b: sensors.Sensor):
    assert (a.name, a.rows, a.cols, a.model, a.fov_urad) == (b.name, b.rows, b.cols, b.model, b.fov_urad)
    assert np.array_equal(a.beam_elev_rad, b.beam_elev_rad)  # float64: the same degrees read
    assert (a.mount_height_m, a.max_range_m) == (b.mount_height_m, b.max_range_m)


# ---- lidet_tools.sensors ---------------------------------------------------------------------------------

@pytest.mark.parametrize("case,content,msg", BAD_DESCRIPTIONS, ids=[c[0] for c in BAD_DESCRIPTIONS])
def test_bad_description_names_its_field(tmp_path, case, content, msg):
    p = _write(tmp_path, case, content)
    with pytest.raises(sensors.SensorFileError) as e:
        sensors.load_sensor_file(p)
    _expect(msg, p, str(e.value))


@pytest.mark.parametrize("case,content,msg", BAD_OUSTER, ids=[c[0] for c in BAD_OUSTER])
def test_bad_ouster_metadata_names_its_field(tmp_path, case, content, msg):
    p = _write(tmp_path, case, content)
    with pytest.raises(sensors.SensorFileError) as e:
        sensors.load_ouster_metadata(p)
    _expect(msg, p, str(e.value))


def test_missing_and_oversized_files(tmp_path):
    with pytest.raises(sensors.SensorFileError, match="cannot read: No such file"):
        sensors.load_sensor_file(tmp_path / "nope.json")
    big = tmp_path / "big.json"
    big.write_bytes(b" " * (sensors.SENSOR_FILE_MAX_BYTES + 1))
    with pytest.raises(sensors.SensorFileError, match="larger than 16 MiB"):
        sensors.load_ouster_metadata(big)
    bad = tmp_path / "latin1.json"
    bad.write_bytes(b'{"name": "\xe9"}')
    with pytest.raises(sensors.SensorFileError, match=r"not valid JSON \(not UTF-8 text\)"):
        sensors.load_sensor_file(bad)


@pytest.mark.parametrize("preset", ["hdl64", "vlp16"])
def test_description_repeating_a_preset_gives_its_table(preset):
    s = sensors.load_sensor_file(DATA / f"{preset}.json")
    p = sensors.get_sensor(preset)
    assert s.name == f"{preset}-table" and (s.rows, s.cols) == (p.rows, p.cols)
    assert np.array_equal(s.beam_elev_rad.astype(np.float32), p.beam_elev_rad.astype(np.float32))
    assert np.array_equal(s.beam_elev_urad, p.beam_elev_urad)  # the integer profile too
    assert s.mount_height_m == p.mount_height_m and s.max_range_m == p.max_range_m
    assert s.fov_urad is None and s.model is None


def test_uniform_description_is_custom_sensor():
    s = sensors.load_sensor_file(DATA / "uniform32.json")
    c = sensors.custom_sensor("uniform32", 1024, fov_up_deg=10, fov_down_deg=-30, rows=32, mount_height_m=1.2,
                              max_range_m=100)
    assert (s.rows, s.cols, s.fov_urad) == (32, 1024, c.fov_urad)
    assert np.array_equal(s.beam_elev_rad, c.beam_elev_rad)
    assert np.array_equal(s.beam_elev_urad, c.beam_elev_urad)
    assert s.beam_elev_rad[0] > s.beam_elev_rad[-1]  # beam 0 at the top, as uniform_beams


def test_model_family_rule(tmp_path):
    def load(**kv):
        return sensors.load_sensor_file(_write(tmp_path, "m", _with(BASE, **kv)))
    assert sensors.model_family(load()) == "vlp16"  # 4 rows
    assert sensors.model_family(load(beam_elevation_deg=[10 - i for i in range(32)])) == "hdl64"
    assert sensors.model_family(load(beam_elevation_deg=[10 - i for i in range(31)])) == "vlp16"
    assert sensors.model_family(load(model="vlp16s")) == "vlp16s"
    assert sensors.model_family(load(beam_elevation_deg=[10 - i for i in range(64)], model="vlp16")) == "vlp16"


def test_description_accepts_integral_floats_and_rows(tmp_path):
    s = sensors.load_sensor_file(_write(tmp_path, "f", _with(BASE, cols=1024.0, version=1.0, rows=4, model="hdl64")))
    assert (s.cols, s.rows, s.model) == (1024, 4, "hdl64")
    assert isinstance(s.cols, int)
    np.testing.assert_array_equal(s.beam_elev_rad, np.radians([2.0, 0.0, -2.0, -4.0]))


def test_ouster_nested_layout():
    s = sensors.load_ouster_metadata(DATA / "ouster_nested.json")
    bi = NESTED["beam_intrinsics"]
    assert (s.name, s.rows, s.cols) == ("os-1-32-u2", 32, 2048)
    assert np.array_equal(s.beam_elev_rad, np.radians(bi["beam_altitude_angles"]))
    assert np.array_equal(s.beam_azimuth_rad, np.radians(bi["beam_azimuth_angles"]))
    assert s.beam_origin_mm == bi["lidar_origin_to_beam_origin_mm"]
    assert s.mount_height_m == sensors.OUSTER_MOUNT_HEIGHT_M and s.max_range_m == sensors.OUSTER_MAX_RANGE_M
    assert s.model is None and sensors.model_family(s) == "hdl64"


def test_ouster_flat_layout_reads_the_same(tmp_path):
    """The fields at the top level (older firmware) give the same sensor as nested."""
    flat = dict(NESTED["beam_intrinsics"])
    flat.update(lidar_mode=NESTED["config_params"]["lidar_mode"], prod_line=NESTED["sensor_info"]["prod_line"])
    a = sensors.load_ouster_metadata(DATA / "ouster_nested.json")
    b = sensors.load_ouster_metadata(_write(tmp_path, "flat", flat))
    _same_sensor(a, b)
    assert np.array_equal(a.beam_azimuth_rad, b.beam_azimuth_rad) and a.beam_origin_mm == b.beam_origin_mm


@pytest.mark.parametrize("prod,name", [("OS-1-64-U02", "os-1-64-u02"), ("OS 1/64", "os-1-64"), ("", "ouster-4"),
                                       ("X" * 80, "x" * 63), ("\u00c9", "--"), (None, "ouster-4")])
def test_ouster_names(tmp_path, prod, name):
    d = _with(OBASE, prod_line=prod if prod is not None else _DROP)
    assert sensors.load_ouster_metadata(_write(tmp_path, "n", d)).name == name


def test_ouster_mount_height(tmp_path):
    p = _write(tmp_path, "o", OBASE)
    assert sensors.load_ouster_metadata(p).mount_height_m == 1.0
    assert sensors.load_ouster_metadata(p, mount_height_m=1.8).mount_height_m == 1.8
    for bad in (-0.1, 10.5, float("nan"), "1", True):
        with pytest.raises(ValueError, match="mount_height_m must be metres in"):
            sensors.load_ouster_metadata(p, mount_height_m=bad)


def _ouster_files():
    if not OUSTER.is_dir():
        pytest.skip(f"Ouster metadata not available at {OUSTER} (../shared/data/packets)")
    files = sorted(OUSTER.glob("*.json"))
    meta = [f for f in files if not f.name.endswith("_digest.json")]
    assert meta, f"no metadata files in {OUSTER}"
    return meta, [f for f in files if f.name.endswith("_digest.json")]


def test_ouster_shared_metadata():
    meta, digests = _ouster_files()
    for f in meta:
        raw = json.loads(f.read_text())
        s = sensors.load_ouster_metadata(f)
        alt = raw.get("beam_intrinsics", raw)["beam_altitude_angles"]
        assert s.rows == len(alt) and s.cols == 1024, f.name  # every file here is 1024x10
        assert np.array_equal(s.beam_elev_rad, np.radians(alt)), f.name
        assert s.beam_elev_rad[0] == s.beam_elev_rad.max(), f.name  # Ouster's ring order: top beam first
        assert s.beam_azimuth_rad is not None and len(s.beam_azimuth_rad) == s.rows, f.name
        want = raw["prod_line"].lower() if "prod_line" in raw else f"ouster-{s.rows}"
        assert s.name == want, f.name
        assert (s.beam_origin_mm is None) == ("lidar_origin_to_beam_origin_mm" not in raw), f.name
    for f in digests:
        with pytest.raises(sensors.SensorFileError, match="packet digest"):
            sensors.load_ouster_metadata(f)


# ---- the CLI's loader (ports/host/cli_sensor.c) against the Python one -------------------------------------

@pytest.fixture(scope="module")
def cli_json(cli):
    """The CLI, when built with cJSON (else the tests that need it skip, saying so)."""
    r = subprocess.run([str(cli), "project", "--sensor-file", str(DATA / "vlp16.json"), "--print-sensor"],
                       capture_output=True, text=True)
    if r.returncode != 0 and "built without" in r.stderr:
        pytest.skip("the CLI was built without cJSON (apt-get install libcjson-dev): " + r.stderr.strip())
    assert r.returncode == 0, r.stderr
    return cli


def _print_sensor(cli, option, path, tmp_path, *extra) -> pathlib.Path:
    r = subprocess.run([str(cli), "project", option, str(path), *map(str, extra), "--print-sensor"],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    out = tmp_path / f"printed_{pathlib.Path(path).stem}.json"
    out.write_text(r.stdout)
    return out


def _cli_error(cli, option, path) -> str:
    r = subprocess.run([str(cli), "project", option, str(path), "--print-sensor"], capture_output=True, text=True)
    assert r.returncode == 1 and r.stdout == "", (r.stdout, r.stderr)
    assert r.stderr.startswith("lidet project: ") and r.stderr.endswith("\n") and r.stderr.count("\n") == 1, r.stderr
    return r.stderr[len("lidet project: "):-1]


@pytest.mark.parametrize("case,content,msg", BAD_DESCRIPTIONS, ids=[c[0] for c in BAD_DESCRIPTIONS])
def test_cli_bad_description_same_message(cli_json, tmp_path, case, content, msg):
    p = _write(tmp_path, case, content)
    _expect(msg, p, _cli_error(cli_json, "--sensor-file", p))


@pytest.mark.parametrize("case,content,msg", BAD_OUSTER, ids=[c[0] for c in BAD_OUSTER])
def test_cli_bad_ouster_same_message(cli_json, tmp_path, case, content, msg):
    p = _write(tmp_path, case, content)
    _expect(msg, p, _cli_error(cli_json, "--ouster-meta", p))


def test_cli_missing_file_and_option_conflicts(cli_json, tmp_path):
    assert _cli_error(cli_json, "--sensor-file", tmp_path / "nope.json") == \
        f"{tmp_path / 'nope.json'}: cannot read: No such file or directory"
    r = subprocess.run([str(cli_json), "detect", "x.bin", "--sensor", "hdl64", "--sensor-file", DATA / "hdl64.json"],
                       capture_output=True, text=True)
    assert r.returncode == 1 and "give one of --sensor, --sensor-file, --ouster-meta and --velodyne-calib" in r.stderr


def _good_files(tmp_path):
    """(option, file, Python loader) of every good file: the committed ones, hand-made variants, Ouster's."""
    out = [("--sensor-file", DATA / f, sensors.load_sensor_file)
           for f in ("hdl64.json", "vlp16.json", "uniform32.json")]
    out.append(("--ouster-meta", DATA / "ouster_nested.json", sensors.load_ouster_metadata))
    for i, d in enumerate([_with(BASE, model="vlp16s", rows=4), _with(FOV, fov_up_deg=2.0, fov_down_deg=-24.9, rows=64),
                           _with(BASE, beam_elevation_deg=[0.1 * i - 3.3 for i in range(MAX_ROWS)], cols=MAX_COLS),
                           _with(BASE, beam_elevation_deg=[1 / 3, -1 / 7, 88.5, -88.5], mount_height_m=1.73,
                                 max_range_m=0.001)]):
        out.append(("--sensor-file", _write(tmp_path, f"good{i}", d), sensors.load_sensor_file))
    out.append(("--ouster-meta", _write(tmp_path, "flat", OBASE), sensors.load_ouster_metadata))
    if OUSTER.is_dir():
        out += [("--ouster-meta", f, sensors.load_ouster_metadata) for f in _ouster_files()[0]]
    return out


def test_cli_and_python_read_the_same_sensor(cli_json, tmp_path):
    """The CLI's --print-sensor (what it read, as a description) read back by Python equals Python's own reading
    of the file: name, rows, cols, the elevation degrees as doubles, mount height, range, model."""
    files = _good_files(tmp_path)
    assert len(files) >= 9
    # the format's bounds (the library's projection then refuses beams beyond 88.8 deg at init)
    edge = _with(BASE, beam_elevation_deg=[89.99999, -89.99999, 0.0], mount_height_m=10, max_range_m=1000)
    files.append(("--sensor-file", _write(tmp_path, "edge", edge), sensors.load_sensor_file))
    for option, f, load in files:
        py = load(f)
        back = sensors.load_sensor_file(_print_sensor(cli_json, option, f, tmp_path))
        _same_sensor(py, back)
    # --mount-height reaches a file's sensor (Ouster's 1.0 m default included)
    back = sensors.load_sensor_file(_print_sensor(cli_json, "--ouster-meta", DATA / "ouster_nested.json", tmp_path,
                                                  "--mount-height", "1.8"))
    assert back.mount_height_m == 1.8


@pytest.mark.usefixtures("need_lib")
def test_cli_presets_print_as_their_tables(cli, tmp_path):
    """`--sensor P --print-sensor`: a description that reads back as the C preset (tables bit for bit)."""
    from lidet_tools import native
    cs = native.c_sensors()
    for name, p in sensors.SENSORS.items():
        r = subprocess.run([str(cli), "project", "--sensor", name, "--print-sensor"], capture_output=True, text=True)
        assert r.returncode == 0, r.stderr
        f = tmp_path / f"{name}.json"
        f.write_text(r.stdout)
        s = sensors.load_sensor_file(f)
        assert (s.name, s.rows, s.cols) == (name, p.rows, p.cols)
        assert np.float32(s.mount_height_m) == np.float32(p.mount_height_m)
        if p.fov_urad is None:
            assert np.array_equal(s.beam_elev_rad.astype(np.float32), cs[name][2]), name
        else:
            assert s.fov_urad == p.fov_urad, name  # the uniform presets print as their field of view
            np.testing.assert_allclose(s.beam_elev_rad, p.beam_elev_rad, atol=1e-7)


@pytest.mark.usefixtures("need_lib")
def test_cli_projection_equals_bindings(cli_json, tmp_path):
    """`lidet project --sensor-file/--ouster-meta --out` puts every point in the pixel the bindings give with the
    Python-loaded Sensor: the same single-precision table reaches the library from both loaders."""
    from lidet_tools import native
    scan = ROOT / "tests" / "data" / "sim_hdl64" / "velodyne" / "000000.bin"
    pts = kitti.read_bin(scan)
    for option, f, load in _good_files(tmp_path):
        out = tmp_path / "pix.bin"
        r = subprocess.run([str(cli_json), "project", str(scan), option, str(f), "--out", str(out)],
                           capture_output=True, text=True)
        assert r.returncode == 0, r.stderr
        ref = native.project(pts, load(f)).point_pixel
        assert np.array_equal(np.fromfile(out, np.int32), ref), f


# ---- the detector: a description repeating a preset's table, and a sensor of its own -----------------------

def _dump_labels_and_detections(path: pathlib.Path):
    """Per-point (cluster id, ground) and the detections (class, cluster, points, score, energies, box) of a
    `lidet detect --dump` file (format: write_dump in ports/host/cli_detect.c)."""
    b = path.read_bytes()
    assert b[:4] == b"LDTD"
    n, _, nd = np.frombuffer(b[4:16], "<u4")
    per_point = np.frombuffer(b[16:16 + 5 * int(n)], np.dtype([("id", "<u4"), ("g", "u1")]))
    tail = b[len(b) - 52 * int(nd):]
    det = np.frombuffer(tail, np.dtype([("u", "<u4", 3), ("f", "<f4", 10)]))
    return per_point["id"], per_point["g"], det


@pytest.mark.parametrize("preset", ["hdl64", "vlp16"])
def test_cli_description_of_a_preset_detects_bit_for_bit(cli_json, tmp_path, preset):
    scan = ROOT / "tests" / "data" / f"sim_{preset}" / "velodyne" / "000000.bin"
    a, b = tmp_path / "a.bin", tmp_path / "b.bin"
    for opts, out in ((["--sensor", preset], a), (["--sensor-file", DATA / f"{preset}.json"], b)):
        r = subprocess.run([str(cli_json), "detect", str(scan), *map(str, opts), "--dump", str(out), "--json"],
                           capture_output=True, text=True)
        assert r.returncode == 0, r.stderr
        js = json.loads(r.stdout)
        assert js["model"] == preset and js["detections"] > 0
    assert a.read_bytes() == b.read_bytes()
    # the integer detector takes the file's integer profile: the same boxes as the preset's
    outs = []
    for opts in (["--sensor", preset], ["--sensor-file", DATA / f"{preset}.json"]):
        o = tmp_path / f"q{len(outs)}.txt"
        r = subprocess.run([str(cli_json), "detect", str(scan), *map(str, opts), "--fixed", "--out", str(o)],
                           capture_output=True, text=True)
        assert r.returncode == 0, r.stderr
        outs.append(o.read_text())
    assert outs[0] == outs[1] and outs[0]


@pytest.mark.usefixtures("need_lib")
@pytest.mark.parametrize("preset", ["hdl64", "vlp16"])
def test_bindings_description_of_a_preset_detects_bit_for_bit(preset):
    from lidet_tools import native
    pts = kitti.read_bin(ROOT / "tests" / "data" / f"sim_{preset}" / "velodyne" / "000000.bin")
    a = native.detect(pts, preset)
    s = sensors.load_sensor_file(DATA / f"{preset}.json")
    assert native.default_family(s) == native.default_family(preset) == preset
    b = native.detect(pts, s)
    assert len(a.score) > 0
    for k in ("cls", "score", "energy_cls", "energy_box", "box", "cluster_id", "outcome", "point_cluster",
              "point_ground"):
        assert np.array_equal(getattr(a, k), getattr(b, k)), k
    assert a.stats == b.stats


@pytest.mark.usefixtures("need_lib")
def test_cli_and_bindings_detect_alike_on_a_sensor_of_their_own(cli_json, tmp_path):
    """A table no preset has (the nested Ouster file, 32 x 2048): the CLI and the bindings give the same labels
    and the same detections, bit for bit."""
    from lidet_tools import native
    scan = ROOT / "tests" / "data" / "sim_hdl64" / "velodyne" / "000000.bin"
    meta = DATA / "ouster_nested.json"
    dump = tmp_path / "d.bin"
    r = subprocess.run([str(cli_json), "detect", str(scan), "--ouster-meta", str(meta), "--mount-height", "1.73",
                        "--set", "gate1=0", "--dump", str(dump), "--json"], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert json.loads(r.stdout)["model"] == "hdl64"  # 32 rows
    ids, gnd, det = _dump_labels_and_detections(dump)
    d = native.detect(kitti.read_bin(scan), sensors.load_ouster_metadata(meta, mount_height_m=1.73), gate1=False)
    assert np.array_equal(ids, d.point_cluster) and np.array_equal(gnd, d.point_ground)
    assert len(det) == len(d.score) > 0
    assert np.array_equal(det["u"][:, 0], d.cls) and np.array_equal(det["u"][:, 1], d.cluster_id)
    assert np.array_equal(det["f"][:, 0], d.score)
    assert np.array_equal(det["f"][:, 1], d.energy_cls) and np.array_equal(det["f"][:, 2], d.energy_box)
    assert np.array_equal(det["f"][:, 3:], d.box)


@pytest.mark.usefixtures("need_lib")
def test_model_of_a_description(cli_json, tmp_path):
    from lidet_tools import native
    scan = ROOT / "tests" / "data" / "sim_vlp16" / "velodyne" / "000000.bin"
    d = json.loads((DATA / "vlp16.json").read_text())
    for model, ok in (("vlp16s", True), ("nosuch", False)):
        f = _write(tmp_path, model, dict(d, model=model))
        r = subprocess.run([str(cli_json), "detect", str(scan), "--sensor-file", str(f), "--json"],
                           capture_output=True, text=True)
        s = sensors.load_sensor_file(f)
        if ok:
            assert r.returncode == 0 and json.loads(r.stdout)["model"] == model, r.stderr
            assert native.default_family(s) == model
            native.detect(kitti.read_bin(scan), s)
        else:
            assert r.returncode == 1 and "no models cls_nosuch / box_nosuch" in r.stderr
            with pytest.raises(KeyError, match="cls_nosuch"):
                native.detect(kitti.read_bin(scan), s)
    with pytest.raises(TypeError, match="preset name or a Sensor"):
        native.detect(kitti.read_bin(scan), 16)
