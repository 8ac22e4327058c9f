#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# The main job on the embedded default: installs what is missing, builds,
# simulates the default synthetic sequence, builds its Gaussian-RCS map, runs
# the w_rcs sweep {0, 0.1, 0.25, 0.5, 0.75, 1} with the own Gauss-Newton,
# prints the table and writes the plots, then runs odometry on the same
# sequence and prints its evaluation. Output: build/demo/.
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
RADARGAUSS_DEPS_EXTRA="python3-matplotlib ${RADARGAUSS_DEPS_EXTRA:-}" "$root/scripts/deps.sh"
cmake -S "$root" -B "$root/build/release" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$root/build/release" -j "$(nproc)" --target radargauss_cli
tool="$root/build/release/bin/radargauss"
demo="$root/build/demo"
mkdir -p "$demo"

"$tool" simulate --out "$demo/sequence" --config "$root/configs/synthetic_world.yaml" --force
"$tool" build-map \
  --sequence "$demo/sequence" --gt "$demo/sequence/gt_radar_tum.txt" \
  --out "$demo/map.rgm" --ply "$demo/map.ply"
"$tool" localize --config "$root/configs/synthetic_world_localize.yaml" \
  --sequence "$demo/sequence" --gt "$demo/sequence/gt_radar_tum.txt" \
  --map "$demo/map.rgm" --out "$demo/results"
/usr/bin/python3 "$root/scripts/plot_results.py" "$demo/results" --reference "$demo/results/reference.tum"
# Odometry on the same sequence: no reference poses in the run, the ground
# truth only for the evaluation it prints.
"$tool" odometry --sequence "$demo/sequence" --gt "$demo/sequence/gt_radar_tum.txt" --out "$demo/odometry"
/usr/bin/python3 "$root/scripts/plot_odometry.py" "$demo/odometry" --reference "$demo/sequence/gt_radar_tum.txt"
echo "demo: table in $demo/results/table.md, plots in $demo/results/*.png; odometry in $demo/odometry"
