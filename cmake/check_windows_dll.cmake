# SPDX-License-Identifier: BSD-2-Clause
cmake_minimum_required(VERSION 3.18)
# ctest platform_win64_binaries_imports_and_exports: each Windows DLL
# imports only DLLs that every Windows has (KERNEL32, msvcrt: libstdc++,
# libgcc, winpthread and CVODE are linked in) and exports exactly the FMI
# functions listed in src/fmi/fmi_functions.h.
#   cmake -DOBJDUMP=... -DBINARIES=a.dll;b.dll -DFUNCTIONS=fmi_functions.h -P check_windows_dll.cmake
set(_system_dlls KERNEL32.dll msvcrt.dll)
file(READ "${FUNCTIONS}" _h)
string(REGEX MATCHALL "X\\((fmi[23][A-Za-z0-9]+)\\)" _listed "${_h}")
list(TRANSFORM _listed REPLACE "X\\((.*)\\)" "\\1")
list(SORT _listed)
list(LENGTH _listed _n_listed)
foreach(_dll IN LISTS BINARIES)
  execute_process(COMMAND ${OBJDUMP} -p "${_dll}" OUTPUT_VARIABLE _out RESULT_VARIABLE _rc)
  if(NOT _rc EQUAL 0)
    message(FATAL_ERROR "${OBJDUMP} -p ${_dll} failed")
  endif()
  string(REGEX MATCHALL "DLL Name: [^\n]+" _imports "${_out}")
  list(TRANSFORM _imports REPLACE "DLL Name: " "")
  foreach(_i IN LISTS _imports)
    if(NOT _i IN_LIST _system_dlls)
      message(FATAL_ERROR "${_dll} imports ${_i}; allowed: ${_system_dlls}")
    endif()
  endforeach()
  # The export table: "[ordinal] name" lines after "[Ordinal/Name Pointer] Table".
  string(REGEX MATCH "Ordinal/Name Pointer. Table[^\n]*\n(.*)" _table "${_out}")
  string(REGEX MATCHALL "\n[ \t]*.[ 0-9]+.[ \t]+[A-Za-z_][A-Za-z0-9_]*" _exports "\n${CMAKE_MATCH_1}")
  list(TRANSFORM _exports REPLACE "^.*[ \t]" "")
  list(SORT _exports)
  if(NOT _exports STREQUAL _listed)
    message(FATAL_ERROR "${_dll} exports\n  ${_exports}\nnot the ${_n_listed} functions of ${FUNCTIONS}:\n  ${_listed}")
  endif()
  message(STATUS "${_dll}: imports ${_imports}; exports the ${_n_listed} FMI functions")
endforeach()
