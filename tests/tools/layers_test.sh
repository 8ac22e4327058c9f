#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# scripts/check_sources.py (its layer check, scripts/check_layers.py) passes
# on the tree, and fails on a copy of it with one upward include planted (the
# map layer including the odometry's header), a line clang-format would
# write otherwise, and a file in no layer.
#   tests/tools/layers_test.sh <source root>
set -euo pipefail
root=$1
check="/usr/bin/python3 $root/scripts/check_sources.py"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

$check "$root" > "$tmp/tree.log" || { cat "$tmp/tree.log"; echo "FAIL: the tree has upward includes"; exit 1; }

mkdir -p "$tmp/copy"
for item in README.md CMakeLists.txt include src apps python examples bench docs scripts \
            configs cmake .ci fuzz .clang-format; do
  cp -r "$root/$item" "$tmp/copy/"
done
$check "$tmp/copy" > /dev/null || { echo "FAIL: the copy fails before a plant"; exit 1; }

# refused <what was planted> <the line that must name it>: the check fails on
# the copy and names the fault; the planted header is put back after.
planted="$tmp/copy/include/radargauss/map/gaussian_map.hpp"
refused() {
  if $check "$tmp/copy" > "$tmp/planted.log"; then
    echo "FAIL: $1 passed"; exit 1
  fi
  grep -qF "$2" "$tmp/planted.log" || { cat "$tmp/planted.log"; echo "FAIL: not named: $2"; exit 1; }
  cp "$root/include/radargauss/map/gaussian_map.hpp" "$planted"
}

sed -i '/#pragma once/a #include "radargauss/odometry/radar_odometry.hpp"' "$planted"
refused "an upward include" \
  "include/radargauss/map/gaussian_map.hpp: includes radargauss/odometry/radar_odometry.hpp of layer 'pipelines' above its own 'map'"
# An include that resolves only through a link the build would make.
sed -i '/#pragma once/a #include "radargauss/solvers/gauss_newton_linked.hpp"' "$planted"
refused "an include of no file" \
  "include/radargauss/map/gaussian_map.hpp: includes radargauss/solvers/gauss_newton_linked.hpp, which names no file"
# A line clang-format would write otherwise.
sed -i 's/^#pragma once$/#pragma once\nconstexpr  int kBadlySpaced = 1;/' "$planted"
refused "an unformatted file" "include/radargauss/map/gaussian_map.hpp: not as clang-format writes it"
echo '// SPDX-License-Identifier: BSD-3-Clause' > "$tmp/copy/include/radargauss/stray.hpp"
refused "a file in no layer" "include/radargauss/stray.hpp: in no layer"
echo "layers_test: passed"
