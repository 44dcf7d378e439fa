#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# Checks that scripts/install-deps.sh provides every program and Python module that the build,
# the test suite and the scripts call: each one must be installed and come from a package that
# install-deps.sh installs, or from one of their dependencies, or from a package every Debian
# system has (Essential or Priority: required, which a minimal debootstrap root holds). A tool
# that only the machine's base image happens to have (llvm-symbolizer, issue 48) fails here.
#
#   scripts/check-install-deps.sh [--without PACKAGE]...
#
# --without drops a package from install-deps.sh's list before the check, to show that the check
# notices (tests/CMakeLists.txt runs it once with `--without llvm`). Exit 0 when every tool is
# provided, 1 otherwise with a line per tool that is not. Needs dpkg and apt-cache (Debian).
# docs/developers/fresh-debian.md says how the same set-up is rehearsed on a clean Debian 12 root.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"

without=()
while [ $# -gt 0 ]; do
  case "$1" in
    --without) [ $# -ge 2 ] || { echo "check-install-deps: --without needs a package" >&2; exit 2; }
               without+=("$2"); shift 2 ;;
    *) echo "usage: $0 [--without PACKAGE]..." >&2; exit 2 ;;
  esac
done

# What is called, by what. `cmd:NAME` is a program looked up on PATH (and in the sbin folders,
# where Debian puts daemons); `py:MODULE` a module of Debian's python3.
tools=(
  "cmd:cmake           configure and build (scripts/run.sh, scripts/test.sh)"
  "cmd:ctest           the test runner (scripts/test.sh)"
  "cmd:ninja           the presets' generator (CMakePresets.json)"
  "cmd:g++             the Release and sanitizer builds"
  "cmd:pkg-config      finding Ipopt, NLopt and urdfdom (CMakeLists.txt)"
  "cmd:clang++         the fuzz preset (scripts/fuzz.sh)"
  "cmd:llvm-symbolizer LeakSanitizer's function names, which tests/fuzz/lsan.supp matches (scripts/fuzz.sh)"
  "cmd:/usr/bin/python3 the Python module's tests, plots and the report (tests/python, scripts/*.py)"
  "py:numpy            the Python module (python/)"
  "py:pytest           the Python tests (tests/python)"
  "py:matplotlib       mcopt plot, study plots (scripts/plot_*.py)"
  "py:cvxopt           the conic reference of scripts/inner_baselines.py"
  "cmd:chromium        the replay page's test (tests/python/test_replay.py)"
  "cmd:munged          the local Slurm cluster (scripts/slurm-local.sh)"
  "cmd:mungekey        the local cluster's key (scripts/slurm-local.sh)"
  "cmd:slurmctld       the local Slurm cluster (scripts/slurm-local.sh)"
  "cmd:slurmd          the local Slurm cluster (scripts/slurm-local.sh)"
  "cmd:sinfo           the local cluster's state (scripts/slurm-local.sh)"
  "cmd:sbatch          mcopt study --slurm (study/)"
  "cmd:squeue          mcopt study --slurm --wait (study/)"
  "cmd:scancel         the Slurm study test (tests/apps/test_cli_study.cpp)"
  "cmd:hostname        the local cluster's node name (scripts/slurm-local.sh)"
  "cmd:timeout         the study's time limits and tests"
  "cmd:awk             scripts/slurm-local.sh"
  "cmd:mkdocs          the documentation site's strict build (tests/python/test_docs.py)"
  "cmd:cpack           the Debian package (cmake/mcoptInstall.cmake, tests/install/check_install.sh)"
  "cmd:dpkg-shlibdeps  the Debian package's library dependencies (cpack -G DEB)"
  "cmd:dpkg-deb        the Debian package's fields and its install in a scratch root (tests/install/check_install.sh)"
  "py:yaml             the reference drift tests (tests/python/test_reference.py)"
  "py:markdown         the anchors' slugs, as mkdocs makes them (tests/python/test_docs.py)"
)

command -v dpkg-query >/dev/null && command -v apt-cache >/dev/null ||
  { echo "check-install-deps: needs dpkg-query and apt-cache (a Debian system)" >&2; exit 2; }

mapfile -t listed < <(bash "$root/scripts/install-deps.sh" --list)
packages=()
for p in "${listed[@]}"; do
  keep=1
  for w in "${without[@]}"; do [ "$p" = "$w" ] && keep=0; done
  [ $keep -eq 1 ] && packages+=("$p")
done
[ ${#without[@]} -eq 0 ] || echo "check-install-deps: without ${without[*]} (as if install-deps.sh did not list it)"

# Every package install-deps.sh brings, with what they depend on (installed ones: a dependency
# that is not installed provides nothing here), then every package a minimal system has.
declare -A provided=()
while read -r p; do provided["${p%%:*}"]=1; done < <(
  apt-cache depends --recurse --installed --no-recommends --no-suggests --no-conflicts --no-breaks \
    --no-replaces --no-enhances "${packages[@]}" 2>/dev/null | grep -v '^ ' | tr -d '<>')
while read -r p essential priority; do
  [ "$essential" = yes ] || [ "$priority" = required ] && provided["${p%%:*}"]=1
done < <(dpkg-query -W -f='${Package} ${Essential} ${Priority}\n')

# The package that owns a file, trying the path as it is, then as Debian's merged /usr has it
# registered (/bin vs /usr/bin), then the file a link points to.
owner() {
  local f="$1" candidates=("$1") out
  case "$f" in /usr/bin/*|/usr/sbin/*|/usr/lib/*) candidates+=("${f#/usr}") ;; /bin/*|/sbin/*|/lib/*) candidates+=("/usr$f") ;; esac
  candidates+=("$(readlink -f "$f")")
  for c in "${candidates[@]}"; do
    if out="$(dpkg-query -S "$c" 2>/dev/null)"; then
      out="${out%%: *}"; echo "${out%%,*}" | sed 's/:.*//'; return 0
    fi
  done
  return 1
}

failures=0
for entry in "${tools[@]}"; do
  spec="${entry%% *}"; why="$(echo "${entry#* }" | sed 's/^ *//')"
  kind="${spec%%:*}"; name="${spec#*:}"
  if [ "$kind" = cmd ]; then
    case "$name" in
      /*) file="$name"; [ -x "$file" ] || file="" ;;
      *) file="$(PATH="$PATH:/usr/sbin:/sbin" command -v "$name" || true)" ;;
    esac
  else
    file="$(/usr/bin/python3 -c "import $name, sys; sys.stdout.write($name.__file__)" 2>/dev/null || true)"
  fi
  if [ -z "$file" ]; then
    echo "MISSING  $name: not installed; used for: $why"
    failures=$((failures + 1)); continue
  fi
  if ! pkg="$(owner "$file")"; then
    echo "UNOWNED  $name ($file) belongs to no Debian package: install-deps.sh cannot provide it; used for: $why"
    failures=$((failures + 1)); continue
  fi
  if [ -z "${provided[$pkg]:-}" ]; then
    echo "NOT PROVIDED  $name ($file, package $pkg): install-deps.sh installs neither $pkg nor a package that depends on it; used for: $why"
    failures=$((failures + 1)); continue
  fi
  printf 'ok  %-16s %s\n' "$name" "$pkg"
done

if [ $failures -gt 0 ]; then
  echo "check-install-deps: $failures of ${#tools[@]} tools are not provided by scripts/install-deps.sh"
  exit 1
fi
echo "check-install-deps: all ${#tools[@]} tools are provided by scripts/install-deps.sh (${#packages[@]} packages listed)"
