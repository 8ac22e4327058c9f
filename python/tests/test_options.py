# SPDX-License-Identifier: BSD-3-Clause
"""The option keywords of match, RadarOdometry, RadarSlam and Relocalizer
against the C++ headers (every field of the options structs is a keyword,
but those the code sets, and round-trips), the
docstrings' name lists against the library's name tables, pose matrices
against quaternions by hand, and the stubs against the module."""
import ast
import pathlib
import re
import subprocess
import sys

import numpy as np
import pytest

import radargauss as rg

ROOT = pathlib.Path(__file__).resolve().parents[2]
STRUCT = re.compile(r"^struct (\w+) \{\n(.*?)^\};", re.M | re.S)
FIELD = re.compile(r"^  ([A-Za-z_][\w:]*(?:<[\w:, ]+>)?) ([a-z_][a-z0-9_]*)\s*(?:=[^;]*|\{[^;]*\})?;", re.M)


def cpp_structs():
    """Every struct of the public headers: name -> [(type, field)]."""
    structs = {}
    for folder in ("include", "solvers", "residuals"):
        for header in (ROOT / folder).rglob("*.hpp"):
            for name, body in STRUCT.findall(header.read_text()):
                structs[name] = [(t, f) for t, f in FIELD.findall(body) if t not in ("return", "using")]
    return structs


def leaf_paths(structs, name, prefix=""):
    for kind, field in structs[name]:
        inner = kind.split("::")[-1]
        if inner in structs:
            yield from leaf_paths(structs, inner, prefix + field + ".")
        else:
            yield prefix + field


# Members the code sets, not the user: the local map's matching map is
# always updatable, and the loop's match is geometric.
SET_BY_THE_CODE = {"map.matching.updatable", "verification.match.matching.w_rcs",
                   "verification.match.matching.rcs_loss.type", "verification.match.matching.rcs_loss.scale",
                   "verification.match.matching.rcs_translation"}
KINDS = [("match", "MatchOptions", rg.match_options), ("odometry", "OdometryOptions", rg.odometry_options),
         ("slam", "SlamOptions", rg.slam_options), ("relocalization", "RelocalizationOptions", rg.relocalization_options)]


@pytest.mark.parametrize("kind, struct, read_back", KINDS)
def test_every_field_of_the_cpp_options_is_a_keyword(kind, struct, read_back):
    structs = cpp_structs()
    expected = set(leaf_paths(structs, struct))
    fields = rg.option_fields(kind)
    assert len(expected) > (30 if kind == "match" else 70)
    assert {f["path"] for f in fields} == expected - {p for p in expected if p.removeprefix("odometry.") in
                                                       SET_BY_THE_CODE}
    keywords = [f["keyword"] for f in fields]
    assert len(set(keywords)) == len(keywords)
    assert set(read_back()) == set(keywords)


def in_range(field, value):
    low, high = (float(x) for x in field["range"][1:-1].split(", "))
    return (value > low if field["range"][0] == "(" else value >= low) and value <= high


def test_the_members_the_code_sets_exist():
    structs = cpp_structs()
    members = set(leaf_paths(structs, "SlamOptions")) | set(leaf_paths(structs, "RelocalizationOptions"))
    assert {"odometry." + p if p.startswith("map.") else p for p in SET_BY_THE_CODE} <= members


def other_value(field):
    """A valid value that differs from the default, inside the option's range."""
    default, kind = field["default"], field["type"]
    if kind.startswith("{"):
        return next(choice for choice in re.findall(r"'([^']+)'", kind) if choice != default)
    if kind == "bool":
        return not default
    if kind == "int":
        return default + 1 if in_range(field, default + 1) else default - 1
    if kind == "float":
        high = float(field["range"].split(", ")[1][:-1])
        for value in (default / 2 if default else 0.25, (default + high) / 2, default * 2):
            if value != default and np.isfinite(value) and in_range(field, value):
                return value
    if kind == "list of float":
        return [0.5]
    if kind == "sequence of 3 float":
        return [2.0, 3.0, 45.0]
    pose = np.eye(4)
    pose[:3, 3] = [1.0, 2.0, 3.0]
    return pose


@pytest.mark.parametrize("kind, struct, read_back", KINDS)
def test_every_keyword_round_trips(kind, struct, read_back):
    defaults = read_back()
    for field in rg.option_fields(kind):
        value = other_value(field)
        got = read_back(**{field["keyword"]: value})
        if isinstance(value, np.ndarray):
            assert np.array_equal(got[field["keyword"]], value), field["keyword"]
        else:
            assert got[field["keyword"]] == value, field["keyword"]
        changed = [k for k in got if not np.array_equal(got[k], defaults[k])]
        assert changed == [field["keyword"]], field["keyword"]


def test_keywords_reach_match_and_odometry_and_bad_ones_are_refused():
    sequence = rg.simulate(seed=2, scans=3)
    world = rg.build_map(sequence)
    one = rg.match(sequence.scans[1], world, sequence.poses[1], max_iterations=1, coarse_iterations=1)
    full = rg.match(sequence.scans[1], world, sequence.poses[1])
    assert one.iterations < full.iterations
    odometry = rg.RadarOdometry(keyframe_distance=2.0, rotation_weight=0.0)
    assert odometry.options()["keyframe_distance"] == 2.0 and odometry.options()["rotation_weight"] == 0.0
    with pytest.raises(TypeError, match="unknown keyword 'gates'"):
        rg.match(sequence.scans[1], world, sequence.poses[1], gates=2.0)
    with pytest.raises(TypeError, match="max_iterations must be an int"):
        rg.match_options(max_iterations=2.5)
    with pytest.raises(TypeError, match="reassociate must be a bool"):
        rg.match_options(reassociate=1)
    with pytest.raises(ValueError, match="gate = inf is not a finite number"):
        rg.match_options(gate=float("inf"))
    with pytest.raises(ValueError, match=r"max_iterations = 0 is not in \[1, "):
        rg.match_options(max_iterations=0)
    with pytest.raises(ValueError, match=r"region_capacity \(6\) must be at least region_min_points \(8\)"):
        rg.odometry_options(region_capacity=6)
    assert rg.odometry_options(region_capacity=6, region_min_points=6)["region_capacity"] == 6


def names_in_doc(doc, keyword):
    return re.search(keyword + r" : \{([^}]*)\}", doc).group(1).replace("'", "").split(", ")


def test_docstring_names_are_the_librarys_names():
    """The solver and loss lists of match's docstring against the names the
    library's own message lists when it refuses an unknown one."""
    for keyword in ("solver", "loss", "ceres_blocks"):
        with pytest.raises(ValueError) as refused:
            rg.match_options(**{keyword: "no-such-name"})
        library = str(refused.value).split("{", 1)[1].rstrip("}").split(",")
        assert names_in_doc(rg.match.__doc__, keyword) == library, keyword
    assert "mh-gn" in names_in_doc(rg.match.__doc__, "solver")


def test_poses_matrix_composes_as_numpy_users_do():
    sequence = rg.simulate(seed=2, scans=3)
    matrices = sequence.poses_matrix
    assert matrices.shape == (3, 4, 4)
    for tum, matrix in zip(sequence.poses, matrices):
        x, y, z, w = tum[3:]
        by_hand = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])
        assert np.allclose(matrix[:3, :3], by_hand, atol=1e-12) and np.array_equal(matrix[:3, 3], tum[:3])
        assert np.array_equal(matrix[3], [0, 0, 0, 1])
    step = np.eye(4)
    step[0, 3] = 1.0
    moved = matrices[0] @ step
    assert np.allclose(moved[:3, 3], matrices[0][:3, 3] + matrices[0][:3, 0])
    assert np.array_equal(rg.pose_matrices(sequence.poses), matrices)
    assert np.array_equal(rg.pose_matrix(sequence.poses[1]), matrices[1])


def test_stubs_are_the_modules():
    generated = subprocess.run([sys.executable, str(ROOT / "scripts" / "generate_stubs.py")], capture_output=True,
                               text=True, check=True).stdout
    ast.parse(generated)
    committed = (ROOT / "python" / "radargauss" / "_radargauss.pyi").read_text()
    assert generated == committed, "stale stubs: run scripts/generate_stubs.py > python/radargauss/_radargauss.pyi"
