# SPDX-License-Identifier: BSD-2-Clause
# The FMUs: the FMI 2.0 and 3.0 headers, the FMU shared objects and their
# .fmu archives.
#
#   PKM_FMU_PYTHON    (cache) the Python that has fmpy (tests: fmpy validate);
#                     default: the project's .venv, else python3.
#
#   pkm_add_fmu(<modelIdentifier> DEFINITION <function in namespace pkm_fmi>
#               SOURCES <the model's sources...>)
include_guard(GLOBAL)

# The FMI standard's headers, vendored (third_party/fmi, BSD-2-Clause).
if(NOT TARGET pkm_fmi_headers)
  add_library(pkm_fmi_headers INTERFACE)
  target_include_directories(pkm_fmi_headers SYSTEM INTERFACE "${PROJECT_SOURCE_DIR}/third_party/fmi/include")
  add_library(pkm::fmi_headers ALIAS pkm_fmi_headers)
endif()

set(PKM_FMU_PYTHON "" CACHE FILEPATH "Python interpreter with fmpy installed (FMU tests)")
if(NOT PKM_FMU_PYTHON)
  if(EXISTS "${PROJECT_SOURCE_DIR}/.venv/bin/python")
    set(PKM_FMU_PYTHON "${PROJECT_SOURCE_DIR}/.venv/bin/python" CACHE FILEPATH "Python interpreter with fmpy installed (FMU tests)" FORCE)
  else()
    find_program(PKM_PYTHON3_EXECUTABLE NAMES python3)
    mark_as_advanced(PKM_PYTHON3_EXECUTABLE)
    set(PKM_FMU_PYTHON "${PKM_PYTHON3_EXECUTABLE}" CACHE FILEPATH "Python interpreter with fmpy installed (FMU tests)" FORCE)
  endif()
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
  execute_process(COMMAND git -C "${PROJECT_SOURCE_DIR}" log -1 --format=%ct
                  OUTPUT_VARIABLE PKM_SOURCE_DATE_EPOCH OUTPUT_STRIP_TRAILING_WHITESPACE
                  RESULT_VARIABLE _pkm_git_rc ERROR_QUIET)
  if(NOT _pkm_git_rc EQUAL 0 OR NOT PKM_SOURCE_DATE_EPOCH MATCHES "^[0-9]+$")
    set(PKM_SOURCE_DATE_EPOCH 315532800)
  endif()
endif()
# The commit being built, appended to generationTool in the archives' model
# descriptions (cmake/pack_fmu.py), with generationDateAndTime from
# PKM_SOURCE_DATE_EPOCH. Both are read at configure time, and the build
# configures again when HEAD or its branch moves (a new commit). Empty
# outside git.
execute_process(COMMAND git -C "${PROJECT_SOURCE_DIR}" rev-parse --short=12 HEAD
                OUTPUT_VARIABLE PKM_GIT_COMMIT OUTPUT_STRIP_TRAILING_WHITESPACE
                RESULT_VARIABLE _pkm_git_rc ERROR_QUIET)
if(NOT _pkm_git_rc EQUAL 0)
  set(PKM_GIT_COMMIT "")
else()
  execute_process(COMMAND git -C "${PROJECT_SOURCE_DIR}" symbolic-ref -q HEAD
                  OUTPUT_VARIABLE _pkm_branch OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
  foreach(_ref HEAD ${_pkm_branch})
    execute_process(COMMAND git -C "${PROJECT_SOURCE_DIR}" rev-parse --path-format=absolute --git-path ${_ref}
                    OUTPUT_VARIABLE _pkm_ref_file OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
    if(EXISTS "${_pkm_ref_file}")
      set_property(DIRECTORY "${PROJECT_SOURCE_DIR}" APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS "${_pkm_ref_file}")
    endif()
  endforeach()
endif()

# The licences in every archive's documentation/licenses/: the project's
# (LICENSE.txt) and the notices of what the host's binary links
# (third_party/licenses/): SUNDIALS (static), Eigen (compiled templates), the
# GCC runtime (libstdc++ and libgcc linked statically, GCC Runtime Library
# Exception) and, for mingw-w64 builds, its runtime and winpthreads.
# cmake/check_fmu_archives.py knows the same rule per platform folder.
set(PKM_LICENSES_DIR "${PROJECT_SOURCE_DIR}/third_party/licenses")
set(PKM_FMU_LICENSES "${PKM_LICENSES_DIR}/SUNDIALS.txt" "${PKM_LICENSES_DIR}/Eigen.txt")
if(CMAKE_SYSTEM_NAME STREQUAL "Linux" OR MINGW)
  list(APPEND PKM_FMU_LICENSES "${PKM_LICENSES_DIR}/GCC-runtime-exception.txt")
endif()
if(MINGW)
  list(APPEND PKM_FMU_LICENSES "${PKM_LICENSES_DIR}/mingw-w64.txt")
endif()
set(_pkm_license_names documentation/licenses/LICENSE.txt)
foreach(_f IN LISTS PKM_FMU_LICENSES)
  get_filename_component(_n "${_f}" NAME)
  list(APPEND _pkm_license_names "documentation/licenses/${_n}")
endforeach()
list(SORT _pkm_license_names)  # the order check_reproducible_fmu.cmake packs them in

# Packing an archive takes Python's standard library (cmake/pack_fmu.py);
# without any Python the binaries are still built.
if(PKM_FMU_PYTHON)
  set(_pkm_pack_python "${PKM_FMU_PYTHON}")
else()
  find_program(_pkm_pack_python NAMES python3)
endif()
if(NOT _pkm_pack_python)
  message(WARNING "python3 not found: the FMU binaries are built, their .fmu archives are not")
endif()
set(PKM_PACK_FMU "${CMAKE_CURRENT_LIST_DIR}/pack_fmu.py")

# One FMU from its model's folder (the caller's CMAKE_CURRENT_SOURCE_DIR/<id>):
#   pkm_model_<id>  its sources (the variable table and the data hooks) on
#                   the core and the generic FMI layer, for the binary, the
#                   tests and the tools;
#   <id>_files      the build tool that writes its model descriptions
#                   (build/modelDescription/fmi<v>/<id>.xml) and its
#                   documentation page from the table;
#   <id>            the binary (PREFIX "", only the fmi2* and fmi3* functions
#                   exported, the C++ runtime linked statically);
#   ${PROJECT_BINARY_DIR}/<id>.fmu       FMI 2.0 (Co-Simulation and Model Exchange)
#   ${PROJECT_BINARY_DIR}/fmi3/<id>.fmu  FMI 3.0 (Co-Simulation and Model Exchange)
# Each archive ships the committed model description <id>/fmi<v>/modelDescription.xml.
# Targets <id>_fmu and <id>_fmu3 (part of ALL). Sets <id>_FMU_DIR,
# <id>_FMU_FILE, <id>_FMU3_DIR and <id>_FMU3_FILE in the caller's scope and
# appends <id> to the global property PKM_FMU_MODELS.
function(pkm_add_fmu id)
  cmake_parse_arguments(F "" "DEFINITION" "SOURCES" ${ARGN})
  set(model_dir "${CMAKE_CURRENT_SOURCE_DIR}/${id}")
  set(binary_name "${id}${CMAKE_SHARED_LIBRARY_SUFFIX}")
  set_property(GLOBAL APPEND PROPERTY PKM_FMU_MODELS ${id})
  set_property(GLOBAL PROPERTY PKM_FMU_DEFINITION_${id} ${F_DEFINITION})

  add_library(pkm_model_${id} STATIC ${F_SOURCES})
  target_link_libraries(pkm_model_${id} PUBLIC pkm_fmi pkm_core PRIVATE pkm::sundials pkm::options)
  set_target_properties(pkm_model_${id} PROPERTIES CXX_VISIBILITY_PRESET hidden VISIBILITY_INLINES_HIDDEN ON)
  pkm_fat_lto_objects(pkm_model_${id})  # cmake/Lto.cmake: the tests and the tools link it without LTO

  add_executable(${id}_files ${PROJECT_SOURCE_DIR}/src/fmi/fmu_files.cpp)
  target_compile_definitions(${id}_files PRIVATE PKM_FMI_DEFINITION=${F_DEFINITION})
  target_link_libraries(${id}_files PRIVATE pkm_model_${id} pkm_version pkm::sundials pkm::options)
  pkm_without_lto(${id}_files)
  set(generated_md "${PROJECT_BINARY_DIR}/modelDescription")
  # ... and the documentation site's reference page of the model (docs/fmus.md
  # includes docs/generated/<id>.md of the build tree).
  set(generated_doc "${PROJECT_BINARY_DIR}/docs/generated/${id}.md")
  add_custom_command(
    OUTPUT "${generated_md}/fmi2/${id}.xml" "${generated_md}/fmi3/${id}.xml" "${generated_doc}"
    COMMAND ${CMAKE_COMMAND} -E make_directory "${generated_md}/fmi2" "${generated_md}/fmi3"
            "${PROJECT_BINARY_DIR}/docs/generated"
    COMMAND ${id}_files --xml "${generated_md}"
    COMMAND ${id}_files --markdown "${generated_doc}"
    DEPENDS ${id}_files
    COMMENT "Generating ${id}'s model descriptions and reference page from its variable table"
    VERBATIM)
  add_custom_target(${id}_model_descriptions ALL
                    DEPENDS "${generated_md}/fmi2/${id}.xml" "${generated_md}/fmi3/${id}.xml" "${generated_doc}")
  # `cmake --build build --target update_model_descriptions` writes them into
  # the model's folder (commit them); the test model_descriptions_up_to_date
  # compares the two.
  add_custom_target(${id}_update_model_descriptions
    COMMAND ${CMAKE_COMMAND} -E copy "${generated_md}/fmi2/${id}.xml" "${model_dir}/fmi2/modelDescription.xml"
    COMMAND ${CMAKE_COMMAND} -E copy "${generated_md}/fmi3/${id}.xml" "${model_dir}/fmi3/modelDescription.xml"
    DEPENDS ${id}_model_descriptions
    COMMENT "Copying ${id}'s generated model descriptions into ${model_dir} (commit them)"
    VERBATIM)
  if(NOT TARGET update_model_descriptions)
    add_custom_target(update_model_descriptions)
  endif()
  add_dependencies(update_model_descriptions ${id}_update_model_descriptions)

  add_library(${id} SHARED ${PKM_FMI_FRONT_ENDS})
  target_compile_definitions(${id} PRIVATE PKM_FMI_DEFINITION=${F_DEFINITION})
  target_link_libraries(${id} PRIVATE pkm_model_${id} pkm::sundials pkm::fmi_headers pkm::options)
  set_target_properties(${id} PROPERTIES
    PREFIX ""
    OUTPUT_NAME "${id}"
    LIBRARY_OUTPUT_DIRECTORY "${PROJECT_BINARY_DIR}/fmu-binaries"
    RUNTIME_OUTPUT_DIRECTORY "${PROJECT_BINARY_DIR}/fmu-binaries"
    C_VISIBILITY_PRESET hidden
    CXX_VISIBILITY_PRESET hidden
    VISIBILITY_INLINES_HIDDEN ON
    LINK_DEPENDS "${PKM_FMI_EXPORTS_MAP}")
  if(CMAKE_SYSTEM_NAME STREQUAL "Linux")
    # Portable binary: nothing but libc/libm/ld-linux needed at run time.
    # Except under clang's sanitizers (PKM_FUZZ): the binary then takes the
    # sanitizer runtime from the process (LD_PRELOAD, scripts/check_sanitized_fmpy.sh).
    set(_no_undefined "LINKER:--no-undefined")
    if(PKM_FUZZ)
      set(_no_undefined)
    endif()
    target_link_options(${id} PRIVATE
      "LINKER:--version-script=${PKM_FMI_EXPORTS_MAP}" ${_no_undefined} "LINKER:--exclude-libs,ALL"
      -static-libstdc++ -static-libgcc)
    if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
      # Linked with -static-libstdc++: free its private exception pool on unload (fmu_binary.cpp).
      target_compile_definitions(${id} PRIVATE PKM_FMI_FREE_EH_POOL=1)
    endif()
  elseif(MINGW)
    target_link_options(${id} PRIVATE -static)
  endif()

  foreach(version 2 3)
    if(NOT _pkm_pack_python)
      break()
    endif()
    if(version EQUAL 2)
      set(stage "${PROJECT_BINARY_DIR}/fmu/${id}")
      set(fmu "${PROJECT_BINARY_DIR}/${id}.fmu")
      set(platform "${PKM_FMU_PLATFORM}")
      set(target ${id}_fmu)
    else()
      set(stage "${PROJECT_BINARY_DIR}/fmu3/${id}")
      set(fmu "${PROJECT_BINARY_DIR}/fmi3/${id}.fmu")
      set(platform "${PKM_FMU3_PLATFORM}")
      set(target ${id}_fmu3)
    endif()
    set(md "${model_dir}/fmi${version}/modelDescription.xml")
    add_custom_command(
      OUTPUT "${fmu}"
      COMMAND ${CMAKE_COMMAND} -E rm -rf "${stage}" "${fmu}"
      COMMAND ${CMAKE_COMMAND} -E make_directory "${stage}/binaries/${platform}" "${stage}/documentation/licenses"
              "${PROJECT_BINARY_DIR}/fmi3"
      COMMAND ${CMAKE_COMMAND} -E copy "${PROJECT_SOURCE_DIR}/LICENSE" "${stage}/documentation/licenses/LICENSE.txt"
      COMMAND ${CMAKE_COMMAND} -E copy ${PKM_FMU_LICENSES} "${stage}/documentation/licenses"
      COMMAND ${CMAKE_COMMAND} -E copy "${md}" "${stage}/modelDescription.xml"
      COMMAND ${CMAKE_COMMAND} -E copy "$<TARGET_FILE:${id}>" "${stage}/binaries/${platform}/${binary_name}"
      COMMAND ${id}_files ${id} "${stage}/documentation/index.html"
      COMMAND ${CMAKE_COMMAND} -E env SOURCE_DATE_EPOCH=${PKM_SOURCE_DATE_EPOCH}
              "${_pkm_pack_python}" "${PKM_PACK_FMU}" --commit "${PKM_GIT_COMMIT}" "${fmu}" "${stage}"
              modelDescription.xml "binaries/${platform}/${binary_name}" documentation/index.html
              ${_pkm_license_names}
      DEPENDS ${id} "${md}" ${id}_files "${PKM_PACK_FMU}" "${PROJECT_SOURCE_DIR}/LICENSE" ${PKM_FMU_LICENSES}
      COMMENT "Packaging ${fmu} (FMI ${version}.0)"
      VERBATIM)
    add_custom_target(${target} ALL DEPENDS "${fmu}")
    if(PKM_BUILD_TESTS AND NOT CMAKE_CROSSCOMPILING)
      add_test(NAME fmu_archive_reproducible_fmi${version}_${id}
               COMMAND ${CMAKE_COMMAND} -DFMU=${fmu} -DSTAGE=${stage} -DID=${id} -DDOC_TOOL=$<TARGET_FILE:${id}_files>
                       -DPYTHON=${_pkm_pack_python} -DPACK=${PKM_PACK_FMU} -DEPOCH=${PKM_SOURCE_DATE_EPOCH}
                       -DCOMMIT=${PKM_GIT_COMMIT}
                       -DWORK=${PROJECT_BINARY_DIR}/reproducible/fmi${version}_${id}
                       -P ${CMAKE_CURRENT_FUNCTION_LIST_DIR}/check_reproducible_fmu.cmake)
      add_test(NAME model_descriptions_up_to_date_fmi${version}_${id}
               COMMAND ${CMAKE_COMMAND} -E compare_files "${generated_md}/fmi${version}/${id}.xml" "${md}")
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
