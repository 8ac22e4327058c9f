#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# Installs radargauss into a temporary prefix, builds examples/ against it
# as another project would (find_package, nothing but the prefix), and runs
# build_map and match_scan on a simulated sequence: the match must end
# within 5 cm and 0.2 deg of the reference; the Python package, when built,
# imports from the prefix.
#   install_test.sh <build dir> <source dir>
set -euo pipefail
build=$1
source=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
prefix="$work/prefix"

cmake --install "$build" --prefix "$prefix" >"$work/install.log"
# The installed target's include path is the prefix's include/ alone.
targets=$(find "$prefix" -name radargaussTargets.cmake)
includes=$(grep -o 'INTERFACE_INCLUDE_DIRECTORIES "[^"]*"' "$targets")
if [ "$includes" != 'INTERFACE_INCLUDE_DIRECTORIES "${_IMPORT_PREFIX}/include"' ]; then
  echo "FAIL: installed include path is $includes"; exit 1
fi
# Only the public headers: none of RADARGAUSS_INTERNAL_HEADERS, and every
# radargauss/ include of an installed header names an installed file.
/usr/bin/python3 - "$source" "$prefix/include" <<'PY' || exit 1
import pathlib, re, sys
source, installed = pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2])
listed = re.search(r"set\(RADARGAUSS_INTERNAL_HEADERS([^)]*)\)", (source / "CMakeLists.txt").read_text()).group(1).split()
headers = sorted(installed.rglob("*.hpp"))
problems = ["installed: " + name for name in listed if (installed / "radargauss" / name).exists()]
for header in headers:
    for name in re.findall(r'^\s*#\s*include\s+"(radargauss/[^"]+)"', header.read_text(), re.M):
        if not (installed / name).exists():
            problems.append("%s includes %s, which is not installed" % (header.relative_to(installed), name))
print("\n".join(problems) or "installed headers: %d, none internal, every include resolves" % len(headers))
sys.exit(1 if problems or len(listed) < 5 else 0)
PY
cmake -S "$source/examples" -B "$work/examples" -DCMAKE_PREFIX_PATH="$prefix" \
  -DCMAKE_BUILD_TYPE=Release >"$work/configure.log"
cmake --build "$work/examples" -j 2 >"$work/build.log" || { cat "$work/build.log"; exit 1; }

"$prefix/bin/radargauss" simulate --out "$work/sequence" --scans 120 >/dev/null
"$work/examples/build_map" "$work/sequence" "$work/sequence/gt_radar_tum.txt" "$work/map.rgm"
output=$("$work/examples/match_scan" "$work/sequence" "$work/sequence/gt_radar_tum.txt" "$work/map.rgm" 100)
echo "$output"
echo "$output" | awk '/^error:/ { found = 1; ok = ($3 <= 0.05 && $6 <= 0.2) }
                      END { if (!found || !ok) { print "FAIL: match outside 5 cm / 0.2 deg"; exit 1 } }'
# The Python package, when built, is importable from the prefix's site-packages.
module=$(find "$prefix" -name '_radargauss*.so' | head -1)
if [ -n "$module" ]; then
  site=$(dirname "$(dirname "$module")")
  PYTHONPATH="$site" /usr/bin/python3 -c "import radargauss; print(len(radargauss.simulate(scans=2)))" |
    grep -qx 2 || { echo "FAIL: the installed Python package does not import"; exit 1; }
  echo "python package importable from $site"
fi
echo "1 passed, 0 failed"
