#!/usr/bin/env bash
# Installs abuopt's build and run dependencies from Debian's packages, only those missing.
# Idempotent and non-interactive; needs root (or sudo) only when something is missing.
set -euo pipefail

packages=(
  build-essential cmake pkg-config git
  libeigen3-dev          # linear algebra (model solves, response surfaces)
  libsundials-dev        # ARKODE/CVODE with root finding: the event-driven simulator
  libyaml-cpp-dev        # study configs
  libnlopt-dev libnlopt-cxx-dev  # NLopt optimisers (C API + C++ wrapper; the CMake config is in libnlopt-dev)
  coinor-libipopt-dev    # Ipopt
  libpagmo-dev           # pagmo2 optimisers (CMA-ES, xNES, SADE, PSO; links TBB and Boost.Serialization)
  python3-optuna         # examples/python/optuna_study.py (TPE, CMA-ES samplers; exits 0 without it)
  libsqlite3-dev         # evaluation archive
  libopenmpi-dev openmpi-bin  # MPI across ranks (parallel/, option ABUOPT_MPI; docs/cluster.md)
  libcli11-dev           # command line parsing
  nlohmann-json3-dev     # JSON output (--json, summaries)
  libgtest-dev           # tests
  libbenchmark-dev       # bench/
  gnuplot-nox            # plots (optional at run time: studies skip plots without it)
  doxygen                # the optional API reference target `doc` (cmake/AbuoptData.cmake)
  clang libclang-rt-14-dev  # libFuzzer targets (fuzz/, scripts/fuzz.sh) with ASan/UBSan runtimes
  python3                # scripts/robust_evidence.py, benchmarks_report.py (standard library only)
  python3-dev pybind11-dev python3-numpy  # the Python module abuopt (python/; skipped without them)
  python3-scipy python3-matplotlib        # examples/python (each says so and exits 0 without its package)
  chromium               # headless browser: the test that opens abuopt study's report.html (tests/app/study_cli_test.py)
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi

echo "install-deps: installing ${missing[*]}" >&2
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
