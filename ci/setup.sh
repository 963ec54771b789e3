#!/usr/bin/env bash
# ci/setup.sh — install exactly the Debian (bookworm) packages MINER needs.
# Idempotent: re-running it installs nothing new. Needs root (or sudo) and apt.
#
#   bash ci/setup.sh            # install build + test dependencies
#
# The list is the single source of truth for dependencies; docs/layout.md explains
# the job each package does.
set -euo pipefail

PACKAGES=(
  # toolchain
  g++ cmake ninja-build make git ca-certificates pkg-config
  # numerics
  libeigen3-dev        # linear algebra everywhere
  libceres-dev         # independent optimiser: checks MINCO optimality, refines time allocation
  libsundials-dev      # CVODE integrates the quadrotor rigid body
  # world model and I/O
  liboctomap-dev       # OctoMap: scan integration (miner map scan), oracle for the .bt/.ot reader tests
  nlohmann-json3-dev   # map / scenario / result JSON
  libcli11-dev         # the `miner` command line
  # benchmark peers
  libompl-dev ompl-demos libboost-filesystem-dev libboost-system-dev libboost-serialization-dev
  libboost-dev         # Boost.Math: chi-square quantiles (EKF gate, NEES/NIS tests); Boost.Multiprecision: exact waypoint misses (traj properties)
  # verification
  catch2               # unit tests (Catch2 v2)
  librapidcheck-dev    # property tests
  gcovr                # coverage reports and thresholds
  clang-16 libclang-rt-16-dev libfuzzer-16-dev libomp-16-dev   # libFuzzer targets (ci/fuzz.sh; omp.h for sgan.cpp)
  python3              # traceability checker
  python3-mpmath       # docs/figures/answer_check.sh: the exact optimum of refused trajectory problems
  pybind11-dev python3-dev python3-pytest   # the Python bindings (`import miner`, src/python) and their tests
  # learned heuristic
  libdnnl-dev          # oneDNN: the sGAN's 3D convolutions in C++ (~20x LibTorch's default CPU path)
  python3-torch python3-numpy python3-scipy   # sGAN training (src/python/sgan; scipy: connected components) and its test
  # reports
  libjs-three          # three.js r111, embedded in every flight report's 3D view
  chromium             # headless browser: the report's screenshot test
)

SUDO=""
if [ "$(id -u)" -ne 0 ]; then
  if command -v sudo >/dev/null 2>&1; then SUDO="sudo"; else
    echo "ci/setup.sh: needs root or sudo to install packages" >&2; exit 1; fi
fi

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ "${#missing[@]}" -eq 0 ]; then
  echo "ci/setup.sh: all ${#PACKAGES[@]} packages already installed"
  exit 0
fi

echo "ci/setup.sh: installing ${#missing[@]} packages: ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
