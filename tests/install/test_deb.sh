#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# The Debian package as a farm node gets it: `apt-get install ./ssao_*.deb` on a clean Debian 12.
#
#   test_deb.sh --setup                  make the clean bookworm folder once (idempotent, locked)
#   test_deb.sh BUILD_DIR SOURCE_DIR     the test
#
# The test builds the package with scripts/package.sh (its own tree, BUILD_DIR/deb, prefix /usr),
# checks that it holds exactly what `cmake --install` installs, that dpkg-shlibdeps gave it its
# run-time dependencies and that the tools' run path points at the multiarch libdir; then copies
# the clean folder to a temporary one and, chrooted into the copy, installs the package with
# apt-get (its dependencies come from Debian's archive), runs `ssao --version`,
# `povray-ssao --version`, `pkg-config --modversion ssao`, `import ssao` in python3 (with
# Debian's python3-numpy) and its ambient_occlusion() and `ssao` on the bundled sample, whose AO
# must both equal BUILD_DIR/bin/ssao's bit for bit, and purges it again.
# The clean folder is never written to: a copy is, and removed at the end.
#
# Why a debootstrap folder: the host has every build dependency, so installing there proves
# nothing about the package's Depends; a minbase bookworm has none of them.
#
# The folder is ${SSAO_BOOKWORM_DIR:-/var/cache/ssao/bookworm} (made like the trixie and sid ones
# of scripts/blender/debian-blender.sh, from the host's Debian mirror, scripts/debian_mirror.sh).
# apt's package lists and downloads are kept in ${SSAO_BOOKWORM_DIR}.apt-cache, bind-mounted into
# each copy, so the dependencies are downloaded once. Needs root (chroot, mount namespaces).
# Exit codes: 0 passed, 1 failed (also when the folder is missing: run --setup).
set -euo pipefail

SUITE=bookworm
ROOT=${SSAO_BOOKWORM_DIR:-/var/cache/ssao/$SUITE}
ROOT=${ROOT%/}
STAMP_NAME=.ssao-debian-ready
PARTIAL_NAME=.ssao-debian-partial
SELF=$(realpath "${BASH_SOURCE[0]}")
REPO=$(cd "$(dirname "$SELF")/../.." && pwd)

say() { printf 'test_deb: %s\n' "$*" >&2; }
fail() { say "FAILED: $*"; exit 1; }
now() { date +%s.%N; }
since() { awk -v a="$1" -v b="$(now)" 'BEGIN { printf "%.1f s", b - a }'; }

[[ $(id -u) -eq 0 ]] || fail "must run as root (chroot and mount namespaces)"
[[ "$ROOT" == /*/* ]] || fail "SSAO_BOOKWORM_DIR must be an absolute path two levels deep: $ROOT"

# Run CMD... chrooted into the folder $1 with /proc, /dev and a tmpfs /run mounted, and apt's
# package lists and downloads kept in $ROOT.apt-cache, all in a private mount namespace: the
# mounts vanish with the command, however it ends.
in_root() {
  local root=$1
  shift
  mkdir -p "$ROOT.apt-cache/lists/partial" "$ROOT.apt-cache/archives/partial"
  # shellcheck disable=SC2016 # expanded by the inner shell
  unshare --mount --propagation private /bin/bash -euc '
    root=$1 cache=$2
    shift 2
    mount -t proc proc "$root/proc"
    mount --rbind /dev "$root/dev"
    mount -t tmpfs -o mode=0755 tmpfs "$root/run"
    mount --bind "$cache/lists" "$root/var/lib/apt/lists"
    mount --bind "$cache/archives" "$root/var/cache/apt/archives"
    exec chroot "$root" /usr/bin/env -i PATH=/usr/sbin:/usr/bin:/sbin:/bin LANG=C.UTF-8 \
      HOME=/root DEBIAN_FRONTEND=noninteractive "$@"
  ' in_root "$root" "$ROOT.apt-cache" "$@"
}

# ---------------------------------------------------------------------------
# --setup: debootstrap --variant=minbase bookworm, from the host's mirror.
setup() {
  local t0 mirror log
  t0=$(now)
  if [[ -f "$ROOT/$STAMP_NAME" ]]; then
    say "ready: $ROOT"
    return 0
  fi
  mkdir -p "$(dirname "$ROOT")"
  exec 9>>"$ROOT.lock"
  flock -w 3600 9 || fail "timed out waiting for another setup of $ROOT (lock $ROOT.lock)"
  if [[ -f "$ROOT/$STAMP_NAME" ]]; then
    say "ready: $ROOT (made by another process meanwhile)"
    return 0
  fi
  # shellcheck source=SCRIPTDIR/../../scripts/debian_mirror.sh
  source "$REPO/scripts/debian_mirror.sh"
  mirror=$(host_mirror) || true
  [[ -n "$mirror" ]] ||
    fail "no Debian archive found in the host's apt sources; set SSAO_DEBIAN_MIRROR"
  if [[ -e "$ROOT" ]]; then
    if [[ -f "$ROOT/$PARTIAL_NAME" ]]; then
      say "removing the half-made $ROOT"
      rm -rf --one-file-system "$ROOT"
    elif [[ -n "$(ls -A "$ROOT")" ]]; then
      fail "$ROOT exists, is not empty and was not made by this script:" \
        "remove it or set SSAO_BOOKWORM_DIR"
    fi
  fi
  if ! command -v debootstrap > /dev/null; then
    say "installing debootstrap on the host"
    export DEBIAN_FRONTEND=noninteractive
    apt-get install -y -q debootstrap > /dev/null 2>&1 ||
      { apt-get update -q > /dev/null && apt-get install -y -q debootstrap > /dev/null; } ||
      fail "cannot install debootstrap"
  fi
  mkdir -p "$ROOT"
  touch "$ROOT/$PARTIAL_NAME"
  say "debootstrap --variant=minbase $SUITE $ROOT $mirror"
  log="$ROOT.debootstrap.log"
  if ! debootstrap --variant=minbase "$SUITE" "$ROOT" "$mirror" > "$log" 2>&1; then
    tail -n 20 "$log" >&2
    fail "debootstrap failed (log: $log); rerun --setup to start over"
  fi
  rm -f "$log"
  printf 'deb %s %s main\ndeb %s %s-updates main\n' "$mirror" "$SUITE" "$mirror" "$SUITE" \
    > "$ROOT/etc/apt/sources.list"
  # A mirror that is a dated snapshot of the archive serves Release files past their Valid-Until.
  echo 'Acquire::Check-Valid-Until "false";' > "$ROOT/etc/apt/apt.conf.d/99ssao-snapshot"
  cp -L /etc/resolv.conf "$ROOT/etc/resolv.conf"
  printf '#!/bin/sh\nexit 101\n' > "$ROOT/usr/sbin/policy-rc.d" # no services start in a chroot
  chmod 755 "$ROOT/usr/sbin/policy-rc.d"
  # Clean: no package lists (each test run fetches current ones), no downloaded packages.
  rm -rf "$ROOT"/var/lib/apt/lists/* "$ROOT"/var/cache/apt/archives/*.deb
  [[ "$(cut -d. -f1 "$ROOT/etc/debian_version")" == 12 ]] ||
    fail "$ROOT is Debian $(cat "$ROOT/etc/debian_version"), not 12; rerun --setup to start over"
  in_root "$ROOT" /bin/true || fail "cannot chroot into $ROOT; rerun --setup to start over"
  {
    echo "made: $(date -u +%Y-%m-%dT%H:%M:%SZ)"
    echo "suite: $SUITE"
    echo "mirror: $mirror"
    echo "debian_version: $(cat "$ROOT/etc/debian_version")"
  } > "$ROOT/$STAMP_NAME"
  rm -f "$ROOT/$PARTIAL_NAME"
  say "ready: $ROOT ($(du -sh --one-file-system "$ROOT" | cut -f1)) after $(since "$t0")"
}

if [[ "${1:-}" == --setup ]]; then
  [[ $# -eq 1 ]] || fail "--setup takes no other arguments"
  setup
  exit 0
fi

# ---------------------------------------------------------------------------
# The test.
[[ $# -eq 2 ]] || { echo "usage: $0 --setup | $0 BUILD_DIR SOURCE_DIR" >&2; exit 1; }
build=$(realpath "$1")
source=$(realpath "$2")
[[ -x "$build/bin/ssao" ]] || fail "no $build/bin/ssao: build first (scripts/build.sh)"
if [[ ! -f "$ROOT/$STAMP_NAME" ]]; then
  fail "the clean Debian 12 folder $ROOT is not set up: run '$SELF --setup' first" \
    "(about 1 min, needs the Debian mirror; ctest runs it as install.deb_setup)"
fi
t_start=$(now)
work=$(mktemp -d)
# The copy's mounts live in namespaces that end with their commands; --one-file-system all the same.
trap 'rm -rf --one-file-system "$work"' EXIT

# The package, built as scripts/package.sh builds it, with the build tree's compilers and build
# type (its AO is compared with the build tree's below).
cached() { sed -n "s/^$1:[A-Z]*=//p" "$build/CMakeCache.txt"; }
t=$(now)
deb=$("$source/scripts/package.sh" --build-dir "$build/deb" --output "$work/package" -- \
  -DCMAKE_BUILD_TYPE="$(cached CMAKE_BUILD_TYPE)" -DCMAKE_C_COMPILER="$(cached CMAKE_C_COMPILER)" \
  -DCMAKE_CXX_COMPILER="$(cached CMAKE_CXX_COMPILER)" 2> "$work/package.log" | tail -n 1) ||
  { tail -n 30 "$work/package.log" >&2; fail "scripts/package.sh (log above)"; }
[[ -f "$deb" ]] ||
  { tail -n 30 "$work/package.log" >&2; fail "scripts/package.sh wrote no package"; }
t_package=$(since "$t")
say "$(basename "$deb"): $(stat -c %s "$deb") bytes, built in $t_package"

# Exactly what `cmake --install` installs, under /usr.
cmake --install "$build/deb" --prefix "$work/staged/usr" > /dev/null ||
  fail "cmake --install $build/deb"
(cd "$work/staged" && find . ! -type d | sort) > "$work/installed.txt"
dpkg-deb -c "$deb" | awk '$1 !~ /^d/ { print $6 }' | sort > "$work/packaged.txt"
diff "$work/installed.txt" "$work/packaged.txt" > "$work/contents.diff" ||
  { cat "$work/contents.diff" >&2
    fail "the package's files differ from cmake --install's (<: installed only, >: packaged)"; }
for f in usr/bin/ssao usr/bin/povray-ssao usr/include/ssao/ssao.h usr/include/ssao/ssao.hpp \
  usr/share/doc/ssao/copyright; do
  grep -qx "./$f" "$work/packaged.txt" || fail "$f is not in the package"
done
for f in libssao.so libssao.so.0 libssao_image_codec.so pkgconfig/ssao.pc \
  cmake/ssao/ssaoConfig.cmake; do
  grep -q "^\./usr/lib/[^/]*/$f\$" "$work/packaged.txt" ||
    fail "usr/lib/<multiarch>/$f is not in the package"
done
libdir=$(dirname "$(grep -m1 '/libssao\.so\.0$' "$work/packaged.txt")")
libdir=${libdir#./usr/}
multiarch=$(gcc -print-multiarch)
[[ "$libdir" == "lib/$multiarch" ]] || fail "libssao is in usr/$libdir, not usr/lib/$multiarch"
depends=$(dpkg-deb -f "$deb" Depends)
for dep in libopenimageio libtbb libstdc++6; do
  [[ "$depends" == *"$dep"* ]] || fail "Depends has no $dep (dpkg-shlibdeps?): $depends"
done
# The tools' run path is the multiarch libdir, and it works: the unpacked ssao takes libssao
# from beside it, not from anywhere else.
dpkg-deb -x "$deb" "$work/unpacked"
for tool in ssao povray-ssao; do
  runpath=$(readelf -d "$work/unpacked/usr/bin/$tool" | sed -n 's/.*(RUNPATH).*\[\(.*\)\]$/\1/p')
  # shellcheck disable=SC2016 # a literal $ORIGIN
  [[ "$runpath" == '$ORIGIN/../'"$libdir" ]] ||
    fail "$tool's RUNPATH is '$runpath', not \$ORIGIN/../$libdir"
done
found=$(ldd "$work/unpacked/usr/bin/ssao" | awk '$1 == "libssao.so.0" { print $3 }')
beside=$(realpath "$work/unpacked/usr/$libdir/libssao.so.0")
[[ -n "$found" && "$(realpath "$found")" == "$beside" ]] ||
  { ldd "$work/unpacked/usr/bin/ssao" >&2
    fail "the unpacked ssao does not find libssao through its RUNPATH"; }

# A copy of the clean folder; the package installed into it by apt-get, as on a farm node.
t=$(now)
cp -a "$ROOT" "$work/root" || fail "cannot copy $ROOT"
t_copy=$(since "$t")
say "copied $ROOT ($(du -s --one-file-system -BM "$ROOT" | cut -f1)) in $t_copy"
inside=/tmp/ssao-deb-test
mkdir -p "$work/root$inside"
sample="$source/tests/data/sample"
cp "$deb" "$sample.exr" "$sample.camera.json" "$work/root$inside/"
# The sample's depth and normal passes as .npy files, for the Python module inside (Debian's
# python3-numpy there, no OpenImageIO).
/usr/bin/python3 - "$sample.exr" "$work/root$inside" <<'PY' || fail "writing the sample's passes as .npy"
import sys
import numpy as np
import OpenImageIO as oiio
image = oiio.ImageInput.open(sys.argv[1])
names, pixels = list(image.spec().channelnames), image.read_image(oiio.FLOAT)
k = names.index("ViewLayer.Normal.X")
np.save(sys.argv[2] + "/depth.npy", pixels[:, :, names.index("ViewLayer.Depth.Z")])
np.save(sys.argv[2] + "/normals.npy", pixels[:, :, k:k + 3])
PY
chmod -R a+rX "$work/root$inside"
t=$(now)
(
  flock -w 600 8 || fail "timed out waiting for another run's apt-get ($ROOT.apt-cache.lock)"
  in_root "$work/root" /bin/sh -c "apt-get update -q &&
    apt-get install -y -q --no-install-recommends $inside/$(basename "$deb") pkg-config \
      python3-numpy" \
    > "$work/apt.log" 2>&1 ||
    { tail -n 30 "$work/apt.log" >&2
      fail "apt-get install ./$(basename "$deb") in Debian 12 (log above)"; }
) 8>> "$ROOT.apt-cache.lock"
t_apt=$(since "$t")
say "apt-get install in $t_apt ($(grep -c '^Setting up ' "$work/apt.log") packages set up)"

# Inside: the tools from PATH, the library known to ld.so, pkg-config, the Python module (its
# library, then its AO of the sample), the sample.
version=$(sed -n 's/^project(ssao VERSION \([0-9.]*\).*/\1/p' "$source/CMakeLists.txt")
t=$(now)
# shellcheck disable=SC2016 # expanded by the inner shell
in_root "$work/root" /bin/sh -euc '
  dir=$1 version=$2 libdir=$3
  cd "$dir"
  fail() { echo "test_deb: FAILED inside Debian 12: $*" >&2; exit 1; }
  [ "$(command -v ssao)" = /usr/bin/ssao ] || fail "ssao is not /usr/bin/ssao"
  ssao --version || fail "ssao --version"
  povray-ssao --version || fail "povray-ssao --version"
  ldconfig -p | grep -q "libssao.so.0 " || fail "ld.so does not know libssao.so.0 (ldconfig)"
  [ "$(pkg-config --modversion ssao)" = "$version" ] ||
    fail "pkg-config --modversion ssao is not $version"
  pkg-config --libs ssao | grep -q -- -lssao || fail "pkg-config --libs ssao has no -lssao"
  # The Python module takes the library from the package (its _installed.py), not by SONAME.
  python3 -c "import ssao; print(\"python3: ssao\", ssao.version(), ssao.library()._name)" \
    > python.txt || fail "python3 -c \"import ssao\""
  [ "$(cat python.txt)" = "python3: ssao $version /usr/$libdir/libssao.so.0" ] ||
    fail "the Python module: $(cat python.txt), not ssao $version /usr/$libdir/libssao.so.0"
  cat python.txt
  python3 -c "import json, numpy as np, ssao
camera = json.load(open(\"sample.camera.json\"))
ao = ssao.ambient_occlusion(np.load(\"depth.npy\"), normals=np.load(\"normals.npy\"),
                            camera=camera, radius=0.8)
np.save(\"python_ao.npy\", ao)" || fail "ssao.ambient_occlusion on the sample"
  ssao sample.exr --camera sample.camera.json --radius 0.8 --ao-only -o installed.exr --quiet ||
    fail "ssao on the sample"
' inside "$inside" "$version" "$libdir" > "$work/inside.log" 2>&1 ||
  { cat "$work/inside.log" >&2; fail "the installed package in Debian 12 (output above)"; }
t_run=$(since "$t")
sed 's/^/  bookworm: /' "$work/inside.log" >&2

"$build/bin/ssao" "$sample.exr" --camera "$sample.camera.json" --radius 0.8 --ao-only \
  -o "$work/built.exr" --quiet || fail "$build/bin/ssao on the sample"
/usr/bin/python3 - "$work/root$inside/installed.exr" "$work/built.exr" <<'PY' ||
  fail "the packaged ssao's AO differs from $build/bin/ssao's"
import sys
import numpy as np
import OpenImageIO as oiio
a, b = (oiio.ImageBuf(p).get_pixels(oiio.FLOAT) for p in sys.argv[1:3])
sys.exit(0 if a.shape == b.shape and np.array_equal(a, b) and a.size > 0 else 1)
PY
/usr/bin/python3 - "$work/root$inside/python_ao.npy" "$work/built.exr" <<'PY' ||
  fail "the packaged Python module's AO differs from $build/bin/ssao's"
import sys
import numpy as np
import OpenImageIO as oiio
a, b = np.load(sys.argv[1]), oiio.ImageBuf(sys.argv[2]).get_pixels(oiio.FLOAT)[:, :, 0]
sys.exit(0 if a.shape == b.shape and np.array_equal(a, b) and a.size > 0 else 1)
PY

# And out again: nothing of it is left after a purge.
in_root "$work/root" dpkg --purge ssao > "$work/purge.log" 2>&1 ||
  { cat "$work/purge.log" >&2; fail "dpkg --purge ssao"; }
while read -r f; do
  [[ ! -e "$work/root/${f#./}" && ! -L "$work/root/${f#./}" ]] ||
    fail "${f#./} is left after dpkg --purge ssao"
done < "$work/packaged.txt"
# Nor what using it made: python3 (as root, above) wrote the module's __pycache__.
! grep -i "warning" "$work/purge.log" || fail "dpkg --purge ssao warned (above)"
module_dir=$(grep -m1 '/dist-packages/ssao/__init__\.py$' "$work/packaged.txt")
[[ ! -e "$work/root/$(dirname "${module_dir#./}")" ]] ||
  fail "$(dirname "${module_dir#./}") is left after dpkg --purge ssao"

say "ok: $(basename "$deb") installs on a clean Debian 12 with apt-get; the AO of its ssao" \
  "and of its Python module equals the build tree's (package $t_package, copy $t_copy, apt-get $t_apt, tools $t_run," \
  "total $(since "$t_start"))"
