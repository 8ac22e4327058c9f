# SPDX-License-Identifier: BSD-3-Clause
"""Sweeps as data (docs/python.md, "Sweeps"): an experiment of sequences x
configurations becomes independent tasks that the command-line tool runs:
one map per sequence (shared by every configuration), `localize --shard I/N`
per configuration and chunk of scans, and `merge` per configuration, whose
files are exactly those one `radargauss localize` run writes. `sweep` runs
them here in order; scripts/sweep_dask.py runs the same tasks on a Dask
cluster.
"""
import dataclasses
import os
import shutil
import subprocess


@dataclasses.dataclass(frozen=True)
class Task:
    """One command of a sweep; `after` names the tasks whose outputs it reads."""
    name: str
    command: tuple
    output: str
    after: tuple = ()


def tool_path(tool=None):
    """The radargauss tool: `tool`, $RADARGAUSS_CLI, or radargauss on PATH."""
    path = tool or os.environ.get("RADARGAUSS_CLI") or shutil.which("radargauss")
    if not path or not os.path.exists(path):
        raise ValueError("the radargauss tool was not found: pass tool=, set RADARGAUSS_CLI or put it on PATH")
    return path


def _flags(options):
    flags = []
    for key, value in sorted(options.items()):
        if isinstance(value, (list, tuple)):
            value = ",".join(str(v) for v in value)
        flags += [f"--{key}", str(value)]
    return flags


def plan(configurations, sequences, work, shards=1, tool=None):
    """The tasks of a sweep, in an order that runs each after its inputs.

    configurations: {name: {localize flag: value}}, e.g. {"w": {"w-rcs": [0, 0.25]}};
    sequences: {name: {"sequence": folder, "gt": file, ...}} (the flags that
    read it, plus map flags for build-map under "map"); work: the folder of
    every output, <work>/<sequence>/<configuration>/merged the results."""
    if not configurations or not sequences:
        raise ValueError("a sweep needs at least one configuration and one sequence")
    if not isinstance(shards, int) or shards < 1:
        raise ValueError("shards must be an integer >= 1")
    tool = tool_path(tool)
    tasks = []
    for sequence_name, reading in sorted(sequences.items()):
        reading = dict(reading)
        map_flags = reading.pop("map", {})
        source = _flags(reading)
        root = os.path.join(work, sequence_name)
        world = os.path.join(root, "map.rgm")
        map_task = Task(f"{sequence_name}/map", (tool, "build-map", *source, *_flags(map_flags), "--out", world), world)
        tasks.append(map_task)
        for configuration, options in sorted(configurations.items()):
            parts = []
            for index in range(1, shards + 1):
                out = os.path.join(root, configuration, f"shard{index}")
                command = (tool, "localize", *source, "--map", world, *_flags(options),
                           "--shard", f"{index}/{shards}", "--out", out)
                parts.append(Task(f"{sequence_name}/{configuration}/{index}", command, out, (map_task.name,)))
            tasks += parts
            merged = os.path.join(root, configuration, "merged")
            tasks.append(Task(f"{sequence_name}/{configuration}/merge",
                              (tool, "merge", *[p.output for p in parts], "--out", merged), merged,
                              tuple(p.name for p in parts)))
    return tasks


def run_task(task):
    """Runs one task; raises RuntimeError with the tool's message when it fails."""
    os.makedirs(os.path.dirname(task.output), exist_ok=True)
    done = subprocess.run(list(task.command), stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    if done.returncode != 0:
        raise RuntimeError(f"{task.name}: {done.stderr.strip()}")
    return task.output


def sweep(configurations, sequences, work, shards=1, tool=None):
    """Runs every task of plan(...) here, in order; returns
    {(sequence, configuration): merged results folder}."""
    results = {}
    for task in plan(configurations, sequences, work, shards, tool):
        output = run_task(task)
        if task.name.endswith("/merge"):
            sequence_name, configuration, _ = task.name.split("/")
            results[(sequence_name, configuration)] = output
    return results
