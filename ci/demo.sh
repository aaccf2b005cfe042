#!/usr/bin/env bash
# The README's first command: installs what is missing (Debian 12), builds, and
# runs the main job, `irbench demo`: render the default session (theater4, p1,
# the thesis sensor preset, about 20 s), track, score, print the tables.
# Extra arguments go to `irbench demo` (e.g. --frames 60 for a quick look).
set -euo pipefail
cd "$(dirname "$0")/.."
./ci/install_deps.sh
./ci/configure.sh build -DCMAKE_BUILD_TYPE=Release -DCMAKE_UNITY_BUILD=ON
cmake --build build -j"$(nproc)"
./build/irbench demo --force "$@"
