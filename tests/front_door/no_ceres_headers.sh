#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# Fails when the compiler's dependency file of an object names a Ceres, glog
# or gflags header (or is missing).
#   tests/front_door/no_ceres_headers.sh <object file>
set -euo pipefail
depfile="$1.d"
[ -s "$depfile" ] || { echo "FAIL: no dependency file $depfile"; exit 1; }
grep -q 'radargauss/radargauss.hpp' "$depfile" || { echo "FAIL: $depfile does not name the front door"; exit 1; }
if grep -E '/(ceres|glog|gflags)/' "$depfile"; then
  echo "FAIL: the front door pulls the headers above"; exit 1
fi
echo "no_ceres_headers: $(grep -o '\.h[p]*\b' "$depfile" | wc -l) headers, none of Ceres, glog or gflags"
