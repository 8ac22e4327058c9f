# SPDX-License-Identifier: BSD-3-Clause
"""Sweeps: the tasks of radargauss.plan, run here or on a Dask LocalCluster
whose worker is killed midway, give the files `radargauss localize` writes."""
import importlib.util
import os
import signal
import subprocess

import pytest

import radargauss as rg

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
CONFIGURATIONS = {"weights": {"w-rcs": [0, 0.25]}, "ceres": {"solver": "ceres", "w-rcs": 0.25}}


def rows(folder):
    """per_scan.csv without its time column, sorted."""
    with open(os.path.join(folder, "per_scan.csv")) as f:
        return sorted(line.rsplit(",", 1)[0] for line in f)


def direct(cli, written, options):
    out = str(written["root"] / ("direct-" + "-".join(f"{k}{v}" for k, v in sorted(options.items()))))
    flags = [item for key, value in sorted(options.items())
             for item in (f"--{key}", ",".join(map(str, value)) if isinstance(value, list) else str(value))]
    subprocess.run([cli, "localize", "--sequence", written["sequence"], "--gt", written["gt"], "--map",
                    written["map"], *flags, "--out", out], check=True, stdout=subprocess.DEVNULL)
    return out


def test_plan_builds_each_map_once_and_merges_every_configuration(cli, tmp_path):
    tasks = rg.plan(CONFIGURATIONS, {"a": {"sequence": "x"}, "b": {"sequence": "y"}}, str(tmp_path), shards=3, tool=cli)
    assert len(tasks) == 2 * (1 + 2 * (3 + 1))
    names = [task.name for task in tasks]
    assert names.count("a/map") == 1 and "a/ceres/merge" in names
    merge = next(task for task in tasks if task.name == "b/weights/merge")
    assert merge.after == ("b/weights/1", "b/weights/2", "b/weights/3")
    assert all(names.index(before) < names.index(task.name) for task in tasks for before in task.after)
    with pytest.raises(ValueError, match="shards"):
        rg.plan(CONFIGURATIONS, {"a": {"sequence": "x"}}, str(tmp_path), shards=0, tool=cli)


def test_sweep_here_equals_localize(cli, written, tmp_path):
    sequences = {"sim": {"sequence": written["sequence"], "gt": written["gt"]}}
    results = rg.sweep(CONFIGURATIONS, sequences, str(tmp_path), shards=3, tool=cli)
    for name, options in CONFIGURATIONS.items():
        assert rows(results[("sim", name)]) == rows(direct(cli, written, options)), name


def load_sweep_dask():
    spec = importlib.util.spec_from_file_location("sweep_dask", os.path.join(ROOT, "scripts", "sweep_dask.py"))
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_dask_cluster_with_a_killed_worker_equals_localize(cli, written, tmp_path):
    distributed = pytest.importorskip("distributed")
    sweep_dask = load_sweep_dask()
    sequences = {"sim": {"sequence": written["sequence"], "gt": written["gt"]}}
    tasks = rg.plan(CONFIGURATIONS, sequences, str(tmp_path), shards=4, tool=cli)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster, distributed.Client(cluster) as client:
        futures = sweep_dask.submit(client, tasks)
        futures["sim/map"].result()  # the map is built: kill a worker while the shards run
        pids = client.run(os.getpid)
        os.kill(next(iter(pids.values())), signal.SIGKILL)
        outputs = {name: future.result(timeout=300) for name, future in futures.items()}
    assert len(outputs) == len(tasks)
    for name, options in CONFIGURATIONS.items():
        merged = outputs[f"sim/{name}/merge"]
        assert rows(merged) == rows(direct(cli, written, options)), name
