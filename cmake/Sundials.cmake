# SPDX-License-Identifier: BSD-2-Clause
# SUNDIALS from Debian's libsundials-dev, linked statically so that nothing
# built here (in particular the FMU binaries) needs SUNDIALS at run time.
# Defines the imported target pkm::sundials.
set(_pkm_sundials_parts
    cvode sunnonlinsolfixedpoint sunnonlinsolnewton sunlinsoldense sunmatrixdense nvecserial)
find_path(SUNDIALS_INCLUDE_DIR cvode/cvode.h REQUIRED)
set(_pkm_sundials_libs)
foreach(part IN LISTS _pkm_sundials_parts)
  find_library(SUNDIALS_${part}_STATIC NAMES libsundials_${part}.a)
  if(NOT SUNDIALS_${part}_STATIC)
    message(FATAL_ERROR "libsundials_${part}.a not found: install Debian's libsundials-dev "
                        "(./scripts/setup.sh does it)")
  endif()
  list(APPEND _pkm_sundials_libs ${SUNDIALS_${part}_STATIC})
endforeach()
# libsundials_generic holds SUNContext and the shared helpers in 6.x when present.
find_library(SUNDIALS_generic_STATIC NAMES libsundials_generic.a)
if(SUNDIALS_generic_STATIC)
  list(APPEND _pkm_sundials_libs ${SUNDIALS_generic_STATIC})
endif()
add_library(pkm_sundials INTERFACE)
target_include_directories(pkm_sundials SYSTEM INTERFACE ${SUNDIALS_INCLUDE_DIR})
target_link_libraries(pkm_sundials INTERFACE ${_pkm_sundials_libs} m)
add_library(pkm::sundials ALIAS pkm_sundials)
