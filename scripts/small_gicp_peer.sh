#!/bin/bash
# SPDX-License-Identifier: BSD-3-Clause
# Builds bench/small_gicp_target_peer.cpp (the map build against small_gicp's
# VGICP target) against build/release, from a small_gicp checkout (headers):
#   scripts/small_gicp_peer.sh ~/src/small_gicp
# then: build/small_gicp_target_peer SEQUENCE_DIR GT_TUM [points_per_gaussian]
set -euo pipefail
if [ $# -ne 1 ]; then
  echo "usage: $0 SMALL_GICP_DIR" >&2
  exit 2
fi
root="$(cd "$(dirname "$0")/.." && pwd)"
[ -f "$1/include/small_gicp/ann/kdtree.hpp" ] || { echo "$0: no small_gicp headers under $1" >&2; exit 1; }
[ -f "$root/build/release/libradargauss.a" ] || { echo "$0: build radargauss first (scripts/test.sh)" >&2; exit 1; }
g++ -std=c++17 -O3 -DNDEBUG -I"$1/include" -I/usr/include/eigen3 -I"$root/include" \
  "$root/bench/small_gicp_target_peer.cpp" "$root/build/release/libradargauss.a" \
  -lrosbag_storage -lroslz4 -lroscpp_serialization -lrostime -lcpp_common -lconsole_bridge -lboost_filesystem \
  -lboost_regex -lbz2 -llz4 -ltbb -lz -llzf -lyaml-cpp -lsqlite3 -lzstd -lpthread -o "$root/build/small_gicp_target_peer"
echo "built $root/build/small_gicp_target_peer"
