#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# Builds the libFuzzer targets (fuzz/) with clang, ASan and UBSan in their own
# tree (build/fuzz) and runs each for SECONDS on one worker, one target per
# core at a time, seeded by scripts/fuzz_seeds.py and the regression inputs of
# tests/data/fuzz.
# Prints executions and coverage per target; exits non-zero on a finding
# (a crash, leak, UB, a 10 s timeout or more than 2 GB) and names the
# reproducer, which `build/fuzz/fuzz/fuzz_<target> <file>` replays.
#   scripts/fuzz.sh [TARGET|all] [SECONDS]      (default: all 60)
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
which=${1:-all}
seconds=${2:-60}
targets=(pcd kitti_bin tum map_file pointcloud2 simulator_yaml cli_yaml shard_json map_places mcap cdr map_tiles rig_yaml)
if [ "$which" != all ]; then
  if [[ ! " ${targets[*]} " =~ " $which " ]]; then
    echo "fuzz.sh: unknown target '$which' (all, ${targets[*]})" >&2
    exit 2
  fi
  targets=("$which")
fi
if ! [[ "$seconds" =~ ^[1-9][0-9]*$ ]]; then
  echo "fuzz.sh: SECONDS must be a positive integer, not '$seconds'" >&2
  exit 2
fi

RADARGAUSS_DEPS_EXTRA="clang libclang-rt-14-dev libcli11-dev ${RADARGAUSS_DEPS_EXTRA:-}" "$root/scripts/deps.sh"
build="$root/build/fuzz"
CC=clang CXX=clang++ cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Debug \
  -DCMAKE_CXX_FLAGS_DEBUG="-O1 -g1" -DCMAKE_CXX_FLAGS="-fsanitize=fuzzer-no-link" \
  -DRADARGAUSS_SANITIZE=ON -DRADARGAUSS_BUILD_FUZZERS=ON -DRADARGAUSS_BUILD_TESTS=OFF \
  -DRADARGAUSS_BUILD_BENCHMARKS=OFF -DRADARGAUSS_BUILD_APPS=OFF -DRADARGAUSS_BUILD_EXAMPLES=OFF \
  -DRADARGAUSS_WITH_ROSBAG=OFF >/dev/null
cmake --build "$build" -j "$(nproc)" --target "${targets[@]/#/fuzz_}"
/usr/bin/python3 "$root/scripts/fuzz_seeds.py" "$build/corpus"

# run_target <target>: fuzzes one target, its exit status in findings/<target>.status.
run_target() {
  local target=$1 corpus="$build/corpus/$1" findings="$build/findings/$1"
  mkdir -p "$corpus" "$findings"
  local extra=() seeds=("$corpus")
  if [ -f "$root/fuzz/dict/$target.dict" ]; then extra+=(-dict="$root/fuzz/dict/$target.dict"); fi
  if [ -d "$root/tests/data/fuzz/$target" ]; then seeds+=("$root/tests/data/fuzz/$target"); fi
  local code=0
  ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1 \
    "$build/fuzz/fuzz_$target" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 \
    -print_final_stats=1 -artifact_prefix="$findings/" "${extra[@]}" "${seeds[@]}" \
    >"$build/findings/$target.log" 2>&1 || code=$?
  echo "$code" >"$build/findings/$target.status"
}

# One target per core at a time: each still fuzzes on one worker for SECONDS.
mkdir -p "$build/findings"
for target in "${targets[@]}"; do
  while [ "$(jobs -rp | wc -l)" -ge "$(nproc)" ]; do wait -n || true; done
  rm -f "$build/findings/$target.status"
  run_target "$target" &
done
wait

status=0
printf '%-15s %10s %8s %8s %s\n' target executions coverage features findings
for target in "${targets[@]}"; do
  log="$build/findings/$target.log"
  code=$(cat "$build/findings/$target.status" 2>/dev/null || echo 1)
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  coverage=$( (grep -o 'cov: [0-9]*' "$log" || true) | tail -1 | cut -d' ' -f2)
  features=$( (grep -o 'ft: [0-9]*' "$log" || true) | tail -1 | cut -d' ' -f2)
  if [ "$code" -eq 0 ]; then
    printf '%-15s %10s %8s %8s %s\n' "$target" "${runs:-?}" "${coverage:-?}" "${features:-?}" none
  else
    reproducer=$( (ls -t "$build/findings/$target"/crash-* "$build/findings/$target"/leak-* \
      "$build/findings/$target"/timeout-* "$build/findings/$target"/oom-* 2>/dev/null || true) | head -1)
    printf '%-15s %10s %8s %8s %s\n' "$target" "${runs:-?}" "${coverage:-?}" "${features:-?}" \
      "FINDING: ${reproducer:-see $log}"
    status=1
  fi
done
rm -rf /tmp/radargauss_fuzz_* 2>/dev/null || true  # a fuzzer of another run may be writing there
exit $status
