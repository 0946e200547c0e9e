# SPDX-License-Identifier: BSD-2-Clause
# Link-time optimisation where the speed ships: the FMU binaries, libpkm,
# the auto-test app and the benchmarks. The libraries they share with the
# tests (pkm_core, pkm_capi, pkm_fmi_models, pkm_autotest_lib) are compiled
# to fat LTO objects (the intermediate code and ordinary machine code), so
# that the tests and the build tools link the machine code without a
# link-time optimisation pass of their own. The tests that check the shipped
# binaries load the FMUs themselves (dlopen), optimised at link time.
#
#   PKM_LTO  (option, ON) in Release builds; OFF: no LTO anywhere.
#   pkm_without_lto(<target>...)  links those targets without LTO;
#   pkm_directory_without_lto()   every later target of the directory.
include_guard(GLOBAL)
option(PKM_LTO "Link-time optimisation in Release builds (inlines the small kinematics helpers across files)" ON)
set(PKM_LTO_ACTIVE OFF)
if(PKM_LTO AND CMAKE_BUILD_TYPE STREQUAL "Release")
  include(CheckIPOSupported)
  check_ipo_supported(RESULT _pkm_ipo OUTPUT _pkm_ipo_why LANGUAGES C CXX)
  if(_pkm_ipo)
    set(CMAKE_INTERPROCEDURAL_OPTIMIZATION ON)
    set(PKM_LTO_ACTIVE ON)
  else()
    message(STATUS "PKM: link-time optimisation not available: ${_pkm_ipo_why}")
  endif()
endif()

function(pkm_fat_lto_objects)
  if(PKM_LTO_ACTIVE AND CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
    foreach(_t IN LISTS ARGN)
      target_compile_options(${_t} PRIVATE -ffat-lto-objects)
    endforeach()
  endif()
endfunction()

# The link option that makes gcc link fat objects' machine code (none elsewhere).
set(PKM_NO_LTO_LINK_OPTION)
if(PKM_LTO_ACTIVE AND CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
  set(PKM_NO_LTO_LINK_OPTION -fno-lto)
endif()

function(pkm_without_lto)
  foreach(_t IN LISTS ARGN)
    set_target_properties(${_t} PROPERTIES INTERPROCEDURAL_OPTIMIZATION OFF)
    target_link_options(${_t} PRIVATE ${PKM_NO_LTO_LINK_OPTION})
  endforeach()
endfunction()

# Every target defined after it in the calling directory (and below): no LTO.
macro(pkm_directory_without_lto)
  set(CMAKE_INTERPROCEDURAL_OPTIMIZATION OFF)
  add_link_options(${PKM_NO_LTO_LINK_OPTION})
endmacro()
