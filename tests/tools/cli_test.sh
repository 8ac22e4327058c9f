#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# End-to-end checks of the radargauss command-line tool: good runs work, bad
# input gives a one-line error on stderr and a non-zero exit.
#   cli_test.sh <path to radargauss> [pcl|bag]
set -u
tool=$1
source "$(dirname "${BASH_SOURCE[0]}")/cli_expect.sh"

# The cases on optional parts run as tests of their own: "pcl" (the PCL
# peers) and "bag" (the ROS1 bag reader and the TI bag of ../shared); each
# exits with 77 (ctest: skipped) when its part is absent.
skipped=0
finish_section() {
  echo "cli, $1: $passed passed, $failed failed, $skipped skipped"
  [ "$failed" -eq 0 ] || exit 1
  [ "$skipped" -eq 0 ] || exit 77
  exit 0
}
if [ "${2:-}" = pcl ]; then
  "$tool" simulate --out "$work/seq10" --scans 10 >/dev/null
  if "$tool" odometry --sequence "$work/seq10" --matcher pcl-gicp --max-scans 2 --out "$work/odometry_probe" \
       2>&1 | grep -q "RADARGAUSS_WITH_PCL"; then
    echo "skipped: radargauss built without PCL"; skipped=$((skipped + 1))
  else
    expect_ok "odometry with PCL GICP as the loop's matcher" "wrote $work/odometry_gicp" -- \
      "$tool" odometry --sequence "$work/seq10" --matcher pcl-gicp --out "$work/odometry_gicp"
  fi
  finish_section pcl
fi
if [ "${2:-}" = bag ]; then
  ti_bag="$(cd "$(dirname "$0")/../.." && pwd)/../shared/data/ti_mmwave_demo/demo_ti_mmwave_rospkg_format.bag"
  if [[ -f "$ti_bag" ]] && "$tool" info --bag "$ti_bag" >/dev/null 2>&1; then
    expect_ok "odometry on the TI bag with its IMU" "wrote $work/ti" -- \
      "$tool" odometry --bag "$ti_bag" --topic /ti_mmwave/radar_scan_pcl --rcs-field none --max-scans 60 \
      --imu-topic /sensor_platform/imu --imu-stamps record --out "$work/ti"
    expect_ok "info on the TI bag's IMU" "imu: 8270 samples" -- \
      "$tool" info --bag "$ti_bag" --imu-topic /sensor_platform/imu
    expect_fail "odometry on a bag without the topic" "no messages on topic" -- \
      "$tool" odometry --bag "$ti_bag" --topic /absent --out "$work/ti_absent"
    expect_fail "odometry with an IMU topic of the wrong type" "not sensor_msgs/Imu" -- \
      "$tool" odometry --bag "$ti_bag" --topic /ti_mmwave/radar_scan_pcl --rcs-field none \
      --imu-topic /sensor_platform/baro --out "$work/ti_baro"
    expect_fail "odometry with IMU stamps on another clock" "do not overlap" -- \
      "$tool" odometry --bag "$ti_bag" --topic /ti_mmwave/radar_scan_pcl --rcs-field none \
      --imu-topic /sensor_platform/imu --out "$work/ti_clock"
    [[ ! -e "$work/ti_clock" ]] || { echo "FAIL: a failed odometry left its output folder"; failed=$((failed + 1)); }
    # Through a ROS 2 bag and back: the same trajectory, with the IMU too.
    expect_ok "convert the TI bag to .mcap" "412 scans" -- \
      "$tool" convert --bag "$ti_bag" --topic /ti_mmwave/radar_scan_pcl --imu-topic /sensor_platform/imu \
      --imu-stamps record --out "$work/ti.mcap"
    for input in ros1 mcap; do
      if [ $input = ros1 ]; then bag=(--bag "$ti_bag" --topic /ti_mmwave/radar_scan_pcl --imu-topic /sensor_platform/imu \
        --imu-stamps record); else bag=(--bag "$work/ti.mcap" --topic /radar/points --imu-topic /imu/data); fi
      "$tool" odometry "${bag[@]}" --max-scans 120 --out "$work/ti_$input" >/dev/null
    done
    expect_same "TI odometry from its ROS1 bag and from the .mcap" "$work/ti_ros1/odometry.tum" "$work/ti_mcap/odometry.tum"
  else
    echo "skipped: the TI mmWave bag or ROS1 bag support is absent"; skipped=$((skipped + 1))
  fi
  finish_section bag
fi

expect_fail "no subcommand" "subcommand" -- "$tool"
expect_fail "unknown flag" "bogus" -- "$tool" info --bogus
expect_fail "missing sequence" "radargauss: error:" -- "$tool" info --sequence "$work/absent"
expect_fail "no sequence at all" "radargauss: error: no sequence" -- "$tool" info
expect_fail "simulate without --out" "out" -- "$tool" simulate
expect_fail "bad scan count" "scans" -- "$tool" simulate --out "$work/s" --scans -3
expect_ok "simulate" "simulated 6 scans" -- "$tool" simulate --out "$work/seq" --scans 6 --seed 3
expect_ok "convert to a ROS 2 bag" "wrote $work/seq.db3: 6 scans" -- \
  "$tool" convert --sequence "$work/seq" --gt "$work/seq/gt_radar_tum.txt" --out "$work/seq.db3"
expect_ok "info on the ROS 2 bag" "/reference/pose .*geometry_msgs/msg/PoseStamped *6 messages" -- \
  "$tool" info --bag "$work/seq.db3"
expect_ok "info on the ROS 2 bag's scans" "scans: 6 read" -- "$tool" info --bag "$work/seq.db3" --topic /radar/points
ntu="$(cd "$(dirname "$0")/../.." && pwd)/../shared/data/ntu4dradlm_loop1_eagle"
if [[ -d "$ntu/points" ]]; then
  "$tool" convert --sequence "$ntu/points" --gt "$ntu/gt_tum.txt" --extrinsic identity --out "$work/ntu.mcap" >/dev/null
  ntu_config="$(cd "$(dirname "$0")/../.." && pwd)/configs/ntu_eagle_odometry.yaml"
  "$tool" odometry --config "$ntu_config" --sequence "$ntu/points" --max-scans 150 --out "$work/ntu_pcd" >/dev/null
  "$tool" odometry --config "$ntu_config" --bag "$work/ntu.mcap" --topic /radar/points --max-scans 150 \
    --out "$work/ntu_mcap" >/dev/null
  expect_same "NTU odometry from its PCD folder and from the .mcap" "$work/ntu_pcd/odometry.tum" \
    "$work/ntu_mcap/odometry.tum"
fi
expect_ok "info on the simulation" "scans: 6 read, 6 matched" -- \
  "$tool" info --sequence "$work/seq" --gt "$work/seq/gt_radar_tum.txt"
expect_fail "simulate over an existing sequence" "already holds" -- \
  "$tool" simulate --out "$work/seq" --scans 2
expect_ok "simulate --force" "simulated 2 scans" -- "$tool" simulate --out "$work/seq" --scans 2 --force
expect_ok "build-map" "wrote $work/seq.rgm" -- \
  "$tool" build-map --sequence "$work/seq" --gt "$work/seq/gt_radar_tum.txt" --out "$work/seq.rgm"
expect_ok "map-info" "rcs coverage" -- "$tool" map-info "$work/seq.rgm"
expect_fail "build-map without gt" "needs --gt" -- "$tool" build-map --sequence "$work/seq" --out "$work/x.rgm"
expect_fail "bad incidence" "incidence" -- \
  "$tool" build-map --sequence "$work/seq" --gt "$work/seq/gt_radar_tum.txt" --out "$work/x.rgm" --incidence side
head -c 100 "$work/seq.rgm" > "$work/cut.rgm"
expect_fail "truncated map" "radargauss: error:" -- "$tool" map-info "$work/cut.rgm"
expect_ok "localize" "configurations" -- \
  "$tool" localize --sequence "$work/seq" --gt "$work/seq/gt_radar_tum.txt" --map "$work/seq.rgm" \
  --w-rcs 0,0.25 --solver gn,ceres --out "$work/results"
for f in per_scan.csv summary.json table.md reference.tum trajectories/gn-w0-trivial-offset-L3.tum; do
  if [ -s "$work/results/$f" ]; then passed=$((passed + 1)); else failed=$((failed + 1)); echo "FAIL: missing $f"; fi
done
expect_ok "localize with merged coarse levels" "configurations" -- \
  "$tool" localize --sequence "$work/seq" --gt "$work/seq/gt_radar_tum.txt" --map "$work/seq.rgm" \
  --w-rcs 0 --coarse-levels merged --coarse-points 100 --coarse-gate 2 --out "$work/results_merged"
expect_ok "localize with the losses' curvature" "configurations" -- \
  "$tool" localize --sequence "$work/seq" --gt "$work/seq/gt_radar_tum.txt" --map "$work/seq.rgm" \
  --w-rcs 0.25 --solver gn --loss-curvature --out "$work/results_curvature"
expect_ok "localize with a Swerling likelihood and the map's own weight" "gn-wmap" -- \
  "$tool" localize --sequence "$work/seq" --gt "$work/seq/gt_radar_tum.txt" --map "$work/seq.rgm" \
  --w-rcs 0 --rcs-likelihood swerling3 --rcs-confidence --w-rcs-from-map --out "$work/results_swerling"
expect_fail "localize with an unknown RCS likelihood" "rcs-likelihood" -- \
  "$tool" localize --sequence "$work/seq" --gt "$work/seq/gt_radar_tum.txt" --map "$work/seq.rgm" \
  --rcs-likelihood swerling2 --out "$work/results_bad"
expect_ok "map-info: the RCS fits' statistics and chosen weight" "chosen w_rcs" -- "$tool" map-info "$work/seq.rgm"
expect_fail "localize with unknown coarse levels" "coarse-levels" -- \
  "$tool" localize --sequence "$work/seq" --gt "$work/seq/gt_radar_tum.txt" --map "$work/seq.rgm" \
  --coarse-levels blurred --out "$work/r5"
expect_fail "localize with a zero coarse gate" "coarse-gate" -- \
  "$tool" localize --sequence "$work/seq" --gt "$work/seq/gt_radar_tum.txt" --map "$work/seq.rgm" \
  --coarse-gate 0 --out "$work/r6"
expect_ok "localize with the scan's points on the coarse levels" "configurations" -- \
  "$tool" localize --sequence "$work/seq" --gt "$work/seq/gt_radar_tum.txt" --map "$work/seq.rgm" \
  --w-rcs 0 --coarse-voxel-per-sigma 0 --out "$work/results_points"
# An old flag's name still works, warns, and gives the same results as the new one.
expect_ok "localize with the deprecated --coarse-voxel" "configurations" -- \
  "$tool" localize --sequence "$work/seq" --gt "$work/seq/gt_radar_tum.txt" --map "$work/seq.rgm" \
  --w-rcs 0 --coarse-voxel 0 --out "$work/results_points_old"
if grep -q "warning: --coarse-voxel is deprecated: use --coarse-voxel-per-sigma" "$work/err"; then
  passed=$((passed + 1))
else
  failed=$((failed + 1)); echo "FAIL: --coarse-voxel does not say it is deprecated"; cat "$work/err"
fi
expect_same "localize under the old and the new coarse-voxel flag" "$work/results_points/reference.tum" \
  "$work/results_points_old/reference.tum"
expect_same "the old and the new coarse-voxel flag's trajectories" \
  "$work/results_points/trajectories/gn-w0-trivial-offset-L3.tum" \
  "$work/results_points_old/trajectories/gn-w0-trivial-offset-L3.tum"
expect_ok "localize with eq. 2 throughout on the exact map" "configurations" -- \
  "$tool" localize --sequence "$work/seq" --gt "$work/seq/gt_radar_tum.txt" --map "$work/seq.rgm" \
  --w-rcs 0.25 --no-geometric-first --out "$work/results_throughout"
expect_fail "localize with a value for the geometric-first flag" "geometric-first" -- \
  "$tool" localize --sequence "$work/seq" --gt "$work/seq/gt_radar_tum.txt" --map "$work/seq.rgm" \
  --no-geometric-first=maybe --out "$work/r8"
expect_fail "localize with a negative coarse voxel" "coarse-voxel" -- \
  "$tool" localize --sequence "$work/seq" --gt "$work/seq/gt_radar_tum.txt" --map "$work/seq.rgm" \
  --coarse-voxel -1 --out "$work/r7"
expect_fail "localize with RCS weights on a sequence without RCS" "has no RCS field" -- \
  "$tool" localize --sequence "$work/seq" --gt "$work/seq/gt_radar_tum.txt" --rcs-field none \
  --w-rcs 0,0.25 --out "$work/r9"
mkdir -p "$work/dataset" && cp -r "$work/seq/ars548/points" "$work/dataset/points"
expect_fail "a data set's root as the sequence" "did you mean $work/dataset/points" -- \
  "$tool" info --sequence "$work/dataset"
expect_fail "localize with a bad weight" "w-rcs" -- \
  "$tool" localize --sequence "$work/seq" --gt "$work/seq/gt_radar_tum.txt" --w-rcs 1.5 --out "$work/r2"
expect_fail "localize with a map of another version" "map version 4" -- \
  bash -c "cp '$work/seq.rgm' '$work/v4.rgm' && printf '\\x04' | dd of='$work/v4.rgm' bs=1 seek=8 conv=notrunc 2>/dev/null && '$tool' localize --sequence '$work/seq' --gt '$work/seq/gt_radar_tum.txt' --map '$work/v4.rgm' --out '$work/r3'"
expect_fail "localize --map with --degrees" "drop --map" -- \
  "$tool" localize --sequence "$work/seq" --gt "$work/seq/gt_radar_tum.txt" --map "$work/seq.rgm" --degrees 1 --out "$work/r4"
"$tool" simulate --out "$work/seq10" --scans 10 >/dev/null
expect_ok "evaluate a trajectory against itself" "ATE translation: RMSE 0.000 m" -- \
  "$tool" evaluate --est "$work/seq10/gt_radar_tum.txt" --ref "$work/seq10/gt_radar_tum.txt" \
  --align first --out "$work/evaluation"
if [ -s "$work/evaluation/evaluation.json" ]; then passed=$((passed + 1)); else failed=$((failed + 1)); echo "FAIL: evaluation.json"; fi
"$tool" build-map --sequence "$work/seq10" --gt "$work/seq10/gt_radar_tum.txt" --out "$work/seq10.rgm" >/dev/null
expect_ok "refine a trajectory and its map" "wrote $work/refined/refined.tum" -- \
  "$tool" refine --sequence "$work/seq10" --poses "$work/seq10/gt_radar_tum.txt" --gt "$work/seq10/gt_radar_tum.txt" \
  --map "$work/seq10.rgm" --rounds 1 --iterations 5 --out "$work/refined"
expect_fail "refine without --poses" "poses" -- \
  "$tool" refine --sequence "$work/seq10" --map "$work/seq10.rgm" --out "$work/refined2"
expect_ok "odometry with its evaluation" "wrote $work/odometry" -- \
  "$tool" odometry --sequence "$work/seq10" --gt "$work/seq10/gt_radar_tum.txt" --out "$work/odometry"
for file in odometry.tum per_scan.csv summary.json map.rgm map.ply evaluation.json; do
  [[ -s "$work/odometry/$file" ]] || { echo "FAIL: odometry wrote no $file"; failed=1; }
done
cp -r "$work/seq10" "$work/backwards"
second=$(ls "$work/backwards/ars548/points" | grep pcd | sed -n 2p)
cp "$work/backwards/ars548/points/$second" "$work/backwards/ars548/points/${second%%.*}.1.pcd"
expect_ok "slam with its evaluation" "wrote $work/slam" -- \
  "$tool" slam --sequence "$work/seq10" --gt "$work/seq10/gt_radar_tum.txt" --submap-distance 2 --out "$work/slam"
for file in slam.tum keyframes.csv loops.csv slam.json map.rgm map.ply evaluation.json odometry/odometry.tum \
  odometry/evaluation.json; do
  [[ -s "$work/slam/$file" ]] || { echo "FAIL: slam wrote no $file"; failed=1; }
done
expect_ok "map-info counts the places" "places (SLAM keyframes for relocalize): [1-9]" -- \
  "$tool" map-info "$work/slam/map.rgm"
expect_ok "relocalize says when nothing verifies" "relocalize: no fix" -- \
  "$tool" relocalize --map "$work/slam/map.rgm" --sequence "$work/seq10" --submap-distance 2 \
  --max-scan-context-distance 0 --out "$work/relocalized"
[[ -s "$work/relocalized/per_scan.csv" && ! -s "$work/relocalized/relocalization.tum" ]] ||
  { echo "FAIL: relocalize without a fix wrote no per_scan.csv or a pose"; failed=1; }
expect_ok "relocalize with the map's own w_rcs" "w_rcs [0-9.]* from the map's RCS fits" -- \
  "$tool" relocalize --map "$work/slam/map.rgm" --sequence "$work/seq10" --submap-distance 2 \
  --w-rcs-from-map --rcs-likelihood swerling1 --out "$work/relocalized_w"
expect_fail "relocalize with both --w-rcs and --w-rcs-from-map" "excludes" -- \
  "$tool" relocalize --map "$work/slam/map.rgm" --sequence "$work/seq10" --w-rcs 0.25 --w-rcs-from-map \
  --out "$work/relocalized_x"
# The map as tiles: map-info and relocalize read the folder as they read the file.
# slam reads the scans one at a time; with --mcap it holds them all (the
# viewer file draws them): the same trajectory and map either way.
expect_ok "slam holding its scans for --mcap" "wrote $work/slam_held" -- \
  "$tool" slam --sequence "$work/seq10" --gt "$work/seq10/gt_radar_tum.txt" --submap-distance 2 \
  --out "$work/slam_held" --mcap "$work/slam_held.mcap"
for file in slam.tum map.rgm keyframes.csv odometry/odometry.tum; do
  if [[ "$file" == keyframes.csv ]]; then
    same=$(diff <(cut -d, -f1-12 "$work/slam/$file") <(cut -d, -f1-12 "$work/slam_held/$file") > /dev/null && echo yes)
  else
    same=$(cmp -s "$work/slam/$file" "$work/slam_held/$file" && echo yes)
  fi
  [[ "$same" == yes ]] || { echo "FAIL: slam streamed and slam holding its scans differ in $file"; failed=1; }
done
expect_fail "slam --hold-map-points=false with --map-tiles" "drop --no-map" -- \
  "$tool" slam --sequence "$work/seq10" --map-tiles 20 --hold-map-points=false --out "$work/slam_unheld"
# A rig of two radars (two simulated folders) on the vehicle's axis.
"$tool" simulate --out "$work/seq10b" --scans 10 --seed 3 >/dev/null
printf 'radars:\n  - {name: front, sequence: seq10, extrinsic: [3.7, 0, 0.5, 0, 0, 0, 1]}\n  - {name: rear, sequence: seq10b, extrinsic: [-1, 0, 0.5, 0, 0, 1, 0], clock_offset: 0.02}\n' \
  > "$work/rig.yaml"
expect_ok "info on a rig" "rear: 10 scans .*clock offset 0.0200 s" -- "$tool" info --rig "$work/rig.yaml"
expect_ok "info on a rig says what its Doppler observes" "all but the rotation about the line through the radars (1.000" -- \
  "$tool" info --rig "$work/rig.yaml"
printf 'radars:\n  - {name: front, sequence: seq10, extrinsic: [3.7, 0, 0.5, 0, 0, 0, 1]}\n  - {name: rear, sequence: seq10, extrinsic: [-1, 0, 0.5, 0, 0, 1, 0]}\n' \
  > "$work/rig_shared.yaml"
expect_fail "a rig whose radars share a folder" "radar 'rear' reads the folder" -- "$tool" info --rig "$work/rig_shared.yaml"
expect_fail "a rig and a sequence" "drop --sequence" -- "$tool" info --rig "$work/rig.yaml" --sequence "$work/seq10"
expect_ok "odometry on a rig" "rig: 2 radars, 20 scans in 10 frames" -- \
  "$tool" odometry --rig "$work/rig.yaml" --out "$work/rig_odometry"
[[ -s "$work/rig_odometry/body.tum" ]] || { echo "FAIL: odometry --rig wrote no body.tum"; failed=1; }
expect_ok "odometry on a rig calibrating it online" "online calibration: [1-9][0-9]* windows" -- \
  "$tool" odometry --rig "$work/rig.yaml" --rig-calibrate --rig-calibration-window 0.3 --out "$work/rig_online"
expect_ok "the rig calibrated online is a rig" "rear: 10 scans" -- "$tool" info --rig "$work/rig_online/rig.yaml"
expect_fail "an online calibration without a window" "rig-calibration-window" -- \
  "$tool" odometry --rig "$work/rig.yaml" --rig-calibrate --rig-calibration-window 0 --out "$work/rig_online_bad"
[[ ! -e "$work/rig_online_bad" ]] || { echo "FAIL: a refused online calibration left its folder"; failed=1; }
expect_ok "export a rig's run" "the frames of 2 radars" -- \
  "$tool" export "$work/rig_odometry" --rig "$work/rig.yaml" --mcap "$work/rig_odometry.mcap"
expect_fail "export a rig's run with a sequence" "drop --sequence" -- \
  "$tool" export "$work/rig_odometry" --rig "$work/rig.yaml" --sequence "$work/seq10" --mcap "$work/rig_seq_run.mcap"
[[ ! -e "$work/rig_seq_run.mcap" ]] || { echo "FAIL: a refused rig export left its file"; failed=1; }
expect_fail "odometry on a rig of folders with an IMU topic" "needs the radars in one bag" -- \
  "$tool" odometry --rig "$work/rig.yaml" --imu-topic /imu --out "$work/rig_imu"
[[ ! -e "$work/rig_imu" ]] || { echo "FAIL: a refused rig run left $work/rig_imu"; failed=1; }
# The reference radar's mounting is its roll and pitch on the body: a rig of
# one radar pitched 10 deg is that radar's odometry with --mounting 0 10 0.
printf 'radars:\n  - {name: front, sequence: seq10, extrinsic: [0, 0, 0, 0, 0.0871557427476582, 0, 0.9961946980917455]}\n' \
  > "$work/rig_pitched.yaml"
"$tool" odometry --rig "$work/rig_pitched.yaml" --out "$work/rig_pitched" >/dev/null
"$tool" odometry --sequence "$work/seq10" --mounting 0 10 0 --out "$work/sequence_pitched" >/dev/null
python3 - "$work/rig_pitched/odometry.tum" "$work/sequence_pitched/odometry.tum" <<'PY' || failed=1
import sys
a = [[float(v) for v in line.split()] for line in open(sys.argv[1]) if not line.startswith("#")]
b = [[float(v) for v in line.split()] for line in open(sys.argv[2]) if not line.startswith("#")]
if len(a) != len(b) or any(abs(x - y) > 1e-6 for ra, rb in zip(a, b) for x, y in zip(ra, rb)):
    sys.exit("FAIL: odometry on a pitched rig of one radar differs from the radar's with --mounting")
PY
expect_fail "a rig and --mounting" "in its rig file" -- \
  "$tool" odometry --rig "$work/rig.yaml" --mounting 0 1 0 --out "$work/rig_mounting"
expect_ok "a rig to one bag" "20 scans of 2 radars" -- "$tool" convert --rig "$work/rig.yaml" --out "$work/rig_bag.mcap"
expect_ok "the bag's rig file" "rear: 10 scans (rosbag)" -- "$tool" info --rig "$work/rig_bag.rig.yaml"
expect_ok "odometry on the bag's rig" "rig: 2 radars" -- \
  "$tool" odometry --rig "$work/rig_bag.rig.yaml" --out "$work/rig_bag_odometry"
cmp -s "$work/rig_odometry/body.tum" "$work/rig_bag_odometry/body.tum" || {
  echo "FAIL: odometry on the rig's bag differs from odometry on its folders"; failed=1; }
expect_fail "a rig and a sequence to convert" "drop --sequence" -- \
  "$tool" convert --rig "$work/rig.yaml" --sequence "$work/seq10" --out "$work/rig_seq.mcap"
[[ ! -e "$work/rig_seq.mcap" ]] || { echo "FAIL: a refused rig conversion left its bag"; failed=1; }
expect_ok "slam on a rig" "rig: 2 radars, 20 scans in 10 frames" -- \
  "$tool" slam --rig "$work/rig.yaml" --submap-distance 2 --out "$work/rig_slam"
[[ -s "$work/rig_slam/body.tum" && -s "$work/rig_slam/map.rgm" ]] || { echo "FAIL: slam --rig wrote no body.tum or map"; failed=1; }
expect_ok "slam on a rig calibrating it online" "rig.yaml: the rig calibrated online" -- \
  "$tool" slam --rig "$work/rig.yaml" --submap-distance 2 --rig-calibrate --rig-calibration-window 0.3 \
  --out "$work/rig_slam_online"
expect_ok "the rig slam calibrated online is a rig" "rear: 10 scans" -- "$tool" info --rig "$work/rig_slam_online/rig.yaml"
printf 'radars:\n  - {name: front, sequence: seq10, extrinsic: [0, 0, 0, 0, 0, 0, 1]}\n' > "$work/rig_front.yaml"
"$tool" slam --rig "$work/rig_front.yaml" --submap-distance 2 --out "$work/rig_slam_one" >/dev/null
"$tool" slam --sequence "$work/seq10" --submap-distance 2 --out "$work/slam_one" >/dev/null
cmp -s "$work/rig_slam_one/slam.tum" "$work/slam_one/slam.tum" || {
  echo "FAIL: slam on a rig of one radar differs from slam on its sequence"; failed=1; }
expect_fail "slam on a rig with an IMU file that is not one" "$work/seq10/gt_radar_tum.txt" -- \
  "$tool" slam --rig "$work/rig.yaml" --imu "$work/seq10/gt_radar_tum.txt" --out "$work/rig_slam_imu"
[[ ! -e "$work/rig_slam_imu" ]] || { echo "FAIL: a refused rig run left $work/rig_slam_imu"; failed=1; }
expect_ok "relocalize a rig in its slam map" "rig: 2 radars, 20 scans in 10 frames" -- \
  "$tool" relocalize --rig "$work/rig.yaml" --map "$work/rig_slam/map.rgm" --submap-distance 2 --out "$work/rig_reloc"
[[ -e "$work/rig_reloc/body.tum" ]] || { echo "FAIL: relocalize --rig wrote no body.tum"; failed=1; }
"$tool" relocalize --rig "$work/rig_front.yaml" --map "$work/slam_one/map.rgm" --submap-distance 2 \
  --out "$work/rig_reloc_one" >/dev/null
"$tool" relocalize --sequence "$work/seq10" --map "$work/slam_one/map.rgm" --submap-distance 2 \
  --out "$work/reloc_one" >/dev/null
[[ -s "$work/reloc_one/relocalization.tum" ]] && cmp -s "$work/rig_reloc_one/relocalization.tum" "$work/reloc_one/relocalization.tum" || {
  echo "FAIL: relocalize on a rig of one radar differs from relocalize on its sequence"; failed=1; }
expect_ok "calibrate a rig" "wrote .*calibrated" -- \
  "$tool" calibrate --rig "$work/rig.yaml" --compare "$work/rig.yaml" --out "$work/calibrated"
[[ -s "$work/calibrated/rig.yaml" && -s "$work/calibrated/calibration.json" ]] || {
  echo "FAIL: calibrate wrote no rig.yaml or calibration.json"; failed=1; }
expect_ok "the calibrated rig is a rig" "rig: .*2 radars" -- "$tool" info --rig "$work/calibrated/rig.yaml"
expect_fail "calibrate with an IMU extrinsic but no IMU" "needs --imu" -- \
  "$tool" calibrate --rig "$work/rig.yaml" --imu-extrinsic "$work/body_from_imu.txt" --out "$work/calibrated_no_imu"
expect_fail "calibrate with an IMU file that is not one" "gt_radar_tum.txt" -- \
  "$tool" calibrate --rig "$work/rig.yaml" --imu "$work/seq10/gt_radar_tum.txt" --out "$work/calibrated_bad_imu"
[[ ! -e "$work/calibrated_no_imu" && ! -e "$work/calibrated_bad_imu" ]] || {
  echo "FAIL: a refused calibration with an IMU left its folder"; failed=1; }
printf 'radars:\n  - {name: front, sequence: seq10, extrinsic: [0, 0, 0, 0, 0, 0, 1]}\n' > "$work/rig_one.yaml"
expect_fail "calibrate a rig of one radar" "needs a reference radar and another" -- \
  "$tool" calibrate --rig "$work/rig_one.yaml" --out "$work/calibrated_one"
expect_fail "calibrate against a rig of other radars" "--compare: 1 radars, the rig has 2" -- \
  "$tool" calibrate --rig "$work/rig.yaml" --compare "$work/rig_one.yaml" --out "$work/calibrated_other"
[[ ! -e "$work/calibrated_one" && ! -e "$work/calibrated_other" ]] || {
  echo "FAIL: a refused calibration left its folder"; failed=1; }
expect_ok "slam writes the map as tiles" "map_tiles/" -- \
  "$tool" slam --sequence "$work/seq10" --submap-distance 2 --map-tiles 20 --out "$work/slam_tiles"
[[ -s "$work/slam_tiles/map_tiles/tiles.json" ]] || { echo "FAIL: slam --map-tiles wrote no tiles.json"; failed=1; }
if [[ "$("$tool" map-info "$work/slam_tiles/map.rgm" | tail -n +2)" != \
      "$("$tool" map-info "$work/slam_tiles/map_tiles" | tail -n +2)" ]]; then
  echo "FAIL: map-info of the tiles differs from the map file's"; failed=1
fi
"$tool" relocalize --map "$work/slam_tiles/map_tiles" --sequence "$work/seq10" --submap-distance 2 \
  --out "$work/relocalized_tiles" >/dev/null
"$tool" relocalize --map "$work/slam_tiles/map.rgm" --sequence "$work/seq10" --submap-distance 2 \
  --out "$work/relocalized_file" >/dev/null
cmp -s "$work/relocalized_tiles/per_scan.csv" "$work/relocalized_file/per_scan.csv" ||
  { echo "FAIL: relocalize in the tiles differs from relocalize in the map file"; failed=1; }
expect_fail "--map-tiles needs the map" "drop --no-map" -- \
  "$tool" slam --sequence "$work/seq10" --map-tiles 20 --no-map --out "$work/slam_no_map_tiles"
# The evaluation in memory (odometry --gt) and from the files (evaluate) agree
# field by field, here on the straight drive whose positions lie on a line.
"$tool" simulate --out "$work/straight" --scans 120 --seed 3 >/dev/null
"$tool" odometry --sequence "$work/straight" --gt "$work/straight/gt_radar_tum.txt" --out "$work/straight_odometry" \
  >/dev/null
"$tool" evaluate --est "$work/straight_odometry/odometry.tum" --ref "$work/straight/gt_radar_tum.txt" \
  --out "$work/straight_evaluate" >/dev/null
if /usr/bin/python3 - "$work/straight_odometry/evaluation.json" "$work/straight_evaluate/evaluation.json" <<'PY'
import json, math, sys
def flat(value, prefix=""):
    if isinstance(value, dict):
        return {k: v for key in value for k, v in flat(value[key], prefix + key + ".").items()}
    if isinstance(value, list):
        return {k: v for i, item in enumerate(value) for k, v in flat(item, prefix + str(i) + ".").items()}
    return {prefix: value}
memory, files = (flat(json.load(open(path))) for path in sys.argv[1:])
assert memory.keys() == files.keys(), set(memory) ^ set(files)
for key, value in memory.items():
    other = files[key]
    same = value == other if isinstance(value, str) else math.isclose(value, other, rel_tol=1e-6, abs_tol=1e-9)
    assert same, "%s: %r in memory, %r from the files" % (key, value, other)
assert memory["alignment_note."].startswith("rotation from the orientations"), memory["alignment_note."]
assert memory["ate_rotation_deg.max."] < 5.0, memory["ate_rotation_deg.max."]
PY
then
  passed=$((passed + 1))
else
  echo "FAIL: odometry's evaluation and evaluate's differ"; failed=$((failed + 1))
fi
expect_fail "odometry on a scan folder with a repeated stamp" "does not increase" -- \
  "$tool" odometry --sequence "$work/backwards" --out "$work/odometry_backwards"
[[ ! -e "$work/odometry_backwards/odometry.tum" ]] || { echo "FAIL: a failed odometry left outputs"; failed=1; }
expect_fail "odometry with a missing reference" "cannot open" -- \
  "$tool" odometry --sequence "$work/seq10" --gt "$work/absent.tum" --out "$work/odometry_nogt"
[[ ! -e "$work/odometry_nogt" ]] || { echo "FAIL: odometry with a bad reference left its output folder"; failed=1; }
expect_fail "odometry with RCS weights on a sequence without RCS" "has no RCS field" -- \
  "$tool" odometry --sequence "$work/seq10" --rcs-field none --w-rcs 0.25 --out "$work/odometry_rcs"
expect_fail "odometry with a NaN velocity weight" "velocity-weight" -- \
  "$tool" odometry --sequence "$work/seq10" --velocity-weight nan --out "$work/odometry_nan"
expect_fail "odometry with a zero rotation rate std" "rotation-rate-std" -- \
  "$tool" odometry --sequence "$work/seq10" --rotation-rate-std 1 0 90 --out "$work/odometry_tilt"
expect_fail "odometry with two rotation rate stds" "rotation-rate-std" -- \
  "$tool" odometry --sequence "$work/seq10" --rotation-rate-std 1 1 --out "$work/odometry_tilt2"
expect_fail "odometry with an IMU topic but no bag" "needs --bag" -- \
  "$tool" odometry --sequence "$work/seq10" --imu-topic /imu --out "$work/odometry_imu"
# Radar-inertial odometry: the same trajectory and states for any thread count.
printf 'scans: 30\nimu_rate_hz: 200\n' >"$work/imu_world.yaml"
"$tool" simulate --config "$work/imu_world.yaml" --out "$work/seq_imu" >/dev/null
for threads in 1 2 8; do
  expect_ok "radar-inertial odometry, $threads threads" "inertial.csv" -- \
    "$tool" --threads "$threads" odometry --sequence "$work/seq_imu" --imu "$work/seq_imu/imu.txt" \
    --imu-extrinsic "$work/seq_imu/imu_extrinsic.txt" --out "$work/inertial_$threads"
done
for threads in 2 8; do
  for file in odometry.tum inertial.csv; do
    cmp -s "$work/inertial_1/$file" "$work/inertial_$threads/$file" ||
      { echo "FAIL: radar-inertial $file differs between 1 and $threads threads"; failed=1; }
  done
done
# A rig of one radar with the IMU on the body: the IMU's T_body_imu = T_body_radar T_radar_imu
# (here exact in floating point) gives the single radar's radar-inertial run, bit for bit.
printf 'radars:\n  - {name: front, sequence: seq_imu, extrinsic: [1.5, 0.25, 0.5, 0, 0, 0, 1]}\n' > "$work/rig_imu_one.yaml"
printf '1.5 0.25 0.5 0 0 0 1\n' > "$work/body_from_imu.txt"
grep -q '^0 0 0 0 0 0 1$' "$work/seq_imu/imu_extrinsic.txt" || { echo "FAIL: the simulated T_radar_imu is not the identity"; failed=1; }
expect_ok "radar-inertial odometry on a rig of one radar" "inertial.csv" -- \
  "$tool" odometry --rig "$work/rig_imu_one.yaml" --imu "$work/seq_imu/imu.txt" \
  --imu-extrinsic "$work/body_from_imu.txt" --out "$work/rig_inertial_one"
for file in odometry.tum inertial.csv; do
  cmp -s "$work/inertial_1/$file" "$work/rig_inertial_one/$file" ||
    { echo "FAIL: radar-inertial $file on a rig of one radar differs from the radar's own"; failed=1; }
done
"$tool" slam --sequence "$work/seq_imu" --imu "$work/seq_imu/imu.txt" --imu-extrinsic "$work/seq_imu/imu_extrinsic.txt" \
  --submap-distance 2 --out "$work/slam_inertial" >/dev/null
expect_ok "radar-inertial slam on a rig of one radar" "rig: 1 radars" -- \
  "$tool" slam --rig "$work/rig_imu_one.yaml" --imu "$work/seq_imu/imu.txt" --imu-extrinsic "$work/body_from_imu.txt" \
  --submap-distance 2 --out "$work/rig_slam_inertial"
cmp -s "$work/slam_inertial/slam.tum" "$work/rig_slam_inertial/slam.tum" ||
  { echo "FAIL: radar-inertial slam on a rig of one radar differs from the radar's own"; failed=1; }
"$tool" slam --rig "$work/rig_imu_one.yaml" --submap-distance 2 --out "$work/rig_slam_radar" >/dev/null
! cmp -s "$work/rig_slam_radar/slam.tum" "$work/rig_slam_inertial/slam.tum" ||
  { echo "FAIL: slam on a rig with its IMU equals slam without it"; failed=1; }
# Calibrating: each estimated parameter per scan in inertial.csv, its last row summary.json's value.
expect_ok "radar-inertial odometry, calibrating" "inertial.csv" -- \
  "$tool" odometry --sequence "$work/seq_imu" --imu "$work/seq_imu/imu.txt" \
  --imu-extrinsic "$work/seq_imu/imu_extrinsic.txt" --estimate-clock-offset --estimate-elevation-bias \
  --out "$work/inertial_calibrating"
python3 - "$work/inertial_calibrating" <<'PY' || failed=1
import csv, json, sys
rows = list(csv.DictReader(open(sys.argv[1] + "/inertial.csv")))
summary = json.load(open(sys.argv[1] + "/summary.json"))["calibration"]
last = rows[-1]
for column, key in (("clock_offset_s", "clock_offset_s"), ("elevation_bias_deg", "elevation_bias_deg")):
    if abs(float(last[column]) - summary[key]) > 1e-7:
        sys.exit("FAIL: inertial.csv's last %s %s against summary.json's %s" % (column, last[column], summary[key]))
if not all(row["clock_offset_std_s"] for row in rows if row["bgx"]):
    sys.exit("FAIL: a solved scan without its clock offset's std")
PY
# An extrinsic file that states its accuracy: rough parts estimated, exact ones held, a given flag obeyed.
{ cat "$work/seq_imu/imu_extrinsic.txt"; echo "std 2 0 0.03"; } >"$work/rough_extrinsic.txt"
{ cat "$work/seq_imu/imu_extrinsic.txt"; echo "std 0 0 0"; } >"$work/exact_extrinsic.txt"
expect_ok "an extrinsic stated rough" "estimating the rotation yes, the translation no, the clock offset yes" -- \
  "$tool" odometry --sequence "$work/seq_imu" --imu "$work/seq_imu/imu.txt" \
  --imu-extrinsic "$work/rough_extrinsic.txt" --out "$work/inertial_rough"
expect_ok "an extrinsic stated exact, the clock's flag given" \
  "estimating the rotation no, the translation no, the clock offset yes" -- \
  "$tool" odometry --sequence "$work/seq_imu" --imu "$work/seq_imu/imu.txt" \
  --imu-extrinsic "$work/exact_extrinsic.txt" --estimate-clock-offset --out "$work/inertial_exact"
grep -q clock_offset_s "$work/inertial_rough/inertial.csv" ||
  { echo "FAIL: a rough extrinsic's run has no clock offset in inertial.csv"; failed=1; }
expect_fail "evaluate with a missing reference" "cannot open" -- \
  "$tool" evaluate --est "$work/results/reference.tum" --ref "$work/absent.tum"
expect_fail "evaluate with an unknown alignment" "align" -- \
  "$tool" evaluate --est "$work/results/reference.tum" --ref "$work/results/reference.tum" --align umeyama
printf 'w-rcs: [0, 1]\nstride: 1\n' > "$work/loc.yaml"
expect_ok "localize --config" "2 configurations" -- \
  "$tool" localize --config "$work/loc.yaml" --sequence "$work/seq" --gt "$work/seq/gt_radar_tum.txt" --map "$work/seq.rgm" --out "$work/r5"
printf 'bogus-key: 1\n' > "$work/bad_loc.yaml"
expect_fail "localize --config with an unknown key" "bogus-key" -- \
  "$tool" localize --config "$work/bad_loc.yaml" --sequence "$work/seq" --gt "$work/seq/gt_radar_tum.txt" --out "$work/r6"
expect_fail "bad doppler sign" "doppler-sign" -- \
  "$tool" info --sequence "$work/seq" --doppler-sign 2
printf 'scans: lots\n' >"$work/bad.yaml"
expect_fail "bad config" "wrong type" -- "$tool" simulate --out "$work/s2" --config "$work/bad.yaml"
expect_fail "bad ground truth" "expected 8 columns" -- \
  bash -c "printf '0 1 2\n' > '$work/gt.txt'; '$tool' info --sequence '$work/seq' --gt '$work/gt.txt'"
first=$(ls "$work/seq/ars548/points/"*.pcd | head -1)
head -c 300 "$first" >"$work/cut" && mv "$work/cut" "$first"
expect_fail "truncated scan" "truncated" -- "$tool" info --sequence "$work/seq"

echo "cli: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
