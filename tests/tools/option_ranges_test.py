#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
"""Documented ranges are the accepted ones (docs/design/formats.md, "Bounds on
input"): every numeric flag whose `--help-all` states a range, in every
subcommand that runs on a sequence, is tried at each end of that range (a
closed end is accepted and the run ends, or is refused for what the value
means on the data in one line naming the flag, within a time and memory bound),
just outside it (refused in one line naming the flag), and, for an open
end, at the end itself (refused) and just inside it (accepted or refused in
one line naming the flag, never a crash, a hang or memory exhaustion). A
flag documented as "at least --other" is tried with --other at the same
value.

    option_ranges_test.py <path to radargauss>
"""
import concurrent.futures
import itertools
import math
import os
import re
import resource
import subprocess
import sys
import tempfile
import threading

TIMEOUT_S = 60  # a release build's; a sanitized one runs several times slower and gets three times as long
MEMORY_BYTES = 4 << 30  # a run that needs more has exhausted what a flag's range should allow
RANGE = re.compile(r"^\s+(--[a-z0-9-]+) (FLOAT|INT|UINT):([\[(])([^,\]]+), ([^\])]+)([\])])(?:\S* x (\d+))?")


def limit_memory():
    resource.setrlimit(resource.RLIMIT_AS, (MEMORY_BYTES, MEMORY_BYTES))


def run(command, sanitized):
    try:
        result = subprocess.run(command, capture_output=True, text=True, timeout=TIMEOUT_S * (3 if sanitized else 1),
                                preexec_fn=None if sanitized else limit_memory)
    except subprocess.TimeoutExpired:
        return None, "timed out after %d s" % (TIMEOUT_S * (3 if sanitized else 1))
    return result.returncode, result.stderr.strip()


def ranges(tool, command):
    """(flag, type, low, high, low_closed, high_closed, values, companion) of every ranged numeric flag;
    companion: the flag it may not fall below, or None."""
    text = subprocess.run([tool, command, "--help-all"], capture_output=True, text=True, check=True).stdout
    lines = text.splitlines()
    found = []
    for k, line in enumerate(lines):
        match = RANGE.match(line)
        if match:
            flag, kind, left, low, high, right, count = match.groups()
            described = " ".join(lines[k:k + 2])
            companion = re.search(r"at least (--[a-z0-9-]+)", described)
            found.append((flag, kind, float(low), float(high), left == "[", right == "]", int(count or 1),
                          companion.group(1) if companion else None))
    return found


FLAG = re.compile(r"^\s+(--[a-z0-9-]+)(?:=(?:true|false))?(?:\s{2,}\S.*)?$")


def flags(tool, command):
    """Every boolean flag of `command`'s --help-all: a name with no type (and its default, when it has one)."""
    text = subprocess.run([tool, command, "--help-all"], capture_output=True, text=True, check=True).stdout
    found = [match.group(1) for match in map(FLAG.match, text.splitlines()) if match]
    return [flag for flag in found if flag not in ("--help", "--help-all")]


def outside(value, kind, direction):
    if kind != "FLOAT":
        return int(value) + direction
    return value + direction * max(abs(value) * 1e-6, 1e-6)


def inside(value, kind, direction):
    if kind != "FLOAT":
        return int(value) + direction
    return value + direction * max(abs(value) * 1e-12, 1e-300)


def text(value):
    return repr(value) if isinstance(value, float) else str(value)


def main():
    tool = sys.argv[1]
    sanitized = "asan" in subprocess.run(["ldd", tool], capture_output=True, text=True).stdout
    work = tempfile.mkdtemp()
    sequence = os.path.join(work, "seq")
    subprocess.run([tool, "simulate", "--out", sequence, "--scans", "6", "--seed", "2"], check=True,
                   stdout=subprocess.DEVNULL)
    gt = os.path.join(sequence, "gt_radar_tum.txt")
    drive = os.path.join(work, "drive_tum.txt")  # 4 s, long enough for simulate-imu's default knots
    with open(drive, "w") as out:
        out.writelines("%.2f %.2f 0 0 0 0 0 1\n" % (0.1 * k, 0.6 * k) for k in range(41))
    world_map = os.path.join(work, "world.rgm")
    subprocess.run([tool, "build-map", "--sequence", sequence, "--gt", gt, "--out", world_map], check=True,
                   stdout=subprocess.DEVNULL)
    slam_out = os.path.join(work, "slam")
    subprocess.run([tool, "slam", "--sequence", sequence, "--out", slam_out, "--submap-distance", "2"], check=True,
                   stdout=subprocess.DEVNULL)
    inputs = ["--sequence", sequence, "--gt", gt]
    commands = {
        "odometry": inputs + ["--out", os.path.join(work, "o")],
        "slam": inputs + ["--out", os.path.join(work, "s")],
        "relocalize": inputs + ["--map", os.path.join(slam_out, "map.rgm"), "--out", os.path.join(work, "r")],
        "localize": inputs + ["--out", os.path.join(work, "l")],
        "build-map": inputs + ["--out", os.path.join(work, "m.rgm")],
        "refine": ["--sequence", sequence, "--poses", gt, "--extrinsic", "identity", "--map", world_map,
                   "--out", os.path.join(work, "f")],
        "evaluate": ["--est", gt, "--ref", gt, "--out", os.path.join(work, "e")],
        "simulate": ["--out", os.path.join(work, "sim"), "--force"],
        "simulate-imu": ["--gt", drive, "--out", os.path.join(work, "imu"), "--force"],
    }
    passed, failures = 0, []
    lock, runs = threading.Lock(), itertools.count()

    def expect(command, flag, value, accepted, count, companion=None):
        nonlocal passed
        extra = [companion, text(value)] if companion else []
        arguments = list(commands[command])
        if "--out" in arguments:  # runs side by side: each writes its own results
            at = arguments.index("--out") + 1
            arguments[at] += "_%d" % next(runs)
        status, error = run([tool, command] + arguments + [flag] + [text(value)] * count + extra, sanitized)
        lines = [line for line in error.splitlines() if line and not line.startswith("Run with --help")]
        one_line = len(lines) <= 1
        crashed = status is None or status < 0 or status > 125 or "out of memory" in error or "bad_alloc" in error
        if accepted is True:  # run, or refused for what the value means on this data, naming the flag
            ok = status == 0 or (not crashed and one_line and flag.lstrip("-") in error and "is not in" not in error)
        elif accepted is False:
            ok = status not in (0, None) and not crashed and one_line and flag.lstrip("-") in error
        else:  # either, but cleanly
            ok = not crashed and (status == 0 or (one_line and flag.lstrip("-") in error))
        with lock:
            if ok:
                passed += 1
            else:
                wanted = {True: "accepted", False: "refused naming the flag",
                          None: "accepted or refused cleanly"}[accepted]
                failures.append("%s %s %s: wanted %s, exit %s: %s" % (command, flag, text(value), wanted, status,
                                                                       error.replace("\n", " | ")[:300]))

    # The runs are independent: as many side by side as there are cores.
    pool = concurrent.futures.ThreadPoolExecutor(max_workers=os.cpu_count() or 1)
    jobs = []
    tried = set()
    for command in commands:
        for flag, kind, low, high, low_closed, high_closed, count, companion in ranges(tool, command):
            # A row nested in several commands (the match's, the odometry's) reaches the same code
            # from each: the sanitizer tree tries it in the first command that has it, the other in all.
            if sanitized and (flag, low, high) in tried:
                continue
            tried.add((flag, low, high))
            for end, closed, direction in ((low, low_closed, -1), (high, high_closed, +1)):
                if math.isinf(end):
                    continue
                pair = companion if direction < 0 else None
                at_end = int(end) if kind != "FLOAT" else end
                if closed:
                    jobs.append(pool.submit(expect, command, flag, at_end, True, count, pair))
                    jobs.append(pool.submit(expect, command, flag, outside(end, kind, direction), False, count, pair))
                else:
                    jobs.append(pool.submit(expect, command, flag, at_end, False, count, pair))
                    jobs.append(pool.submit(expect, command, flag, inside(end, kind, -direction), None, count, pair))
    for job in jobs:
        job.result()
    pool.shutdown()
    # Boolean flags: the documented words only, in any case; any other word refused naming the flag,
    # on the command line and in YAML (no abort, no word read as true).
    every = ["info", "convert", "export", "map-info"] + list(commands)
    flag_count = 0
    words_tried = set()
    for command in every:
        for flag in flags(tool, command):
            flag_count += 1
            # The parse is the same code in both trees and for every command: the sanitizer tree
            # tries one word per flag, in the first command that has it; the other four in all.
            if sanitized and flag in words_tried:
                continue
            words_tried.add(flag)
            for word in ("maybe",) if sanitized else ("maybe", "2x", "yes-please", "-1"):
                status, error = run([tool, command, flag + "=" + word], sanitized)
                lines = [line for line in error.splitlines() if line and not line.startswith("Run with --help")]
                if status not in (0, None) and status < 126 and len(lines) == 1 and flag in error and \
                        "is not one of true/false, 1/0, on/off, yes/no" in error:
                    passed += 1
                else:
                    failures.append("%s %s=%s: wanted refused naming the flag, exit %s: %s" %
                                    (command, flag, word, status, error.replace("\n", " | ")[:300]))
    # --help shows a subset of --help-all, and says so when it leaves flags out.
    option_name = re.compile(r"^\s+(?:-[a-z],)?(--[a-z0-9-]+)")
    for command in every:
        shown = {}
        for mode in ("--help", "--help-all"):
            listing = subprocess.run([tool, command, mode], capture_output=True, text=True, check=True).stdout
            shown[mode] = ({m.group(1) for m in map(option_name.match, listing.splitlines()) if m}, listing)
        brief, every_flag = shown["--help"][0], shown["--help-all"][0]
        if not brief <= every_flag:
            failures.append("%s: --help lists %s, which --help-all does not" % (command, sorted(brief - every_flag)))
        elif brief != every_flag and "--help-all lists every option" not in shown["--help"][1]:
            failures.append("%s: --help leaves out %d flags without saying so" % (command, len(every_flag - brief)))
        else:
            passed += 1
    if flag_count < 25:
        failures.append("only %d boolean flags found in --help-all: the pattern misses the help's layout" % flag_count)
    yaml_word = os.path.join(work, "maybe.yaml")
    for command, key in (("odometry", "estimate-elevation-bias"), ("relocalize", "verify-geometric-first")):
        with open(yaml_word, "w") as f:
            f.write(key + ": maybe\n")
        status, error = run([tool, command] + commands[command] + ["--config", yaml_word], sanitized)
        if status not in (0, None) and status < 126 and key in error and "is not one of true/false" in error:
            passed += 1
        else:
            failures.append("%s --config with '%s: maybe': exit %s: %s" % (command, key, status, error[:300]))
    for word in ("yes", "no", "on", "OFF", "1", "0", "True", "false"):
        expect("build-map", "--doppler-filter=" + word, "", True, 0)
    with open(yaml_word, "w") as f:
        f.write("doppler-filter: no\n")
    expect("build-map", "--config", yaml_word, True, 1)
    for failure in sorted(failures):
        print("FAIL:", failure)
    print("option ranges: %d passed, %d failed" % (passed, len(failures)))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
