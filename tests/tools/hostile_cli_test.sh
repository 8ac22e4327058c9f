#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# Hostile input through the command-line tool (docs/design/formats.md, "Bounds on
# input"): one line naming the file and the fault, a non-zero exit, at once.
#   hostile_cli_test.sh <path to radargauss> <source dir> [privileged]
set -u
tool=$1
data=$2/tests/data/fuzz
timeout_s=20   # every refusal comes at once
max_length=200
source "$(dirname "${BASH_SOURCE[0]}")/cli_expect.sh"

"$tool" simulate --out "$work/seq" --scans 4 --seed 2 >/dev/null
seq=(--sequence "$work/seq" --gt "$work/seq/gt_radar_tum.txt")

# The cases that need root's powers (mknod, mount) run as a test of their own,
# "privileged", which exits with 77 (ctest: skipped) when it may not run them.
if [ "${3:-}" = privileged ]; then
  skipped=0
  if mknod "$work/null" c 1 3 2>/dev/null; then
    expect_fail "build-map --out a device node" "null: is not a regular file" -- \
      "$tool" build-map "${seq[@]}" --out "$work/null"
    [[ -c "$work/null" ]] || { echo "FAIL: the device node was replaced"; failed=$((failed + 1)); }
  else
    echo "skipped: build-map --out a device node (mknod not permitted here)"; skipped=$((skipped + 1))
  fi

  # A full disk: the results folder is the old one or none, never a part.
  disk="$work/disk"
  mkdir -p "$disk"
  if mount -t tmpfs -o size=16k tmpfs "$disk" 2>/dev/null; then
    "$tool" simulate --out "$work/big" --scans 30 --seed 4 >/dev/null
    "$tool" build-map "${seq[@]}" --out "$work/map.rgm" >/dev/null
    for command in odometry localize; do
      extra=()
      [ "$command" = localize ] && extra=(--map "$work/map.rgm" --w-rcs 0,0.5,1 --solver gn,ceres)
      expect_fail "$command on a full disk" "No space left\|write failed\|cannot" -- \
        "$tool" "$command" --sequence "$work/big" --gt "$work/big/gt_radar_tum.txt" "${extra[@]}" --out "$disk/$command"
      [[ ! -e "$disk/$command" ]] || { echo "FAIL: $command left part of its folder"; failed=$((failed + 1)); }
    done
    mkdir -p "$disk/old" && echo "the old results" >"$disk/old/odometry.tum"
    expect_fail "odometry over old results on a full disk" "" -- \
      "$tool" odometry --sequence "$work/big" --gt "$work/big/gt_radar_tum.txt" --out "$disk/old"
    [ "$(cat "$disk/old/odometry.tum")" = "the old results" ] && [ "$(ls "$disk/old")" = odometry.tum ] ||
      { echo "FAIL: the old results were changed"; failed=$((failed + 1)); }
    leftovers=$(find "$disk" -maxdepth 1 -name '*.radargauss-tmp.*' | wc -l)
    [ "$leftovers" -eq 0 ] || { echo "FAIL: $leftovers staging folders left on the full disk"; failed=$((failed + 1)); }
    umount "$disk"
  else
    echo "skipped: the full-disk cases (mounting a tmpfs is not permitted here)"; skipped=$((skipped + 1))
  fi
  echo "hostile cli, privileged: $passed passed, $failed failed, $skipped skipped"
  [ "$failed" -eq 0 ] || exit 1
  [ "$skipped" -eq 0 ] || exit 77
  exit 0
fi

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

# Configuration files: bounded, one document, no key twice, no special file.
head -c 2000000 /dev/zero | tr '\0' '#' >"$work/big.yaml"
expect_fail "a 2 MB config" "big.yaml: configuration file of 2000000 bytes, more than 1048576" -- \
  "$tool" build-map --config "$work/big.yaml" "${seq[@]}" --out "$work/m.rgm"
expect_fail "/dev/zero as config" "/dev/zero: is a character device, not a configuration file" -- \
  "$tool" build-map --config /dev/zero "${seq[@]}" --out "$work/m.rgm"
mkfifo "$work/fifo.yaml"
expect_fail "a FIFO as config, at once" "fifo.yaml: is a FIFO, not a configuration file" -- \
  "$tool" odometry --config "$work/fifo.yaml" "${seq[@]}" --out "$work/o"
printf 'w-rcs: 0.25\nseed: 3\nw-rcs: 0.5\n' >"$work/twice.yaml"
expect_fail "a key given twice" "twice.yaml:3: key 'w-rcs' given twice (first on line 1)" -- \
  "$tool" localize --config "$work/twice.yaml" "${seq[@]}" --out "$work/l"
printf 'seed: 3\n---\nseed: 4\n' >"$work/two.yaml"
expect_fail "a second YAML document" "two.yaml: more than one YAML document" -- \
  "$tool" localize --config "$work/two.yaml" "${seq[@]}" --out "$work/l"
printf 'b\033]0;retitled\007ogus: 1\n' >"$work/escape.yaml"
expect_fail "escape sequences in a key are escaped" "unknown flag 'b.x1b]0;retitled.x07ogus'" -- \
  "$tool" localize --config "$work/escape.yaml" "${seq[@]}"
if grep -q $'\033' "$work/err"; then echo "FAIL: a raw escape byte reached the terminal"; failed=$((failed + 1)); fi
printf 'align: first\n' >"$work/evaluate.yaml"
expect_ok "evaluate reads --config" "first alignment" -- \
  "$tool" evaluate --config "$work/evaluate.yaml" --est "$work/seq/gt_radar_tum.txt" --ref "$work/seq/gt_radar_tum.txt"
printf 'bogus: 1\n' >"$work/evaluate_bogus.yaml"
expect_fail "evaluate names an unknown config key" "evaluate_bogus.yaml: unknown flag 'bogus'" -- \
  "$tool" evaluate --config "$work/evaluate_bogus.yaml" --est "$work/seq/gt_radar_tum.txt" --ref "$work/seq/gt_radar_tum.txt"

# Numbers: bounded where a square or a cell count follows, unit quaternions.
for sigma in 1e300 1e160 101; do
  expect_fail "coarse sigma $sigma, at once" "coarse-sigmas: $sigma is not in \[0, 100\]" -- \
    "$tool" odometry --coarse-sigmas "$sigma" "${seq[@]}" --out "$work/o"
done
expect_fail "an index cell of 1e300" "index-cell: 1e300 is not in \[0.1, 100\]" -- \
  "$tool" odometry --index-cell 1e300 "${seq[@]}" --out "$work/o"
expect_fail "a zero quaternion" "--imu-rotation: not a unit quaternion (x y z w), its norm is 0" -- \
  "$tool" odometry --imu-topic /imu --imu-rotation 0 0 0 0 "${seq[@]}" --out "$work/o"
# IMU files: refused before the run, naming the file and line; nothing written.
printf '1702450000.00 0 0 0 0 0 9.8\n1702450000.01 0 0 0 0 0 9.8\n1702450000.005 0 0 0 0 0 9.8\n' >"$work/imu_back.txt"
printf '1702450000.00 0 0 0 0 0 9.8\n1702450000.01 0 nan 0 0 0 9.8\n' >"$work/imu_nan.txt"
printf '1702450000.00 0 0 0 0 0 9.8\n1702450000.01 0 0 0' >"$work/imu_cut.txt"
printf '5 0 0 0 0 0 9.8\n6 0 0 0 0 0 9.8\n' >"$work/imu_far.txt"
expect_fail "an IMU stamp going back" "imu_back.txt:3: stamp does not increase" -- \
  "$tool" odometry --imu "$work/imu_back.txt" "${seq[@]}" --out "$work/imu_o"
expect_fail "a NaN in an IMU file" "imu_nan.txt:2: non-finite value" -- \
  "$tool" odometry --imu "$work/imu_nan.txt" "${seq[@]}" --out "$work/imu_o"
expect_fail "an IMU file that ends mid-line" "imu_cut.txt:2: expected 7 columns (stamp wx wy wz ax ay az), found 4" -- \
  "$tool" info --imu "$work/imu_cut.txt"
expect_fail "an IMU that covers none of the scans" "the IMU's stamps (5.000000 to 6.000000 s) do not overlap the scans'" -- \
  "$tool" odometry --imu "$work/imu_far.txt" "${seq[@]}" --out "$work/imu_o"
# A 1 kHz file of 10^7 lines (sparse: no disk) is refused by its size, unread.
truncate -s 800M "$work/imu_huge.txt"
expect_fail "an IMU file of 10^7 lines" "imu_huge.txt: IMU file of 838860800 bytes, more than 671088640" -- \
  "$tool" odometry --imu "$work/imu_huge.txt" "${seq[@]}" --out "$work/imu_o"
rm -f "$work/imu_huge.txt"
# An IMU that ends a tenth of a second into the drive: the radar-inertial window stops there, nothing is written.
first=$(awk '!/^#/ { print $1; exit }' "$work/seq/gt_radar_tum.txt")
awk -v t0="$first" 'BEGIN { for (k = 0; k <= 20; ++k) printf "%.6f 0 0 0 0 0 9.81\n", t0 + k * 0.005 }' >"$work/imu_short.txt"
expect_fail "an IMU that ends before the scans" "the IMU has no sample from" -- \
  "$tool" odometry --imu "$work/imu_short.txt" "${seq[@]}" --out "$work/imu_o"
expect_fail "--imu-extrinsic without an IMU" "--imu-extrinsic needs an IMU (--imu or --imu-topic)" -- \
  "$tool" odometry --imu-extrinsic "$work/imu_far.txt" "${seq[@]}" --out "$work/imu_o"
[[ ! -e "$work/imu_o" ]] || { echo "FAIL: a refused IMU left odometry output"; failed=$((failed + 1)); }
# The IMU's settings without its topic, and its topic without a bag: refused, each flag named.
expect_fail "--imu-rotation without --imu-topic" "--imu-rotation requires --imu-topic" -- \
  "$tool" odometry --imu-rotation 0 0 0 1 "${seq[@]}" --out "$work/o"
expect_fail "--imu-stamps without --imu-topic" "--imu-stamps requires --imu-topic" -- \
  "$tool" odometry --imu-stamps record "${seq[@]}" --out "$work/o"
expect_fail "--imu-topic without --bag" "--imu-topic needs --bag" -- \
  "$tool" odometry --imu-topic /imu "${seq[@]}" --out "$work/o"
awk '{ $2 = 5; $3 = 5; $4 = 5; print }' "$work/seq/gt_radar_tum.txt" >"$work/still.tum"
expect_fail "sim3 of an estimate that never moves" "a sim3 alignment needs an estimate that moves" -- \
  "$tool" evaluate --align sim3 --est "$work/still.tum" --ref "$work/seq/gt_radar_tum.txt"
awk '{ $1 = sprintf("%.9f", $1 + 1000); print }' "$work/seq/gt_radar_tum.txt" >"$work/later.tum"
expect_fail "odometry's --gt of another time" "later.tum: --gt: 0 of the 4 scans lie in the reference's time span" -- \
  "$tool" odometry --sequence "$work/seq" --gt "$work/later.tum" --out "$work/o"
[[ ! -e "$work/o" ]] || { echo "FAIL: a refused odometry left its output"; failed=$((failed + 1)); }

# Every unbounded number flag at both extremes: a result or a one-line
# refusal within the timeout, never a hang or a crash (squares, cell counts
# and region counts derive from them).
for command in odometry slam localize build-map; do
  while read -r flag count; do
    for value in 1e300 1e-300; do
      values=()
      for ((k = 0; k < count; ++k)); do values+=("$value"); done
      out="$work/sweep.rgm"; [ "$command" = build-map ] || out="$work/sweep"
      timeout "$timeout_s" "$tool" "$command" "${seq[@]}" "$flag" "${values[@]}" --out "$out" >/dev/null 2>"$work/err"
      status=$?
      if [ "$status" -ge 124 ] || [ "$(wc -l <"$work/err")" -gt 2 ]; then
        failed=$((failed + 1)); echo "FAIL: $command $flag $value: exit $status"; head -c 600 "$work/err"
      else
        passed=$((passed + 1))
      fi
    done
  done < <("$tool" "$command" --help |
    awk '$0 ~ /^ *--[a-z-]+ FLOAT:[[(]0, inf\)/ { n = 1; if (match($0, / x [0-9]+/)) n = substr($0, RSTART + 3, RLENGTH - 3); print $1, n }')
done

# Special files as inputs: named by type, at once.
expect_fail "map-info /dev/zero" "/dev/zero: is a character device, not a map" -- "$tool" map-info /dev/zero
expect_fail "info --gt /dev/zero" "/dev/zero: is a character device, not a TUM trajectory" -- \
  "$tool" info --sequence "$work/seq" --gt /dev/zero
expect_fail "evaluate --est /dev/zero" "/dev/zero: is a character device, not a TUM trajectory" -- \
  "$tool" evaluate --est /dev/zero --ref "$work/seq/gt_radar_tum.txt"
expect_fail "an extrinsic from /dev/zero" "/dev/zero: is a character device, not a pose file (extrinsic)" -- \
  "$tool" info "${seq[@]}" --extrinsic /dev/zero

# A map of another place: refine refuses it before refining.
"$tool" build-map "${seq[@]}" --out "$work/map.rgm" >/dev/null
awk '{ $2 = sprintf("%.9f", $2 + 1000); print }' "$work/seq/gt_radar_tum.txt" >"$work/far.tum"
expect_fail "refine on a map the scans miss" "map.rgm: 0.0 % of the scans' points lie near the map" -- \
  "$tool" refine --sequence "$work/seq" --poses "$work/far.tum" --extrinsic identity --map "$work/map.rgm" --out "$work/r"
[[ ! -e "$work/r" ]] || { echo "FAIL: a refused refine left its output"; failed=$((failed + 1)); }

# SLAM and relocalisation: a map without places, an empty sequence, a missing map.
expect_fail "relocalize on a map without places" "map.rgm: the map has no places to relocalise against" -- \
  "$tool" relocalize --map "$work/map.rgm" --sequence "$work/seq" --out "$work/rl"
[[ ! -e "$work/rl" ]] || { echo "FAIL: a refused relocalize left its output"; failed=$((failed + 1)); }
expect_fail "relocalize on a missing map" "absent.rgm" -- \
  "$tool" relocalize --map "$work/absent.rgm" --sequence "$work/seq" --out "$work/rl"
mkdir -p "$work/empty"
expect_fail "slam on an empty sequence" "empty: no scans found" -- "$tool" slam --sequence "$work/empty" --out "$work/sl"
[[ ! -e "$work/sl" ]] || { echo "FAIL: a refused slam left its output"; failed=$((failed + 1)); }
expect_fail "slam with a PCL matcher" "not expected: pcl-ndt --matcher" -- \
  "$tool" slam --matcher pcl-ndt "${seq[@]}" --out "$work/sl"

# Empty input is refused before the run, naming the sequence or the flag.
expect_fail "slam --first-scan past the end" "--first-scan 40 skips every one of the 4 scans of $work/seq" -- \
  "$tool" slam --first-scan 40 "${seq[@]}" --out "$work/sl"
expect_fail "odometry --first-scan 2^64-1" "--first-scan 18446744073709551615 skips every one of the 4 scans" -- \
  "$tool" odometry --first-scan 18446744073709551615 "${seq[@]}" --out "$work/o"
mkdir -p "$work/hollow/ars548/points"
for pcd in "$work"/seq/ars548/points/*.pcd; do
  sed -n '1,11p' "$pcd" | sed -e 's/^WIDTH .*/WIDTH 0/' -e 's/^POINTS .*/POINTS 0/' >"$work/hollow/ars548/points/$(basename "$pcd")"
done
expect_fail "slam on scans without points" "hollow: every one of the 4 scans has no points" -- \
  "$tool" slam --sequence "$work/hollow" --out "$work/sl"
[[ ! -e "$work/sl" ]] || { echo "FAIL: a refused slam left its output"; failed=$((failed + 1)); }
# A map with places and no Gaussian: named with the fault.
"$tool" slam "${seq[@]}" --submap-distance 2 --out "$work/slam" >/dev/null
/usr/bin/python3 - "$work/slam/map.rgm" "$work/placesonly.rgm" <<'PY'
import struct, sys, zlib
data = open(sys.argv[1], "rb").read()
count = struct.unpack_from("<Q", data, 16)[0]
body = data[:16] + struct.pack("<Q", 0) + data[24 + 260 * count:-4]
open(sys.argv[2], "wb").write(body + struct.pack("<I", zlib.crc32(body)))
PY
expect_fail "relocalize on a map without Gaussians" "placesonly.rgm: the map has no Gaussians to match against" -- \
  "$tool" relocalize --map "$work/placesonly.rgm" "${seq[@]}" --out "$work/rl"

# Results folders: not the sequence's own folder, not a shared one; an
# earlier run's evaluation does not stay beside a new trajectory.
expect_fail "odometry into the sequence's folder" "seq is also read (--sequence)" -- \
  "$tool" odometry "${seq[@]}" --out "$work/seq"
mkdir -p "$work/shared" && chmod 1777 "$work/shared"
"$tool" build-map "${seq[@]}" --out "$work/shared_map.rgm" >/dev/null
for args in "odometry" "slam" "relocalize --map $work/slam/map.rgm" "localize --map $work/shared_map.rgm" \
  "refine --poses $work/seq/gt_radar_tum.txt --extrinsic identity --map $work/shared_map.rgm"; do
  read -r -a command <<<"$args"
  expect_fail "${command[0]} into a sticky shared folder" "shared: is a shared folder (sticky bit" -- \
    "$tool" "${command[@]}" "${seq[@]}" --out "$work/shared"
done
expect_fail "evaluate into a sticky shared folder" "shared: is a shared folder (sticky bit" -- \
  "$tool" evaluate --est "$work/seq/gt_radar_tum.txt" --ref "$work/seq/gt_radar_tum.txt" --out "$work/shared"
# An IMU from a reference: one too short to smooth, one that is not TUM.
expect_fail "simulate-imu on a reference too short" "a smooth motion needs four" -- \
  "$tool" simulate-imu --gt "$work/seq/gt_radar_tum.txt" --out "$work/imu_short"
printf '0 0 0 0 0 0 0 1\nnot a pose\n' >"$work/not_tum.txt"
expect_fail "simulate-imu on a reference that is not TUM" "not_tum.txt" -- \
  "$tool" simulate-imu --gt "$work/not_tum.txt" --out "$work/imu_bad"
[ ! -e "$work/imu_short/imu.txt" ] && [ ! -e "$work/imu_bad/imu.txt" ] ||
  { echo "FAIL: simulate-imu left an imu.txt behind a refusal"; failed=$((failed + 1)); }
expect_fail "simulate into a sticky shared folder" "shared: is a shared folder (sticky bit" -- \
  "$tool" simulate --scans 2 --out "$work/shared"
[ -z "$(ls -A "$work/shared")" ] || { echo "FAIL: a refused run wrote into the shared folder"; failed=$((failed + 1)); }
mkdir -p "$work/private" && chmod 0700 "$work/private"
"$tool" slam "${seq[@]}" --submap-distance 2 --out "$work/private" >/dev/null
[ -e "$work/private/evaluation.json" ] || { echo "FAIL: slam --gt wrote no evaluation"; failed=$((failed + 1)); }
"$tool" slam --sequence "$work/seq" --submap-distance 2 --out "$work/private" >/dev/null
if [ -e "$work/private/evaluation.json" ] || [ -e "$work/private/odometry/evaluation.json" ]; then
  echo "FAIL: an earlier run's evaluation stayed beside the new trajectory"; failed=$((failed + 1))
else
  passed=$((passed + 1))
fi
[ "$(stat -c %a "$work/private")" = 700 ] && passed=$((passed + 1)) ||
  { echo "FAIL: the results folder lost its mode 0700 ($(stat -c %a "$work/private"))"; failed=$((failed + 1)); }

# Aliases of aliases ("billion laughs"): refused at once by every command.
{
  echo 'l0: &l0 [x, x, x, x, x, x, x, x, x, x]'
  for level in 1 2 3 4 5 6 7 8 9; do
    echo "l$level: &l$level [$(printf "*l$((level - 1)), %.0s" 1 2 3 4 5 6 7 8 9)*l$((level - 1))]"
  done
} >"$work/laughs.yaml"
for command in build-map simulate odometry localize slam relocalize; do
  inputs=("${seq[@]}")
  [ "$command" = simulate ] && inputs=()
  expect_fail "$command: a billion laughs" "laughs.yaml:6: more than 262144 YAML nodes with aliases expanded" -- \
    "$tool" "$command" --config "$work/laughs.yaml" "${inputs[@]}" --out "$work/laughs"
done

# Negative stamps order numerically (as text -1 would come before -2).
mkdir -p "$work/negative"
stamps=(-2.000000000 -1.000000000 0.500000000)
i=0
for name in $(ls "$work/seq/ars548/points" | grep '\.pcd$' | head -3); do
  cp "$work/seq/ars548/points/$name" "$work/negative/${stamps[$i]}.pcd"
  i=$((i + 1))
done
expect_ok "negative stamps in numeric order" "time span: -2.000000000 .. 0.500000000" -- "$tool" info --sequence "$work/negative"

# Outputs: only regular files or nothing are replaced; two-file outputs
# check both destinations first.
mkfifo "$work/out.fifo"
expect_fail "build-map --out a FIFO" "out.fifo: is not a regular file" -- \
  "$tool" build-map "${seq[@]}" --out "$work/out.fifo"
[[ -p "$work/out.fifo" ]] || { echo "FAIL: the FIFO was replaced"; failed=$((failed + 1)); }
expect_fail "build-map --ply into a missing folder" "absent/map.ply: its folder does not exist" -- \
  "$tool" build-map "${seq[@]}" --out "$work/two.rgm" --ply "$work/absent/map.ply"
[[ ! -e "$work/two.rgm" ]] || { echo "FAIL: the .rgm was written before the --ply was checked"; failed=$((failed + 1)); }
touch "$work/a_file"
expect_fail "odometry --out a file" "a_file: exists and is not a folder" -- "$tool" odometry "${seq[@]}" --out "$work/a_file"


# ROS 2 bags (docs/design/formats.md, "ROS 2 bags"): a bag of the sequence, then lies about it.
"$tool" convert "${seq[@]}" --out "$work/seq.mcap" >/dev/null
bag_bytes=$(stat -c %s "$work/seq.mcap")
head -c $((bag_bytes - 100)) "$work/seq.mcap" >"$work/cut.mcap"
expect_fail "odometry on a truncated .mcap" "cut.mcap: MCAP file is truncated" -- \
  "$tool" odometry --bag "$work/cut.mcap" --topic /radar/points --out "$work/cut_run"
[[ ! -e "$work/cut_run" ]] || { echo "FAIL: a failed odometry left its output folder"; failed=$((failed + 1)); }
# The first chunk's uncompressed size (after magic, header record and the chunk's times) set to 10 GB.
cp "$work/seq.mcap" "$work/huge.mcap"
printf '\x00\x00\x00\x80\x02\x00\x00\x00' | dd of="$work/huge.mcap" bs=1 seek=$((8 + 31 + 9 + 16)) conv=notrunc 2>/dev/null
expect_fail "a chunk that claims 10 GB" "MiB limit" -- "$tool" info --bag "$work/huge.mcap" --topic /radar/points
/usr/bin/python3 -c "import sqlite3, sys; c = sqlite3.connect(sys.argv[1]); c.execute('create table notes(t)'); c.commit()" \
  "$work/notes.db3"
expect_fail "a sqlite file that is not a bag" "not a rosbag2 sqlite3 file" -- \
  "$tool" info --bag "$work/notes.db3"
mkdir -p "$work/escape"
printf 'rosbag2_bagfile_information:\n  relative_file_paths: [../seq.mcap]\n' >"$work/escape/metadata.yaml"
expect_fail "a rosbag2 folder that points outside itself" "not inside the bag's folder" -- \
  "$tool" info --bag "$work/escape"
expect_fail "convert to an unknown format" "say --format" -- "$tool" convert "${seq[@]}" --out "$work/seq.bag2"
expect_fail "convert into a missing folder" "radargauss: error:" -- \
  "$tool" convert "${seq[@]}" --out "$work/absent/seq.mcap"
printf 'not a bag at all\n' >"$work/text.mcap"
expect_fail "a text file named .mcap" "not a bag" -- "$tool" info --bag "$work/text.mcap"

# IMU values past any IMU, extrinsics that are not poses, references that name no bag or no child frame.
printf '1702450000.00 0 0 0 0 0 9.8\n1702450000.01 1e300 0 0 0 0 9.8\n' >"$work/imu_1e300.txt"
expect_fail "an IMU sample of 1e300 rad/s" "imu_1e300.txt:2: angular rate 1e+300 rad/s is past any IMU's 10000" -- \
  "$tool" odometry --imu "$work/imu_1e300.txt" "${seq[@]}" --out "$work/imu_o"
printf '0 0 nan 0 0 0 1\n' >"$work/extrinsic_nan.txt"
expect_fail "an extrinsic holding NaN, no --gt to use it" "extrinsic_nan.txt: extrinsic holds nan, a value that is not finite" -- \
  "$tool" odometry --sequence "$work/seq" --extrinsic "$work/extrinsic_nan.txt" --out "$work/en"
expect_fail "--gt with no bag before ':/'" "no bag before ':/'" -- "$tool" info --sequence "$work/seq" --gt :/radar/pose
"$tool" odometry "${seq[@]}" --out "$work/tf_run" --mcap "$work/tf_run.mcap" >/dev/null
expect_fail "--gt BAG:/tf without a child frame" "holds transforms (tf2_msgs/TFMessage): name the child frame" -- \
  "$tool" info --sequence "$work/seq" --gt "$work/tf_run.mcap:/tf"

# convert: topics a reader finds again, distinct; stamps ROS can hold, named by their file.
printf -- '-5 0 0 0 0 0 9.8\n-4.99 0 0 0 0 0 9.8\n' >"$work/imu_negative.txt"
expect_fail "convert with an empty scan topic" "--scan-topic '' is empty" -- \
  "$tool" convert "${seq[@]}" --out "$work/t.mcap" --scan-topic ''
expect_fail "convert's IMU on the scans' topic" "--scan-topic and --imu-topic-out are both /radar/points" -- \
  "$tool" convert "${seq[@]}" --imu "$work/imu_negative.txt" --out "$work/t.mcap" --imu-topic-out /radar/points
expect_fail "convert's poses on the scans' topic" "--scan-topic and --pose-topic are both /radar/points" -- \
  "$tool" convert "${seq[@]}" --out "$work/t.mcap" --pose-topic /radar/points
expect_fail "convert with a topic of two slashes" "--pose-topic '/a//b' has a part that is empty" -- \
  "$tool" convert "${seq[@]}" --out "$work/t.mcap" --pose-topic /a//b
expect_fail "convert of an IMU stamped before 1970" "imu_negative.txt: IMU stamp -5.000000 s does not fit ROS's time" -- \
  "$tool" convert "${seq[@]}" --imu "$work/imu_negative.txt" --out "$work/t.mcap"
[[ ! -e "$work/t.mcap" ]] || { echo "FAIL: a refused convert left its bag"; failed=$((failed + 1)); }

# Map tiles whose index lies: refused before a tile is read, by every reader.
"$tool" slam "${seq[@]}" --out "$work/slam_tiles" --submap-distance 2 --map-tiles 100 >/dev/null
ln -s "$work/slam_tiles/map_tiles" "$work/tiles"
cp "$work/tiles/tiles.json" "$work/tiles.json.good"
spoil_index() {
  /usr/bin/python3 -c "import json, sys; j = json.load(open(sys.argv[1])); $1; json.dump(j, open(sys.argv[1], 'w'))" \
    "$work/tiles/tiles.json"
}
for past in 50 1000000; do
  cp "$work/tiles.json.good" "$work/tiles/tiles.json"
  spoil_index "j['order'] = [[0, j['tiles'][0]['gaussians'] + $past], [0, 2**64 - $past]]"
  expect_fail "tile order runs that wrap past 2^64 ($past)" "more Gaussians of tile" -- "$tool" map-info "$work/tiles"
  expect_fail "relocalize on tiles that wrap ($past)" "more Gaussians of tile" -- \
    "$tool" relocalize "${seq[@]}" --map "$work/tiles" --out "$work/wrap"
done
cp "$work/tiles.json.good" "$work/tiles/tiles.json"
spoil_index "j['tiles'].append(j['tiles'][0])"
expect_fail "a tile listed twice" "listed twice" -- "$tool" map-info "$work/tiles"
cp "$work/tiles.json.good" "$work/tiles/tiles.json"
spoil_index "j['places'] = 10**9"
expect_fail "an index declaring 10^9 places" "places in its tiles for 1000000000 places" -- "$tool" map-info "$work/tiles"
cp "$work/tiles.json.good" "$work/tiles/tiles.json"
spoil_index "j['tiles'] += [dict(x=9000 + k, y=1, file='tile_%d_1.rgm' % (9000 + k), gaussians=1, places=[]) for k in range(10**6)]"
expect_fail "10^6 tiles, none present, the first named" "tile_9000_1.rgm: cannot open map tile" -- \
  "$tool" map-info "$work/tiles"

echo "hostile cli: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
