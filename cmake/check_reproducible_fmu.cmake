# SPDX-License-Identifier: BSD-2-Clause
# ctest fmu_archive_reproducible_*: the archive is rebuilt from freshly
# written inputs (the model description copied anew, the documentation page
# written again by the doc tool, the binary copied: new files, new
# timestamps) by the same packer and must be bit-identical (sha256) to the
# one the build wrote. Together with deterministic compiling and linking
# (no dates or paths in the binary), the same commit builds the same .fmu.
#   cmake -DFMU=... -DSTAGE=... -DID=... -DDOC_TOOL=... -DPYTHON=... -DPACK=...
#         -DSTAMP=... -DWORK=... -P check_reproducible_fmu.cmake
file(REMOVE_RECURSE "${WORK}")
file(GLOB_RECURSE _files RELATIVE "${STAGE}" "${STAGE}/*")
list(SORT _files)
set(_binary "")
set(_licenses)
foreach(_f IN LISTS _files)
  if(_f MATCHES "^binaries/")
    set(_binary "${_f}")
  elseif(_f MATCHES "^documentation/licenses/")
    list(APPEND _licenses "${_f}")
  endif()
endforeach()
if(NOT _binary)
  message(FATAL_ERROR "no binary in ${STAGE}")
endif()
get_filename_component(_bindir "${WORK}/${_binary}" DIRECTORY)
file(MAKE_DIRECTORY "${_bindir}" "${WORK}/documentation/licenses")
execute_process(COMMAND ${CMAKE_COMMAND} -E sleep 1)  # later timestamps than the build's
file(READ "${STAGE}/modelDescription.xml" _md)
file(WRITE "${WORK}/modelDescription.xml" "${_md}")
file(COPY_FILE "${STAGE}/${_binary}" "${WORK}/${_binary}")
foreach(_f IN LISTS _licenses)
  file(COPY_FILE "${STAGE}/${_f}" "${WORK}/${_f}")
endforeach()
execute_process(COMMAND "${DOC_TOOL}" "${ID}" "${WORK}/documentation/index.html" RESULT_VARIABLE _rc)
if(NOT _rc EQUAL 0)
  message(FATAL_ERROR "${DOC_TOOL} failed: ${_rc}")
endif()
execute_process(COMMAND "${PYTHON}" "${PACK}" --stamp "${STAMP}" "${WORK}.fmu" "${WORK}"
                        modelDescription.xml "${_binary}" documentation/index.html ${_licenses}
                RESULT_VARIABLE _rc)
if(NOT _rc EQUAL 0)
  message(FATAL_ERROR "pack_fmu.py failed: ${_rc}")
endif()
file(SHA256 "${FMU}" _built)
file(SHA256 "${WORK}.fmu" _again)
file(REMOVE_RECURSE "${WORK}" "${WORK}.fmu")
if(NOT _built STREQUAL _again)
  message(FATAL_ERROR "${FMU} is not reproducible: sha256 ${_built}, rebuilt from fresh inputs ${_again}")
endif()
message(STATUS "${FMU}: sha256 ${_built}, the same when rebuilt from fresh inputs")
