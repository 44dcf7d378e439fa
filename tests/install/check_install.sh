#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# What an installed mcopt promises (docs/getting-started/install.md), checked from the outside:
#   check_install.sh STEP BUILD_DIR SOURCE_DIR WORK_DIR
# STEP:
#   prefix     cmake --install BUILD_DIR into WORK_DIR/prefix (emptied first); the others read it
#   consumer   examples/cpp configured, built and run against the prefix alone
#   headers    every installed header compiles alone against the prefix
#   version    find_package(mcopt 99) fails with CMake's version message; 0.1 is found
#   pkgconfig  a program built with `pkg-config --cflags --libs --static mcopt-core` runs
#   command    the installed command: --version, a run of a bundled scenario from share/mcopt,
#              `plot` and `replay` with the installed scripts and template (not the source tree's)
#   deb        cpack -G DEB: the package's name, its declared dependencies (each installed here,
#              so apt resolves them), installed by dpkg into a scratch root: the command runs a
#              bundled scenario from it and Debian's python3 imports the module from its place
set -euo pipefail
step="$1"; build="$(cd "$2" && pwd)"; source="$(cd "$3" && pwd)"; work="$4"
prefix="$work/prefix"
mkdir -p "$work"
fail() { echo "check_install $step: $*" >&2; exit 1; }
# An installed command under PREFIX: `--version`, then the bundled throw from PREFIX/share/mcopt
# capped at 3 iterations (exit 0, or 4: not optimal yet) in the current folder; sets $code.
run_installed() {  # PREFIX WHAT
  local p="$1" what="$2"
  "$p/bin/mcopt" --version | grep -qx "mcopt [0-9]*\.[0-9]*\.[0-9]*" || fail "$what: mcopt --version"
  set +e
  "$p/bin/mcopt" run "$p/share/mcopt/scenarios/hrp2_throw.yaml" --out out --max-iterations 3 > run.log 2>&1
  code=$?
  set -e
  [ $code -eq 0 ] || [ $code -eq 4 ] || { cat run.log; fail "$what: mcopt run ended $code"; }
  [ -f out/result.json ] || fail "$what: no result.json"
}
python=/usr/bin/python3

case "$step" in
prefix)
  rm -rf "$prefix"
  cmake --install "$build" --prefix "$prefix" > "$work/install.log"
  [ -x "$prefix/bin/mcopt" ] || fail "no bin/mcopt"
  # Nothing installed names the source or build tree.
  if grep -rlI -e "$source" -e "$build" "$prefix" --exclude-dir=scenarios; then fail "installed files name the source or build tree (above)"; fi
  echo "installed $(find "$prefix" -type f | wc -l) files"
  ;;
consumer)
  rm -rf "$work/consumer"
  cmake -S "$source/examples/cpp" -B "$work/consumer" -G Ninja -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_BUILD_TYPE=Release > "$work/consumer.log"
  cmake --build "$work/consumer" >> "$work/consumer.log" || { cat "$work/consumer.log"; fail "the consumer does not build"; }
  "$work/consumer/mcopt_consumer"
  ;;
headers)
  rm -rf "$work/headers"; mkdir -p "$work/headers/src"
  count=0
  while IFS= read -r header; do
    relative="${header#"$prefix/include/"}"
    echo "#include <$relative>" > "$work/headers/src/$(echo "$relative" | tr '/.' '__').cpp"
    count=$((count + 1))
  done < <(find "$prefix/include/mcopt" -name '*.hpp' | sort)
  [ "$count" -ge 40 ] || fail "only $count installed headers"
  cat > "$work/headers/CMakeLists.txt" <<'CMAKE'
cmake_minimum_required(VERSION 3.20)
project(mcopt_headers LANGUAGES CXX)
set(CMAKE_CXX_STANDARD 20)
find_package(mcopt 0.1 REQUIRED)
file(GLOB sources ${CMAKE_SOURCE_DIR}/src/*.cpp)
add_library(headers OBJECT ${sources})
target_link_libraries(headers PRIVATE mcopt::core mcopt::inner_qp mcopt::sensitivity mcopt::outer_nlp mcopt::study)
target_compile_options(headers PRIVATE -fsyntax-only)
CMAKE
  cmake -S "$work/headers" -B "$work/headers/build" -G Ninja -DCMAKE_PREFIX_PATH="$prefix" > "$work/headers.log"
  cmake --build "$work/headers/build" -- -k 0 >> "$work/headers.log" 2>&1 || { grep -B2 -A8 "error" "$work/headers.log" | head -60; fail "installed headers that do not compile alone (above)"; }
  echo "$count installed headers compile alone"
  ;;
version)
  rm -rf "$work/version"; mkdir -p "$work/version"
  for wanted in 99 0.1; do
    printf 'cmake_minimum_required(VERSION 3.20)\nproject(v LANGUAGES CXX)\nfind_package(mcopt %s REQUIRED)\nmessage(STATUS "found mcopt ${mcopt_VERSION}")\n' "$wanted" > "$work/version/CMakeLists.txt"
    rm -rf "$work/version/build"
    if cmake -S "$work/version" -B "$work/version/build" -DCMAKE_PREFIX_PATH="$prefix" > "$work/version/$wanted.log" 2>&1; then
      [ "$wanted" != 99 ] || fail "find_package(mcopt 99) succeeded"
      grep -q "found mcopt 0\.1\." "$work/version/$wanted.log" || fail "find_package(mcopt 0.1) did not report the version"
    else
      [ "$wanted" = 99 ] || { cat "$work/version/$wanted.log"; fail "find_package(mcopt $wanted) failed"; }
      tr -s ' \n' ' ' < "$work/version/$wanted.log" | grep -q 'compatible with requested version "99"' || { cat "$work/version/99.log"; fail "no version message"; }
    fi
  done
  echo "find_package(mcopt 99) refused with CMake's version message; 0.1 found"
  ;;
pkgconfig)
  rm -rf "$work/pkgconfig"; mkdir -p "$work/pkgconfig"
  cat > "$work/pkgconfig/main.cpp" <<'CPP'
#include <cstdio>
#include <mcopt/core/inverse_dynamics.hpp>
#include <mcopt/core/robot_model.hpp>
int main(int, char** argv) {
  const mcopt::RobotModel robot = mcopt::loadUrdfFile(argv[1]);
  const mcopt::DynamicsModel model(robot, "l_sole");
  mcopt::DynamicsData data(model);
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(robot.jointCount());
  mcopt::inverseDynamics(model, data, zero, zero, zero);
  std::printf("%d joints, |tau| %.3f N m at rest\n", robot.jointCount(), data.tau.norm());
  return data.tau.allFinite() ? 0 : 1;
}
CPP
  flags="$(PKG_CONFIG_PATH="$prefix/lib/pkgconfig" pkg-config --cflags --libs --static mcopt-core)"
  # shellcheck disable=SC2086
  g++ -std=c++20 -O1 "$work/pkgconfig/main.cpp" -o "$work/pkgconfig/main" $flags
  "$work/pkgconfig/main" "$prefix/share/mcopt/robots/hrp2/hrp2.urdf"
  ;;
command)
  rm -rf "$work/command"; mkdir -p "$work/command"
  cp -a "$prefix" "$work/command/prefix"   # a copy, whose scripts can be told apart from the source tree's
  p="$work/command/prefix"
  cd "$work/command"
  run_installed "$p" "the prefix"
  # The installed plotting script and replay template are the ones used: marked copies show it.
  printf 'import sys\nprint("installed plot script", sys.argv[1:])\n' > "$p/share/mcopt/scripts/plot_result.py"
  "$p/bin/mcopt" plot out | grep -q "installed plot script" || fail "mcopt plot did not run share/mcopt/scripts/plot_result.py"
  sed -i 's|<head>|<head><!-- installed template -->|' "$p/share/mcopt/replay/viewer.html"
  "$p/bin/mcopt" replay out > /dev/null
  grep -q "installed template" out/replay.html || fail "mcopt replay did not use share/mcopt/replay"
  echo "the installed command ran hrp2_throw from share/mcopt (exit $code) and used its own scripts and template"
  ;;
deb)
  rm -rf "$work/deb"; mkdir -p "$work/deb"
  (cd "$work/deb" && cpack -G DEB --config "$build/CPackConfig.cmake" > cpack.log) || { cat "$work/deb/cpack.log"; fail "cpack -G DEB failed"; }
  version="$(sed -n 's/^set(CPACK_PACKAGE_VERSION "\(.*\)")/\1/p' "$build/CPackConfig.cmake")"
  package="$work/deb/mcopt_${version}_amd64.deb"
  [ -f "$package" ] || { ls "$work/deb"; fail "no mcopt_${version}_amd64.deb"; }
  depends="$(dpkg-deb -f "$package" Depends)"
  echo "Depends: $depends"
  for needed in python3-numpy python3-matplotlib libjs-three libipopt libnlopt yaml-cpp urdfdom libklu libumfpack libgomp; do
    echo "$depends" | grep -q "$needed" || fail "Depends lacks $needed"
  done
  # Each dependency (an alternative of it) is installed here: apt resolves them from Debian 12.
  IFS=',' read -ra entries <<< "$depends"
  for entry in "${entries[@]}"; do
    satisfied=0
    IFS='|' read -ra alternatives <<< "$entry"
    for alternative in "${alternatives[@]}"; do
      name="$(echo "$alternative" | sed 's/(.*//' | tr -d ' ')"
      dpkg-query -W -f='${Status}' "$name" 2>/dev/null | grep -q "install ok installed" && satisfied=1
    done
    [ $satisfied -eq 1 ] || fail "dependency not installable from this machine's Debian: $entry"
  done
  root="$work/deb/root"
  mkdir -p "$root/var/lib/dpkg/info" "$root/var/lib/dpkg/updates"
  touch "$root/var/lib/dpkg/status"
  dpkg --root="$root" --force-depends --force-not-root --force-script-chrootless -i "$package" > "$work/deb/dpkg.log" 2>&1 \
    || { cat "$work/deb/dpkg.log"; fail "dpkg -i into the scratch root failed"; }
  [ -x "$root/usr/bin/mcopt" ] || fail "no usr/bin/mcopt in the package"
  cd "$work/deb"
  run_installed "$root/usr" "the package"
  # The module sits where Debian's python3 looks under /usr.
  "$python" -c "import sys; assert '/usr/lib/python3/dist-packages' in sys.path" || fail "Debian's python3 does not search /usr/lib/python3/dist-packages"
  PYTHONPATH="$root/usr/lib/python3/dist-packages" "$python" -c "import mcopt; assert mcopt.__file__.startswith('$root/usr/lib/python3/dist-packages/'), mcopt.__file__; print('import mcopt', mcopt.__version__)"
  echo "mcopt_${version}_amd64.deb: installed into a scratch root; mcopt run ended $code"
  ;;
*) fail "unknown step" ;;
esac
