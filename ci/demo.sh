#!/usr/bin/env bash
# Installs what is missing (Debian 12), builds, and runs the main job. Until
# `irbench demo` exists (issue 8) the main job renders the default sequence
# (theater4, person p1, the wave motion) and prints where it went.
# Extra arguments go to `irbench render` (e.g. --frames 30).
set -euo pipefail
cd "$(dirname "$0")/.."
./ci/install_deps.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release
cmake --build build -j"$(nproc)"
out=$(./build/irbench render --force "$@")
echo "sequence written to: ${out}"
ls "${out}"
