#!/usr/bin/env bash
# Installs what is missing (Debian 12), builds, and runs every test: the
# closed-loop tests (and the unit tests too slow under the sanitizers) from a
# Release build, then the unit tests and fuzzers under the sanitizers
# (ci/sanitize.sh). IRBENCH_UNIT_TESTS=ON runs every unit test in the Release
# build as well. Both builds compile each target's sources in batches of eight
# (CMAKE_UNITY_BUILD: a sixth less time here, a third under the sanitizers).
# The README's second command and what CI runs (.ci/run).
set -euo pipefail
cd "$(dirname "$0")/.."
./ci/install_deps.sh
./ci/configure.sh build -DCMAKE_BUILD_TYPE=Release -DCMAKE_UNITY_BUILD=ON -DIRBENCH_UNIT_TESTS="${IRBENCH_UNIT_TESTS:-OFF}"
cmake --build build -j"$(nproc)"
ctest --test-dir build --output-on-failure -j"$(nproc)"
# The unit tests under ASan + UBSan (clang, build-san/) and a short run of every
# fuzzer (docs/fuzzing.md).
./ci/sanitize.sh
# The README's first command with a short setting: 60 frames rendered, tracked,
# scored, the tables printed and report.html written.
./ci/demo.sh --frames 60 --out build/ci-demo
