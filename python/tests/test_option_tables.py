# SPDX-License-Identifier: BSD-3-Clause
"""One option table per options struct (docs/design.md, "Options"): the
command line's flags, their ranges, the YAML keys and the Python keywords
are the table's, and no interface has an option the others lack."""
import os
import re
import subprocess

import pytest

import radargauss as rg

CLI = os.environ.get("RADARGAUSS_CLI")
FLAG = re.compile(r"^\s+(--[a-z0-9-]+)(?: ([A-Z]+:(?:\{[^}]*\}|[\[(][^\])]*[\])])))?")
# What each command reads and writes besides its options: the run's inputs and outputs.
RUN_FLAGS = {"--help", "--sequence", "--gt", "--extrinsic", "--bag", "--topic", "--bin-layout", "--rcs-field",
             "--doppler-field", "--doppler-sign", "--elevation-bias", "--out", "--first-scan", "--max-scans", "--mcap"}
IMU_FLAGS = {"--imu", "--imu-extrinsic", "--imu-topic", "--imu-stamps", "--imu-rotation"}
# command, the option tables its flags come from, its own flags.
COMMANDS = [("odometry", ("odometry", "radar_inertial"), {"--matcher", "--rig"} | IMU_FLAGS),
            ("slam", ("slam", "radar_inertial"), {"--no-map", "--map-tiles", "--false-loop-rate", "--false-loop-seed", "--rig"}
             | IMU_FLAGS),
            ("relocalize", ("relocalization",), {"--map", "--w-rcs-from-map", "--rig"})]

pytestmark = pytest.mark.skipif(not CLI, reason="RADARGAUSS_CLI names no command-line tool")


def help_flags(command, which="--help-all"):
    """flag -> its type and range as --help prints them ("FLOAT:[0, 1]", "" for a flag without a value)."""
    text = subprocess.run([CLI, command, which], capture_output=True, text=True, check=True).stdout
    flags = {}
    for line in text.splitlines():
        match = FLAG.match(line)
        if match:
            flags[match.group(1)] = match.group(2) or ""
    return flags


def flag_of(field):
    return "--" + field["keyword"].replace("_", "-")


def fields_of(kinds):
    return [field for kind in kinds for field in rg.option_fields(kind)]


def listed_elsewhere(command, table, flags):
    """The table's flags that `command --help-all` leaves to `odometry --help-all`: the front end's
    tuning and the --verify-X whose default is --X's (slam and relocalize)."""
    if command not in ("slam", "relocalize"):
        return set()
    odometry = set(help_flags("odometry"))
    return {flag for flag in table - set(flags)
            if flag in odometry or (flag.startswith("--verify-") and "--" + flag[len("--verify-"):] in table)}


@pytest.mark.parametrize("command, kind, own", COMMANDS)
def test_the_flags_are_the_table(command, kind, own):
    flags = help_flags(command)
    fields = fields_of(kind)
    table = {flag_of(field) for field in fields}
    elsewhere = listed_elsewhere(command, table, flags)
    assert set(flags) - RUN_FLAGS - own == table - elsewhere
    if command == "slam":
        assert len(flags) <= 150 and "--verify-max-iterations" in elsewhere and "--verify-solver" in flags
    for field in fields:
        if field["type"] == "bool" or flag_of(field) in elsewhere:
            continue
        kind_text = "TEXT" if field["type"].startswith("{") else "INT" if field["type"] == "int" else "FLOAT"
        assert flags[flag_of(field)] == kind_text + ":" + field["range"], field["keyword"]


def test_localize_sweeps_table_rows_and_refine_reads_its_table():
    """localize: every row of the match's and the matching map's tables is a flag, the solver, the weight
    and the loss lists (sweeps) checked per element by their rows; refine: the joint refinement's table."""
    localize = subprocess.run([CLI, "localize", "--help-all"], capture_output=True, text=True, check=True).stdout
    flags = help_flags("localize")
    for field in fields_of(("match", "matching_map")):
        assert flag_of(field) in flags, field["keyword"]
    assert "--w-rcs FLOAT:[0, 1]...=0,0.25,1" in localize and "--loss TEXT:{trivial," in localize
    refine = set(help_flags("refine"))
    table = {flag_of(field) for field in rg.option_fields("joint_refinement")}
    assert table <= refine and "--gate" in table and "--max-iterations" not in table
    assert refine - table <= RUN_FLAGS | {"--poses", "--map"}


@pytest.mark.parametrize("command, kind, own", COMMANDS)
def test_help_shows_the_sensor_group_and_help_all_the_rest(command, kind, own):
    shown = set(help_flags(command, "--help"))
    groups = {flag_of(field): field["group"] for field in fields_of(kind)}
    assert {flag for flag, group in groups.items() if group == "sensor"} <= shown
    assert not {flag for flag, group in groups.items() if group != "sensor"} & shown
    lines = subprocess.run([CLI, command, "--help"], capture_output=True, text=True, check=True).stdout.splitlines()
    assert len(lines) <= 50, "%s --help has %d lines, more than a screen" % (command, len(lines))


def yaml_value(field):
    value = field["default"]
    if field["type"].startswith("array"):
        return "[0, 0, 0, 0, 0, 0, 1]"
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, list):
        return "[" + ", ".join(repr(x) for x in value) + "]"
    return str(value)


@pytest.mark.parametrize("command, kind, own", COMMANDS)
def test_every_keyword_is_a_yaml_key(command, kind, own, tmp_path):
    config = tmp_path / "every.yaml"
    config.write_text("".join(flag_of(f)[2:] + ": " + yaml_value(f) + "\n" for f in fields_of(kind)))
    inputs = ["--sequence", str(tmp_path / "absent"), "--out", str(tmp_path / "out")]
    if command == "relocalize":
        inputs += ["--map", str(tmp_path / "absent.rgm")]
    run = subprocess.run([CLI, command, "--config", str(config)] + inputs, capture_output=True, text=True)
    assert run.returncode != 0 and "absent" in run.stderr, run.stderr
    assert "unknown flag" not in run.stderr and "is not" not in run.stderr


def test_a_range_and_a_pair_are_checked_alike_in_python_and_on_the_command_line(tmp_path):
    with pytest.raises(ValueError, match=r"region_capacity \(6\) must be at least region_min_points \(8\)"):
        rg.odometry_options(region_capacity=6)
    run = subprocess.run([CLI, "odometry", "--region-capacity", "6", "--sequence", str(tmp_path), "--out",
                          str(tmp_path / "o")], capture_output=True, text=True)
    assert "--region-capacity (6) must be at least --region-min-points (8)" in run.stderr
    with pytest.raises(ValueError, match=r"w_rcs = 2 is not in \[0, 1\]"):
        rg.odometry_options(w_rcs=2.0)
    run = subprocess.run([CLI, "odometry", "--w-rcs", "2", "--sequence", str(tmp_path), "--out", str(tmp_path / "o")],
                         capture_output=True, text=True)
    assert "--w-rcs: 2 is not in [0, 1]" in run.stderr
