#!/usr/bin/env bash
# The sanitizer CI configuration (issue 27): clang with AddressSanitizer, UBSan
# and LeakSanitizer in build-san/. Builds the unit tests (CTest label "unit":
# the GoogleTest binaries beside each library, each one CTest test running
# all its tests in one process; not the closed-loop tests in
# tests/) and the libFuzzer harnesses (fuzz/), runs the unit tests, then runs
# every fuzzer on a scratch copy of its seed corpus. Fails on any test failure,
# sanitizer report, leak, crash or timeout. ci/test.sh calls it; docs/fuzzing.md
# tells how to fuzz longer.
#
# Environment:
#   SANITIZE_STEPS="build tests fuzz"  which steps, in this order
#   FUZZ_SECONDS=60     seconds per fuzzer (0: build them, fuzz nothing)
#   FUZZ_PARALLEL=2     fuzzers at a time (default: the core count, at most 2);
#                       the remainder of whole rounds runs in the first round
#   FUZZ_TARGETS="bvh rig"  only these fuzzers (default: all)
#   BUILD_DIR=build-san
#   SANITIZE_CC=clang SANITIZE_CXX=clang++  the compilers (e.g. clang-16)
#   IRBENCH_BUILD_LOCK=/tmp/x.lock  run the configure and build under flock(1)
#     on that file (a machine shared with other builds)
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
BUILD_DIR=${BUILD_DIR:-build-san}
FUZZ_SECONDS=${FUZZ_SECONDS:-60}
JOBS=$(nproc)
FUZZ_PARALLEL=${FUZZ_PARALLEL:-$((JOBS < 2 ? JOBS : 2))}
if ! [[ "$FUZZ_PARALLEL" =~ ^[1-9][0-9]*$ ]]; then
  echo "sanitize: FUZZ_PARALLEL must be a whole number from 1 (got '$FUZZ_PARALLEL')" >&2
  exit 2
fi
ALL_FUZZERS=(bvh asf_amc gltf rig scene suite calibration)
read -r -a FUZZERS <<<"${FUZZ_TARGETS:-${ALL_FUZZERS[*]}}"
start=$SECONDS

# The unit tests that take minutes under ASan (dense voxel grids checked voxel
# by voxel; a render and a track in each test process's set-up) are declared
# SLOW_UNDER_SANITIZERS beside their library: this build leaves them out, and
# ci/test.sh's Release build runs them.

# Mesa's software DRI driver, which EGL (surfaceless) loads and unloads again in
# eglTerminate: preloaded, it stays mapped, so LeakSanitizer neither reports
# its never-freed driver state from an unknown module at exit nor hides a leak
# of ours behind one.
MESA_DRI_DRIVER=/usr/lib/x86_64-linux-gnu/dri/swrast_dri.so

locked() {
  if [ -n "${IRBENCH_BUILD_LOCK:-}" ]; then flock "$IRBENCH_BUILD_LOCK" "$@"; else "$@"; fi
}

step() { echo "sanitize: [$((SECONDS - start)) s] $*" >&2; }

# The dictionary each fuzzer uses (fuzz/*.dict).
dictionary_of() {
  case "$1" in
    rig | scene | suite) echo fuzz/json.dict ;;
    *) echo "fuzz/$1.dict" ;;
  esac
}

configure_and_build() {
  step "configure $BUILD_DIR (clang, ASan + UBSan, libFuzzer)"
  # -Wno-unknown-warning-option: the project's GCC-only -Wno-restrict.
  # -gline-tables-only: the reports' stacks keep their files and lines, and
  # the build takes about a third less time than with full debug information.
  # CMAKE_UNITY_BUILD: each target's sources compiled eight to a translation
  # unit. Under the sanitizers much of the compile time goes to instrumenting
  # the inline template code (Eigen, JSON, GoogleTest) every file instantiates
  # again; batched, each batch instruments it once: 470 s instead of 700 s
  # for this build on 2 cores.
  locked ./ci/configure.sh "$BUILD_DIR" \
    -DCMAKE_C_COMPILER="${SANITIZE_CC:-clang}" -DCMAKE_CXX_COMPILER="${SANITIZE_CXX:-clang++}" \
    -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O2 -gline-tables-only -DNDEBUG" \
    -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -gline-tables-only -DNDEBUG" \
    -DCMAKE_CXX_FLAGS=-Wno-unknown-warning-option -DCMAKE_UNITY_BUILD=ON \
    -DIRBENCH_SANITIZE=ON -DIRBENCH_FUZZ=ON \
    -DIRBENCH_BUILD_TESTS=ON -DIRBENCH_BUILD_BENCHMARKS=OFF >/dev/null
  step "build the unit tests and the fuzzers"
  locked cmake --build "$BUILD_DIR" -j"$JOBS" --target irbench_unit_tests irbench_fuzzers
}

# Sanitizer settings for the tests and the fuzzers. UBSan stops at the first
# report (it only prints by default); leaks are errors; ci/lsan.supp holds the
# third-party libraries' own leaks (never ours).
export ASAN_OPTIONS="detect_leaks=1:check_initialization_order=1:strict_init_order=1:detect_stack_use_after_return=0"
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1"
export LSAN_OPTIONS="suppressions=$ROOT/ci/lsan.supp:print_suppressions=0"

run_unit_tests() {
  step "unit tests and the fuzz regressions (ctest -L 'unit|fuzz')"
  local args=(--test-dir "$BUILD_DIR" -L 'unit|fuzz' --output-on-failure -j"$JOBS" --timeout 300)
  if [ -f "$MESA_DRI_DRIVER" ]; then
    LD_PRELOAD="$MESA_DRI_DRIVER${LD_PRELOAD:+:$LD_PRELOAD}" ctest "${args[@]}"
  else
    ctest "${args[@]}"
  fi
}

# Fuzzes one target for FUZZ_SECONDS on a copy of its corpus under
# $BUILD_DIR/fuzz-work/<target>/; a crash, leak, timeout or out-of-memory input
# lands in its artifacts/ folder. libFuzzer's exit status goes to status.
fuzz_one() {
  local target=$1 work="$BUILD_DIR/fuzz-work/$1"
  rm -rf "$work"
  mkdir -p "$work/corpus" "$work/artifacts"
  cp fuzz/corpus/"$target"/* "$work/corpus/"
  if "$BUILD_DIR/fuzz/${target}_fuzz" "$work/corpus" \
    -dict="$(dictionary_of "$target")" \
    -max_total_time="$FUZZ_SECONDS" -rss_limit_mb=2048 -timeout=10 \
    -artifact_prefix="$work/artifacts/" -print_final_stats=1 \
    >"$work/fuzz.log" 2>&1; then
    echo 0 >"$work/status"
  else
    echo $? >"$work/status"
  fi
}

run_fuzzers() {
  if [ "$FUZZ_SECONDS" -le 0 ]; then
    step "FUZZ_SECONDS=0: no fuzzing"
    return 0
  fi
  # Whole rounds of FUZZ_PARALLEL fuzzers; what is left over runs in the first
  # round (in ci/test.sh beside the sanitized unit tests) instead of alone at
  # the end with the other cores idle (7 fuzzers on 2 cores: 3, 2, 2 = three
  # minutes).
  local n=${#FUZZERS[@]}
  local first=$((n <= FUZZ_PARALLEL ? n : FUZZ_PARALLEL + n % FUZZ_PARALLEL))
  step "fuzz ${FUZZERS[*]}: ${FUZZ_SECONDS} s each, $first at first, then $FUZZ_PARALLEL at a time"
  local target failed=() launched=0
  for target in "${FUZZERS[@]}"; do
    if [ "$launched" -ge "$first" ]; then
      while [ "$(jobs -rp | wc -l)" -ge "$FUZZ_PARALLEL" ]; do sleep 1; done
    fi
    fuzz_one "$target" &
    launched=$((launched + 1))
  done
  wait
  for target in "${FUZZERS[@]}"; do
    local work="$BUILD_DIR/fuzz-work/$target"
    if [ "$(cat "$work/status" 2>/dev/null)" = 0 ]; then
      echo "sanitize: fuzz $target: ok, $(grep -o 'cov: [0-9]* ft: [0-9]*' "$work/fuzz.log" | tail -n 1)," \
        "$(grep -o 'stat::number_of_executed_units: [0-9]*' "$work/fuzz.log" | grep -o '[0-9]*$') runs," \
        "$(grep -o 'exec/s: [0-9]*' "$work/fuzz.log" | tail -n 1)" >&2
    else
      failed+=("$target")
      echo "sanitize: fuzz $target: FAILED; the end of $work/fuzz.log:" >&2
      tail -n 60 "$work/fuzz.log" >&2
      echo "sanitize: the input that failed:" "$work"/artifacts/* >&2
    fi
  done
  if [ ${#failed[@]} -gt 0 ]; then
    echo "sanitize: fuzzers failed: ${failed[*]} (docs/fuzzing.md: save the input as a test)" >&2
    return 1
  fi
}

read -r -a STEPS <<<"${SANITIZE_STEPS:-build tests fuzz}"
for s in "${STEPS[@]}"; do
  case "$s" in
    build) configure_and_build ;;
    tests) run_unit_tests ;;
    fuzz) run_fuzzers ;;
    *) echo "sanitize: SANITIZE_STEPS: unknown step '$s' (build, tests, fuzz)" >&2; exit 2 ;;
  esac
done
step "done"
