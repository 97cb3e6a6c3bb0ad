#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Drop-in stand-in for the `blender` executable that runs another Debian suite's
# `blender` package from a debootstrap folder on a Debian 12 host:
#
#   debian-blender.sh SUITE --setup     create the SUITE folder once (idempotent, locked)
#   debian-blender.sh SUITE ARGS...     run `blender ARGS...` inside it (--version, -b ...)
#
# blender43.sh (trixie: Blender 4.3) and blender52.sh (sid: Blender 5.2) name the
# suite and the Blender version they expect ($SSAO_EXPECT_BLENDER, major.minor:
# --setup fails when the suite ships another one).
#
# The folder is ${SSAO_DEBIAN_BLENDER_DIR:-/var/cache/ssao/SUITE}. Each run happens
# in a private mount namespace (unshare --mount --propagation private): /proc, /dev,
# /sys and the caller's folders are mounted inside the folder only for that
# process and vanish with it, whatever way it ends. Blender ends up with the
# script's own PID (exec all the way down), so signals reach Blender directly
# and the exit code is Blender's.
#
# Host folders seen at the same absolute path inside: /work, /tmp, /var/tmp,
# $TMPDIR, the repository, the current directory, the nearest existing folder
# of every absolute path among the arguments (also --opt=/path), and the
# colon-separated list $SSAO_BLENDER_BINDS. System trees (/usr, /etc, /var, ...)
# are never mounted over the folder's own.
#
# Environment passed to Blender: BLENDER_*, SSAO_*, DISPLAY and XAUTHORITY (the UI
# under Xvfb, whose socket and cookie are in /tmp), a few PYTHON*/thread/locale variables and the names in $SSAO_BLENDER_ENV (space-separated). HOME is passed
# when visible inside, otherwise it is a private tmpfs.
#
# The Debian mirror is the host's, read from its apt sources at run time
# ($SSAO_DEBIAN_MIRROR overrides it).
#
# Exit codes: Blender's; 2 when the folder is not set up or cannot be entered.
set -euo pipefail

if [[ "${1:-}" != __inside ]]; then
  [[ $# -ge 1 && "$1" =~ ^[a-z]+$ ]] || { echo "usage: $0 SUITE --setup | SUITE BLENDER-ARGS..." >&2; exit 2; }
  SUITE=$1
  shift
  ROOT=${SSAO_DEBIAN_BLENDER_DIR:-/var/cache/ssao/$SUITE}
  ROOT=${ROOT%/}
fi
EXPECT=${SSAO_EXPECT_BLENDER:-}
STAMP_NAME=.ssao-blender-ready
LEGACY_STAMP_NAME=.ssao-blender43-ready  # written by blender43.sh before it took a suite
PARTIAL_NAME=.ssao-blender-partial
# blender + numpy (not pulled in without recommends); EEVEE in 4.x needs an
# OpenGL context, which in -b mode it makes through EGL: libEGL (glvnd) + Mesa's
# EGL vendor library; Mesa renders it on the CPU (llvmpipe). The GL/GLX ones come
# with blender's dependencies and are named to keep them if those change.
PACKAGES="blender python3-numpy libegl1 libegl-mesa0 libgl1 libglx-mesa0 libgl1-mesa-dri${SSAO_BLENDER_EXTRA_PACKAGES:+ $SSAO_BLENDER_EXTRA_PACKAGES}"
SELF=$(realpath "${BASH_SOURCE[0]}")

say() { printf 'blender-%s: %s\n' "${SUITE:-}" "$*" >&2; }
die() { say "error: $*"; exit 2; }
now() { date +%s.%N; }
since() { awk -v a="$1" -v b="$(now)" 'BEGIN { printf "%.1f s", b - a }'; }

# ---------------------------------------------------------------------------
# Internal: entered through unshare, in a private mount namespace.
# Args: __inside ROOT CWD PRIVATE_HOME(0|1) CMD... ; binds in $SSAO__BINDS.
if [[ "${1:-}" == __inside ]]; then
  shift
  root=$1 cwd=$2 private_home=$3
  shift 3
  fail() { echo "debian-blender: error: $*" >&2; exit 2; }
  while IFS= read -r b; do
    [[ -n "$b" ]] || continue
    if [[ -d "$b" ]]; then
      { mkdir -p "$root$b" && mount --rbind "$b" "$root$b"; } || fail "cannot bind-mount $b"
    fi
  done <<< "${SSAO__BINDS:-}"
  mount -t proc proc "$root/proc" || fail "cannot mount /proc"
  mount --rbind /dev "$root/dev" || fail "cannot bind-mount /dev"
  mount --rbind /sys "$root/sys" || fail "cannot bind-mount /sys"
  mount -t tmpfs -o mode=0755 tmpfs "$root/run" || fail "cannot mount /run"
  envs=(PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin LANG=C.UTF-8)
  if [[ "$private_home" == 1 ]]; then
    mkdir -m 0700 "$root/run/home"
    envs+=(HOME=/run/home)
  else
    envs+=("HOME=$HOME")
  fi
  while IFS= read -r name; do
    case "$name" in
      BLENDER_* | SSAO_* | TMPDIR | TERM | TZ | CI | COLUMNS | LINES | DISPLAY | XAUTHORITY \
        | PYTHONPATH | PYTHONUNBUFFERED | PYTHONDONTWRITEBYTECODE | PYTHONFAULTHANDLER \
        | PYTHONHASHSEED | PYTHONWARNINGS | OMP_NUM_THREADS | OPENBLAS_* | OCIO \
        | TBB_* | CYCLES_* | LIBGL_* | MESA_* | GALLIUM_* | LP_NUM_THREADS | EGL_*)
        [[ "$name" == SSAO__BINDS ]] || envs+=("$name=${!name}")
        ;;
      *)
        [[ " ${SSAO_BLENDER_ENV:-} " == *" $name "* ]] && envs+=("$name=${!name}")
        ;;
    esac
  done < <(compgen -e)
  # Mesa's compiled-shader cache, kept in the folder across runs unless the caller
  # chose one: EEVEE's first render spends ~25 s compiling shaders, ~1 s once cached.
  if [[ -z "${MESA_SHADER_CACHE_DIR:-}" ]]; then
    mkdir -p "$root/var/cache/mesa-shader-cache"
    envs+=(MESA_SHADER_CACHE_DIR=/var/cache/mesa-shader-cache)
  fi
  exec chroot "$root" /usr/bin/env -i -C "$cwd" "${envs[@]}" "$@"
fi

# ---------------------------------------------------------------------------
# Shared helpers

require_root() {
  [[ $(id -u) -eq 0 ]] || die "must run as root (needs chroot and mount namespaces)"
}

check_root_path() {
  [[ "$ROOT" == /* ]] || die "SSAO_DEBIAN_BLENDER_DIR must be an absolute path: $ROOT"
  local depth
  depth=$(tr -cd / <<< "$ROOT" | wc -c)
  [[ $depth -ge 2 ]] || die "SSAO_DEBIAN_BLENDER_DIR must be at least two levels deep: $ROOT"
}

# Wait for the setup lock (another process may be making the folder) and
# hold it on file descriptor 9 until the process ends or it is closed.
take_lock() {
  local wait=$1 lock="$ROOT.lock"
  mkdir -p "$(dirname "$ROOT")"
  exec 9>>"$lock"
  if ! flock -n 9; then
    say "waiting for another setup of $ROOT (lock $lock)"
    flock -w "$wait" 9 || die "timed out waiting for the lock $lock"
  fi
}

# Mount points below ROOT in this namespace (there should be none outside
# a running invocation's private namespace).
mounts_below_root() {
  awk -v r="$ROOT" '{ p = $5; gsub(/\\040/, " ", p); if (p == r || index(p, r "/") == 1) print p }' \
    /proc/self/mountinfo
}

# Run CMD... as root inside the folder with /proc, /dev, /sys mounted (setup use).
chroot_cmd() {
  SSAO__BINDS="" unshare --mount --propagation private \
    "$SELF" __inside "$ROOT" / 1 /usr/bin/env DEBIAN_FRONTEND=noninteractive "$@"
}

# host_mirror: the host's Debian archive URI (scripts/debian_mirror.sh).
# shellcheck source=SCRIPTDIR/../debian_mirror.sh
source "$(dirname "$SELF")/../debian_mirror.sh"

# ---------------------------------------------------------------------------
# --setup

# A folder made before the script took a suite carries the old stamp's name.
adopt_legacy_stamp() {
  if [[ -f "$ROOT/$LEGACY_STAMP_NAME" && ! -f "$ROOT/$STAMP_NAME" ]]; then
    mv "$ROOT/$LEGACY_STAMP_NAME" "$ROOT/$STAMP_NAME" 2>/dev/null || true
  fi
}

stamp_packages() { sed -n 's/^packages: //p' "$ROOT/$STAMP_NAME" 2>/dev/null || true; }

write_stamp() {
  local version=$1 mirror=$2 eevee=$3
  {
    echo "made: $(date -u +%Y-%m-%dT%H:%M:%SZ)"
    echo "suite: $SUITE"
    echo "mirror: $mirror"
    echo "packages: $PACKAGES"
    echo "blender: $version"
    echo "eevee: $eevee"
  } > "$ROOT/$STAMP_NAME.tmp"
  mv "$ROOT/$STAMP_NAME.tmp" "$ROOT/$STAMP_NAME"
}

apt_install() {
  local log="$ROOT.apt.log"
  if ! chroot_cmd sh -c "apt-get update -q && apt-get install -y -q --no-install-recommends $PACKAGES && apt-get clean && rm -rf /var/lib/apt/lists/*" > "$log" 2>&1; then
    tail -n 20 "$log" >&2
    say "apt log: $log"
    return 1
  fi
  rm -f "$log"
}

smoke_test() {
  local out
  out=$(SSAO__BINDS="" unshare --mount --propagation private "$SELF" __inside "$ROOT" / 1 \
    blender -b --factory-startup -noaudio --python-exit-code 1 \
    --python-expr "import bpy, numpy; print('BLENDER_OK', '.'.join(map(str, bpy.app.version)), numpy.__version__)" 2>&1) \
    || { printf '%s\n' "$out" >&2; return 1; }
  out=$(grep -m1 '^BLENDER_OK' <<< "$out") || return 1
  echo "${out#BLENDER_OK }"
}

# An EEVEE still of the default scene, which also fills Mesa's shader cache.
eevee_test() {
  local out
  out=$(SSAO__BINDS="" unshare --mount --propagation private "$SELF" __inside "$ROOT" / 1 \
    blender -b --factory-startup -noaudio --python-exit-code 1 --python-expr "
import bpy
scene = bpy.context.scene
engines = scene.render.bl_rna.properties['engine'].enum_items.keys()
scene.render.engine = 'BLENDER_EEVEE_NEXT' if 'BLENDER_EEVEE_NEXT' in engines else 'BLENDER_EEVEE'
scene.render.resolution_x, scene.render.resolution_y = 64, 36
scene.render.resolution_percentage = 100
scene.eevee.taa_render_samples = 1
bpy.ops.render.render()
assert bpy.data.images['Render Result']
print('BLENDER_EEVEE_OK')
" 2>&1) || { printf '%s\n' "$out" | tail -n 20 >&2; return 1; }
  grep -q '^BLENDER_EEVEE_OK' <<< "$out" || { printf '%s\n' "$out" | tail -n 20 >&2; return 1; }
}

setup() {
  require_root
  check_root_path
  local t0 t mirror version
  t0=$(now)
  adopt_legacy_stamp
  if [[ -f "$ROOT/$STAMP_NAME" && "$(stamp_packages)" == "$PACKAGES" ]]; then
    say "ready: $ROOT ($(sed -n 's/^blender: //p' "$ROOT/$STAMP_NAME"))"
    return 0
  fi
  take_lock 3600
  if [[ -f "$ROOT/$STAMP_NAME" && "$(stamp_packages)" == "$PACKAGES" ]]; then
    say "ready: $ROOT (made by another process meanwhile)"
    return 0
  fi
  mirror=$(host_mirror) || true
  [[ -n "$mirror" ]] || die "no Debian archive found in the host's apt sources; set SSAO_DEBIAN_MIRROR"

  if [[ -f "$ROOT/$STAMP_NAME" ]]; then
    # Made by an older version of this script with another package list.
    say "updating packages in $ROOT"
    rm -f "$ROOT/$STAMP_NAME"
    t=$(now)
    apt_install || die "installing packages failed"
    say "packages installed in $(since "$t")"
  else
    if [[ -e "$ROOT" ]]; then
      if [[ -f "$ROOT/$PARTIAL_NAME" || -f "$ROOT/.ssao-blender43-partial" ]]; then
        [[ -z "$(mounts_below_root)" ]] \
          || die "a half-made $ROOT has mounts below it; unmount them: $(mounts_below_root | tr '\n' ' ')"
        say "removing the half-made $ROOT"
        rm -rf --one-file-system "$ROOT"
      elif [[ -n "$(ls -A "$ROOT")" ]]; then
        die "$ROOT exists, is not empty and was not made by this script: remove it or set SSAO_DEBIAN_BLENDER_DIR"
      fi
    fi
    if ! command -v debootstrap > /dev/null; then
      say "installing debootstrap on the host"
      t=$(now)
      DEBIAN_FRONTEND=noninteractive apt-get install -y -q debootstrap > /dev/null 2>&1 \
        || { apt-get update -q > /dev/null && DEBIAN_FRONTEND=noninteractive apt-get install -y -q debootstrap > /dev/null; } \
        || die "cannot install debootstrap"
      say "debootstrap installed in $(since "$t")"
    fi
    mkdir -p "$ROOT"
    touch "$ROOT/$PARTIAL_NAME"
    say "debootstrap --variant=minbase $SUITE $ROOT $mirror"
    t=$(now)
    local log="$ROOT.debootstrap.log"
    if ! debootstrap --variant=minbase "$SUITE" "$ROOT" "$mirror" > "$log" 2>&1; then
      tail -n 20 "$log" >&2
      die "debootstrap failed (log: $log); rerun --setup to start over"
    fi
    rm -f "$log"
    say "debootstrap done in $(since "$t")"

    echo "deb $mirror $SUITE main" > "$ROOT/etc/apt/sources.list"
    # sid's Release file is valid for a week only; a mirror that is a dated snapshot of the
    # archive serves an expired one, which apt refuses by default.
    echo 'Acquire::Check-Valid-Until "false";' > "$ROOT/etc/apt/apt.conf.d/99ssao-snapshot"
    cp -L /etc/resolv.conf "$ROOT/etc/resolv.conf"
    ln -sfn ../proc/self/mounts "$ROOT/etc/mtab" # Blender lists mounted file systems from it
    printf '#!/bin/sh\nexit 101\n' > "$ROOT/usr/sbin/policy-rc.d"
    chmod 755 "$ROOT/usr/sbin/policy-rc.d"
    mkdir -p "$ROOT/work" "$ROOT/var/tmp"

    say "installing $PACKAGES"
    t=$(now)
    apt_install || die "installing packages failed; rerun --setup to start over"
    say "packages installed in $(since "$t")"
  fi

  say "checking that Blender starts"
  t=$(now)
  version=$(smoke_test) || die "Blender does not start in $ROOT; rerun --setup to start over"
  say "Blender ${version%% *} (numpy ${version#* }) started in $(since "$t")"
  if [[ -n "$EXPECT" && "${version%% *}" != "$EXPECT" && "${version%% *}" != "$EXPECT".* ]]; then
    die "$SUITE ships Blender ${version%% *}, not $EXPECT; rerun --setup to start over"
  fi
  say "checking that EEVEE renders (the first time compiles shaders: ~30 s)"
  t=$(now)
  local eevee=failed
  if eevee_test; then
    eevee=ok
    say "EEVEE rendered in $(since "$t")"
  else
    say "warning: EEVEE did not render in $ROOT (Cycles works); see the output above"
  fi
  write_stamp "${version%% *}" "$mirror" "$eevee"
  rm -f "$ROOT/$PARTIAL_NAME"
  say "ready: $ROOT ($(du -sh --one-file-system "$ROOT" | cut -f1)) after $(since "$t0")"
}

# ---------------------------------------------------------------------------
# Running Blender

BINDS=()

is_system_path() {
  case "$1" in
    / | /var) return 0 ;;
    /var/tmp | /var/tmp/*) return 1 ;;
    /usr | /usr/* | /etc | /etc/* | /bin | /bin/* | /sbin | /sbin/* | /lib | /lib/* \
      | /lib32 | /lib32/* | /lib64 | /lib64/* | /libx32 | /libx32/* | /boot | /boot/* \
      | /dev | /dev/* | /proc | /proc/* | /sys | /sys/* | /run | /run/* | /var/*) return 0 ;;
  esac
  return 1
}

is_covered() {
  local p=$1 b
  for b in "${BINDS[@]}"; do
    [[ "$p" == "$b" || "$p" == "$b"/* ]] && return 0
  done
  return 1
}

# Add the nearest existing directory of a host path to the bind list.
want_bind() {
  local p=$1
  [[ "$p" == /* ]] || return 0
  p=$(realpath -s -m -- "$p") || return 0
  while [[ "$p" != / && ! -d "$p" ]]; do p=$(dirname -- "$p"); done
  is_system_path "$p" && return 0
  CANDIDATES+=("$p")
}

run_blender() {
  require_root
  check_root_path
  adopt_legacy_stamp
  if [[ ! -f "$ROOT/$STAMP_NAME" ]]; then
    # A setup may be under way in another process: wait for it.
    if [[ -e "$ROOT.lock" || -e "$ROOT" ]]; then
      take_lock 3600
      exec 9>&-
    fi
    [[ -f "$ROOT/$STAMP_NAME" ]] \
      || die "Blender ($SUITE) is not set up in $ROOT: run '$SELF $SUITE --setup' first (takes ~2 min, needs the Debian mirror)"
  fi

  CANDIDATES=()
  local repo a p cwd private_home=1
  repo=$(cd "$(dirname "$SELF")/../.." && pwd)
  for p in /work /tmp /var/tmp "${TMPDIR:-}" "$repo" "$PWD"; do
    [[ -n "$p" ]] && want_bind "$p"
  done
  if [[ -n "${SSAO_BLENDER_BINDS:-}" ]]; then
    IFS=: read -r -a extra <<< "$SSAO_BLENDER_BINDS"
    for p in "${extra[@]}"; do [[ -n "$p" ]] && want_bind "$p"; done
  fi
  for a in "$@"; do
    case "$a" in
      /*) want_bind "$a" ;;
      --*=/*) want_bind "${a#*=}" ;;
    esac
  done
  # Parents before children, children inside a parent dropped.
  while IFS= read -r p; do
    [[ -n "$p" ]] && ! is_covered "$p" && BINDS+=("$p")
  done < <(printf '%s\n' "${CANDIDATES[@]}" | awk '{ print length($0) "\t" $0 }' | sort -n -s | cut -f2- | uniq)

  cwd=/
  if is_covered "$PWD"; then
    cwd=$PWD
  elif [[ "$PWD" != / ]]; then
    say "warning: the current directory $PWD is not visible inside; running from /"
  fi
  if [[ -n "${HOME:-}" && -d "$HOME" ]] && is_covered "$HOME"; then
    private_home=0
  fi
  SSAO__BINDS=$(printf '%s\n' "${BINDS[@]}") \
    exec unshare --mount --propagation private \
    "$SELF" __inside "$ROOT" "$cwd" "$private_home" blender "$@"
}

case "${1:-}" in
  --setup)
    [[ $# -eq 1 ]] || die "--setup takes no other arguments"
    setup
    ;;
  *)
    run_blender "$@"
    ;;
esac
