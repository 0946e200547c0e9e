# SPDX-License-Identifier: BSD-2-Clause
# The FMUs: the FMI 2.0 and 3.0 headers, the FMU shared objects and their
# .fmu archives.
#
#   Python3_EXECUTABLE  find_package(Python3): packs the archives (its standard
#                       library), and runs the FMU tests (fmpy); scripts/build.sh
#                       passes the project's .venv/bin/python when there is one.
#
#   pkm_add_fmu(<modelIdentifier> DEFINITION <function in namespace pkm_fmi>
#               SOURCES <the model's sources...>)
#   pkm_fmu_paths(<target> <modelIdentifier> <prefix>)
include_guard(GLOBAL)

# The FMI standard's headers, vendored (third_party/fmi, BSD-2-Clause).
if(NOT TARGET pkm_fmi_headers)
  add_library(pkm_fmi_headers INTERFACE)
  target_include_directories(pkm_fmi_headers SYSTEM INTERFACE "${PROJECT_SOURCE_DIR}/third_party/fmi/include")
  add_library(pkm::fmi_headers ALIAS pkm_fmi_headers)
endif()

find_package(Python3 COMPONENTS Interpreter)

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

# What changes from commit to commit, read when the build runs (a commit
# does not make CMake configure again): the commit (appended to
# generationTool in the archives' model descriptions) and the archives'
# entry dates ($SOURCE_DATE_EPOCH if set, else the commit's date, else
# 1980-01-01; generationDateAndTime too), reproducible-builds.org's
# convention. cmake/source_stamp.cmake writes them to PKM_SOURCE_STAMP
# (JSON), rewritten only when they change; with cmake/pack_fmu.py writing
# nothing else that varies, the same commit builds bit-identical .fmu files.
set(PKM_SOURCE_STAMP "${PROJECT_BINARY_DIR}/source_stamp.json")
if(NOT TARGET pkm_source_stamp)
  add_custom_target(pkm_source_stamp
    COMMAND ${CMAKE_COMMAND} -DSOURCE=${PROJECT_SOURCE_DIR} -DOUT=${PKM_SOURCE_STAMP}
            -P ${CMAKE_CURRENT_LIST_DIR}/source_stamp.cmake
    BYPRODUCTS "${PKM_SOURCE_STAMP}"
    COMMENT "The commit and its date (${PKM_SOURCE_STAMP})" VERBATIM)
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
if(NOT Python3_Interpreter_FOUND)
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
# Targets <id>_fmu and <id>_fmu3 (part of ALL). The binary's target <id>
# carries what other folders need to know (pkm_fmu_paths, cmake/Platforms.cmake,
# cmake/Install.cmake): PKM_FMI_DEFINITION, and with the archives
# PKM_FMU_ARCHIVE_FMI<v> and PKM_FMU_STAGE_FMI<v> (the folder packed). <id>
# is appended to the global property PKM_FMU_MODELS.
function(pkm_add_fmu id)
  cmake_parse_arguments(F "" "DEFINITION" "SOURCES" ${ARGN})
  set(model_dir "${CMAKE_CURRENT_SOURCE_DIR}/${id}")
  set(binary_name "${id}${CMAKE_SHARED_LIBRARY_SUFFIX}")
  set_property(GLOBAL APPEND PROPERTY PKM_FMU_MODELS ${id})

  add_library(pkm_model_${id} STATIC ${F_SOURCES})
  target_link_libraries(pkm_model_${id} PUBLIC pkm_fmi pkm_core PRIVATE pkm::options)
  set_target_properties(pkm_model_${id} PROPERTIES CXX_VISIBILITY_PRESET hidden VISIBILITY_INLINES_HIDDEN ON
                                                  UNITY_BUILD ON)  # its sources in one file: one parse of the core's headers
  pkm_fat_lto_objects(pkm_model_${id})  # cmake/Lto.cmake: the tests and the tools link it without LTO

  add_executable(${id}_files ${PROJECT_SOURCE_DIR}/src/fmi/fmu_files.cpp)
  target_compile_definitions(${id}_files PRIVATE PKM_FMI_DEFINITION=${F_DEFINITION})
  target_link_libraries(${id}_files PRIVATE pkm_model_${id} pkm_version pkm::options)
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

  # The FMI front ends (pkm_fmi_binary's sources) compiled for this model.
  add_library(${id} SHARED)
  target_compile_definitions(${id} PRIVATE PKM_FMI_DEFINITION=${F_DEFINITION})
  target_link_libraries(${id} PRIVATE pkm_fmi_binary pkm_model_${id} pkm::options)
  set_target_properties(${id} PROPERTIES
    PKM_FMI_DEFINITION ${F_DEFINITION}
    PREFIX ""
    OUTPUT_NAME "${id}"
    LIBRARY_OUTPUT_DIRECTORY "${PROJECT_BINARY_DIR}/fmu-binaries"
    RUNTIME_OUTPUT_DIRECTORY "${PROJECT_BINARY_DIR}/fmu-binaries"
    C_VISIBILITY_PRESET hidden
    CXX_VISIBILITY_PRESET hidden
    VISIBILITY_INLINES_HIDDEN ON)
  if(CMAKE_SYSTEM_NAME STREQUAL "Linux")
    # Portable binary: nothing but libc/libm/ld-linux needed at run time.
    # Except under clang's sanitizers (PKM_FUZZ): the binary then takes the
    # sanitizer runtime from the process (LD_PRELOAD, scripts/check_sanitized_fmpy.sh).
    set(_no_undefined "LINKER:--no-undefined")
    if(PKM_FUZZ)
      set(_no_undefined)
    endif()
    target_link_options(${id} PRIVATE ${_no_undefined} "LINKER:--exclude-libs,ALL" -static-libstdc++ -static-libgcc)
    if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
      # Linked with -static-libstdc++: free its private exception pool on unload (fmu_binary.cpp).
      target_compile_definitions(${id} PRIVATE PKM_FMI_FREE_EH_POOL=1)
    endif()
  elseif(MINGW)
    target_link_options(${id} PRIVATE -static)
  endif()

  foreach(version 2 3)
    if(NOT Python3_Interpreter_FOUND)
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
      COMMAND Python3::Interpreter "${PKM_PACK_FMU}" --stamp "${PKM_SOURCE_STAMP}" "${fmu}" "${stage}"
              modelDescription.xml "binaries/${platform}/${binary_name}" documentation/index.html
              ${_pkm_license_names}
      DEPENDS ${id} "${md}" ${id}_files "${PKM_PACK_FMU}" pkm_source_stamp "${PKM_SOURCE_STAMP}"
              "${PROJECT_SOURCE_DIR}/LICENSE" ${PKM_FMU_LICENSES}
      COMMENT "Packaging ${fmu} (FMI ${version}.0)"
      VERBATIM)
    add_custom_target(${target} ALL DEPENDS "${fmu}")
    if(PKM_BUILD_TESTS AND NOT CMAKE_CROSSCOMPILING)
      add_test(NAME fmu_archive_reproducible_fmi${version}_${id}
               COMMAND ${CMAKE_COMMAND} -DFMU=${fmu} -DSTAGE=${stage} -DID=${id} -DDOC_TOOL=$<TARGET_FILE:${id}_files>
                       -DPYTHON=${Python3_EXECUTABLE} -DPACK=${PKM_PACK_FMU} -DSTAMP=${PKM_SOURCE_STAMP}
                       -DWORK=${PROJECT_BINARY_DIR}/reproducible/fmi${version}_${id}
                       -P ${CMAKE_CURRENT_FUNCTION_LIST_DIR}/check_reproducible_fmu.cmake)
      add_test(NAME model_descriptions_up_to_date_fmi${version}_${id}
               COMMAND ${CMAKE_COMMAND} -E compare_files "${generated_md}/fmi${version}/${id}.xml" "${md}")
    endif()
    set_target_properties(${id} PROPERTIES PKM_FMU_ARCHIVE_FMI${version} "${fmu}" PKM_FMU_STAGE_FMI${version} "${stage}")
  endforeach()
endfunction()

# pkm_fmu_paths(<target> <id> <prefix>): <target> compiled with where the
# build puts the FMU <id>'s files, as string macros, and built after them:
#   <prefix>_SO    the binary             <prefix>_FMU   the FMI 2.0 archive
#   <prefix>_XML   its staged model       <prefix>_FMU3  the FMI 3.0 archive
#                  description (FMI 2.0)
function(pkm_fmu_paths target id prefix)
  target_compile_definitions(${target} PRIVATE ${prefix}_SO="$<TARGET_FILE:${id}>")
  add_dependencies(${target} ${id})
  if(TARGET ${id}_fmu)
    target_compile_definitions(${target} PRIVATE
      ${prefix}_XML="$<TARGET_PROPERTY:${id},PKM_FMU_STAGE_FMI2>/modelDescription.xml"
      ${prefix}_FMU="$<TARGET_PROPERTY:${id},PKM_FMU_ARCHIVE_FMI2>"
      ${prefix}_FMU3="$<TARGET_PROPERTY:${id},PKM_FMU_ARCHIVE_FMI3>")
    add_dependencies(${target} ${id}_fmu ${id}_fmu3)
  endif()
endfunction()
