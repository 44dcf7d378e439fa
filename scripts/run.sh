#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# Installs the dependencies, builds mcopt (Release) and runs the main job on the
# bundled HRP-2 scenario. Extra arguments go to `mcopt`, e.g. `scripts/run.sh run X.yaml`.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
"$root/scripts/install-deps.sh"
cmake --preset release -S "$root" >/dev/null
cmake --build "$root/build/release" --target mcopt
if [ $# -eq 0 ]; then
  set -- run "$root/scenarios/hrp2_kick.yaml" --out "$root/out/hrp2_kick"
fi
exec "$root/build/release/apps/mcopt" "$@"
