#!/usr/bin/env bash
# libFuzzer targets (fuzz/): builds them with clang (libraries instrumented, ASan + UBSan) in
# build-fuzz/ and runs each for ABUOPT_FUZZ_SECONDS seconds (default 10: the short CI run).
# The long run (docs/testing.md): ABUOPT_FUZZ_SECONDS=3600 bash scripts/fuzz.sh
# Seeds: every YAML under configs/ for the config readers, fuzz/corpus/<target>/ for the others;
# new inputs accumulate in build-fuzz/corpus/<target>/, crashes go to build-fuzz/artifacts/.
set -euo pipefail
cd "$(dirname "$0")/.."
secs=${ABUOPT_FUZZ_SECONDS:-10}
jobs=$(nproc 2>/dev/null || echo 2)
san="-fsanitize=address,undefined -fno-sanitize-recover=all"
cmake -S . -B build-fuzz -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DABUOPT_BUILD_TESTS=OFF -DABUOPT_BUILD_BENCH=OFF -DABUOPT_BUILD_FUZZ=ON \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g -fno-omit-frame-pointer -fsanitize=fuzzer-no-link $san" \
  -DCMAKE_EXE_LINKER_FLAGS="$san" >/dev/null
targets=(fuzz_config fuzz_cli fuzz_simulator)
cmake --build build-fuzz -j "$jobs" --target "${targets[@]}"

mkdir -p build-fuzz/artifacts build-fuzz/seeds/fuzz_config
find configs -name '*.yaml' -exec cp {} build-fuzz/seeds/fuzz_config/ \;
for t in "${targets[@]}"; do
  mkdir -p "build-fuzz/corpus/$t"
  seeds="fuzz/corpus/$t"
  [ -d "$seeds" ] || seeds="build-fuzz/seeds/$t"
  t0=$SECONDS
  # -timeout: libFuzzer's own hang limit per input, above the simulator target's 60 s guard.
  ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
    "build-fuzz/fuzz/$t" -max_total_time="$secs" -timeout=120 -rss_limit_mb=2048 \
    -artifact_prefix=build-fuzz/artifacts/"$t"- -print_final_stats=1 \
    "build-fuzz/corpus/$t" "$seeds" 2>"build-fuzz/$t.log" ||
    { tail -n 60 "build-fuzz/$t.log"; echo "fuzz: $t found a problem (input in build-fuzz/artifacts/)"; exit 1; }
  echo "fuzz: $t $((SECONDS - t0)) s, $(grep -m1 -o 'stat::number_of_executed_units: *[0-9]*' "build-fuzz/$t.log" | grep -o '[0-9]*$') inputs"
done
