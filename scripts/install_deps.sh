#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Installs the Debian 12 packages the project needs, only those that are missing.
set -euo pipefail

PACKAGES=(
  g++ cmake ninja-build pkg-config clang-format   # build, style check
  clang-14 libfuzzer-14-dev libclang-rt-14-dev    # fuzzing (scripts/fuzz.sh: libFuzzer, sanitizers)
  libgtest-dev                              # unit tests
  g++-mingw-w64-x86-64-posix googletest     # the Windows DLL (scripts/build_windows.sh)
  wine wine64                               # its tests, run under Wine
  libtbb-dev                                # the library's thread pool (oneTBB)
  libhwy-dev                                # the library's SIMD kernels (Highway)
  libopenimageio-dev openimageio-tools      # EXR I/O of the command-line tool
  libopenexr-dev nlohmann-json3-dev
  python3-numpy python3-openimageio         # Python test helpers (/usr/bin/python3)
  python3-matplotlib                        # benchmark plots (scripts/benchmark.sh)
  blender                                   # ground truth renders (Cycles AO pass)
  povray povray-examples                    # the POV-Ray bridge and its test scenes
  debootstrap                               # Debian 13, sid (Blender 4.3, 5.2) and 12 (the .deb) folders
  dpkg-dev                                  # the Debian package (scripts/package.sh: dpkg-shlibdeps)
  xvfb xauth                                # the add-on tests in Blender's UI (xvfb-run)
  slurmctld slurmd slurm-client munge       # the farm test (a Slurm cluster on localhost)
  nodejs                                    # the Flamenco job type's test (node)
)

missing=()
for package in "${PACKAGES[@]}"; do
  status=$(dpkg-query -W -f='${Status}' "$package" 2>/dev/null || true)
  [[ "$status" == "install ok installed" ]] || missing+=("$package")
done
if [[ ${#missing[@]} -eq 0 ]]; then
  echo "install_deps: all ${#PACKAGES[@]} packages present"
  exit 0
fi

SUDO=()
if [[ $(id -u) -ne 0 ]]; then
  if command -v sudo >/dev/null; then
    SUDO=(sudo)
  else
    echo "install_deps: run as root: apt-get install ${missing[*]}" >&2
    exit 1
  fi
fi
echo "install_deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
"${SUDO[@]}" apt-get update -q
"${SUDO[@]}" apt-get install -y -q --no-install-recommends "${missing[@]}"
