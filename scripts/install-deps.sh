#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# Installs mcopt's build dependencies from Debian 12 packages. Idempotent:
# packages already present are skipped, so it is cheap to run before every build.
# `install-deps.sh --list` prints the packages, one a line, and installs nothing
# (scripts/check-install-deps.sh checks them against every tool the suite calls).
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config
  libeigen3-dev            # Eigen 3.4
  coinor-libipopt-dev      # Ipopt 3.11 (MUMPS)
  libopenblas0-serial      # OpenBLAS as the system BLAS/LAPACK under MUMPS: Ipopt's factorisations twice as fast as the reference BLAS (docs/reference/scenario-file.md)
  libnlopt-cxx-dev         # NLopt 2.7
  libsuitesparse-dev       # SuiteSparse 5.12
  liburdfdom-dev           # urdfdom
  catch2                   # Catch2 v2
  libyaml-cpp-dev nlohmann-json3-dev libcli11-dev
  libbenchmark-dev         # Google Benchmark
  python3-matplotlib       # plots (scripts/plot_*.py) and the Python example
  pybind11-dev python3-dev python3-numpy python3-pytest   # the Python module (docs/reference/python.md) and its tests
  python3-cvxopt           # the independent conic reference of the inner baselines (scripts/inner_baselines.py)
  slurm-wlm munge          # studies as Slurm job arrays; scripts/slurm-local.sh and its test
  libjs-three              # three.js, inlined into the pages of `mcopt replay` (docs/guides/replay.md)
  chromium                 # headless browser of the replay's test
  clang libclang-rt-14-dev libomp-14-dev   # the libFuzzer targets (scripts/fuzz.sh, docs/developers/fuzzing.md)
  llvm                     # llvm-symbolizer: LeakSanitizer names the frames its suppressions match (tests/fuzz/lsan.supp)
  mkdocs                   # the documentation site: mkdocs build --strict (mkdocs.yml, tests/python/test_docs.py)
)

if [ "${1:-}" = --list ]; then
  printf '%s\n' "${packages[@]}"
  exit 0
fi

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages already installed"
  exit 0
fi

sudo_cmd=()
[ "$(id -u)" -eq 0 ] || sudo_cmd=(sudo)
echo "install-deps: installing ${missing[*]}"
"${sudo_cmd[@]}" apt-get update -qq
DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
