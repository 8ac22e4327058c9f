# SPDX-License-Identifier: BSD-3-Clause
"""examples/python/quickstart.py runs, stays under 80 lines and writes its plot."""
import os
import subprocess
import sys

import pytest

import radargauss as rg

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
QUICKSTART = os.path.join(ROOT, "examples", "python", "quickstart.py")


def test_quickstart_runs_and_plots(tmp_path):
    assert len(open(QUICKSTART).read().splitlines()) < 80
    out = tmp_path / "quickstart.png"
    done = subprocess.run([sys.executable, QUICKSTART, str(out)], capture_output=True, text=True, env=os.environ)
    assert done.returncode == 0, done.stderr
    assert "converged" in done.stdout and "odometry: RPE" in done.stdout
    assert out.stat().st_size > 10000


def test_odometry_refuses_bad_options():
    with pytest.raises(ValueError, match="keyframe"):
        rg.RadarOdometry(keyframe_distance=-1.0)
    with pytest.raises(ValueError, match="initial_pose"):
        rg.RadarOdometry(initial_pose=[0, 0, 0, 0, 0, 0, 2.0])
