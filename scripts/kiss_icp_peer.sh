#!/bin/bash
# SPDX-License-Identifier: BSD-3-Clause
# Builds bench/kiss_icp_peer.cpp (kiss-icp's C++ core on radargauss
# sequences) against build/release: give the checkouts of kiss-icp, Sophus
# and robin-map (headers only), e.g.
#   scripts/kiss_icp_peer.sh ~/src/kiss-icp ~/src/Sophus ~/src/robin-map
# then: build/kiss_icp_peer SEQUENCE_DIR out.tum times.csv
set -euo pipefail
if [ $# -ne 3 ]; then
  echo "usage: $0 KISS_ICP_DIR SOPHUS_DIR ROBIN_MAP_DIR" >&2
  exit 2
fi
root="$(cd "$(dirname "$0")/.." && pwd)"
kiss="$1/cpp/kiss_icp"
[ -f "$kiss/pipeline/KissICP.cpp" ] || { echo "$0: no kiss-icp C++ core under $1" >&2; exit 1; }
[ -f "$root/build/release/libradargauss.a" ] || { echo "$0: build radargauss first (scripts/test.sh)" >&2; exit 1; }
include="$root/build/kiss_icp_include"
mkdir -p "$include/kiss_icp"
ln -sfn "$kiss/core" "$include/kiss_icp/core"
ln -sfn "$kiss/pipeline" "$include/kiss_icp/pipeline"
g++ -std=c++17 -O3 -DNDEBUG -DSOPHUS_USE_BASIC_LOGGING -I"$include" -I"$2" -I"$3/include" -I/usr/include/eigen3 \
  -I"$root/include" "$root/bench/kiss_icp_peer.cpp" "$kiss"/core/*.cpp "$kiss/pipeline/KissICP.cpp" \
  "$root/build/release/libradargauss.a" -lrosbag_storage -lroslz4 -lroscpp_serialization -lrostime -lcpp_common \
  -lconsole_bridge -lboost_filesystem -lboost_regex -lbz2 -llz4 -ltbb -lz -llzf -lyaml-cpp -lsqlite3 -lzstd -lpthread \
  -o "$root/build/kiss_icp_peer"
echo "built $root/build/kiss_icp_peer"
