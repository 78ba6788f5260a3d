#!/usr/bin/env bash
# The README's test command: installs what is missing, builds, runs the default test suite.
# Then the sanitizer and fuzz steps (scripts/sanitize.sh: ASan+UBSan unit tests, TSan on the threaded
# tests, a short libFuzzer run per target; docs/testing.md has what each costs).
# ABUOPT_SANITIZE=0 leaves them out (a quick local check; CI runs them).
# Long studies carry the ctest label "long" and run with: ctest --test-dir build -L long
set -euo pipefail
cd "$(dirname "$0")/.."
t0=$SECONDS
bash scripts/build.sh
echo "test: build $((SECONDS - t0)) s"
t1=$SECONDS
ctest --test-dir build -LE long --output-on-failure -j "$(nproc 2>/dev/null || echo 2)"
echo "test: default suite $((SECONDS - t1)) s"
if [ "${ABUOPT_SANITIZE:-1}" != "0" ]; then
  bash scripts/sanitize.sh
fi
echo "test: total $((SECONDS - t0)) s"
