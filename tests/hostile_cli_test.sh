#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# Hostile input through the command-line tool (docs/design.md, "Bounds on
# input"): one line naming the file and the fault, a non-zero exit, at once.
#   hostile_cli_test.sh <path to radargauss> <source dir>
set -u
tool=$1
data=$2/tests/data/fuzz
timeout_s=20   # every refusal comes at once
max_length=200
source "$(dirname "${BASH_SOURCE[0]}")/cli_expect.sh"

"$tool" simulate --out "$work/seq" --scans 4 --seed 2 >/dev/null
seq=(--sequence "$work/seq" --gt "$work/seq/gt_radar_tum.txt")
for command in info build-map localize odometry; do
  expect_fail "$command: a YAML key that is a list" "key_not_a_scalar.yaml: line 1: a key must be a flag name" -- \
    "$tool" "$command" --config "$data/cli_yaml/key_not_a_scalar.yaml" "${seq[@]}"
  expect_fail "$command: a map inside a list" "map_in_a_list.yaml: 'a' (line 1): a list of values" -- \
    "$tool" "$command" --config "$data/cli_yaml/map_in_a_list.yaml" "${seq[@]}"
done
printf 'bogus: 1\n' >"$work/extra.yaml"
expect_fail "unknown config key names the file, not INI" "extra.yaml: unknown flag 'bogus'" -- \
  "$tool" localize --config "$work/extra.yaml" "${seq[@]}"
expect_fail "a directory as config" "$work" -- "$tool" localize --config "$work" "${seq[@]}"
expect_fail "negative threads, brief range" "threads: -1 is not in \[0, inf)" -- "$tool" --threads -1 info "${seq[@]}"
expect_fail "NaN weight before the sequence is read" "w-rcs: nan is not a finite number" -- \
  "$tool" localize --w-rcs nan --sequence "$work/absent"
expect_fail "inf points per Gaussian" "points-per-gaussian: inf is not a finite number" -- \
  "$tool" build-map --points-per-gaussian inf "${seq[@]}" --out "$work/m.rgm"
expect_fail "NaN in a config file" "is not a finite number" -- \
  bash -c "printf 'velocity-weight: .nan\n' > '$work/nan.yaml'; '$tool' odometry --config '$work/nan.yaml' --sequence '$work/seq'"
expect_fail "simulator YAML with a list as key" "key_not_a_scalar.yaml:1: a key must be a parameter name" -- \
  "$tool" simulate --config "$data/simulator_yaml/key_not_a_scalar.yaml" --out "$work/s1"
expect_fail "simulator YAML with NaN" "attitude_wobble_deg must be a finite number" -- \
  "$tool" simulate --config "$data/simulator_yaml/nan_wobble.yaml" --out "$work/s2"
[[ ! -e "$work/s2" ]] || { echo "FAIL: a refused simulation left its output"; failed=$((failed + 1)); }
expect_fail "a 10 km Gaussian" "std_10km.rgm: Gaussian 0: covariance with principal stds outside" -- \
  "$tool" localize --map "$data/map_file/std_10km.rgm" "${seq[@]}" --out "$work/r1"
expect_fail "a mean of 1e300" "mean_1e300.rgm: Gaussian 0: mean beyond" -- "$tool" map-info "$data/map_file/mean_1e300.rgm"
expect_fail "a NaN RCS median" "non-finite RCS model" -- "$tool" map-info "$data/map_file/nan_rcs_median.rgm"
expect_fail "a directory as map" "is a directory, not a map" -- "$tool" map-info "$work"
expect_fail "a directory as ground truth" "is a directory, not a TUM trajectory" -- \
  "$tool" info --sequence "$work/seq" --gt "$work"
mkdir -p "$work/wide"
cp "$data/pcd/fields_4096.pcd" "$work/wide/1702450000.000000000.pcd"
expect_fail "a PCD of 4096 fields" "4096 FIELDS, more than 256" -- "$tool" info --sequence "$work/wide"

echo "hostile cli: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
