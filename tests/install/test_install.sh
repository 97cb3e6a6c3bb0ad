#!/bin/bash
# SPDX-License-Identifier: MIT
# The installed library as a user gets it: `cmake --install BUILD --prefix P` into a temp folder,
# then, from the prefix alone,
#   - docs/examples/minimal.c and minimal.cpp built with find_package(ssao) (ssao::ssao) and with
#     pkg-config (ssao.pc), and run (each checks its own AO);
#   - the installed ssao and povray-ssao: no run path into the build tree, --version, and the
#     installed ssao on the bundled sample giving the build tree's AO bit for bit;
#   - the installed Python module ssao: it loads the prefix's library by itself and passes
#     tests/python/test_module.py against the installed ssao.
# Usage: test_install.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
build=$(realpath "$1")
source=$(realpath "$2")
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
prefix="$work/prefix"
fail() { echo "test_install: FAILED: $*" >&2; exit 1; }

cmake --install "$build" --prefix "$prefix" > "$work/install.log" || fail "cmake --install"
for f in include/ssao/ssao.h include/ssao/ssao.hpp bin/ssao bin/povray-ssao; do
  [ -e "$prefix/$f" ] || fail "$f not installed"
done
libdir=$(dirname "$(find "$prefix" -name 'libssao.so.0' | head -1)")
[ -n "$libdir" ] || fail "no libssao.so.0 installed"
readelf -d "$libdir/libssao.so" | grep -q 'SONAME.*libssao.so.0' || fail "SONAME is not libssao.so.0"

# find_package(ssao): a consumer project of its own.
mkdir -p "$work/consumer"
cp "$source/docs/examples/minimal.c" "$source/docs/examples/minimal.cpp" "$work/consumer/"
cat > "$work/consumer/CMakeLists.txt" <<'CMAKE'
cmake_minimum_required(VERSION 3.20)
project(ssao_consumer C CXX)
find_package(ssao 0.1 REQUIRED)
add_executable(minimal_c minimal.c)
target_link_libraries(minimal_c PRIVATE ssao::ssao m)
add_executable(minimal_cpp minimal.cpp)
set_target_properties(minimal_cpp PROPERTIES CXX_STANDARD 17)
target_link_libraries(minimal_cpp PRIVATE ssao::ssao)
CMAKE
cmake -S "$work/consumer" -B "$work/consumer/build" -DCMAKE_PREFIX_PATH="$prefix" \
  -DCMAKE_BUILD_RPATH="$libdir" > "$work/consumer.log" 2>&1 || { cat "$work/consumer.log"; fail "find_package(ssao)"; }
cmake --build "$work/consumer/build" >> "$work/consumer.log" 2>&1 || { cat "$work/consumer.log"; fail "building against ssao::ssao"; }
"$work/consumer/build/minimal_c" || fail "minimal.c built with find_package"
"$work/consumer/build/minimal_cpp" || fail "minimal.cpp built with find_package"

# pkg-config: the .pc file is relocatable (its prefix is found from its own folder).
export PKG_CONFIG_PATH="$libdir/pkgconfig"
[ "$(pkg-config --modversion ssao)" = "$(sed -n 's/^project(ssao VERSION \([0-9.]*\).*/\1/p' "$source/CMakeLists.txt")" ] ||
  fail "pkg-config --modversion ssao"
# shellcheck disable=SC2046
cc -std=c99 -Wall -Werror "$source/docs/examples/minimal.c" -o "$work/pc_c" $(pkg-config --cflags --libs ssao) -lm \
  -Wl,-rpath,"$libdir" || fail "cc with pkg-config"
# shellcheck disable=SC2046
c++ -std=c++17 -Wall -Werror "$source/docs/examples/minimal.cpp" -o "$work/pc_cpp" $(pkg-config --cflags --libs ssao) \
  -Wl,-rpath,"$libdir" || fail "c++ with pkg-config"
"$work/pc_c" || fail "minimal.c built with pkg-config"
"$work/pc_cpp" || fail "minimal.cpp built with pkg-config"

# The installed tools: their own run path only, and the same AO as the build tree's.
for tool in ssao povray-ssao; do
  if readelf -d "$prefix/bin/$tool" | grep -i 'runpath\|rpath' | grep -q "$build"; then
    fail "$tool has a run path into the build tree"
  fi
  "$prefix/bin/$tool" --version > /dev/null || fail "$tool --version"
done
sample="$source/tests/data/sample"
run_sample() {
  "$1" "$sample.exr" --camera "$sample.camera.json" --radius 0.8 --ao-only -o "$2" --quiet ||
    fail "$1 on the sample"
}
run_sample "$prefix/bin/ssao" "$work/installed.exr"
run_sample "$build/bin/ssao" "$work/built.exr"
/usr/bin/python3 - "$work/installed.exr" "$work/built.exr" <<'PY' || fail "installed ssao's AO differs"
import sys
import numpy as np
import OpenImageIO as oiio
a, b = (oiio.ImageBuf(p).get_pixels(oiio.FLOAT) for p in sys.argv[1:3])
sys.exit(0 if a.shape == b.shape and np.array_equal(a, b) and a.size > 0 else 1)
PY

# The installed Python module: it finds the installed library by itself (no SSAO_LIBRARY, no
# build tree on its search path), and passes the module's test against the installed ssao.
module=$(find "$prefix" -path '*/dist-packages/ssao/__init__.py' | head -1)
[ -n "$module" ] || fail "the Python module ssao is not installed (no */dist-packages/ssao)"
pythondir=$(dirname "$(dirname "$module")")
# Installed with the prefix /usr/local, it would be on Debian's python3's own path.
/usr/bin/python3 -c 'import sys; sys.exit(sys.argv[1] not in sys.path)' "/usr/local/${pythondir#"$prefix"/}" ||
  fail "${pythondir#"$prefix"/} under /usr/local is not on Debian python3's sys.path"
found=$(cd "$work" && env -u SSAO_LIBRARY PYTHONPATH="$pythondir" /usr/bin/python3 -c \
  'import ssao; print(ssao.library()._name)') || fail "import ssao from the prefix"
case "$found" in "$prefix"/*) ;; *) fail "the installed module loaded $found, not the prefix's" ;; esac
env -u SSAO_LIBRARY /usr/bin/python3 "$source/tests/python/test_module.py" "$prefix/bin/ssao" "$pythondir" \
  > "$work/python.log" 2>&1 || { cat "$work/python.log"; fail "the installed Python module's test"; }
echo "test_install: ok (prefix $prefix: find_package, pkg-config, C and C++, installed tools, Python module)"
