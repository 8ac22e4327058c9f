#!/usr/bin/python3
# SPDX-License-Identifier: BSD-3-Clause
"""A sweep on a Dask cluster (docs/python.md, "Sweeps"): the tasks of
radargauss.plan (one map per sequence, localize shards, merges) submitted
with their dependencies, a task whose worker died retried, progress shown;
the merged results are those one `radargauss localize` run writes.

    scripts/sweep_dask.py SWEEP.json --work DIR [--scheduler ADDRESS] [--workers 2] [--shards 4]

SWEEP.json: {"configurations": {name: {flag: value}}, "sequences": {name:
{"sequence": folder, "gt": file}}}. Without --scheduler a LocalCluster of
--workers processes runs here; with it, `dask-scheduler` on one machine and
`dask-worker ADDRESS` on each of the others (every machine needs the tool at
the same path, or RADARGAUSS_CLI set, and the data at the same paths).
"""
import argparse
import json
import sys

from distributed import Client, LocalCluster, as_completed

import radargauss


def submit(client, tasks, retries=3):
    """Futures of every task, each depending on the futures of its inputs."""
    futures = {}
    for task in tasks:
        inputs = [futures[name] for name in task.after]
        futures[task.name] = client.submit(lambda t, *_: radargauss.run_task(t), task, *inputs,
                                           key=f"radargauss-{task.name}", retries=retries, pure=False)
    return futures


def run(client, tasks, progress=True):
    """Waits for every task; returns {task name: output folder}."""
    futures = submit(client, tasks)
    names = {future.key: name for name, future in futures.items()}
    outputs = {}
    for done, future in enumerate(as_completed(list(futures.values())), 1):
        outputs[names[future.key]] = future.result()
        if progress:
            print(f"\r[{done}/{len(futures)}] {names[future.key]}", end="", file=sys.stderr, flush=True)
    if progress:
        print(file=sys.stderr)
    return outputs


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("sweep", help="JSON file of configurations and sequences")
    parser.add_argument("--work", required=True, help="folder of every output")
    parser.add_argument("--scheduler", default="", help="address of a running Dask scheduler")
    parser.add_argument("--workers", type=int, default=2, help="LocalCluster processes without --scheduler")
    parser.add_argument("--shards", type=int, default=2, help="chunks of scans per configuration")
    parser.add_argument("--tool", default=None, help="the radargauss tool (default: RADARGAUSS_CLI or PATH)")
    args = parser.parse_args()
    with open(args.sweep) as f:
        spec = json.load(f)
    tasks = radargauss.plan(spec["configurations"], spec["sequences"], args.work, args.shards, args.tool)
    cluster = None if args.scheduler else LocalCluster(n_workers=args.workers, threads_per_worker=1,
                                                       processes=True, dashboard_address=None)
    with Client(args.scheduler or cluster) as client:
        outputs = run(client, tasks)
    if cluster is not None:
        cluster.close()
    for name, output in sorted(outputs.items()):
        if name.endswith("/merge"):
            print(f"{name[:-len('/merge')]}: {output}")


if __name__ == "__main__":
    main()
