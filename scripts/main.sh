#!/usr/bin/env bash
# The README's main command: installs what is missing, builds, and reproduces the 2003 report's
# study (all its tables) at a reduced size that finishes in a few minutes on a laptop.
# Full size (the report's 1024/256 runs per case): build/app/abuopt reproduce
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh
exec build/app/abuopt reproduce --runs "${ABUOPT_RUNS:-256}" "$@"
