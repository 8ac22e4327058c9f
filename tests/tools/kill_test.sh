#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# build-map and localize killed with SIGKILL at moments spread over their run
# (docs/design/formats.md, "Bounds on input"): every output file is then absent or
# whole (the same bytes, or for files with timings the same lines, as an
# undisturbed run), and once a run ends no temporary file or staged results
# folder is left.
#   kill_test.sh <path to radargauss>
set -u
tool=$1
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
failed=0
checked=0

mkdir -p "$work/out"
"$tool" simulate --out "$work/seq" --scans 120 --seed 5 >/dev/null
seq=(--sequence "$work/seq" --gt "$work/seq/gt_radar_tum.txt")
build=("$tool" build-map "${seq[@]}")
localize=("$tool" localize "${seq[@]}" --map "$work/ref.rgm" --w-rcs 0,0.25)
"${build[@]}" --out "$work/ref.rgm" >/dev/null
"${localize[@]}" --out "$work/ref" >/dev/null

# run_ms <command...>: how long an undisturbed run takes.
run_ms() {
  local start end
  start=$(date +%s%N)
  "$@" >/dev/null 2>&1
  end=$(date +%s%N)
  echo $(((end - start) / 1000000))
}

# whole <file> <reference>: the same bytes, or, where timings differ from run
# to run (per_scan.csv, summary.json, table.md), the same number of lines.
whole() {
  case "$(basename "$1")" in
    per_scan.csv | summary.json | table.md) [ "$(wc -l <"$1")" -eq "$(wc -l <"$2")" ] ;;
    *) cmp -s "$1" "$2" ;;
  esac
}

# kill_at <ms> <command...>: starts the command, kills it after <ms>.
kill_at() {
  local ms=$1
  shift
  "$@" >/dev/null 2>&1 &
  local pid=$!
  sleep "$(awk -v ms="$ms" 'BEGIN { printf "%.3f", ms / 1000 }')"
  kill -9 "$pid" 2>/dev/null
  wait "$pid" 2>/dev/null
}

build_ms=$(run_ms "${build[@]}" --out "$work/timing.rgm")
localize_ms=$(run_ms "${localize[@]}" --out "$work/timing")
for percent in 5 20 40 60 75 85 90 94 97 99; do
  kill_at $((build_ms * percent / 100)) "${build[@]}" --out "$work/out/map.rgm"
  if [ -e "$work/out/map.rgm" ]; then
    checked=$((checked + 1))
    whole "$work/out/map.rgm" "$work/ref.rgm" || { echo "FAIL: build-map killed at $percent %: partial map"; failed=1; }
  fi
  kill_at $((localize_ms * percent / 100)) "${localize[@]}" --out "$work/loc"
  while IFS= read -r file; do
    checked=$((checked + 1))
    whole "$file" "$work/ref/${file#"$work/loc/"}" ||
      { echo "FAIL: localize killed at $percent %: partial ${file#"$work/"}"; failed=1; }
  done < <(find "$work/loc" -type f ! -name '*.radargauss-tmp.*' 2>/dev/null)
done
stale=$(find "$work/out" "$work/loc" -name '*.radargauss-tmp.*' 2>/dev/null | wc -l)
# The next runs that end remove what the killed ones left, and what a
# process killed in the middle of a write leaves (planted: such a moment is
# rarely hit).
true &
ended=$!
wait "$ended"
mkdir -p "$work/loc/trajectories"
for planted in out/map.rgm loc/per_scan.csv loc/trajectories/reference.tum; do
  echo "half" >"$work/$planted.radargauss-tmp.$ended"
done
"${build[@]}" --out "$work/out/map.rgm" >/dev/null
"${localize[@]}" --out "$work/loc" >/dev/null
left=$( (find "$work/out" "$work/loc" -name '*.radargauss-tmp.*'; find "$work" -maxdepth 1 -name '*.radargauss-tmp.*') |
  wc -l)
[ "$left" -eq 0 ] || { echo "FAIL: $left temporaries left after complete runs"; failed=1; }
echo "kill: build-map ${build_ms} ms, localize ${localize_ms} ms per run; $checked files checked after kills," \
  "$stale temporaries left by them"
[ "$failed" -eq 0 ]
