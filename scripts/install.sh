#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# Installs mcopt outside its build tree (docs/getting-started/install.md): the dependencies, a
# Release build, then either
#   scripts/install.sh [--prefix P]   cmake --install into P (default /usr/local): the command,
#                                     libraries, headers, CMake package, Python module, data
#   scripts/install.sh --deb          the Debian package (cpack -G DEB), installed with apt-get,
#                                     which resolves its dependencies; the .deb stays in build/release
#   scripts/install.sh --deb --no-install   the package only
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
prefix=/usr/local
deb=0
install=1
while [ $# -gt 0 ]; do
  case "$1" in
    --prefix) prefix="$2"; shift 2 ;;
    --deb) deb=1; shift ;;
    --no-install) install=0; shift ;;
    *) echo "usage: $0 [--prefix P] | --deb [--no-install]" >&2; exit 2 ;;
  esac
done
sudo_cmd=()
[ "$(id -u)" -eq 0 ] || sudo_cmd=(sudo)
"$root/scripts/install-deps.sh"
cmake --preset release -S "$root" >/dev/null
cmake --build "$root/build/release" --target mcopt mcopt_python mcopt_core mcopt_inner_qp mcopt_sensitivity mcopt_outer_nlp mcopt_study
if [ $deb -eq 0 ]; then
  "${sudo_cmd[@]}" cmake --install "$root/build/release" --prefix "$prefix"
  echo "install: mcopt $("$prefix/bin/mcopt" --version | cut -d' ' -f2) in $prefix"
  exit 0
fi
(cd "$root/build/release" && cpack -G DEB)
package="$(ls -t "$root"/build/release/mcopt_*_amd64.deb | head -1)"
echo "install: $package"
if [ $install -eq 1 ]; then
  "${sudo_cmd[@]}" apt-get install -y "$package"
  echo "install: $(mcopt --version) in /usr"
fi
