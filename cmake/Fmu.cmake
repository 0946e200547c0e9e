# The FMUs: the FMI 2.0 and 3.0 headers, the FMU shared objects and their
# .fmu archives.
#
#   FMI2_HEADERS_DIR  (cache) directory holding fmi2Functions.h and fmi3Functions.h. Default:
#                     fmpy's c-code directory, found with the project's
#                     .venv/bin/python (else python3). The headers are used
#                     in place, never copied into the repository.
#   PKM_FMU_PYTHON    (cache) the Python that has fmpy (tests: fmpy validate).
#
#   pkm_add_fmu(<modelIdentifier> DEFINITION <C++ function> MODEL_DESCRIPTIONS <dir>
#               SOURCES <front ends .cpp> LIBRARIES <libs...>
#               VERSION_SCRIPT <map> DOC_TOOL <executable target>)
include_guard(GLOBAL)

set(FMI2_HEADERS_DIR "" CACHE PATH "Directory with the FMI 2.0 headers (fmi2Functions.h); default: fmpy's c-code")
set(PKM_FMU_PYTHON "" CACHE FILEPATH "Python interpreter with fmpy installed (FMU tests)")

if(NOT PKM_FMU_PYTHON)
  if(EXISTS "${CMAKE_SOURCE_DIR}/.venv/bin/python")
    set(_pkm_python "${CMAKE_SOURCE_DIR}/.venv/bin/python")
  else()
    find_program(PKM_PYTHON3_EXECUTABLE NAMES python3)
    mark_as_advanced(PKM_PYTHON3_EXECUTABLE)
    set(_pkm_python "${PKM_PYTHON3_EXECUTABLE}")
  endif()
else()
  set(_pkm_python "${PKM_FMU_PYTHON}")
endif()

set(_pkm_fmpy_dir "")
if(_pkm_python)
  execute_process(
    COMMAND "${_pkm_python}" -c "import fmpy, os; print(os.path.join(os.path.dirname(fmpy.__file__), 'c-code'))"
    OUTPUT_VARIABLE _pkm_fmpy_dir OUTPUT_STRIP_TRAILING_WHITESPACE
    RESULT_VARIABLE _pkm_fmpy_rc ERROR_QUIET)
  if(NOT _pkm_fmpy_rc EQUAL 0)
    set(_pkm_fmpy_dir "")
  elseif(NOT PKM_FMU_PYTHON)
    set(PKM_FMU_PYTHON "${_pkm_python}" CACHE FILEPATH "Python interpreter with fmpy installed (FMU tests)" FORCE)
  endif()
endif()

if(NOT FMI2_HEADERS_DIR AND _pkm_fmpy_dir AND EXISTS "${_pkm_fmpy_dir}/fmi2Functions.h")
  set(FMI2_HEADERS_DIR "${_pkm_fmpy_dir}" CACHE PATH
      "Directory with the FMI 2.0 headers (fmi2Functions.h); default: fmpy's c-code" FORCE)
endif()
if(NOT FMI2_HEADERS_DIR OR NOT EXISTS "${FMI2_HEADERS_DIR}/fmi2Functions.h"
   OR NOT EXISTS "${FMI2_HEADERS_DIR}/fmi2FunctionTypes.h" OR NOT EXISTS "${FMI2_HEADERS_DIR}/fmi2TypesPlatform.h"
   OR NOT EXISTS "${FMI2_HEADERS_DIR}/fmi3Functions.h")
  message(FATAL_ERROR
    "FMI 2.0 headers not found (FMI2_HEADERS_DIR = '${FMI2_HEADERS_DIR}'). They come from the fmpy package: "
    "run ./scripts/setup.sh to create .venv with python_checks/requirements.txt (fmpy), or install fmpy for "
    "python3, or pass -DFMI2_HEADERS_DIR=<directory with fmi2Functions.h>.")
endif()
message(STATUS "FMI 2.0 headers: ${FMI2_HEADERS_DIR}")

if(NOT TARGET pkm_fmi2_headers)
  add_library(pkm_fmi2_headers INTERFACE)
  target_include_directories(pkm_fmi2_headers SYSTEM INTERFACE "${FMI2_HEADERS_DIR}")
  add_library(pkm::fmi2_headers ALIAS pkm_fmi2_headers)
endif()

# FMI platform directories of the binaries: FMI 2.0 (linux64, win64, ...)
# and FMI 3.0 (x86_64-linux, aarch64-linux, x86_64-windows, ...).
if(CMAKE_SYSTEM_NAME STREQUAL "Linux")
  set(PKM_FMU_PLATFORM "linux")
  set(_pkm_fmi3_os "linux")
elseif(APPLE)
  set(PKM_FMU_PLATFORM "darwin")
  set(_pkm_fmi3_os "darwin")
elseif(WIN32)
  set(PKM_FMU_PLATFORM "win")
  set(_pkm_fmi3_os "windows")
else()
  message(FATAL_ERROR "FMU: unsupported platform ${CMAKE_SYSTEM_NAME}")
endif()
if(CMAKE_SIZEOF_VOID_P EQUAL 8)
  string(APPEND PKM_FMU_PLATFORM "64")
else()
  string(APPEND PKM_FMU_PLATFORM "32")
endif()
string(TOLOWER "${CMAKE_SYSTEM_PROCESSOR}" _pkm_cpu)
if(_pkm_cpu MATCHES "^(x86_64|amd64)$")
  set(_pkm_cpu "x86_64")
elseif(_pkm_cpu MATCHES "^(aarch64|arm64)$")
  set(_pkm_cpu "aarch64")
endif()
set(PKM_FMU3_PLATFORM "${_pkm_cpu}-${_pkm_fmi3_os}")

# The archives' entry dates: $SOURCE_DATE_EPOCH if set, else the date of the
# commit being built (read at configure time), else 1980-01-01; with
# cmake/pack_fmu.py writing nothing else that varies, the same commit builds
# bit-identical .fmu files (reproducible-builds.org's convention).
if(DEFINED ENV{SOURCE_DATE_EPOCH})
  set(PKM_SOURCE_DATE_EPOCH "$ENV{SOURCE_DATE_EPOCH}")
else()
  execute_process(COMMAND git -C "${CMAKE_SOURCE_DIR}" log -1 --format=%ct
                  OUTPUT_VARIABLE PKM_SOURCE_DATE_EPOCH OUTPUT_STRIP_TRAILING_WHITESPACE
                  RESULT_VARIABLE _pkm_git_rc ERROR_QUIET)
  if(NOT _pkm_git_rc EQUAL 0 OR NOT PKM_SOURCE_DATE_EPOCH MATCHES "^[0-9]+$")
    set(PKM_SOURCE_DATE_EPOCH 315532800)
  endif()
endif()
if(PKM_FMU_PYTHON)
  set(_pkm_pack_python "${PKM_FMU_PYTHON}")
else()
  find_program(_pkm_pack_python NAMES python3 REQUIRED)
endif()
set(PKM_PACK_FMU "${CMAKE_CURRENT_LIST_DIR}/pack_fmu.py")

# One FMU binary <id> (PREFIX "", only the fmi2* and fmi3* functions
# exported, the C++ runtime linked statically) and its two archives:
#   ${CMAKE_BINARY_DIR}/<id>.fmu       FMI 2.0 (Co-Simulation and Model Exchange)
#   ${CMAKE_BINARY_DIR}/fmi3/<id>.fmu  FMI 3.0 (Co-Simulation and Model Exchange)
# Each ships the committed model description MODEL_DESCRIPTIONS/fmi<N>/<id>.xml
# and the documentation page written by DOC_TOOL. Targets <id>_fmu and
# <id>_fmu3 (part of ALL). Sets <id>_FMU_DIR, <id>_FMU_FILE, <id>_FMU3_DIR
# and <id>_FMU3_FILE in the caller's scope.
function(pkm_add_fmu id)
  cmake_parse_arguments(F "" "DEFINITION;MODEL_DESCRIPTIONS;VERSION_SCRIPT;DOC_TOOL" "SOURCES;LIBRARIES" ${ARGN})
  set(binary_name "${id}${CMAKE_SHARED_LIBRARY_SUFFIX}")
  add_library(${id} SHARED ${F_SOURCES})
  target_compile_definitions(${id} PRIVATE PKM_FMI_DEFINITION=${F_DEFINITION})
  target_link_libraries(${id} PRIVATE ${F_LIBRARIES} pkm::fmi2_headers)
  set_target_properties(${id} PROPERTIES
    PREFIX ""
    OUTPUT_NAME "${id}"
    LIBRARY_OUTPUT_DIRECTORY "${CMAKE_BINARY_DIR}/fmu-binaries"
    RUNTIME_OUTPUT_DIRECTORY "${CMAKE_BINARY_DIR}/fmu-binaries"
    C_VISIBILITY_PRESET hidden
    CXX_VISIBILITY_PRESET hidden
    VISIBILITY_INLINES_HIDDEN ON
    LINK_DEPENDS "${F_VERSION_SCRIPT}")
  if(CMAKE_SYSTEM_NAME STREQUAL "Linux")
    # Portable binary: nothing but libc/libm/ld-linux needed at run time.
    # Except under clang's sanitizers (PKM_FUZZ): the binary then takes the
    # sanitizer runtime from the process (LD_PRELOAD, scripts/check_sanitized_fmpy.sh).
    set(_no_undefined "LINKER:--no-undefined")
    if(PKM_FUZZ)
      set(_no_undefined)
    endif()
    target_link_options(${id} PRIVATE
      "LINKER:--version-script=${F_VERSION_SCRIPT}" ${_no_undefined} "LINKER:--exclude-libs,ALL"
      -static-libstdc++ -static-libgcc)
  elseif(MINGW)
    target_link_options(${id} PRIVATE -static)
  endif()

  foreach(version 2 3)
    if(version EQUAL 2)
      set(stage "${CMAKE_BINARY_DIR}/fmu/${id}")
      set(fmu "${CMAKE_BINARY_DIR}/${id}.fmu")
      set(platform "${PKM_FMU_PLATFORM}")
      set(target ${id}_fmu)
    else()
      set(stage "${CMAKE_BINARY_DIR}/fmu3/${id}")
      set(fmu "${CMAKE_BINARY_DIR}/fmi3/${id}.fmu")
      set(platform "${PKM_FMU3_PLATFORM}")
      set(target ${id}_fmu3)
    endif()
    set(md "${F_MODEL_DESCRIPTIONS}/fmi${version}/${id}.xml")
    add_custom_command(
      OUTPUT "${fmu}"
      COMMAND ${CMAKE_COMMAND} -E rm -rf "${stage}" "${fmu}"
      COMMAND ${CMAKE_COMMAND} -E make_directory "${stage}/binaries/${platform}" "${stage}/documentation"
              "${CMAKE_BINARY_DIR}/fmi3"
      COMMAND ${CMAKE_COMMAND} -E copy "${md}" "${stage}/modelDescription.xml"
      COMMAND ${CMAKE_COMMAND} -E copy "$<TARGET_FILE:${id}>" "${stage}/binaries/${platform}/${binary_name}"
      COMMAND ${F_DOC_TOOL} ${id} "${stage}/documentation/index.html"
      COMMAND ${CMAKE_COMMAND} -E env SOURCE_DATE_EPOCH=${PKM_SOURCE_DATE_EPOCH}
              "${_pkm_pack_python}" "${PKM_PACK_FMU}" "${fmu}" "${stage}"
              modelDescription.xml "binaries/${platform}/${binary_name}" documentation/index.html
      DEPENDS ${id} "${md}" ${F_DOC_TOOL} "${PKM_PACK_FMU}"
      COMMENT "Packaging ${fmu} (FMI ${version}.0)"
      VERBATIM)
    add_custom_target(${target} ALL DEPENDS "${fmu}")
    if(PKM_BUILD_TESTS AND NOT CMAKE_CROSSCOMPILING)
      add_test(NAME fmu_archive_reproducible_fmi${version}_${id}
               COMMAND ${CMAKE_COMMAND} -DFMU=${fmu} -DSTAGE=${stage} -DID=${id} -DDOC_TOOL=$<TARGET_FILE:${F_DOC_TOOL}>
                       -DPYTHON=${_pkm_pack_python} -DPACK=${PKM_PACK_FMU} -DEPOCH=${PKM_SOURCE_DATE_EPOCH}
                       -DWORK=${CMAKE_BINARY_DIR}/reproducible/fmi${version}_${id}
                       -P ${CMAKE_CURRENT_FUNCTION_LIST_DIR}/check_reproducible_fmu.cmake)
    endif()
    if(version EQUAL 2)
      set(${id}_FMU_DIR "${stage}" PARENT_SCOPE)
      set(${id}_FMU_FILE "${fmu}" PARENT_SCOPE)
    else()
      set(${id}_FMU3_DIR "${stage}" PARENT_SCOPE)
      set(${id}_FMU3_FILE "${fmu}" PARENT_SCOPE)
    endif()
  endforeach()
endfunction()
