#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# Installs every Debian 12 package radargauss needs that is not installed yet.
# Works as root or through sudo; installs nothing when all are present.
#   scripts/deps.sh            core build, tests and benchmarks
#   RADARGAUSS_DEPS_EXTRA="pkg ..." scripts/deps.sh   plus these packages
set -euo pipefail

packages=(
  # toolchain (clang-format: scripts/check_sources.py checks the layout)
  g++ make cmake pkg-config python3 clang-format
  # core (docs/design.md, "Dependencies and pitfalls")
  libceres-dev libeigen3-dev libsuitesparse-dev libmetis-dev
  libyaml-cpp-dev liblzf-dev libcli11-dev nlohmann-json3-dev libtbb-dev zlib1g-dev
  libsqlite3-dev libzstd-dev liblz4-dev
  # tests and benchmarks
  libgtest-dev libgmock-dev libbenchmark-dev
)
# shellcheck disable=SC2206
packages+=(${RADARGAUSS_DEPS_EXTRA:-})

missing=()
for package in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$package")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "deps: all ${#packages[@]} packages present"
  exit 0
fi

if [ "$(id -u)" -eq 0 ]; then
  as_root=()
elif command -v sudo >/dev/null 2>&1; then
  as_root=(sudo)
else
  echo "deps: missing packages (${missing[*]}) and neither root nor sudo" >&2
  exit 1
fi

echo "deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
"${as_root[@]}" apt-get update -qq
"${as_root[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
