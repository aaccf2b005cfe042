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
# The sanitizer build (clang, build-san/) at the lowest CPU priority while the
# Release build's tests run: it takes the CPU time they leave idle (a test
# waiting on another's shared render, a browser or gnuplot starting, files
# written) and yields the rest.
mkdir -p build-san
# (its own process group, so that a failing ctest stops the whole build; not
# its own session: with the kernel's autogroups a new session is scheduled
# beside this one as an equal, whatever its nice level)
set -m
SANITIZE_STEPS=build nice -n 19 ./ci/sanitize.sh >build-san/build.log 2>&1 &
san_build=$!
set +m
status=0
ctest --test-dir build --output-on-failure -j"$(nproc)" || status=$?
if [ "$status" -ne 0 ]; then
  kill -- -"$san_build" 2>/dev/null || true
  wait "$san_build" 2>/dev/null || true
  exit "$status"
fi
if ! wait "$san_build"; then
  tail -n 80 build-san/build.log >&2
  echo "test.sh: the sanitizer build failed (build-san/build.log)" >&2
  exit 1
fi
tail -n 3 build-san/build.log >&2
# The unit tests under ASan + UBSan and a short run of every fuzzer
# (docs/fuzzing.md).
SANITIZE_STEPS="tests fuzz" ./ci/sanitize.sh
# The README's first command with a short setting: 60 frames rendered, tracked,
# scored, the tables printed and report.html written.
./ci/demo.sh --frames 60 --out build/ci-demo
