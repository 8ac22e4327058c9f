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
for item in README.md CMakeLists.txt include src residuals solvers peers apps python examples bench docs scripts \
            configs cmake .ci fuzz .clang-format; do
  cp -r "$root/$item" "$tmp/copy/"
done
$check "$tmp/copy" > /dev/null || { echo "FAIL: the copy fails before a plant"; exit 1; }

planted="$tmp/copy/include/radargauss/map/gaussian_map.hpp"
sed -i '/#pragma once/a #include "radargauss/odometry/radar_odometry.hpp"' "$planted"
expect="include/radargauss/map/gaussian_map.hpp: includes radargauss/odometry/radar_odometry.hpp of layer 'pipelines' above its own 'map'"
if $check "$tmp/copy" > "$tmp/planted.log"; then
  echo "FAIL: an upward include passed"; exit 1
fi
grep -qF "$expect" "$tmp/planted.log" || { cat "$tmp/planted.log"; echo "FAIL: not named: $expect"; exit 1; }

cp "$root/include/radargauss/map/gaussian_map.hpp" "$planted"
# An include that resolves only through a link the build would make.
sed -i '/#pragma once/a #include "radargauss/solvers/gauss_newton_linked.hpp"' "$planted"
expect="include/radargauss/map/gaussian_map.hpp: includes radargauss/solvers/gauss_newton_linked.hpp, which names no file"
if $check "$tmp/copy" > "$tmp/planted.log"; then
  echo "FAIL: an include of no file passed"; exit 1
fi
grep -qF "$expect" "$tmp/planted.log" || { cat "$tmp/planted.log"; echo "FAIL: not named: $expect"; exit 1; }
cp "$root/include/radargauss/map/gaussian_map.hpp" "$planted"
# A line clang-format would write otherwise.
sed -i 's/^#pragma once$/#pragma once\nconstexpr  int kBadlySpaced = 1;/' "$planted"
expect="include/radargauss/map/gaussian_map.hpp: not as clang-format writes it"
if $check "$tmp/copy" > "$tmp/format.log"; then
  echo "FAIL: an unformatted file passed"; exit 1
fi
grep -qF "$expect" "$tmp/format.log" || { cat "$tmp/format.log"; echo "FAIL: not named: $expect"; exit 1; }
cp "$root/include/radargauss/map/gaussian_map.hpp" "$planted"
echo '// SPDX-License-Identifier: BSD-3-Clause' > "$tmp/copy/include/radargauss/stray.hpp"
if $check "$tmp/copy" > "$tmp/stray.log"; then
  echo "FAIL: a file in no layer passed"; exit 1
fi
grep -qF "include/radargauss/stray.hpp: in no layer" "$tmp/stray.log" || { cat "$tmp/stray.log"; exit 1; }
echo "layers_test: passed"
