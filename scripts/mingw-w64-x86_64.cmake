# SPDX-License-Identifier: MIT
# CMake toolchain: Windows x86-64 from Debian, with MinGW-w64's POSIX-threads GCC
# (g++-mingw-w64-x86-64-posix: std::thread needs the posix flavour). The programs it builds run
# here under Wine (CMAKE_CROSSCOMPILING_EMULATOR: ctest and GoogleTest's discovery use it),
# through scripts/wine_run.sh, which runs a program again when Wine failed to launch it.
# scripts/build_windows.sh uses it; docs/install.md ("Windows").
set(CMAKE_SYSTEM_NAME Windows)
set(CMAKE_SYSTEM_PROCESSOR x86_64)
set(SSAO_MINGW_PREFIX x86_64-w64-mingw32)
set(CMAKE_C_COMPILER ${SSAO_MINGW_PREFIX}-gcc-posix)
set(CMAKE_CXX_COMPILER ${SSAO_MINGW_PREFIX}-g++-posix)
set(CMAKE_RC_COMPILER ${SSAO_MINGW_PREFIX}-windres)
set(CMAKE_FIND_ROOT_PATH /usr/${SSAO_MINGW_PREFIX})
# Programs from the build machine; libraries, headers and packages of the target only (so no
# Linux oneTBB, GoogleTest or Highway is found by mistake).
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)
# Every program it builds stands alone: the C++ runtime, libgcc and winpthreads linked in.
set(CMAKE_EXE_LINKER_FLAGS_INIT "-static")
find_program(SSAO_WINE NAMES wine)
if(SSAO_WINE)
  set(CMAKE_CROSSCOMPILING_EMULATOR ${CMAKE_CURRENT_LIST_DIR}/wine_run.sh)
endif()
