# SPDX-License-Identifier: BSD-2-Clause
# Finds SUNDIALS' own CMake package (SUNDIALSConfig.cmake) for its static
# CVODE, SUNDIALS::cvode_static: in this build (cmake/Sundials.cmake) and in
# the installed pkm4puu package (pkm4puuConfig.cmake), which installs this
# file beside it. PKM_SUNDIALS_FIND_ARGS: more of find_package's arguments.
# Debian's SUNDIALSConfig.cmake asks for OpenMP, for its OpenMP vector,
# unless the target OpenMP::OpenMP_C exists; CVODE's serial parts use none.
# Where the compilers have no OpenMP (clang without libomp, the sanitizer
# build), an empty placeholder target lets the package load.
if(NOT TARGET SUNDIALS::cvode_static)
  if(NOT TARGET OpenMP::OpenMP_C)
    find_package(OpenMP QUIET)
    if(NOT TARGET OpenMP::OpenMP_C)
      add_library(OpenMP::OpenMP_C INTERFACE IMPORTED)
    endif()
  endif()
  find_package(SUNDIALS 6 CONFIG ${PKM_SUNDIALS_FIND_ARGS})
endif()
