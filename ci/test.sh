#!/usr/bin/env bash
# Installs what is missing (Debian 12), builds, and runs every test: the
# closed-loop tests (and the unit tests too slow under the sanitizers) from a
# Release build, then the unit tests under the sanitizers beside the fuzzers
# (ci/sanitize.sh). IRBENCH_UNIT_TESTS=ON runs every unit test in the Release
# build as well. Both builds compile each target's sources in batches of eight
# (CMAKE_UNITY_BUILD: a sixth less time here, a third under the sanitizers).
# The README's second command and what CI runs (.ci/run).
set -euo pipefail
cd "$(dirname "$0")/.."
./ci/install_deps.sh
./ci/configure.sh build -DCMAKE_BUILD_TYPE=Release -DCMAKE_UNITY_BUILD=ON -DIRBENCH_UNIT_TESTS="${IRBENCH_UNIT_TESTS:-OFF}"
cmake --build build -j"$(nproc)"
# One test more than there are cores: the closed-loop tests wait on their
# subprocesses, files and the Slurm daemons part of the time (on 2 cores, 612 s
# instead of 663 s for the same tests).
ctest --test-dir build --output-on-failure -j"$(($(nproc) + 1))"
# The unit tests under ASan + UBSan (clang, build-san/) and a short run of
# every fuzzer (docs/fuzzing.md). The fuzzers run a fixed time each, three at
# first and then two at a time (three minutes; the seventh no longer alone at
# the end with a core idle), so the sanitized unit tests and the README's
# first command with a short setting (60 frames rendered, tracked, scored, the
# tables printed and report.html written; its output printed when it ends)
# run beside them: each fuzzer still has its minute, on a share of the cores,
# and the three minutes are not spent again after it.
SANITIZE_STEPS=build ./ci/sanitize.sh
SANITIZE_STEPS=fuzz ./ci/sanitize.sh &
fuzz=$!
IRBENCH_CACHE_DIR=build/ci-cache ./ci/demo.sh --frames 60 --out build/ci-demo >build/ci-demo.log 2>&1 &
demo=$!
failed=0
SANITIZE_STEPS=tests ./ci/sanitize.sh || failed=1
wait "$demo" || { failed=1; echo "test: the demo failed:" >&2; }
cat build/ci-demo.log
if [ "$failed" -ne 0 ]; then
  kill "$fuzz" 2>/dev/null || true
  wait "$fuzz" || true
  exit 1
fi
wait "$fuzz"
