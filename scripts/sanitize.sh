#!/usr/bin/env bash
# Sanitizer and fuzz steps of CI (called by scripts/test.sh; docs/testing.md has the measured times).
#   asan:  one clang build (build-asan/) with ASan + UBSan (-fno-sanitize-recover=all, asserts on)
#          and libFuzzer's coverage instrumentation (-fsanitize=fuzzer-no-link): the libraries,
#          their unit tests and the fuzz targets. Runs the unit tests (ctest -LE long).
#   tsan:  ThreadSanitizer build (build-tsan/) of the threaded tests only (Monte Carlo engine,
#          evaluation archive, minimize, batch evaluation, the startup-profile problem).
#   fuzz:  the libFuzzer targets of build-asan/, each run for ABUOPT_FUZZ_SECONDS (default 10)
#          from the seed corpus made from configs/ (scripts/fuzz.sh).
# One instrumented build serves both the unit tests and the fuzz targets: the coverage hooks that
# fuzzer-no-link adds are no-ops in a test program (the sanitizer runtime defines them), so a
# second library build just for fuzzing would only cost CI time.
# Usage: scripts/sanitize.sh [asan] [tsan] [fuzz]   (no argument: all three; fuzz builds its
# targets in build-asan/ if the asan step did not run)
# Every step prints "sanitize: <step> <seconds> s"; a finding fails the step (exit status != 0).
set -euo pipefail
cd "$(dirname "$0")/.."
jobs=$(nproc 2>/dev/null || echo 2)
steps=("$@")
[ ${#steps[@]} -eq 0 ] && steps=(asan tsan fuzz)

timed() {
  local name=$1
  shift
  local t0=$SECONDS
  "$@"
  echo "sanitize: $name $((SECONDS - t0)) s"
}

# The tests only: no benchmarks. -O1 and line tables only (GCC -g1: enough for the
# sanitizers' stack traces) keep the build and the run fast enough for CI.
configure() {
  local dir=$1 flags=$2
  shift 2
  cmake -S . -B "$dir" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DABUOPT_BUILD_BENCH=OFF "$@" \
    -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1 -fno-omit-frame-pointer $flags" \
    -DCMAKE_EXE_LINKER_FLAGS="$flags" >/dev/null
}

# Every unit test of the libraries (target abuopt_library_tests: tests/common, core, surrogate,
# optimizer, problems, studies). The command-line tests (tests/app) are left out: they run whole
# studies through the binary (minutes under ASan) and their input parsing is fuzzed under ASan by
# fuzz_cli; the MPI ones also because Open MPI's own allocations at exit would read as leaks.
asan_build() {
  bash scripts/fuzz.sh --build-only
  cmake --build build-asan -j "$jobs" --target abuopt_library_tests
}
# Tests named *Cli (suite or whole name) run the abuopt binary, which this build does not make.
# Five tests are left out of this step: they repeat code paths the others cover on many more
# starts (random starts of the study profiles with 1 Hz setpoints; SAO's adaptive sample size and
# global phase from 12 and 5 random starts) and took 159, 132 and 60 s of the step's 495 s of test
# time under ASan; and SAO's convergence on the noisy hs071 and cantilever (99 and 133 s of 272 s
# under ASan; the noise detection, regression designs and nugget they run are covered under ASan by
# SaoNoiseDetection.* and the noisy Rosenbrock and truss cases). They run in the default suite.
asan_slow="QuantisedReference[.]RandomStartsOfTheStudyProfilesAllFinish|SaoSampling[.]FewerSimulationsThanFixedSizeOnNoisyBenchmarks|SaoGlobal[.]Hs071FromRandomStartsReachesTheGlobalOptimum|Noisy/SaoConvergence[.]ReachesBestKnown/noisy_(hs071|cantilever)( |$)"
asan_test() {
  ASAN_OPTIONS=detect_leaks=1:strict_string_checks=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
    ctest --test-dir build-asan -LE "long|package" -E "_NOT_BUILT$|Cli([.]|$)|^package_|$asan_slow" \
    --output-on-failure -j "$jobs"
}

# Target abuopt_threaded_tests (tests/CMakeLists.txt): monte_carlo_test evaluation_archive_test
# minimize_test startup_profile_problem_test evaluation_batch_test startup_batch_test.
tsan_build() {
  configure build-tsan "-fsanitize=thread"
  cmake --build build-tsan -j "$jobs" --target abuopt_threaded_tests
}
tsan_test() {
  # setarch -R: kernels with 28+ bits of mmap randomisation break TSan's memory layout
  # ("unexpected memory mapping"); without address randomisation it runs.
  local regex="^(MonteCarlo|EvaluationArchive|ArchivedProblem|Minimize|StartupProfileProblem|EvaluationBatch|StartupBatch)"
  TSAN_OPTIONS=halt_on_error=1:second_deadlock_stack=1 \
    setarch "$(uname -m)" -R ctest --test-dir build-tsan -LE long -R "$regex" -E "_NOT_BUILT$" \
    --output-on-failure -j "$jobs"
}

for s in "${steps[@]}"; do
  case "$s" in
    asan) timed asan-build asan_build; timed asan-test asan_test ;;
    tsan) timed tsan-build tsan_build; timed tsan-test tsan_test ;;
    fuzz) timed fuzz bash scripts/fuzz.sh ;;
    *) echo "sanitize: unknown step '$s' (asan, tsan, fuzz)" >&2; exit 2 ;;
  esac
done
