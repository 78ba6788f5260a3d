#!/usr/bin/env bash
# The README's main command: installs what is missing, builds, and reproduces the 2003 report's
# whole study (tables 4.1-4.4, the final profile, the friction sensitivity) at the report's own
# run counts: 36 Monte Carlo studies, 25 344 startups, about 20 s on two cores.
# A quicker look: ABUOPT_RUNS=256 bash scripts/main.sh (every case on a 16 x 16 grid).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh
if [ -n "${ABUOPT_RUNS:-}" ]; then
  exec build/app/abuopt reproduce --runs "$ABUOPT_RUNS" "$@"
fi
exec build/app/abuopt reproduce "$@"
