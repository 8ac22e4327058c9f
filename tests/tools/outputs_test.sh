#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# Outputs never replace inputs (docs/design/formats.md, "Bounds on input"): every
# command's outputs against every file and folder it reads, refused in one
# line before the run or as the write would replace a file read, the input
# left as it was; outputs checked writable before the run.
#   outputs_test.sh <path to radargauss>
set -u
tool=$1
timeout_s=60
max_length=300
source "$(dirname "${BASH_SOURCE[0]}")/cli_expect.sh"

"$tool" simulate --out "$work/seq" --scans 6 --seed 2 >/dev/null
seq=(--sequence "$work/seq" --gt "$work/seq/gt_radar_tum.txt")
gt="$work/seq/gt_radar_tum.txt"
first_scan=$(ls "$work/seq/ars548/points" | grep '\.pcd$' | head -1)
scan="$work/seq/ars548/points/$first_scan"
start=$(awk 'NR == 1 { print $1 }' "$gt")
awk -v t="$start" 'BEGIN { for (k = 0; k < 200; ++k) printf "%.3f 0 0 0.01 0 0 9.81\n", t + 0.005 * k }' >"$work/imu.txt"
"$tool" convert "${seq[@]}" --out "$work/own.mcap" >/dev/null
"$tool" build-map "${seq[@]}" --out "$work/map.rgm" >/dev/null
"$tool" odometry "${seq[@]}" --out "$work/run" >/dev/null

# unchanged <file>...: each file byte for byte as keep copied it.
keep() { for f in "$@"; do cp -a "$f" "$f.kept"; done; }
unchanged() {
  for f in "$@"; do
    if cmp -s "$f" "$f.kept"; then passed=$((passed + 1)); else failed=$((failed + 1)); echo "FAIL: $f was changed"; fi
  done
}

keep "$work/own.mcap" "$work/imu.txt" "$gt" "$scan" "$work/map.rgm" "$work/run/odometry.tum"
# The same path as an input, refused before anything is read.
expect_fail "convert onto its own bag" "own.mcap is also read (--bag)" -- \
  "$tool" convert --bag "$work/own.mcap" --topic /radar/points --out "$work/own.mcap"
expect_fail "convert onto its --imu" "imu.txt is also read (--imu)" -- \
  "$tool" convert "${seq[@]}" --imu "$work/imu.txt" --format mcap --out "$work/imu.txt"
expect_fail "convert onto its --gt" "gt_radar_tum.txt is also read (--gt)" -- \
  "$tool" convert "${seq[@]}" --format mcap --out "$gt"
expect_fail "convert onto a bag read as --gt BAG:/topic" "own.mcap is also read (--gt)" -- \
  "$tool" convert --sequence "$work/seq" --gt "$work/own.mcap:/reference/pose" --out "$work/own.mcap"
# A file inside a folder read: refused as the write would replace it.
expect_fail "convert onto one of the sequence's scans" "$first_scan: is read by this run" -- \
  "$tool" convert "${seq[@]}" --format mcap --out "$scan"
expect_fail "export onto the trajectory it reads" "odometry.tum: is read by this run" -- \
  "$tool" export "$work/run" --mcap "$work/run/odometry.tum"
expect_fail "build-map --out its --gt" "is also read (--gt)" -- "$tool" build-map "${seq[@]}" --out "$gt"
expect_fail "build-map --ply its --gt" "is also read (--gt)" -- \
  "$tool" build-map "${seq[@]}" --out "$work/m2.rgm" --ply "$gt"
expect_fail "localize --out the sequence" "is also read (--sequence)" -- \
  "$tool" localize "${seq[@]}" --out "$work/seq"
expect_fail "odometry --out its --gt" "is also read (--gt)" -- "$tool" odometry "${seq[@]}" --out "$gt"
expect_fail "odometry --mcap its --imu" "is also read (--imu)" -- \
  "$tool" odometry "${seq[@]}" --imu "$work/imu.txt" --out "$work/o1" --mcap "$work/imu.txt"
expect_fail "slam --out the sequence" "is also read (--sequence)" -- "$tool" slam "${seq[@]}" --out "$work/seq"
expect_fail "relocalize --out onto its --map's folder" "is also read (--map)" -- \
  "$tool" relocalize "${seq[@]}" --map "$work/map.rgm" --out "$work/map.rgm"
expect_fail "refine --out its --poses" "is also read (--poses)" -- \
  "$tool" refine --sequence "$work/seq" --poses "$gt" --map "$work/map.rgm" --out "$gt"
expect_fail "evaluate --out its --est" "is also read (--est)" -- \
  "$tool" evaluate --est "$work/run/odometry.tum" --ref "$gt" --out "$work/run/odometry.tum"
expect_fail "export --mcap its run folder" "is also read (run)" -- "$tool" export "$work/run" --mcap "$work/run"
printf 'seed: 3\n' >"$work/c.yaml"
keep "$work/c.yaml"
expect_fail "simulate --out its --config" "is also read (--config)" -- "$tool" simulate --config "$work/c.yaml" --out "$work/c.yaml"
unchanged "$work/own.mcap" "$work/imu.txt" "$gt" "$scan" "$work/map.rgm" "$work/run/odometry.tum" "$work/c.yaml"

# Two outputs on one path; outputs that cannot be written: refused before the run, nothing left.
expect_fail "odometry --out X --mcap X" "--out and --mcap name the same path" -- \
  "$tool" odometry "${seq[@]}" --out "$work/X" --mcap "$work/X"
[[ ! -e "$work/X" ]] || { echo "FAIL: a refused run left its folder"; failed=$((failed + 1)); }
expect_fail "odometry --mcap into /proc" "/proc/x.mcap: cannot be written" -- \
  "$tool" odometry "${seq[@]}" --out "$work/p" --mcap /proc/x.mcap
[[ ! -e "$work/p" ]] || { echo "FAIL: a refused run left its folder"; failed=$((failed + 1)); }
expect_fail "slam --mcap into a missing folder" "absent/x.mcap: its folder does not exist" -- \
  "$tool" slam "${seq[@]}" --out "$work/q" --mcap "$work/absent/x.mcap"
[[ ! -e "$work/q" ]] || { echo "FAIL: a refused run left its folder"; failed=$((failed + 1)); }
expect_fail "odometry --out inside /proc" "cannot be written" -- "$tool" odometry "${seq[@]}" --out /proc/results

# A run whose outputs are beside its inputs, not on them, runs.
expect_ok "export into the run's folder under a new name" "wrote" -- \
  "$tool" export "$work/run" --mcap "$work/run/run.mcap"
expect_ok "convert beside the sequence's scans" "wrote" -- \
  "$tool" convert "${seq[@]}" --out "$work/seq/ars548/points/bag.mcap"

# Stale temporaries of a killed writer (the bag writer's old and current names) are removed by the next write.
touch "$work/stale.mcap.radargauss-partial.999999999" "$work/stale.mcap.radargauss-tmp.999999998"
"$tool" convert "${seq[@]}" --out "$work/fresh.mcap" >/dev/null
leftovers=$(find "$work" -maxdepth 1 -name '*.radargauss-*' | wc -l)
if [ "$leftovers" -eq 0 ]; then passed=$((passed + 1)); else failed=$((failed + 1)); echo "FAIL: $leftovers stale temporaries"; fi

echo "outputs: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
