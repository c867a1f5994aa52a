# SPDX-License-Identifier: MIT
"""Sensor profiles, mirrored from lib/src/proj/lidet_sensor.c (tests/python/test_bindings_proj.py keeps the
two identical through the bindings).

Frame: x forward, y left, z up, metres, radians, origin at the sensor's optical centre.
Beam elevations are listed in the sensor's *ring order* (the ring index its driver reports);
the projection sorts them top to bottom to get image rows (row 0 = highest beam).

Column convention (same as the SemanticKITTI API): col = floor(0.5 * (1 - azimuth / pi) * cols),
azimuth = atan2(y, x); so +x (forward) is the middle column, azimuth decreases to the right, and
the seam (col 0 / cols-1) is straight behind the sensor.

Sensors beyond the presets come from files (docs/SENSORS.md): `load_sensor_file` reads lidet's own
description (JSON, "format": "lidet-sensor"), `load_ouster_metadata` Ouster's sensor metadata JSON,
`load_velodyne_calibration` a Velodyne calibration (db.xml / VeloView XML, or velodyne_pointcloud's YAML);
`description_json` writes a Sensor as a description. The host CLI reads the same files with the same rules and
messages (ports/host/cli_sensor.c, cli_velodyne_calib.c: `lidet ... --sensor-file F | --ouster-meta M |
--velodyne-calib C`) and prints what it read as `description_json` writes it (`--print-sensor`);
tests/python/test_sensor_files.py and test_velodyne_calib.py hold the two together.
"""
from __future__ import annotations

import json
import math
import pathlib
import re
from dataclasses import dataclass, field

import numpy as np


def _deg(a):
    return np.radians(np.asarray(a, dtype=np.float64))


@dataclass(frozen=True)
class VelodyneCorrections:
    """What a Velodyne calibration gives besides the elevations and azimuth offsets (load_velodyne_calibration),
    per laser in the Sensor's ring order (lowest beam first), in metres as velodyne_pointcloud's YAML has them
    (db.xml's centimetres times 0.01). Read and validated; the packet decoder applies the distance correction
    (lidet_velodyne.h's lidet_velodyne_calib_t: `velodyne.calibration_table`, `lidet ... --pcap --velodyne-calib`),
    the projection none of them; the offsets and focal corrections are not applied (docs/SENSORS.md)."""
    #: "xml" (db.xml / VeloView) or "yaml" (velodyne_pointcloud)
    source: str
    #: each ring's laser: its id (id_ / laser_id), the laser's place in the packet's data block
    laser_id: np.ndarray = field(repr=False)
    dist_correction_m: np.ndarray = field(repr=False)
    dist_correction_x_m: np.ndarray = field(repr=False)
    dist_correction_y_m: np.ndarray = field(repr=False)
    vert_offset_m: np.ndarray = field(repr=False)
    horiz_offset_m: np.ndarray = field(repr=False)
    focal_distance_m: np.ndarray = field(repr=False)
    focal_slope: np.ndarray = field(repr=False)
    #: distance_resolution (YAML, m) or distLSB_ (db.xml, cm, times 0.01); 0.002 when the file gives none
    distance_resolution_m: float = 0.002


@dataclass(frozen=True)
class Sensor:
    name: str
    rows: int
    cols: int
    #: per-beam elevation in radians, ring order (len == rows)
    beam_elev_rad: np.ndarray = field(repr=False)
    mount_height_m: float
    max_range_m: float
    #: (fov_up, fov_down) in microradians for a uniform sensor (the integer presets give the fov, not a
    #: table, as lib/src/proj/lidet_sensor_q.c); None for a sensor with a beam table
    fov_urad: tuple | None = None
    #: float model family the detector runs (a description file's "model"); None: the rule of `model_family`
    model: str | None = None
    #: per-beam azimuth offsets in radians, ring order, as the file gives them: Ouster metadata's
    #: beam_azimuth_angles (the Ouster packet decoder takes them: lidet_tools.ouster, `lidet detect --pcap --lidar
    #: ouster`), a Velodyne calibration's rot_correction (the Velodyne packet decoder takes it with
    #: `--velodyne-calib`: velodyne.calibration_table); the projection never uses them
    beam_azimuth_rad: np.ndarray | None = field(default=None, repr=False)
    #: Ouster metadata's lidar_origin_to_beam_origin_mm; read and validated, not used by the projection
    beam_origin_mm: float | None = None
    #: the elevation table in degrees as the file gives it (ring order; a velodyne_pointcloud YAML's radians times
    #: 180 / pi): what `description_json` and `lidet ... --print-sensor` write; None for a preset and a uniform
    #: description
    beam_elev_deg: np.ndarray | None = field(default=None, repr=False)
    #: a Velodyne calibration's other corrections (load_velodyne_calibration); None otherwise
    velodyne: VelodyneCorrections | None = field(default=None, repr=False)

    @property
    def beam_elev_urad(self) -> np.ndarray:
        """Beam elevations in ring order, integer microradians (the integer path's profile,
        lidet_sensor_q_elevations): the table rounded, or the uniform beams computed in integers."""
        if self.fov_urad is not None:
            up, down = self.fov_urad
            span = up - down
            i = np.arange(self.rows, dtype=np.int64)
            n = (2 * i + 1) * span  # > 0: round half away from zero = floor(n / d + 1/2)
            return (up - (n + self.rows) // (2 * self.rows)).astype(np.int32)
        return np.round(self.beam_elev_rad * 1e6).astype(np.int32)

    @property
    def mount_height_mm(self) -> int:
        return int(round(self.mount_height_m * 1000.0))

    @property
    def max_range_mm(self) -> int:
        return int(round(self.max_range_m * 1000.0))

    #: horizontal angular resolution in radians
    @property
    def az_step_rad(self) -> float:
        return 2.0 * np.pi / self.cols

    @property
    def elev_sorted_desc(self) -> np.ndarray:
        """Beam elevations in row order (row 0 = top)."""
        return np.sort(self.beam_elev_rad)[::-1]

    @property
    def ring_to_row(self) -> np.ndarray:
        """Row of each ring (stable: equal elevations keep ring order)."""
        order = np.argsort(-self.beam_elev_rad, kind="stable")
        r2r = np.empty(self.rows, dtype=np.int64)
        r2r[order] = np.arange(self.rows)
        return r2r


def uniform_beams(fov_up_deg: float, fov_down_deg: float, rows: int) -> np.ndarray:
    """Beam centres of a uniform fov split into `rows` bins, top to bottom (radians).

    Bin i spans [fov_up - (i+1)*step, fov_up - i*step]; its beam sits at the bin centre, so the
    nearest-beam rule reproduces the uniform formula row = floor((fov_up - pitch) / step).
    """
    step = (fov_up_deg - fov_down_deg) / rows
    return _deg(fov_up_deg - (np.arange(rows) + 0.5) * step)


# KITTI HDL-64E. The datasheet gives +2.0 .. -24.8 deg; in KITTI's own (calibrated, motion-
# compensated) scans the beams sit higher. We recovered each point's ring from the scan order of 11
# real KITTI scans (a new ring starts where the azimuth wraps) and took each ring's median
# elevation: upper block +2.5 .. -7.7 deg (~0.33 deg apart), lower block -8.25 .. -23.5 deg
# (~0.49 deg apart). Ring order = top to bottom, as KITTI's scan order.
_HDL64 = np.concatenate([np.linspace(2.5, -7.7, 32), np.linspace(-8.25, -23.5, 32)])

# Velodyne VLP-16: -15..+15 deg every 2 deg. Ring order as velodyne_pointcloud reports it:
# ring 0 = lowest beam.
_VLP16 = np.arange(-15.0, 15.0 + 1e-9, 2.0)

# Velodyne HDL-32E: -30.67 .. +10.67 deg every 4/3 deg, as its manual lists them (two decimals); ring 0 = lowest.
_HDL32 = np.array([
    -30.67, -29.33, -28.00, -26.67, -25.33, -24.00, -22.67, -21.33, -20.00, -18.67, -17.33, -16.00,
    -14.67, -13.33, -12.00, -10.67, -9.33, -8.00, -6.67, -5.33, -4.00, -2.67, -1.33, 0.00,
    1.33, 2.67, 4.00, 5.33, 6.67, 8.00, 9.33, 10.67,
])

# Velodyne VLP-32C: its real non-uniform table (dense around the horizon), ring 0 = lowest.
_VLP32C = np.array([
    -25.0, -15.639, -11.31, -8.843, -7.254, -6.148, -5.333, -4.667,
    -4.0, -3.667, -3.333, -3.0, -2.667, -2.333, -2.0, -1.667,
    -1.333, -1.0, -0.667, -0.333, 0.0, 0.333, 0.667, 1.0,
    1.333, 1.667, 2.333, 3.333, 4.667, 7.0, 10.333, 15.0,
])

# Hesai Pandar64 (PandaSet's sensor): the nominal channel elevations Hesai publishes, ring r = channel r + 1 (ring 0 =
# the top beam, Hesai's order); 0.167 deg apart between +2.028 and -6.061 deg.
_PANDAR64 = np.array([
    14.882, 11.032, 8.059, 5.057, 3.040, 2.028, 1.860, 1.688, 1.522, 1.351, 1.184, 1.013, 0.846, 0.675, 0.508, 0.337,
    0.169, 0.000, -0.169, -0.337, -0.508, -0.675, -0.845, -1.013, -1.184, -1.351, -1.522, -1.688, -1.860, -2.028,
    -2.198, -2.365, -2.536, -2.700, -2.873, -3.040, -3.210, -3.375, -3.548, -3.712, -3.884, -4.050, -4.221, -4.385,
    -4.558, -4.720, -4.892, -5.057, -5.229, -5.391, -5.565, -5.726, -5.898, -6.061, -7.063, -8.059, -9.060, -9.885,
    -11.032, -12.006, -12.974, -13.930, -18.889, -24.897,
])


def _urad_fov(up_deg: float, down_deg: float) -> tuple:
    return int(round(np.radians(up_deg) * 1e6)), int(round(np.radians(down_deg) * 1e6))


SENSORS: dict[str, Sensor] = {
    "hdl64": Sensor("hdl64", 64, 2048, _deg(_HDL64), 1.73, 120.0),
    "vlp16": Sensor("vlp16", 16, 1800, _deg(_VLP16), 0.5, 100.0),
    "vlp32c": Sensor("vlp32c", 32, 1800, _deg(_VLP32C), 1.0, 200.0),
    # Ouster OS1: uniform +-22.5 deg; ring 0 = top beam (Ouster's convention).
    "os1-64": Sensor("os1-64", 64, 2048, uniform_beams(22.5, -22.5, 64), 1.0, 120.0, _urad_fov(22.5, -22.5)),
    "os1-128": Sensor("os1-128", 128, 2048, uniform_beams(22.5, -22.5, 128), 1.0, 120.0, _urad_fov(22.5, -22.5)),
    # Velodyne HDL-32E at nuScenes' 20 Hz (a firing cycle every 46.08 us: 1085 per revolution), roof mount 1.84 m.
    "hdl32": Sensor("hdl32", 32, 1085, _deg(_HDL32), 1.84, 100.0),
    # Ouster OS0 (+-45 deg), OS1 (+-22.5), OS2 (+-11.25), uniform, at the factory default lidar mode 1024x10.
    **{f"os{k}-{n}": Sensor(f"os{k}-{n}", n, 1024, uniform_beams(fov, -fov, n), 1.0, rng, _urad_fov(fov, -fov))
       for k, n, fov, rng in ((0, 32, 45.0, 100.0), (0, 64, 45.0, 100.0), (0, 128, 45.0, 100.0),
                              (1, 32, 22.5, 120.0), (2, 32, 11.25, 240.0), (2, 64, 11.25, 240.0),
                              (2, 128, 11.25, 240.0))},
    # Pandar64 at 10 Hz (0.2 deg a column), PandaSet's roof mount 2.05 m (lidet_tools.real.pandaset).
    "pandar64": Sensor("pandar64", 64, 1800, _deg(_PANDAR64), 2.05, 200.0),
}


def get_sensor(name: str) -> Sensor:
    try:
        return SENSORS[name]
    except KeyError:
        raise ValueError(f"unknown sensor {name!r}; known: {', '.join(SENSORS)}") from None


def custom_sensor(name: str, cols: int, beam_elev_deg=None, fov_up_deg=None, fov_down_deg=None,
                  rows=None, mount_height_m=1.0, max_range_m=100.0) -> Sensor:
    """A custom profile from a per-beam table (ring order, degrees) or a uniform fov."""
    fov = None
    if beam_elev_deg is not None:
        elev = _deg(beam_elev_deg)
    else:
        if fov_up_deg is None or fov_down_deg is None or rows is None:
            raise ValueError("custom sensor needs beam_elev_deg or fov_up_deg, fov_down_deg and rows")
        elev = uniform_beams(fov_up_deg, fov_down_deg, rows)
        fov = _urad_fov(fov_up_deg, fov_down_deg)
    return Sensor(name, len(elev), int(cols), elev, float(mount_height_m), float(max_range_m), fov)


# ---- sensor descriptions from files (docs/SENSORS.md) ---------------------------------------------------
# ports/host/cli_sensor.c implements the same rules in the same order with the same messages: a change here
# goes there too (tests/python/test_sensor_files.py compares the two on every test file).

#: "format" and "version" of lidet's sensor description files
SENSOR_FILE_FORMAT = "lidet-sensor"
SENSOR_FILE_VERSION = 1
#: the fields a version-1 description may hold
SENSOR_FILE_FIELDS = ("format", "version", "name", "cols", "rows", "beam_elevation_deg", "fov_up_deg",
                      "fov_down_deg", "mount_height_m", "max_range_m", "model")
#: larger files are refused before parsing
SENSOR_FILE_MAX_BYTES = 16 << 20
#: what Ouster's metadata does not say: the mount height (overridable) and the nominal range (informational)
OUSTER_MOUNT_HEIGHT_M = 1.0
OUSTER_MAX_RANGE_M = 120.0
#: a "name" or "model": 1 to 63 of these characters
_NAME_BYTES = frozenset(b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789._+-")
_NAME_RULE = "must be 1 to 63 characters from A-Z a-z 0-9 . _ + -"


class SensorFileError(ValueError):
    """A sensor description or metadata file that cannot be used; the message starts with the path and names
    the field ("PATH: \\"cols\\": 4 is outside [8, 2048] (LIDET_MAX_COLS)")."""


class _Bad(Exception):
    """A validation failure inside a loader (the message without the path)."""


class _Duplicate(Exception):
    pass


class _Constant(Exception):
    pass


def model_family(sensor: Sensor) -> str:
    """The float model family the detector runs for a sensor read from a file: its "model", else hdl64 for 32
    beams or more and vlp16 below (the families trained today; docs/SENSORS.md)."""
    if sensor.model:
        return sensor.model
    return "hdl64" if sensor.rows >= 32 else "vlp16"


def _header_limits() -> tuple[int, int]:
    """LIDET_MAX_ROWS / LIDET_MAX_COLS defaults of lib/include/lidet/lidet_opt.h (when the bindings are not
    built); the bounds the header's #error checks allow when it is not there either."""
    opt = pathlib.Path(__file__).resolve().parents[2] / "lib" / "include" / "lidet" / "lidet_opt.h"
    try:
        txt = opt.read_text()
    except OSError:
        return 256, 16384
    rows = re.search(r"#define\s+LIDET_MAX_ROWS\s+(\d+)", txt)
    cols = re.search(r"#define\s+LIDET_MAX_COLS\s+(\d+)", txt)
    return (int(rows.group(1)) if rows else 256), (int(cols.group(1)) if cols else 16384)


def capacity_limits() -> tuple[int, int]:
    """(LIDET_MAX_ROWS, LIDET_MAX_COLS) of the built library (through the bindings), else lidet_opt.h's
    defaults: the bounds a description's rows and cols must keep."""
    try:
        from . import native
        c = native.capacity()
        return c["max_rows"], c["max_cols"]
    except (FileNotFoundError, OSError, AttributeError):
        return _header_limits()


def _kind(v, yaml: bool = False) -> str:
    """How a JSON (or, yaml=True, a YAML) value is named in the loaders' messages."""
    if isinstance(v, bool):
        return "true" if v else "false"
    if v is None:
        return "null"
    if isinstance(v, str):
        return "a string"
    if isinstance(v, list):
        return "a list" if yaml else "an array"
    if isinstance(v, dict):
        return "a mapping" if yaml else "an object"
    return "a number"


def _float(v) -> float:
    try:
        return float(v)
    except OverflowError:  # an integer literal beyond double's range
        return math.inf


def _number(v, what: str) -> float:
    """A finite JSON number (booleans are not numbers)."""
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        raise _Bad(f"{what}: expected a number, got {_kind(v)}")
    x = _float(v)
    if not math.isfinite(x):
        raise _Bad(f"{what}: not a finite number")
    return x


def _integer(v, what: str, lo: int, hi: int, macro: str = "") -> int:
    """A JSON number with an integral value (2048 or 2048.0) in [lo, hi]."""
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        raise _Bad(f"{what}: expected an integer, got {_kind(v)}")
    x = _float(v)
    if not math.isfinite(x):
        raise _Bad(f"{what}: not a finite number")
    if x != math.floor(x):
        raise _Bad(f"{what}: expected an integer, got {x:g}")
    if not lo <= x <= hi:
        raise _Bad(f"{what}: {x:g} is outside [{lo}, {hi}]" + (f" ({macro})" if macro else ""))
    return int(x)


def _name(v, what: str) -> str:
    if not isinstance(v, str):
        raise _Bad(f"{what}: expected a string, got {_kind(v)}")
    b = v.encode("utf-8", "surrogatepass")
    if not 1 <= len(b) <= 63 or any(c not in _NAME_BYTES for c in b):
        raise _Bad(f"{what}: {_NAME_RULE}")
    return v


def _distinct_rad(deg: np.ndarray) -> int:
    """Index of the first beam whose single-precision radians equal an earlier beam's, or -1."""
    rad = np.radians(deg).astype(np.float32)
    seen: dict = {}
    for i, r in enumerate(rad.tolist()):
        if r in seen:
            return i
        seen[r] = i
    return -1


def _elevations(v, what: str, max_rows: int) -> np.ndarray:
    """A beam elevation table in degrees: 1..max_rows finite numbers in (-90, 90), distinct in single precision
    radians (what the library compares)."""
    if not isinstance(v, list):
        raise _Bad(f"{what}: expected an array of numbers, got {_kind(v)}")
    if not 1 <= len(v) <= max_rows:
        raise _Bad(f"{what}: {len(v)} beams, outside [1, {max_rows}] (LIDET_MAX_ROWS)")
    deg = np.empty(len(v), np.float64)
    for i, e in enumerate(v):
        x = _number(e, f"{what}[{i}]")
        if not -90.0 < x < 90.0:
            raise _Bad(f"{what}[{i}]: {x:g} deg is outside (-90, 90)")
        deg[i] = x
    i = _distinct_rad(deg)
    if i >= 0:
        rad = np.radians(deg).astype(np.float32)
        j = int(np.flatnonzero(rad[:i] == rad[i])[0])
        raise _Bad(f"{what}[{i}]: the same elevation as [{j}] ({deg[i]:g} deg): beams must be distinct")
    return deg


def _read_json(path) -> object:
    p = pathlib.Path(path)
    try:
        data = p.read_bytes()
    except OSError as e:
        raise SensorFileError(f"{path}: cannot read: {e.strerror or e}") from None
    if len(data) > SENSOR_FILE_MAX_BYTES:
        raise SensorFileError(f"{path}: larger than {SENSOR_FILE_MAX_BYTES >> 20} MiB: not a sensor description")
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError:
        raise SensorFileError(f"{path}: not valid JSON (not UTF-8 text)") from None

    def pairs(kv):
        d = {}
        for k, val in kv:
            if k in d:
                raise _Duplicate(k)
            d[k] = val
        return d

    def constant(name):
        raise _Constant(name)

    try:
        return json.loads(text, object_pairs_hook=pairs, parse_constant=constant)
    except _Duplicate as e:
        raise SensorFileError(f'{path}: "{e.args[0]}": given twice') from None
    except _Constant as e:
        raise SensorFileError(f"{path}: not valid JSON ({e.args[0]} is not a JSON number)") from None
    except json.JSONDecodeError as e:
        raise SensorFileError(f"{path}: not valid JSON ({e.msg} at line {e.lineno} column {e.colno})") from None


def _read_object(path) -> dict:
    root = _read_json(path)
    if not isinstance(root, dict):
        raise SensorFileError(f"{path}: the file must hold one JSON object")
    return root


def _description(root: dict, max_rows: int, max_cols: int) -> Sensor:
    """Validates a version-1 description (the order of the checks is the C loader's)."""
    if "format" not in root or root["format"] != SENSOR_FILE_FORMAT:
        hint = ""
        if "beam_altitude_angles" in root or "beam_intrinsics" in root:
            hint = ": this looks like Ouster metadata, read it with --ouster-meta (load_ouster_metadata)"
        problem = "missing (expected \"lidet-sensor\")" if "format" not in root else "expected \"lidet-sensor\""
        raise _Bad(f'"format": {problem}{hint}')
    if "version" not in root:
        raise _Bad('"version": missing')
    version = _integer(root["version"], '"version"', 0, 1000000)
    if version != SENSOR_FILE_VERSION:
        raise _Bad(f'"version": {version} is not supported (this build reads version {SENSOR_FILE_VERSION})')
    for k in root:
        if k not in SENSOR_FILE_FIELDS:
            raise _Bad(f'"{k}": unknown field (known: {", ".join(SENSOR_FILE_FIELDS)})')
    for k in ("name", "cols"):
        if k not in root:
            raise _Bad(f'"{k}": missing')
    name = _name(root["name"], '"name"')
    cols = _integer(root["cols"], '"cols"', 8, max_cols, "LIDET_MAX_COLS")
    table = "beam_elevation_deg" in root
    if table and ("fov_up_deg" in root or "fov_down_deg" in root):
        raise _Bad('"beam_elevation_deg": give the beam table or "fov_up_deg", "fov_down_deg" and "rows", not both')
    fov = None
    if table:
        deg = _elevations(root["beam_elevation_deg"], '"beam_elevation_deg"', max_rows)
        if "rows" in root:
            rows = _integer(root["rows"], '"rows"', 1, max_rows, "LIDET_MAX_ROWS")
            if rows != len(deg):
                raise _Bad(f'"rows": {rows} does not match the {len(deg)} entries of "beam_elevation_deg"')
    else:
        if "fov_up_deg" not in root and "fov_down_deg" not in root:
            raise _Bad('"beam_elevation_deg": missing (or give "fov_up_deg", "fov_down_deg" and "rows")')
        for k in ("fov_up_deg", "fov_down_deg"):
            if k not in root:
                raise _Bad(f'"{k}": missing')
        if "rows" not in root:
            raise _Bad('"rows": missing (needed with "fov_up_deg" and "fov_down_deg")')
        edges = []
        for k in ("fov_up_deg", "fov_down_deg"):
            x = _number(root[k], f'"{k}"')
            if not -90.0 < x < 90.0:
                raise _Bad(f'"{k}": {x:g} deg is outside (-90, 90)')
            edges.append(x)
        up, down = edges
        if not up > down:
            raise _Bad(f'"fov_up_deg": {up:g} deg is not above "fov_down_deg" ({down:g} deg)')
        rows = _integer(root["rows"], '"rows"', 1, max_rows, "LIDET_MAX_ROWS")
        deg = up - (np.arange(rows) + 0.5) * ((up - down) / rows)  # uniform_beams, in degrees
        if _distinct_rad(deg) >= 0:
            raise _Bad(f'"rows": {rows} beams between "fov_down_deg" and "fov_up_deg" are not distinct '
                       "in single precision")
        fov = _urad_fov(up, down)
    for k in ("mount_height_m", "max_range_m"):
        if k not in root:
            raise _Bad(f'"{k}": missing')
    mount = _number(root["mount_height_m"], '"mount_height_m"')
    if not 0.0 <= mount <= 10.0:
        raise _Bad(f'"mount_height_m": {mount:g} is outside [0, 10]')
    max_range = _number(root["max_range_m"], '"max_range_m"')
    if not 0.0 < max_range <= 1000.0:
        raise _Bad(f'"max_range_m": {max_range:g} is outside (0, 1000]')
    model = _name(root["model"], '"model"') if "model" in root else None
    return Sensor(name, len(deg), cols, _deg(deg), mount, max_range, fov, model=model,
                  beam_elev_deg=deg if fov is None else None)


def load_sensor_file(path) -> Sensor:
    """A sensor from a lidet description file (JSON, docs/SENSORS.md): "format": "lidet-sensor", "version": 1,
    "name", "cols", "beam_elevation_deg" (ring order) or "fov_up_deg" + "fov_down_deg" + "rows",
    "mount_height_m", "max_range_m", optional "model" (the float model family; `model_family`). Rows and cols
    must fit the built library (`capacity_limits`). Raises SensorFileError naming the file and the field."""
    root = _read_object(path)
    max_rows, max_cols = capacity_limits()
    try:
        return _description(root, max_rows, max_cols)
    except _Bad as e:
        raise SensorFileError(f"{path}: {e}") from None


def _ouster_name(prod_line: str, rows: int) -> str:
    """lidet's name of an Ouster sensor: the product line in lower case, other characters as '-', at most 63
    bytes; "ouster-<rows>" without one."""
    out = bytearray()
    for c in prod_line.encode("utf-8", "surrogatepass")[:63]:
        c = c + 32 if 65 <= c <= 90 else c
        out.append(c if c in _NAME_BYTES else ord("-"))
    return out.decode("ascii") if out else f"ouster-{rows}"


#: where each field of Ouster's metadata lives: the sections of the nested layout (firmware 2.4 on), then the
#: top level (the older flat layout; 2.x files also nest columns under "data_format")
_OUSTER_SECTIONS = ("beam_intrinsics", "lidar_data_format", "data_format", "config_params", "sensor_info")
_OUSTER_MODE = re.compile(r"([0-9]{1,5})x([0-9]{1,3})")


def _ouster(root: dict, max_rows: int, max_cols: int, mount_height_m: float) -> Sensor:
    if root.get("format") == SENSOR_FILE_FORMAT:
        raise _Bad('"format": this is a lidet sensor description, read it with --sensor-file (load_sensor_file)')
    if "packet_hash" in root:
        raise _Bad('"packet_hash": this is an ouster-sdk packet digest (hashes of decoded fields), not sensor '
                   "metadata")
    for sec in _OUSTER_SECTIONS:
        if sec in root and not isinstance(root[sec], dict):
            raise _Bad(f'"{sec}": expected an object, got {_kind(root[sec])}')

    def find(sections, key):
        for sec in sections:
            if sec in root and key in root[sec]:
                return f"{sec}.{key}", root[sec][key]
        if key in root:
            return key, root[key]
        return None, None

    alt_f, alt = find(("beam_intrinsics",), "beam_altitude_angles")
    if alt_f is None:
        raise _Bad('"beam_altitude_angles": missing (neither in "beam_intrinsics" nor at the top level): '
                   "not Ouster sensor metadata?")
    deg = _elevations(alt, f'"{alt_f}"', max_rows)
    rows = len(deg)
    az_f, az = find(("beam_intrinsics",), "beam_azimuth_angles")
    az_rad = None
    if az_f is not None:
        if not isinstance(az, list):
            raise _Bad(f'"{az_f}": expected an array of numbers, got {_kind(az)}')
        if len(az) != rows:
            raise _Bad(f'"{az_f}": {len(az)} entries for {rows} beams')
        a = np.empty(rows, np.float64)
        for i, e in enumerate(az):
            x = _number(e, f'"{az_f}"[{i}]')
            if not -180.0 < x < 180.0:
                raise _Bad(f'"{az_f}"[{i}]: {x:g} deg is outside (-180, 180)')
            a[i] = x
        az_rad = np.radians(a)
    ppc_f, ppc = find(("lidar_data_format", "data_format"), "pixels_per_column")
    if ppc_f is not None:
        n = _integer(ppc, f'"{ppc_f}"', 1, 65535)
        if n != rows:
            raise _Bad(f'"{ppc_f}": {n} but "{alt_f}" has {rows} entries')
    cpf_f, cpf = find(("lidar_data_format", "data_format"), "columns_per_frame")
    mode_f, mode = find(("config_params",), "lidar_mode")
    cols = None
    if cpf_f is not None:
        cols = _integer(cpf, f'"{cpf_f}"', 8, max_cols, "LIDET_MAX_COLS")
    mode_cols = None
    if mode_f is not None:
        m = _OUSTER_MODE.fullmatch(mode) if isinstance(mode, str) else None
        if m is None:
            raise _Bad(f'"{mode_f}": expected "<columns>x<rate>" such as "1024x10"')
        mode_cols = int(m.group(1))
    if cols is None and mode_cols is None:
        raise _Bad('"lidar_mode": missing (and no "columns_per_frame")')
    if cols is not None and mode_cols is not None and cols != mode_cols:
        raise _Bad(f'"{mode_f}": {mode_cols} columns, but "{cpf_f}" is {cols}')
    if cols is None:
        if not 8 <= mode_cols <= max_cols:
            raise _Bad(f'"{mode_f}": {mode_cols} columns, outside [8, {max_cols}] (LIDET_MAX_COLS)')
        cols = mode_cols
    org_f, org = find(("beam_intrinsics",), "lidar_origin_to_beam_origin_mm")
    origin = _number(org, f'"{org_f}"') if org_f is not None else None
    prod_f, prod = find(("sensor_info",), "prod_line")
    name = f"ouster-{rows}"
    if prod_f is not None:
        if not isinstance(prod, str):
            raise _Bad(f'"{prod_f}": expected a string, got {_kind(prod)}')
        name = _ouster_name(prod, rows)
    return Sensor(name, rows, cols, _deg(deg), float(mount_height_m), OUSTER_MAX_RANGE_M, None,
                  beam_azimuth_rad=az_rad, beam_origin_mm=origin, beam_elev_deg=deg)


def load_ouster_metadata(path, mount_height_m: float | None = None) -> Sensor:
    """A sensor from Ouster's sensor metadata JSON (the flat layout of older firmware, the 2.x layout with
    "data_format", the nested one with "beam_intrinsics" / "lidar_data_format" / "config_params" /
    "sensor_info"): beam elevations from beam_altitude_angles in Ouster's ring order (top beam first), columns
    from columns_per_frame or the lidar mode ("1024x10"), the name from the product line. The mount height is
    not in Ouster's file: `mount_height_m` (metres, [0, 10]; default 1.0). The beam azimuth offsets and the
    beam-origin offset are read and validated (`Sensor.beam_azimuth_rad`, `Sensor.beam_origin_mm`): the projection
    does not use them; the Ouster packet decoder takes the azimuth offsets and `lidet_tools.ouster.xyz` both
    (docs/SENSORS.md). Raises SensorFileError naming the file and the field."""
    if mount_height_m is None:
        mount_height_m = OUSTER_MOUNT_HEIGHT_M
    elif isinstance(mount_height_m, bool) or not isinstance(mount_height_m, (int, float, np.number)) or \
            not 0.0 <= float(mount_height_m) <= 10.0:
        raise ValueError(f"mount_height_m must be metres in [0, 10], got {mount_height_m!r}")
    root = _read_object(path)
    max_rows, max_cols = capacity_limits()
    try:
        return _ouster(root, max_rows, max_cols, float(mount_height_m))
    except _Bad as e:
        raise SensorFileError(f"{path}: {e}") from None


# ---- a Sensor as a description (what `lidet ... --print-sensor` prints) -----------------------------------------

_DEG2RAD = math.pi / 180.0  # the C loaders' DEG2RAD_D (M_PI / 180), numpy's radians()


def _shortest_double(v: float) -> str:
    """The shortest of %.15g .. %.17g that reads back as v (cli_sensor.c: put_double)."""
    for p in (15, 16, 17):
        t = "%.*g" % (p, v)
        if float(t) == v:
            break
    return t


def _shortest_float32(v) -> str:
    """A single-precision value, the shortest of %.6g .. %.9g that reads back as it (put_float)."""
    f = np.float32(v)
    for p in range(6, 10):
        t = "%.*g" % (p, float(f))
        if np.float32(float(t)) == f:
            break
    return t


def _deg_of_float32(rad) -> str:
    """A single-precision angle in degrees, the shortest that a description turns back into it (put_deg_of)."""
    r = np.float32(rad)
    for p in range(6, 18):
        t = "%.*g" % (p, float(r) / _DEG2RAD)
        if np.float32(float(t) * _DEG2RAD) == r:
            break
    return t


def description_json(sensor: Sensor) -> str:
    """The sensor as a version-1 description (JSON text, docs/SENSORS.md), laid out as `lidet ... --print-sensor`
    prints it. A sensor read from a file (`beam_elev_deg` set: a description with a table, Ouster metadata, a
    Velodyne calibration) is written as read: each elevation, the mount height and the range as the shortest
    decimal that reads back as the same double, the model when it has one; the CLI prints the same text for the
    same file and options. Any other sensor (a preset, a uniform description) is written as its beam table: the
    shortest degrees that give back its single-precision radians, as the CLI prints a table preset (the CLI prints
    a uniform sensor as its field of view instead)."""
    from_file = sensor.beam_elev_deg is not None
    if from_file:
        elev = [_shortest_double(float(d)) for d in sensor.beam_elev_deg]
        mount, rng = _shortest_double(float(sensor.mount_height_m)), _shortest_double(float(sensor.max_range_m))
    else:
        elev = [_deg_of_float32(r) for r in np.asarray(sensor.beam_elev_rad, np.float32)]
        mount, rng = _shortest_float32(sensor.mount_height_m), _shortest_float32(sensor.max_range_m)
    table = "".join(("" if i == 0 else ",\n    " if i % 8 == 0 else ", ") + e for i, e in enumerate(elev))
    out = ('{\n  "format": "lidet-sensor",\n  "version": 1,\n'
           f'  "name": "{sensor.name}",\n  "cols": {int(sensor.cols)},\n'
           f'  "beam_elevation_deg": [{table}],\n'
           f'  "mount_height_m": {mount},\n  "max_range_m": {rng}')
    if from_file and sensor.model:
        out += f',\n  "model": "{sensor.model}"'
    return out + "\n}\n"


def write_sensor_file(sensor: Sensor, path) -> None:
    """Writes `description_json(sensor)` to path (read it back with load_sensor_file)."""
    pathlib.Path(path).write_text(description_json(sensor))


# ---- Velodyne calibrations (docs/VELODYNE_CALIBRATION.md) ----------------------------------------------------
# ports/host/cli_velodyne_calib.c reads them with libxml2 and libyaml by the same rules, in the same order, with
# the same messages (tests/python/test_velodyne_calib.py).

#: what a Velodyne calibration does not say: the mount height (overridable), the nominal range (informational)
VELODYNE_MOUNT_HEIGHT_M = 1.0
VELODYNE_MAX_RANGE_M = 100.0
#: the distance resolution when the file gives none (velodyne_pointcloud's default: 2 mm)
VELODYNE_DISTANCE_RESOLUTION_M = 0.002
#: a YAML calibration nested deeper than this is refused
_YAML_MAX_DEPTH = 32
#: the optional per-laser corrections: (db.xml element, its scale to metres, YAML key)
_VELODYNE_OPTIONAL = (("distCorrection_", 0.01, "dist_correction"), ("distCorrectionX_", 0.01, "dist_correction_x"),
                      ("distCorrectionY_", 0.01, "dist_correction_y"),
                      ("vertOffsetCorrection_", 0.01, "vert_offset_correction"),
                      ("horizOffsetCorrection_", 0.01, "horiz_offset_correction"),
                      ("focalDistance_", 0.01, "focal_distance"), ("focalSlope_", 1.0, "focal_slope"))
#: a number in a calibration: db.xml's element text (trimmed), a plain YAML scalar
_CAL_NUMBER = re.compile(r"[-+]?(?:\.[0-9]+|[0-9]+(?:\.[0-9]*)?)(?:[eE][-+]?[0-9]+)?")
_YAML_INF = re.compile(r"[-+]?\.(?:inf|Inf|INF)")
_YAML_NAN = re.compile(r"\.(?:nan|NaN|NAN)")


def velodyne_default_cols(n_lasers: int, max_cols: int | None = None) -> int:
    """Columns per revolution when the caller gives none: 2048 for 64 lasers (the hdl64 preset's, KITTI's HDL-64E),
    else 1800 (VLP-16, VLP-32C at 600 rpm: 0.2 deg a column; the presets' vlp16, vlp32c), at most LIDET_MAX_COLS."""
    if max_cols is None:
        max_cols = capacity_limits()[1]
    return min(2048 if n_lasers == 64 else 1800, max_cols)


def _xml_child(parent, tag: str, what: str):
    """The one child element named tag (None when absent); given twice is an error."""
    found = [c for c in parent if c.tag == tag]
    if len(found) > 1:
        raise _Bad(f"{what}: given twice")
    return found[0] if found else None


def _xml_number(el, what: str) -> float:
    """An element's text as a number: no child element, the text (XML white space trimmed) a decimal number."""
    t = None if len(el) else (el.text or "").strip(" \t\r\n")
    if t is None or not _CAL_NUMBER.fullmatch(t):
        raise _Bad(f"{what}: not a number")
    x = float(t)
    if not math.isfinite(x):
        raise _Bad(f"{what}: not a finite number")
    return x


def _xml_integer(el, what: str, lo: int, hi: int) -> int:
    x = _xml_number(el, what)
    if x != math.floor(x):
        raise _Bad(f"{what}: expected an integer, got {x:g}")
    if not lo <= x <= hi:
        raise _Bad(f"{what}: {x:g} is outside [{lo}, {hi}]")
    return int(x)


def _xml_items(parent, name: str) -> list:
    """The <item> children of a boost-serialized list; its <count>, when given, must say how many."""
    items = [c for c in parent if c.tag == "item"]
    c = _xml_child(parent, "count", f'"{name}.count"')
    if c is not None:
        k = _xml_integer(c, f'"{name}.count"', 0, 1000000)
        if k != len(items):
            raise _Bad(f'"{name}.count": {k} but "{name}" has {len(items)} items')
    return items


def _first_same_f32(rad: np.ndarray) -> tuple[int, int]:
    """(i, j): the first beam whose single-precision radians equal an earlier beam j's; (-1, -1) when none."""
    seen: dict = {}
    for i, r in enumerate(np.asarray(rad, np.float64).astype(np.float32).tolist()):
        if r in seen:
            return i, seen[r]
        seen[r] = i
    return -1, -1


def _velodyne_xml(data: bytes, max_rows: int) -> tuple:
    """db.xml / VeloView XML: (entry names, laser ids, elevations deg, rot corrections deg, optional (n x 7,
    metres), distance resolution m), in the file's order of the enabled lasers."""
    try:
        import defusedxml
        import defusedxml.ElementTree as det
    except ImportError as e:  # requirements.txt pins it
        raise ImportError("reading a Velodyne XML calibration needs defusedxml (pip install defusedxml)") from e
    try:
        root = det.fromstring(data)
    except det.ParseError as e:
        msg = re.sub(r": line [0-9]+, column [0-9]+$", "", str(e))
        raise _Bad(f"not valid XML (line {e.position[0]}: {msg})") from None
    except defusedxml.DefusedXmlException:
        raise _Bad("not valid XML for a calibration (entity declarations are refused)") from None
    db = root if root.tag == "DB" else _xml_child(root, "DB", '"DB"') if root.tag == "boost_serialization" else None
    if db is None:
        raise _Bad('"DB": missing (<boost_serialization><DB>...</DB>): not a Velodyne calibration (db.xml)?')
    res = VELODYNE_DISTANCE_RESOLUTION_M
    el = _xml_child(db, "distLSB_", '"distLSB_"')
    if el is not None:
        x = _xml_number(el, '"distLSB_"')
        if not 0.0 < x <= 100.0:
            raise _Bad(f'"distLSB_": {x:g} is outside (0, 100] (centimetres)')
        res = x * 0.01
    enabled = None
    en = _xml_child(db, "enabled_", '"enabled_"')
    if en is not None:
        enabled = []
        for i, it in enumerate(_xml_items(en, "enabled_")):
            x = _xml_number(it, f'"enabled_"[{i}]')
            if x != 0.0 and x != 1.0:
                raise _Bad(f'"enabled_"[{i}]: expected 0 or 1, got {x:g}')
            enabled.append(x == 1.0)
    pts = _xml_child(db, "points_", '"points_"')
    if pts is None:
        raise _Bad('"points_": missing: not a Velodyne calibration (db.xml)?')
    items = _xml_items(pts, "points_")
    n = sum(enabled) if enabled is not None else len(items)
    if not 1 <= n <= max_rows:
        where = f'"enabled_": {n} lasers enabled' if enabled is not None else f'"points_": {n} lasers'
        raise _Bad(f"{where}, outside [1, {max_rows}] (LIDET_MAX_ROWS)")
    id_hi = (len(enabled) if enabled is not None else len(items)) - 1
    seen: dict = {}
    names, ids, vert, rot, opt = [], [], [], [], []
    for k, it in enumerate(items):
        w = f'"points_"[{k}]'
        px = _xml_child(it, "px", f"{w}.px")
        if px is None:
            raise _Bad(f'{w}: no "px"')
        el = _xml_child(px, "id_", f"{w}.id_")
        if el is None:
            raise _Bad(f"{w}.id_: missing")
        lid = _xml_integer(el, f"{w}.id_", 0, id_hi)
        if lid in seen:
            raise _Bad(f'{w}.id_: {lid} given twice (also "points_"[{seen[lid]}])')
        seen[lid] = k
        if enabled is not None and not enabled[lid]:
            continue  # a laser the unit does not have (db.xml lists 64)
        vals = []
        for tag, lim in (("vertCorrection_", 90.0), ("rotCorrection_", 180.0)):
            el = _xml_child(px, tag, f"{w}.{tag}")
            if el is None:
                raise _Bad(f"{w}.{tag}: missing")
            x = _xml_number(el, f"{w}.{tag}")
            if not -lim < x < lim:
                raise _Bad(f"{w}.{tag}: {x:g} deg is outside ({-lim:g}, {lim:g})")
            vals.append(x)
        o = []
        for tag, scale, _ in _VELODYNE_OPTIONAL:
            el = _xml_child(px, tag, f"{w}.{tag}")
            o.append(_xml_number(el, f"{w}.{tag}") * scale if el is not None else 0.0)
        names.append(w)
        ids.append(lid)
        vert.append(vals[0])
        rot.append(vals[1])
        opt.append(o)
    if enabled is not None:
        for i, e in enumerate(enabled):
            if e and i not in seen:
                raise _Bad(f'"enabled_"[{i}]: laser {i} is enabled, but "points_" has no px with id_ {i}')
    deg = np.array(vert, np.float64)
    i, j = _first_same_f32(np.radians(deg))
    if i >= 0:
        raise _Bad(f"{names[i]}.vertCorrection_: the same elevation as {names[j]} ({deg[i]:g} deg): beams must be "
                   "distinct")
    return ids, deg, np.radians(deg), np.radians(np.array(rot, np.float64)), np.array(opt, np.float64), res


def _yaml_value(raw: str, plain: bool):
    """A YAML scalar as lidet reads it (the C loader's rule, whatever the tags say): quoted, literal or folded: a
    string; plain: null (empty, ~, null), a boolean (true, false), a decimal number, .inf / .nan, else a string."""
    if not plain:
        return raw
    if raw in ("", "~", "null", "Null", "NULL"):
        return None
    if raw in ("true", "True", "TRUE"):
        return True
    if raw in ("false", "False", "FALSE"):
        return False
    if _CAL_NUMBER.fullmatch(raw):
        return float(raw)
    if _YAML_INF.fullmatch(raw):
        return -math.inf if raw[0] == "-" else math.inf
    if _YAML_NAN.fullmatch(raw):
        return math.nan
    return raw


def _yaml_path(parent: str, key) -> str:
    """The name of a member in messages: "key" at the top, parent.key below, parent[i] in a list."""
    if isinstance(key, int):
        return f"{parent}[{key}]"
    return f'"{key}"' if parent == "" else f"{parent}.{key}"


def _yaml_tree(data: bytes):
    """The YAML document as dicts, lists and scalars (`_yaml_value`), built from the parser's events as the C
    loader builds its tree: one document; aliases, non-scalar keys, a key given twice and nesting deeper than
    _YAML_MAX_DEPTH are refused."""
    try:
        import yaml
    except ImportError as e:  # requirements.txt pins it
        raise ImportError("reading a Velodyne YAML calibration needs PyYAML (pip install pyyaml)") from e
    loader = getattr(yaml, "CSafeLoader", None) or yaml.SafeLoader  # CSafeLoader: libyaml, as the CLI
    root = None
    docs = 0
    stack: list = []  # [container, its path, the key waiting for its value (mappings)]

    def put(value, raw, line):
        nonlocal root
        if not stack:
            root = value
            return
        top = stack[-1]
        c = top[0]
        if isinstance(c, list):
            c.append(value)
        elif top[2] is None:
            if raw is None:
                raise _Bad(f"a mapping key must be a scalar (line {line})")
            if raw in c:
                raise _Bad(f"{_yaml_path(top[1], raw)}: given twice")
            top[2] = raw
            c[raw] = None
        else:
            c[top[2]] = value
            top[2] = None

    try:
        for ev in yaml.parse(data, Loader=loader):
            line = ev.start_mark.line + 1 if ev.start_mark is not None else 0
            if isinstance(ev, yaml.DocumentStartEvent):
                docs += 1
                if docs > 1:
                    raise _Bad("the file must hold one YAML document")
            elif isinstance(ev, yaml.AliasEvent):
                raise _Bad(f"YAML aliases are not supported (line {line})")
            elif isinstance(ev, yaml.ScalarEvent):
                put(_yaml_value(ev.value, ev.style in (None, "")), ev.value, line)
            elif isinstance(ev, (yaml.SequenceStartEvent, yaml.MappingStartEvent)):
                if len(stack) >= _YAML_MAX_DEPTH:
                    raise _Bad(f"nested deeper than {_YAML_MAX_DEPTH} levels (line {line})")
                c = [] if isinstance(ev, yaml.SequenceStartEvent) else {}
                if stack:
                    top = stack[-1]
                    path = _yaml_path(top[1], len(top[0]) if isinstance(top[0], list) else top[2])
                else:
                    path = ""
                put(c, None, line)
                stack.append([c, path, None])
            elif isinstance(ev, (yaml.SequenceEndEvent, yaml.MappingEndEvent)):
                stack.pop()
    except yaml.reader.ReaderError as e:
        raise _Bad(f"not valid YAML (byte {e.position}: {e.reason})") from None
    except yaml.MarkedYAMLError as e:
        m = e.problem_mark
        where = f"line {m.line + 1} column {m.column + 1}: " if m is not None else ""
        raise _Bad(f"not valid YAML ({where}{e.problem})") from None
    except yaml.YAMLError as e:
        raise _Bad(f"not valid YAML ({e})") from None
    return root


def _ynumber(v, what: str) -> float:
    if isinstance(v, bool) or not isinstance(v, float):
        raise _Bad(f"{what}: expected a number, got {_kind(v, yaml=True)}")
    if not math.isfinite(v):
        raise _Bad(f"{what}: not a finite number")
    return v


def _yinteger(v, what: str, lo: int, hi: int, macro: str = "") -> int:
    if isinstance(v, bool) or not isinstance(v, float):
        raise _Bad(f"{what}: expected an integer, got {_kind(v, yaml=True)}")
    if not math.isfinite(v):
        raise _Bad(f"{what}: not a finite number")
    if v != math.floor(v):
        raise _Bad(f"{what}: expected an integer, got {v:g}")
    if not lo <= v <= hi:
        raise _Bad(f"{what}: {v:g} is outside [{lo}, {hi}]" + (f" ({macro})" if macro else ""))
    return int(v)


def _velodyne_yaml(data: bytes, max_rows: int) -> tuple:
    """velodyne_pointcloud's YAML: the same tuple as _velodyne_xml (elevations in degrees = radians x 180 / pi)."""
    root = _yaml_tree(data)
    if not isinstance(root, dict):
        raise _Bad("the file must hold one YAML mapping")
    if "lasers" not in root:
        raise _Bad('"lasers": missing: not a velodyne_pointcloud calibration?')
    lasers = root["lasers"]
    if not isinstance(lasers, list):
        raise _Bad(f'"lasers": expected a list, got {_kind(lasers, yaml=True)}')
    if "num_lasers" not in root:
        raise _Bad('"num_lasers": missing')
    n = _yinteger(root["num_lasers"], '"num_lasers"', 1, max_rows, "LIDET_MAX_ROWS")
    if len(lasers) != n:
        raise _Bad(f'"num_lasers": {n} but "lasers" has {len(lasers)} entries')
    res = VELODYNE_DISTANCE_RESOLUTION_M
    if "distance_resolution" in root:
        res = _ynumber(root["distance_resolution"], '"distance_resolution"')
        if not 0.0 < res <= 1.0:
            raise _Bad(f'"distance_resolution": {res:g} is outside (0, 1] (metres)')
    seen: dict = {}
    names, ids, vert, rot, opt = [], [], [], [], []
    for i, las in enumerate(lasers):
        w = f'"lasers"[{i}]'
        if not isinstance(las, dict):
            raise _Bad(f"{w}: expected a mapping, got {_kind(las, yaml=True)}")
        if "laser_id" not in las:
            raise _Bad(f"{w}.laser_id: missing")
        lid = _yinteger(las["laser_id"], f"{w}.laser_id", 0, n - 1)
        if lid in seen:
            raise _Bad(f'{w}.laser_id: {lid} given twice (also "lasers"[{seen[lid]}])')
        seen[lid] = i
        vals = []
        for key, lim in (("vert_correction", 90.0), ("rot_correction", 180.0)):
            if key not in las:
                raise _Bad(f"{w}.{key}: missing")
            x = _ynumber(las[key], f"{w}.{key}")
            d = x * (180.0 / math.pi)
            if not -lim < d < lim:
                raise _Bad(f"{w}.{key}: {x:g} rad ({d:g} deg) is outside ({-lim:g}, {lim:g}) deg")
            vals.append(x)
        opt.append([_ynumber(las[key], f"{w}.{key}") if key in las else 0.0 for _, _, key in _VELODYNE_OPTIONAL])
        names.append(w)
        ids.append(lid)
        vert.append(vals[0])
        rot.append(vals[1])
    rad = np.array(vert, np.float64)
    i, j = _first_same_f32(rad)
    if i >= 0:
        raise _Bad(f"{names[i]}.vert_correction: the same elevation as {names[j]} ({rad[i]:g} rad): beams must be "
                   "distinct")
    deg = np.array([x * (180.0 / math.pi) for x in vert], np.float64)
    return ids, deg, rad, np.array(rot, np.float64), np.array(opt, np.float64), res


def velodyne_calibration_kind(data: bytes) -> str:
    """"xml" when the first character after a UTF-8 byte-order mark and white space is '<', else "yaml"."""
    i = 3 if data.startswith(b"\xef\xbb\xbf") else 0
    while i < len(data) and data[i] in b" \t\r\n":
        i += 1
    return "xml" if i < len(data) and data[i] == ord("<") else "yaml"


def load_velodyne_calibration(path, mount_height_m: float | None = None, cols: int | None = None,
                              name: str | None = None) -> Sensor:
    """A sensor from a Velodyne calibration file (docs/VELODYNE_CALIBRATION.md): the db.xml / VeloView XML
    (boost-serialized <DB>: points_ / item / px with id_, vertCorrection_, rotCorrection_ in degrees, the other
    corrections in cm; enabled_, distLSB_) or velodyne_pointcloud's YAML (num_lasers, lasers: laser_id,
    vert_correction, rot_correction in radians, the other corrections in metres; distance_resolution), told apart by
    the first character ('<': XML).

    The elevation table is in **ring order**: the lasers sorted by elevation, lowest first, as velodyne_pointcloud
    numbers its rings and as lidet's Velodyne decoder and presets do (ring 0 = the lowest beam), whatever the
    file's laser order (a VLP-16's lasers alternate -15, +1, -13, +3 ... deg). `Sensor.velodyne.laser_id` gives
    each ring's laser; `Sensor.beam_azimuth_rad` its rot_correction, `Sensor.velodyne` the other corrections: read
    and validated; the packet decoder takes the rotational and distance corrections (velodyne.calibration_table,
    `lidet ... --pcap --velodyne-calib`), the projection the elevations only.

    mount_height_m: metres in [0, 10] (default 1.0: not in the file). cols: columns per revolution, an integer in
    [8, LIDET_MAX_COLS] (default `velodyne_default_cols`: 1800, or 2048 for 64 lasers). name: the sensor's name
    (default "velodyne-<lasers>"). The model family follows `model_family` (vlp16 below 32 lasers, else hdl64).
    Raises SensorFileError naming the file and the field; ValueError for a bad argument."""
    max_rows, max_cols = capacity_limits()
    if mount_height_m is None:
        mount_height_m = VELODYNE_MOUNT_HEIGHT_M
    elif isinstance(mount_height_m, bool) or not isinstance(mount_height_m, (int, float, np.number)) or \
            not 0.0 <= float(mount_height_m) <= 10.0:
        raise ValueError(f"mount_height_m must be metres in [0, 10], got {mount_height_m!r}")
    if cols is not None and (isinstance(cols, bool) or not isinstance(cols, (int, np.integer)) or
                             not 8 <= int(cols) <= max_cols):
        raise ValueError(f"cols must be an integer in [8, {max_cols}] (LIDET_MAX_COLS), got {cols!r}")
    if name is not None:
        try:
            _name(name, "name")
        except _Bad as e:
            raise ValueError(str(e)) from None
    p = pathlib.Path(path)
    try:
        data = p.read_bytes()
    except OSError as e:
        raise SensorFileError(f"{path}: cannot read: {e.strerror or e}") from None
    if len(data) > SENSOR_FILE_MAX_BYTES:
        raise SensorFileError(f"{path}: larger than {SENSOR_FILE_MAX_BYTES >> 20} MiB: not a Velodyne calibration")
    kind = velodyne_calibration_kind(data)
    try:
        ids, deg, rad, rot, opt, res = (_velodyne_xml if kind == "xml" else _velodyne_yaml)(data, max_rows)
    except _Bad as e:
        raise SensorFileError(f"{path}: {e}") from None
    n = len(ids)
    order = np.argsort(rad, kind="stable")  # ring order: lowest beam first (distinct, so any sort agrees)
    ring = lambda a: np.ascontiguousarray(np.asarray(a)[order])  # noqa: E731
    corr = VelodyneCorrections(kind, ring(np.array(ids, np.int32)), *(ring(opt[:, k]) for k in range(7)),
                               distance_resolution_m=float(res))
    return Sensor(name or f"velodyne-{n}", n, int(cols) if cols is not None else velodyne_default_cols(n, max_cols),
                  ring(rad), float(mount_height_m), VELODYNE_MAX_RANGE_M, None, beam_azimuth_rad=ring(rot),
                  beam_elev_deg=ring(deg), velodyne=corr)
