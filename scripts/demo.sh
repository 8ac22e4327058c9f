#!/usr/bin/env bash
# Sets up and runs the main job on the embedded default.
# The paper's localisation demo on the synthetic sequence (simulate, build the
# Gaussian-RCS map, sweep w_rcs, print the table, plot) arrives with the
# experiment issue; until then this builds the project and runs the API tour.
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
"$root/scripts/deps.sh"
cmake -S "$root" -B "$root/build/release" -DCMAKE_BUILD_TYPE=Release
cmake --build "$root/build/release" -j "$(nproc)" --target lie_sh_example
"$root/build/release/examples/lie_sh_example"
echo "demo: the localisation experiment (radargauss demo) is not implemented yet."
