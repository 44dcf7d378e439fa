#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# Rehearses the README's two commands as a new user runs them on a fresh Debian 12: a minimal
# root made by debootstrap (the `minbase` variant: the required packages and apt, nothing of
# this machine's image), git alone added, this checkout's HEAD cloned into root's home there, then
# `scripts/run.sh` and `scripts/test.sh` one after the other, each timed. What a step of
# install-deps.sh misses shows here and nowhere else (issue 48). docs/developers/fresh-debian.md.
#
#   scripts/rehearse-fresh-debian.sh [--root DIR] [--shared DIR] [--only run|test] [--keep]
#   scripts/rehearse-fresh-debian.sh --deb FILE [--root DIR] [--keep]
#
# --root     where the root is made (default build/fresh-debian in this checkout); emptied first
# --shared   a shared/ folder put beside the clone, read-only, as CI has it (default: none, as a
#            newcomer has it)
# --only     run one of the two commands
# --keep     leave the root in place afterwards (its mounts are always undone)
# --deb      instead of the clone and its commands, the Debian package as a user installs it
#            (`apt-get install ./mcopt_*.deb`, dependencies resolved by apt), then `mcopt --version`,
#            `mcopt run /usr/share/mcopt/scenarios/hrp2_throw.yaml` to an optimal end, and
#            `python3 -c "import mcopt"` (docs/getting-started/install.md)
# The root has /proc, /sys (with no cgroup filesystem: as in a container) and /dev mounted. Its
# log is DIR.log; the exit status is the first failing command's. Needs root and about 12 GiB.
set -euo pipefail
source_dir="$(cd "$(dirname "$0")/.." && pwd)"
root_dir="$source_dir/build/fresh-debian"
shared=""
only=""
keep=0
deb=""
while [ $# -gt 0 ]; do
  case "$1" in
    --root) root_dir="$2"; shift 2 ;;
    --shared) shared="$(cd "$2" && pwd)"; shift 2 ;;
    --only) only="$2"; shift 2 ;;
    --keep) keep=1; shift ;;
    --deb) deb="$(cd "$(dirname "$2")" && pwd)/$(basename "$2")"; shift 2 ;;
    *) echo "usage: $0 [--root DIR] [--shared DIR] [--only run|test] [--keep] | --deb FILE [--root DIR] [--keep]" >&2; exit 2 ;;
  esac
done
case "$only" in ""|run|test) ;; *) echo "rehearse: --only takes run or test" >&2; exit 2 ;; esac
[ -z "$deb" ] || [ -f "$deb" ] || { echo "rehearse: $deb: no such package" >&2; exit 2; }
[ "$(id -u)" -eq 0 ] || { echo "rehearse: needs root (debootstrap, chroot, mount)" >&2; exit 2; }
mkdir -p "$(dirname "$root_dir")"
root_dir="$(cd "$(dirname "$root_dir")" && pwd)/$(basename "$root_dir")"
log="$root_dir.log"
: > "$log"
say() { echo "rehearse: $*" | tee -a "$log"; }

command -v debootstrap >/dev/null || { apt-get update -qq; DEBIAN_FRONTEND=noninteractive apt-get install -y -qq debootstrap; }

mounts=()
cleanup() {
  # Processes the suite left in the root (none should be left), then the mounts, last first.
  if [ -d "$root_dir/proc" ]; then
    for p in /proc/[0-9]*; do
      [ "$(readlink "$p/root" 2>/dev/null)" = "$root_dir" ] && kill -9 "${p#/proc/}" 2>/dev/null || true
    done
  fi
  local i
  for ((i = ${#mounts[@]} - 1; i >= 0; i--)); do umount -l "${mounts[$i]}" 2>/dev/null || true; done
  [ $keep -eq 1 ] || rm -rf --one-file-system "$root_dir"
}
trap cleanup EXIT

rm -rf --one-file-system "$root_dir"
mkdir -p "$root_dir"
start=$SECONDS
say "debootstrap --variant=minbase bookworm $root_dir"
debootstrap --variant=minbase bookworm "$root_dir" >> "$log" 2>&1
say "root made in $((SECONDS - start)) s"

mount -t proc proc "$root_dir/proc"; mounts+=("$root_dir/proc")
mount -t sysfs sysfs "$root_dir/sys"; mounts+=("$root_dir/sys")
mount --bind /dev "$root_dir/dev"; mounts+=("$root_dir/dev")
mount -t devpts devpts "$root_dir/dev/pts" -o newinstance,ptmxmode=0666 2>/dev/null && mounts+=("$root_dir/dev/pts") || true
cp /etc/resolv.conf "$root_dir/etc/resolv.conf"
mkdir -p "$root_dir/src"
mount --bind -o ro "$source_dir" "$root_dir/src"; mounts+=("$root_dir/src")
# The home of the root's user, where the clone goes; shared/ beside the clone, as CI has it.
home_in_root="$root_dir$(chroot "$root_dir" /usr/bin/env -i sh -c 'getent passwd 0 | cut -d: -f6')"
if [ -n "$shared" ]; then
  mkdir -p "$home_in_root/shared"
  mount --bind -o ro "$shared" "$home_in_root/shared"; mounts+=("$home_in_root/shared")
fi

# A clean environment, as a login shell of a new machine has it.
in_root() {
  chroot "$root_dir" /usr/bin/env -i HOME=/root PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin \
    LANG=C.UTF-8 TERM=dumb "$@"
}
timed() {  # name, command...
  local name="$1" t0=$SECONDS status=0
  shift
  say "$name: $*"
  in_root bash -c "$*" >> "$log" 2>&1 || status=$?
  say "$name: exit $status after $((SECONDS - t0)) s ($(( (SECONDS - t0) / 60 )) min $(( (SECONDS - t0) % 60 )) s)"
  return $status
}

if [ -n "$deb" ]; then
  # In the home of the root's user, installed from there as a user does: apt-get install ./FILE.
  cp "$deb" "$home_in_root/"
  package="./$(basename "$deb")"
  status=0
  timed "apt-get install $package" "cd ~ && apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq $package" || status=$?
  if [ $status -eq 0 ]; then
    timed "mcopt --version" "mcopt --version" || status=$?
    timed "mcopt run" "cd ~ && mcopt run /usr/share/mcopt/scenarios/hrp2_throw.yaml --out out/throw && grep -q '\"status\": \"optimal\"' out/throw/result.json" || status=$?
    timed "import mcopt" "cd / && python3 -c 'import mcopt; print(mcopt.__version__, mcopt.__file__)'" || status=$?
  fi
  say "total $((SECONDS - start)) s; log $log"
  exit $status
fi

timed "git" "apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends git ca-certificates"
timed "clone" "git clone -q /src ~/mcopt && git -C ~/mcopt log -1 --format='%h %s'"
status=0
if [ -z "$only" ] || [ "$only" = run ]; then
  timed "scripts/run.sh" "cd ~/mcopt && scripts/run.sh" || status=$?
fi
if [ $status -eq 0 ] && { [ -z "$only" ] || [ "$only" = test ]; }; then
  timed "scripts/test.sh" "cd ~/mcopt && CI=true scripts/test.sh" || status=$?
fi
say "total $((SECONDS - start)) s; log $log"
exit $status
