#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# Installs what is missing, then builds and runs every test twice: in a
# Release tree and in an AddressSanitizer + UndefinedBehaviorSanitizer tree;
# then fuzzes every input format a little (scripts/fuzz.sh, 20 s per target,
# 10 s under CI=true, in its own clang tree: libFuzzer's coverage
# instrumentation would slow the sanitizer tree's tests several times over).
# Ends with the time each phase took.
#   scripts/test.sh            both trees and the fuzzers
#   scripts/test.sh --quick    the Release tree's tests labelled fast, no fuzzing (for iteration)
#   RADARGAUSS_TEST_TREES=release scripts/test.sh   one tree only
#   RADARGAUSS_FUZZ_SECONDS=0 scripts/test.sh       no fuzzing
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
# phase NAME: the seconds since the last phase, kept for the summary at the end.
phases=()
last=$SECONDS
phase() {
  phases+=("$1 $((SECONDS - last)) s")
  last=$SECONDS
}
jobs=$(nproc)
# CI must end within its time: both trees build the library in unity
# batches, the sanitize tree without line tables, and it leaves the long
# drives (label drive) to the release tree.
sanitize_debug_info=-g1
unity=OFF
sanitize_labels=()
if [ "${CI:-}" = true ]; then
  sanitize_debug_info=-g0
  unity=ON
  sanitize_labels=(-LE drive)
fi
trees=${RADARGAUSS_TEST_TREES:-"release sanitize"}
labels=()
case "${1:-}" in
  "") ;;
  --quick) trees=release; labels=(-L fast); RADARGAUSS_FUZZ_SECONDS=0 ;;
  *) echo "test.sh: unknown argument '$1' (--quick)" >&2; exit 2 ;;
esac

# The optional components are on here (and required): the ROS1 bag reader in
# both trees, the PCL NDT/GICP peers and the Python module in the Release tree
# (Debian's PCL and Python are not built with the sanitizers, so the
# sanitizer tree leaves them out).
RADARGAUSS_DEPS_EXTRA="librosbag-storage-dev libsensor-msgs-dev libpcl-dev python3-dev python3-numpy
  python3-pybind11 pybind11-dev python3-pytest python3-hypothesis python3-matplotlib python3-distributed
  ${RADARGAUSS_DEPS_EXTRA:-}" \
  "$root/scripts/deps.sh"
phase "packages"

# The product's own rules: no narrative of the work, design citations and
# includes that resolve, the layers; lengths of files, functions, README and
# RESULTS as warnings.
/usr/bin/python3 "$root/scripts/check_sources.py" "$root"
phase "source checks"

for tree in $trees; do
  build="$root/build/$tree"
  case "$tree" in
    release)
      cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release -DRADARGAUSS_WITH_ROSBAG=ON \
        -DRADARGAUSS_WITH_PCL=ON -DRADARGAUSS_WITH_PYTHON=ON -DRADARGAUSS_UNITY_LIBRARY="$unity" ;;
    sanitize)
      # Debug keeps Eigen's and our assertions on; -O1 keeps it fast enough;
      # -g1 (line tables) gives the sanitizers' reports file:line at a
      # third less compile time than -g (CI: see above). (clang
      # builds this tree faster, but its -O1 code ran the tests twice as
      # slowly under ASan.) The algebra's tests run in the release tree.
      cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Debug \
        -DCMAKE_CXX_FLAGS_DEBUG="-O1 $sanitize_debug_info" -DRADARGAUSS_SANITIZE=ON \
        -DRADARGAUSS_UNITY_LIBRARY="$unity" \
        -DRADARGAUSS_BUILD_ALGEBRA_TESTS=OFF -DRADARGAUSS_BUILD_BENCHMARKS=OFF -DRADARGAUSS_BUILD_EXAMPLES=OFF \
        -DRADARGAUSS_WITH_ROSBAG=ON ;;
    *)
      echo "test.sh: unknown tree '$tree' (release, sanitize)" >&2
      exit 2 ;;
  esac
  cmake --build "$build" -j "$jobs"
  phase "$tree build"
  echo "== tests: $tree tree =="
  tree_labels=("${labels[@]}")
  if [ "$tree" = sanitize ]; then tree_labels+=("${sanitize_labels[@]}"); fi
  (cd "$build" && ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 \
     UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
     ctest --output-on-failure -j "$jobs" "${tree_labels[@]}")
  phase "$tree tests"
done

default_fuzz_seconds=20
if [ "${CI:-}" = true ]; then default_fuzz_seconds=5; fi
fuzz_seconds=${RADARGAUSS_FUZZ_SECONDS:-$default_fuzz_seconds}
if [ "$fuzz_seconds" != 0 ]; then
  echo "== fuzzing: every target for $fuzz_seconds s =="
  "$root/scripts/fuzz.sh" all "$fuzz_seconds"
  phase "fuzzing"
fi
echo "test.sh: $(IFS=,; echo "${phases[*]}" | sed 's/,/, /g'); $SECONDS s in all"
