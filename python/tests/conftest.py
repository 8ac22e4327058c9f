# SPDX-License-Identifier: BSD-3-Clause
"""Shared fixtures: a small simulated sequence written by the command-line
tool (RADARGAUSS_CLI, set by ctest) and its map."""
import os
import subprocess

import pytest


@pytest.fixture(scope="module")
def cli():
    path = os.environ.get("RADARGAUSS_CLI", "")
    if not path or not os.path.exists(path):
        pytest.skip("RADARGAUSS_CLI does not name the radargauss tool")
    return path


@pytest.fixture(scope="module")
def written(cli, tmp_path_factory):
    """A 20-scan simulated sequence and its map, both written by the CLI."""
    root = tmp_path_factory.mktemp("sequence")
    sequence = str(root / "seq")
    subprocess.run([cli, "simulate", "--out", sequence, "--scans", "20", "--seed", "3"], check=True,
                   stdout=subprocess.DEVNULL)
    gt = os.path.join(sequence, "gt_radar_tum.txt")
    world = str(root / "map.rgm")
    subprocess.run([cli, "build-map", "--sequence", sequence, "--gt", gt, "--out", world], check=True,
                   stdout=subprocess.DEVNULL)
    return {"root": root, "sequence": sequence, "gt": gt, "map": world}
