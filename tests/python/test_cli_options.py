# SPDX-License-Identifier: MIT
"""How the host tools read their options (ports/host/cli_options.c: getopt_long over option sets): options before
or after the positional arguments give the same run, --name=VALUE is --name VALUE, "--" ends the options, and an
unknown option, an abbreviation, a value missing at the end or a value given to a flag is an error naming the
option (exit status 1, nothing on stdout)."""
import json
import pathlib
import re
import shutil
import subprocess

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
SIM = ROOT / "tests" / "data" / "sim_hdl64"
SCAN = SIM / "velodyne" / "000000.bin"
V16 = ROOT / "tests" / "data" / "sim_vlp16"
COMMANDS = ("project", "ground", "cluster", "detect", "track")


def _run(cli, *args):
    return subprocess.run([str(cli), *map(str, args)], capture_output=True, text=True)


def _untimed(stdout):
    """A --json object without its times (the only fields that differ from run to run)."""
    js = json.loads(stdout)
    return {k: v for k, v in js.items() if not k.endswith("_ms")}


def _error(r, *want):
    assert r.returncode == 1 and r.stdout == "", (r.returncode, r.stdout, r.stderr)
    for w in want:
        assert w in r.stderr, (w, r.stderr)
    assert "usage:" not in r.stderr  # one line naming the problem, not the whole usage


@pytest.mark.parametrize("cmd", COMMANDS)
def test_unknown_option_is_named(cli, cmd):
    for args in ([SCAN, "--frobnicate"], ["--frobnicate", SCAN], [SCAN, "--json", "--frobnicate=3"]):
        bad = args[-1] if args[0] == SCAN else args[0]
        _error(_run(cli, cmd, *args), f"lidet {cmd}: unknown option {bad}", f"lidet {cmd} --help")
    # abbreviations are not taken (--sens: --sensor or --sensor-file; --sensor-f: one of them, still refused)
    for abbrev in ("--sens", "--sensor-f", "--jso"):
        _error(_run(cli, cmd, SCAN, abbrev, "x"), f"unknown option {abbrev}")
    _error(_run(cli, cmd, SCAN, "-x"), "unknown option -x")


@pytest.mark.parametrize("cmd, opt, what", [
    ("project", "--sensor", "NAME"), ("ground", "--set", "KEY=VALUE"), ("cluster", "--labels", "FILE"),
    ("detect", "--model", "NAME"), ("detect", "--calib", "FILE"), ("detect", "--pcap", "FILE"),
    ("detect", "--cols", "N"), ("track", "--ego", "FILE, or none"), ("track", "--out", "DIR"),
    ("track", "--mount-height", "M"),
])
def test_missing_value_at_the_end(cli, cmd, opt, what):
    _error(_run(cli, cmd, SCAN, opt), f"lidet {cmd}: {opt} needs a value ({what}")


def test_flag_given_a_value(cli):
    _error(_run(cli, "detect", SCAN, "--json=1"), "--json takes no value")
    _error(_run(cli, "track", SCAN, "--fixed=yes"), "--fixed takes no value")


def test_bad_values_say_what_was_expected(cli):
    for args, want in [(["--repeat", "0"], "--repeat needs an integer in [1, 100000], got '0'"),
                       (["--repeat=x"], "got 'x'"),
                       (["--mount-height=-1"], "--mount-height needs metres in [0, 10], got '-1'")]:
        _error(_run(cli, "detect", SCAN, *args), want)


def test_options_before_and_after_the_scan(cli, tmp_path):
    """The same run whatever the order: the box lines, the --dump bytes and the JSON (times aside)."""
    opts = ["--sensor", "hdl64", "--set", "min_score.car=0.5", "--json"]
    outs = []
    for k, args in enumerate(([SCAN, *opts], [*opts, SCAN], ["--sensor", "hdl64", SCAN, "--set", "min_score.car=0.5", "--json"])):
        r = _run(cli, "detect", *args, "--out", tmp_path / f"b{k}.txt", "--dump", tmp_path / f"d{k}.bin")
        assert r.returncode == 0, r.stderr
        outs.append((_untimed(r.stdout), (tmp_path / f"b{k}.txt").read_bytes(), (tmp_path / f"d{k}.bin").read_bytes()))
    assert outs[0] == outs[1] == outs[2] and outs[0][1] != b""
    # the scan-only stages and --fixed alike
    for cmd, extra in (("project", []), ("ground", []), ("cluster", []), ("detect", ["--fixed"])):
        a = _run(cli, cmd, SCAN, "--json", *extra, "--out", tmp_path / "a.bin")
        b = _run(cli, cmd, "--out", tmp_path / "b.bin", *extra, "--json", SCAN)
        assert a.returncode == b.returncode == 0, (a.stderr, b.stderr)
        assert _untimed(a.stdout) == _untimed(b.stdout), cmd
        assert (tmp_path / "a.bin").read_bytes() == (tmp_path / "b.bin").read_bytes(), cmd


def test_track_options_before_and_after_the_scans(cli, tmp_path):
    """lidet track: options before, between and after the scans (and a folder) give the same lines."""
    seq = tmp_path / "seq" / "velodyne"
    seq.mkdir(parents=True)
    for k in range(3):
        shutil.copy(SCAN, seq / f"{k:06d}.bin")
    scans = sorted(seq.glob("*.bin"))
    runs = [
        _run(cli, "track", *scans, "--rate", "5", "--fixed", "--tentative"),
        _run(cli, "track", "--rate", "5", "--fixed", "--tentative", *scans),
        _run(cli, "track", scans[0], "--rate=5", scans[1], "--fixed", scans[2], "--tentative"),
        _run(cli, "track", "--fixed", seq.parent, "--rate", "5", "--tentative"),
    ]
    for r in runs:
        assert r.returncode == 0, r.stderr
    out = [re.sub(r"[0-9.]+ ms", "- ms", r.stdout) for r in runs]  # the scan headers' times
    assert out[0] == out[1] == out[2] == out[3] and len(out[0].splitlines()) > 6


def test_equals_form(cli, tmp_path):
    """--name=VALUE is --name VALUE, for every kind of value (a preset, a file, a number, a KEY=VALUE)."""
    scan, ring = V16 / "velodyne" / "000000.bin", V16 / "ring" / "000000.bin"
    spaced = _run(cli, "detect", scan, "--sensor", "vlp16", "--ring", ring, "--mount-height", "0.6", "--set",
                  "nms_iou=0.2", "--json", "--out", tmp_path / "a.txt")
    joined = _run(cli, "detect", scan, "--sensor=vlp16", f"--ring={ring}", "--mount-height=0.6", "--set=nms_iou=0.2",
                  "--json", f"--out={tmp_path / 'b.txt'}")
    assert spaced.returncode == joined.returncode == 0, (spaced.stderr, joined.stderr)
    assert _untimed(spaced.stdout) == _untimed(joined.stdout)
    assert (tmp_path / "a.txt").read_text() == (tmp_path / "b.txt").read_text() != ""
    js = _untimed(joined.stdout)
    assert js["sensor"] == "vlp16" and js["points"] > 0
    # a value is the next argument, whatever it looks like: --out takes "--json" as its file name
    r = subprocess.run([str(cli), "project", str(SCAN), "--out", "--json"], capture_output=True, text=True,
                       cwd=tmp_path)
    assert r.returncode == 0 and r.stdout.startswith("scan ") and (tmp_path / "--json").stat().st_size > 0


def test_double_dash_ends_the_options(cli, tmp_path):
    odd = tmp_path / "-odd.bin"
    shutil.copy(SCAN, odd)
    r = _run(cli, "project", "--json", "--", odd.name)
    assert r.returncode == 1 and "cannot open scan '-odd.bin'" in r.stderr  # a file name, not an option
    r = subprocess.run([str(cli), "project", "--json", "--", odd.name], capture_output=True, text=True, cwd=tmp_path)
    assert r.returncode == 0 and json.loads(r.stdout)["points"] > 0, r.stderr
    _error(subprocess.run([str(cli), "project", odd.name], capture_output=True, text=True, cwd=tmp_path),
           "unknown option -odd.bin")


def test_help_and_positional_errors_keep_their_statuses(cli):
    for cmd in COMMANDS:
        r = _run(cli, cmd, "--help")
        assert r.returncode == 1 and "usage: lidet" in r.stderr and r.stdout == "", cmd
        assert "--name=VALUE" in r.stderr, cmd
    r = _run(cli, "detect", SCAN, SCAN)
    _error(r, "lidet detect: unexpected argument")
    r = _run(cli, "detect", "--print-sensor", "--sensor=vlp16")
    assert r.returncode == 0 and json.loads(r.stdout)["format"] == "lidet-sensor"


def test_bench_tools_read_options_alike(cli, tmp_path):
    """lidet_bench_proj and lidet_bench_memory: options anywhere, clear errors."""
    bench_proj, bench_mem = cli.parent / "lidet_bench_proj", cli.parent / "lidet_bench_memory"
    if not bench_proj.exists() or not bench_mem.exists():
        pytest.skip("benchmarks not built")
    scan = V16 / "velodyne" / "000000.bin"
    r = _run(bench_proj, scan, "--sensor=vlp16", "--repeat", "1", "--clock", "cpu")
    assert r.returncode == 0 and json.loads(r.stdout.splitlines()[-1])["scans"] == 1, r.stderr
    for args, want in [(["--clock", "gpu"], "--clock wall or cpu, not 'gpu'"), (["--repeat", "0"], "--repeat needs"),
                       (["--frob"], "unknown option --frob"), (["--sensor"], "--sensor needs a value")]:
        r = _run(bench_proj, scan, *args)
        assert r.returncode == 1 and want in r.stderr and r.stdout == "", (args, r.stderr)
    r = _run(bench_mem, scan, "--sensor", "vlp16", "--repeat=1", "--only", "workspace")
    assert r.returncode == 0 and json.loads(r.stdout)["points"] > 0, r.stderr
    for args, want in [(["--only", "both"], "--only stages or --only workspace"), (["--frob"], "unknown option")]:
        r = _run(bench_mem, scan, "--sensor", "vlp16", *args)
        assert r.returncode == 2 and want in r.stderr and r.stdout == "", (args, r.stderr)
