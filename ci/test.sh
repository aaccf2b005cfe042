#!/usr/bin/env bash
# Installs what is missing (Debian 12), builds, and runs every test: the
# closed-loop tests (and the unit tests too slow under the sanitizers) from a
# Release build, while the sanitizer build runs at the lowest priority beside
# them, then the unit tests and fuzzers under the sanitizers (ci/sanitize.sh). IRBENCH_UNIT_TESTS=ON runs every unit test in the Release
# build as well. Both builds compile each target's sources in batches of eight
# (CMAKE_UNITY_BUILD: a sixth less time here, a third under the sanitizers).
# The README's second command and what CI runs (.ci/run).
set -euo pipefail
cd "$(dirname "$0")/.."
./ci/install_deps.sh
./ci/configure.sh build -DCMAKE_BUILD_TYPE=Release -DCMAKE_UNITY_BUILD=ON -DIRBENCH_UNIT_TESTS="${IRBENCH_UNIT_TESTS:-OFF}"
cmake --build build -j"$(nproc)"
# The sanitizer build (clang, build-san/) at the lowest priority beside the
# Release tests: it takes only the CPU time the tests leave idle, so they keep
# their pace, and it goes on at full speed once they are done. Its log is
# printed when it ends. (It stays in this session: with the kernel's
# autogroup scheduling, a process in a session of its own, setsid, would
# share the CPU equally with the tests whatever its nice value.)
SANITIZE_STEPS=build nice -n 19 ./ci/sanitize.sh >build/sanitize-build.log 2>&1 &
san_build=$!
kill_tree() {
  local child
  for child in $(pgrep -P "$1" || true); do kill_tree "$child"; done
  kill "$1" 2>/dev/null || true
}
# One test more than there are cores: the closed-loop tests wait on their
# subprocesses, files and the Slurm daemons part of the time (on 2 cores, 612 s
# instead of 663 s for the same tests).
if ! ctest --test-dir build --output-on-failure -j"$(($(nproc) + 1))"; then
  kill_tree "$san_build"
  wait "$san_build" || true
  exit 1
fi
san_status=0
wait "$san_build" || san_status=$?
cat build/sanitize-build.log
[ "$san_status" -eq 0 ] || exit "$san_status"
# The unit tests under ASan + UBSan, then a short run of every fuzzer
# (docs/fuzzing.md). The fuzzers run a fixed time each, two at a time (the
# seventh alone), so the README's first command runs beside them with a short
# setting: 60 frames rendered, tracked, scored, the tables printed and
# report.html written.
SANITIZE_STEPS=tests ./ci/sanitize.sh
SANITIZE_STEPS=fuzz ./ci/sanitize.sh &
fuzz=$!
if ! ./ci/demo.sh --frames 60 --out build/ci-demo; then
  kill "$fuzz" 2>/dev/null || true
  wait "$fuzz" || true
  exit 1
fi
wait "$fuzz"
