# SPDX-License-Identifier: BSD-2-Clause
# What both toolchain files share: where find_* looks.
#   PKM_CROSS_PREFIX  (cache or environment; ;-list) install prefixes of the
#                     dependencies built for the target (scripts/cross_sundials.sh).
if(NOT PKM_CROSS_PREFIX AND DEFINED ENV{PKM_CROSS_PREFIX})
  set(PKM_CROSS_PREFIX "$ENV{PKM_CROSS_PREFIX}")
endif()
list(APPEND CMAKE_TRY_COMPILE_PLATFORM_VARIABLES PKM_CROSS_PREFIX)

macro(pkm_cross_find_root sysroot)
  set(CMAKE_FIND_ROOT_PATH ${sysroot} ${PKM_CROSS_PREFIX})
  set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
  set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
  set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
  set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)
  # Eigen is header-only: the host's libeigen3-dev serves every target.
  if(NOT Eigen3_DIR AND EXISTS /usr/share/eigen3/cmake/Eigen3Config.cmake)
    set(Eigen3_DIR /usr/share/eigen3/cmake CACHE PATH "Eigen3Config.cmake (header-only, host package)")
  endif()
endmacro()
