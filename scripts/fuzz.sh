#!/usr/bin/env bash
# libFuzzer targets (fuzz/): builds them with clang in build-asan/ (the sanitizer step's build:
# libraries instrumented with ASan + UBSan + fuzzer-no-link, unit tests too; scripts/sanitize.sh)
# and runs each for ABUOPT_FUZZ_SECONDS seconds (default 10: the short CI run).
# The long run (docs/testing.md): ABUOPT_FUZZ_SECONDS=3600 bash scripts/fuzz.sh
# --build-only: configure build-asan/ and build the fuzz targets, run nothing.
# Seeds: every YAML under configs/ for the config readers, fuzz/corpus/<target>/ for the others;
# new inputs accumulate in build-asan/fuzz-corpus/<target>/, crashes go to build-asan/artifacts/.
set -euo pipefail
cd "$(dirname "$0")/.."
secs=${ABUOPT_FUZZ_SECONDS:-10}
jobs=$(nproc 2>/dev/null || echo 2)
dir=build-asan
san="-fsanitize=address,undefined -fno-sanitize-recover=all"
# A build-asan/ configured by an older script with another compiler is started afresh.
if [ -f "$dir/CMakeCache.txt" ] && ! grep -q '^CMAKE_CXX_COMPILER:[A-Z]*=.*clang++' "$dir/CMakeCache.txt"; then
  echo "fuzz: $dir/ was configured with another compiler; rebuilding it with clang++" >&2
  rm -rf "$dir"
fi
# -O1 and line tables only: fast to build, enough for the sanitizers' stack traces.
cmake -S . -B "$dir" -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DABUOPT_BUILD_TESTS=ON -DABUOPT_BUILD_BENCH=OFF -DABUOPT_BUILD_FUZZ=ON \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -gline-tables-only -fno-omit-frame-pointer -fsanitize=fuzzer-no-link $san" \
  -DCMAKE_EXE_LINKER_FLAGS="$san" >/dev/null
targets=(fuzz_config fuzz_cli fuzz_simulator)
cmake --build "$dir" -j "$jobs" --target "${targets[@]}"
[ "${1:-}" = "--build-only" ] && exit 0

mkdir -p "$dir/artifacts" "$dir/seeds/fuzz_config"
find configs -name '*.yaml' -exec cp {} "$dir/seeds/fuzz_config/" \;
for t in "${targets[@]}"; do
  mkdir -p "$dir/fuzz-corpus/$t"
  seeds="fuzz/corpus/$t"
  [ -d "$seeds" ] || seeds="$dir/seeds/$t"
  t0=$SECONDS
  # -timeout: libFuzzer's own hang limit per input, above the simulator target's 60 s guard.
  ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
    "$dir/fuzz/$t" -max_total_time="$secs" -timeout=120 -rss_limit_mb=2048 \
    -artifact_prefix="$dir/artifacts/$t-" -print_final_stats=1 \
    "$dir/fuzz-corpus/$t" "$seeds" 2>"$dir/$t.log" ||
    { tail -n 60 "$dir/$t.log"; echo "fuzz: $t found a problem (input in $dir/artifacts/)"; exit 1; }
  echo "fuzz: $t $((SECONDS - t0)) s, $(grep -m1 -o 'stat::number_of_executed_units: *[0-9]*' "$dir/$t.log" | grep -o '[0-9]*$') inputs"
done
