# SPDX-License-Identifier: BSD-2-Clause
# Windows x64 with Debian's mingw-w64 (posix thread model), run through wine.
# Used by cmake/Platforms.cmake for the Windows sub-build; by hand:
#   cmake -S . -B build-win64 -DCMAKE_TOOLCHAIN_FILE=cmake/toolchains/mingw-w64-x86_64.cmake \
#         -DPKM_CROSS_PREFIX=<static CVODE from scripts/cross_sundials.sh>
set(CMAKE_SYSTEM_NAME Windows)
set(CMAKE_SYSTEM_PROCESSOR AMD64)
set(CMAKE_C_COMPILER x86_64-w64-mingw32-gcc-posix)
set(CMAKE_CXX_COMPILER x86_64-w64-mingw32-g++-posix)
set(CMAKE_RC_COMPILER x86_64-w64-mingw32-windres)
include(${CMAKE_CURRENT_LIST_DIR}/cross_common.cmake)
pkm_cross_find_root(/usr/x86_64-w64-mingw32)

# libstdc++, libgcc and winpthread linked in: the DLL imports only system
# DLLs (KERNEL32, msvcrt) and the test programs run under a bare wine.
set(CMAKE_EXE_LINKER_FLAGS_INIT "-static")
set(CMAKE_SHARED_LINKER_FLAGS_INIT "-static -Wl,--no-insert-timestamp")  # no link date in the DLL: reproducible archives

# wine quiet, and without the Mono/Gecko installers when it creates its prefix.
find_program(PKM_WINE NAMES wine REQUIRED)
set(CMAKE_CROSSCOMPILING_EMULATOR /usr/bin/env WINEDEBUG=-all WINEDLLOVERRIDES=mscoree,mshtml= ${PKM_WINE})
