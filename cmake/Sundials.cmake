# SPDX-License-Identifier: BSD-2-Clause
# SUNDIALS' CVODE through SUNDIALS' own CMake package (SUNDIALSConfig.cmake:
# Debian's libsundials-dev ships it; scripts/cross_sundials.sh installs it
# for the cross targets), linked statically so that nothing built here (in
# particular the FMU binaries) needs SUNDIALS at run time. The static CVODE
# library holds what the core uses (the serial vector, the dense matrix and
# linear solver, the nonlinear solvers). Defines SUNDIALS::cvode_static.
include_guard(GLOBAL)
set(PKM_SUNDIALS_FIND_ARGS COMPONENTS cvode)
include(${CMAKE_CURRENT_LIST_DIR}/pkm4puuSundials.cmake)
if(NOT SUNDIALS_FOUND OR NOT TARGET SUNDIALS::cvode_static)
  message(FATAL_ERROR "SUNDIALS 6 with a static CVODE (SUNDIALS::cvode_static from SUNDIALSConfig.cmake) not found: "
                      "install Debian's libsundials-dev (./scripts/setup.sh does it), or point SUNDIALS_DIR at "
                      "the folder holding SUNDIALSConfig.cmake")
endif()
