# SPDX-License-Identifier: BSD-2-Clause
# The build's source stamp, read when the build runs (target pkm_source_stamp,
# cmake/Fmu.cmake): OUT holds {"epoch": N, "commit": "..."}, the archives'
# entry date ($SOURCE_DATE_EPOCH if set, else the date of the commit being
# built, else 1980-01-01) and the commit (empty outside git). OUT is rewritten
# only when that changes, so that what depends on it is rebuilt only then.
#   cmake -DSOURCE=<source tree> -DOUT=<file> -P source_stamp.cmake
set(_epoch 315532800)
set(_commit "")
find_program(_git git)
if(_git)
  execute_process(COMMAND "${_git}" -C "${SOURCE}" log -1 --format=%ct%n%h --abbrev=12
                  OUTPUT_VARIABLE _out OUTPUT_STRIP_TRAILING_WHITESPACE RESULT_VARIABLE _rc ERROR_QUIET)
  if(_rc EQUAL 0 AND _out MATCHES "^([0-9]+)\n([0-9a-f]+)$")
    set(_epoch "${CMAKE_MATCH_1}")
    set(_commit "${CMAKE_MATCH_2}")
  endif()
endif()
if(DEFINED ENV{SOURCE_DATE_EPOCH} AND "$ENV{SOURCE_DATE_EPOCH}" MATCHES "^[0-9]+$")
  set(_epoch "$ENV{SOURCE_DATE_EPOCH}")
endif()
file(WRITE "${OUT}.tmp" "{\"epoch\": ${_epoch}, \"commit\": \"${_commit}\"}\n")
execute_process(COMMAND ${CMAKE_COMMAND} -E copy_if_different "${OUT}.tmp" "${OUT}")
file(REMOVE "${OUT}.tmp")
