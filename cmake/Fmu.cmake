# FMI 2.0 co-simulation FMUs: the FMI headers, a GUID per model description,
# the FMU shared objects and their .fmu archives.
#
#   FMI2_HEADERS_DIR  (cache) directory holding fmi2Functions.h. Default:
#                     fmpy's c-code directory, found with the project's
#                     .venv/bin/python (else python3). The headers are used
#                     in place, never copied into the repository.
#   PKM_FMU_PYTHON    (cache) the Python that has fmpy (tests: fmpy validate).
#
#   pkm_fmu_guid(<out-var> <modelIdentifier> <modelDescription template>)
#   pkm_add_fmu(<modelIdentifier> DEFINITION <C++ function> MODEL_DESCRIPTION <template>
#               GUID <guid> SOURCES <exported-functions .cpp> LIBRARIES <libs...>
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
   OR NOT EXISTS "${FMI2_HEADERS_DIR}/fmi2FunctionTypes.h" OR NOT EXISTS "${FMI2_HEADERS_DIR}/fmi2TypesPlatform.h")
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

# FMI platform directory of the binaries.
if(CMAKE_SYSTEM_NAME STREQUAL "Linux")
  set(PKM_FMU_PLATFORM "linux")
elseif(APPLE)
  set(PKM_FMU_PLATFORM "darwin")
elseif(WIN32)
  set(PKM_FMU_PLATFORM "win")
else()
  message(FATAL_ERROR "FMU: unsupported platform ${CMAKE_SYSTEM_NAME}")
endif()
if(CMAKE_SIZEOF_VOID_P EQUAL 8)
  string(APPEND PKM_FMU_PLATFORM "64")
else()
  string(APPEND PKM_FMU_PLATFORM "32")
endif()

# A name-based (SHA-1) UUID of the model description template: it changes
# whenever the interface described there changes.
function(pkm_fmu_guid out_var model_identifier template)
  file(SHA1 "${template}" _sha)
  string(UUID _uuid NAMESPACE 6ba7b811-9dad-11d1-80b4-00c04fd430c8 NAME "${model_identifier}:${_sha}" TYPE SHA1)
  set(${out_var} "{${_uuid}}" PARENT_SCOPE)
endfunction()

# One FMU: <id>.so (PREFIX "", only fmi2* exported, C++ runtime linked
# statically), its staging tree ${CMAKE_BINARY_DIR}/fmu/<id>/ and the
# archive ${CMAKE_BINARY_DIR}/<id>.fmu (target <id>_fmu, part of ALL).
# Sets <id>_FMU_DIR and <id>_FMU_FILE in the caller's scope.
function(pkm_add_fmu id)
  cmake_parse_arguments(F "" "DEFINITION;MODEL_DESCRIPTION;GUID;VERSION_SCRIPT;DOC_TOOL" "SOURCES;LIBRARIES" ${ARGN})
  set(stage "${CMAKE_BINARY_DIR}/fmu/${id}")
  set(fmu "${CMAKE_BINARY_DIR}/${id}.fmu")

  set(PKM_FMU_GUID "${F_GUID}")
  configure_file("${F_MODEL_DESCRIPTION}" "${stage}/modelDescription.xml" @ONLY)

  add_library(${id} SHARED ${F_SOURCES})
  target_compile_definitions(${id} PRIVATE PKM_FMI_DEFINITION=${F_DEFINITION})
  target_link_libraries(${id} PRIVATE ${F_LIBRARIES} pkm::fmi2_headers)
  set_target_properties(${id} PROPERTIES
    PREFIX ""
    OUTPUT_NAME "${id}"
    LIBRARY_OUTPUT_DIRECTORY "${stage}/binaries/${PKM_FMU_PLATFORM}"
    C_VISIBILITY_PRESET hidden
    CXX_VISIBILITY_PRESET hidden
    VISIBILITY_INLINES_HIDDEN ON
    LINK_DEPENDS "${F_VERSION_SCRIPT}")
  if(CMAKE_SYSTEM_NAME STREQUAL "Linux")
    # Portable binary: nothing but libc/libm/ld-linux needed at run time.
    target_link_options(${id} PRIVATE
      "LINKER:--version-script=${F_VERSION_SCRIPT}" "LINKER:--no-undefined" "LINKER:--exclude-libs,ALL"
      -static-libstdc++ -static-libgcc)
  endif()

  add_custom_command(
    OUTPUT "${stage}/documentation/index.html"
    COMMAND ${CMAKE_COMMAND} -E make_directory "${stage}/documentation"
    COMMAND ${F_DOC_TOOL} ${id} "${stage}/documentation/index.html"
    DEPENDS ${F_DOC_TOOL}
    COMMENT "Writing the documentation of ${id}.fmu"
    VERBATIM)

  add_custom_command(
    OUTPUT "${fmu}"
    COMMAND ${CMAKE_COMMAND} -E rm -f "${fmu}"
    COMMAND ${CMAKE_COMMAND} -E tar cf "${fmu}" --format=zip
            modelDescription.xml "binaries/${PKM_FMU_PLATFORM}/${id}${CMAKE_SHARED_LIBRARY_SUFFIX}"
            documentation/index.html
    WORKING_DIRECTORY "${stage}"
    DEPENDS ${id} "${stage}/modelDescription.xml" "${stage}/documentation/index.html"
    COMMENT "Packaging ${id}.fmu"
    VERBATIM)
  add_custom_target(${id}_fmu ALL DEPENDS "${fmu}")

  set(${id}_FMU_DIR "${stage}" PARENT_SCOPE)
  set(${id}_FMU_FILE "${fmu}" PARENT_SCOPE)
endfunction()
