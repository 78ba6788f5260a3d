#!/usr/bin/env bash
# The README's test command: installs what is missing, builds, runs the default test suite.
# Long studies carry the ctest label "long" and run with: ctest --test-dir build -L long
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh
ctest --test-dir build -LE long --output-on-failure -j "$(nproc 2>/dev/null || echo 2)"
