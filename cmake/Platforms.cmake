# SPDX-License-Identifier: BSD-2-Clause
# Every platform: the FMU binaries cross-built for Windows x64
# (mingw-w64) and Linux aarch64 (gcc), each in a sub-build of this project
# under ${PROJECT_BINARY_DIR}/platforms/<target> with the toolchain files of
# cmake/toolchains/, against a static CVODE built for the target from
# Debian's source package (scripts/cross_sundials.sh, cached in
# platforms/sundials-<target>, found through the SUNDIALSConfig.cmake it
# installs there, as the host's); the FMI tests run there under wine and
# qemu-user; and one archive per FMU and FMI version holding every platform
# and the source code (cmake/merge_fmu.py):
#
#   build/dist/fmi2/<id>.fmu   binaries/linux64, binaries/win64, sources/
#   build/dist/fmi3/<id>.fmu   binaries/x86_64-linux, x86_64-windows, aarch64-linux, sources/
#
#   PKM_PLATFORMS  (option, OFF) ON: all of this (the test command); OFF: the host's FMUs only.
include_guard(GLOBAL)
option(PKM_PLATFORMS "Cross-build the FMUs for Windows x64 and Linux aarch64, test them under wine and qemu-user, merge every platform into one archive per FMU (the test command turns it on)" OFF)
if(NOT PKM_PLATFORMS OR CMAKE_CROSSCOMPILING)
  return()
endif()
if(NOT CMAKE_SYSTEM_NAME STREQUAL "Linux" OR NOT CMAKE_SYSTEM_PROCESSOR MATCHES "^(x86_64|AMD64|amd64)$")
  message(FATAL_ERROR "PKM_PLATFORMS cross-builds from Linux x86-64 only; configure with -DPKM_PLATFORMS=OFF")
endif()
foreach(_tool x86_64-w64-mingw32-g++-posix wine aarch64-linux-gnu-g++ qemu-aarch64 x86_64-w64-mingw32-objdump)
  find_program(_pkm_have_${_tool} ${_tool})
  if(NOT _pkm_have_${_tool})
    message(FATAL_ERROR "${_tool} not found: ./scripts/setup.sh installs the cross tools (or -DPKM_PLATFORMS=OFF)")
  endif()
endforeach()
include(ExternalProject)

set(PKM_PLATFORMS_DIR "${PROJECT_BINARY_DIR}/platforms")
set(_pkm_previous)
set(_pkm_wine_env WINEDEBUG=-all WINEDLLOVERRIDES=mscoree,mshtml=)

# wine's prefix (in $HOME) once, before anything runs under wine: two first
# starts at once would both try to create it.
add_custom_target(pkm_wine_prefix
  COMMAND ${CMAKE_COMMAND} -E env ${_pkm_wine_env} wine wineboot --init
  COMMENT "wine prefix (created on the first run)" VERBATIM)

# target: toolchain file, FMI 2.0 platform folder (none for aarch64: FMI 2.0
# names no ARM platform), FMI 3.0 platform folder, binary suffix.
set(_pkm_win64 mingw-w64-x86_64 win64 x86_64-windows .dll)
set(_pkm_aarch64 aarch64-linux-gnu "" aarch64-linux .so)
foreach(_t IN ITEMS win64 aarch64)
  list(GET _pkm_${_t} 0 _toolchain)
  list(GET _pkm_${_t} 3 _suffix)
  set(_prefix "${PKM_PLATFORMS_DIR}/sundials-${_t}")
  set(_bin "${PKM_PLATFORMS_DIR}/${_t}")
  add_custom_target(pkm_sundials_${_t}
    COMMAND ${PROJECT_SOURCE_DIR}/scripts/cross_sundials.sh ${_t} ${_prefix}
    COMMENT "Static CVODE for ${_t} (cached in ${_prefix})" VERBATIM)
  # Windows also builds the core bench, its ticks compared with linux64's
  # below (under qemu a timing says nothing about aarch64 hardware).
  set(_extra_targets)
  if(_t STREQUAL "win64")
    set(_extra_targets pkm_bench)
  endif()
  set(_products)
  foreach(_id IN ITEMS PKM4PUU PKM4PUU_Inverse)
    list(APPEND _products "${_bin}/fmu-binaries/${_id}${_suffix}")
  endforeach()
  ExternalProject_Add(pkm_platform_${_t}
    SOURCE_DIR "${PROJECT_SOURCE_DIR}"
    BINARY_DIR "${_bin}"
    CMAKE_ARGS -DCMAKE_TOOLCHAIN_FILE=${PROJECT_SOURCE_DIR}/cmake/toolchains/${_toolchain}.cmake
               -DCMAKE_BUILD_TYPE=Release -DPKM_BUILD_BENCHMARKS=ON -DPKM_PLATFORMS=OFF
               -DPKM_CROSS_PREFIX=${_prefix}
               -DPython3_EXECUTABLE=${Python3_EXECUTABLE} -DPKM_TRACE_REFERENCE=${PKM_TRACE_DIR}
    BUILD_COMMAND ${CMAKE_COMMAND} --build <BINARY_DIR> -j2
                  --target PKM4PUU PKM4PUU_Inverse fmi_state_machine fmi_bad_arguments fmi_variables
                          fmi_fmu_states_restored fmi_fmu_states_refused fmi_stepping fmi_logging fmi_autotest_chain
                          ${_extra_targets}
    BUILD_ALWAYS ON
    BUILD_BYPRODUCTS ${_products}
    INSTALL_COMMAND ""
    DEPENDS pkm_sundials_${_t} ${_pkm_previous})
  set(_pkm_previous pkm_platform_${_t})  # one sub-build at a time: each runs -j2
  set(PKM_${_t}_BINARIES ${_products})
  if(PKM_BUILD_TESTS)
    # The sub-build's FMI tests under the emulator; the auto-test compares
    # with the linux64 run's trace (fmi_autotest_chain writes it).
    add_test(NAME platform_${_t}_fmi_tests
             COMMAND ${CMAKE_CTEST_COMMAND} --test-dir ${_bin} --output-on-failure --no-tests=error)
    set_tests_properties(platform_${_t}_fmi_tests PROPERTIES FIXTURES_REQUIRED linux64_traces TIMEOUT 900)
    if(PKM_BUILD_BENCHMARKS AND _t STREQUAL "win64")
      # The core bench's ticks built for both, run alternately under wine:
      # the ratio to linux64 against its 1.2x target (printed, not asserted)
      # and the poses after 1 s within 1e-12 (tests/platform_ticks.py).
      add_test(NAME platform_win64_tick_ratio
               COMMAND Python3::Interpreter ${PROJECT_SOURCE_DIR}/tests/platform_ticks.py
                       --host $<TARGET_FILE:pkm_bench> --other ${_bin}/bench/pkm_bench.exe
                       --runner wine --name win64 --rounds 1)
      set_tests_properties(platform_win64_tick_ratio PROPERTIES TIMEOUT 300)
    endif()
  endif()
endforeach()
add_dependencies(pkm_platform_win64 pkm_wine_prefix)

if(PKM_BUILD_TESTS)
  # The Windows DLLs need only system DLLs (libstdc++, libgcc, winpthread and
  # CVODE linked in) and export exactly the FMI functions of fmi_functions.h.
  add_test(NAME platform_win64_binaries_imports_and_exports
           COMMAND ${CMAKE_COMMAND} -DOBJDUMP=x86_64-w64-mingw32-objdump
                   "-DBINARIES=${PKM_win64_BINARIES}" -DFUNCTIONS=${PROJECT_SOURCE_DIR}/src/fmi/fmi_functions.h
                   -P ${PROJECT_SOURCE_DIR}/cmake/check_windows_dll.cmake)
endif()

# ---------------------------------------------------------------- the merged archives
# Source build: the core without SUNDIALS (cvode_unavailable.cpp for
# cvode_integrator.cpp: RK4 only), the generic FMI layer and the model's own
# sources, Eigen inside; every file keeps its path below src/ (sources/ is
# the include root, as src/ is here).
set(_src "${PROJECT_SOURCE_DIR}/src")
get_target_property(_core_src pkm_core SOURCES)
get_target_property(_fmi_src pkm_fmi SOURCES)
set(_common_sources)
foreach(_f IN LISTS _core_src)
  if(NOT _f MATCHES "cvode_integrator.cpp$")
    list(APPEND _common_sources "${_src}/${_f}")
  endif()
endforeach()
list(APPEND _common_sources "${_src}/pkm4puu/integrators/cvode_unavailable.cpp")
foreach(_f IN LISTS _fmi_src)
  list(APPEND _common_sources "${_src}/fmi/${_f}")
endforeach()
list(APPEND _common_sources "${_src}/fmi/fmu_binary.cpp")
file(GLOB_RECURSE _headers "${_src}/pkm4puu/*.hpp" "${_src}/fmi/*.hpp" "${_src}/fmi/*.h" "${_src}/models/*.hpp")
list(APPEND _headers "${_src}/fmi/fmi2_functions.cpp" "${_src}/fmi/fmi3_functions.cpp")
get_target_property(_eigen_inc Eigen3::Eigen INTERFACE_INCLUDE_DIRECTORIES)
list(GET _eigen_inc 0 _eigen_inc)
set(_header_args --source-root "${_src}")
foreach(_f IN LISTS _headers)
  list(APPEND _header_args --header "${_f}")
endforeach()
# The notices beyond the host's (cmake/Fmu.cmake): mingw-w64's runtime in the
# Windows binaries, Eigen in sources/.
list(APPEND _header_args --eigen "${_eigen_inc}" --stamp "${PKM_SOURCE_STAMP}"
     --license "${PKM_LICENSES_DIR}/mingw-w64.txt" --license "${PKM_LICENSES_DIR}/Eigen.txt")

set(_merged)
get_property(_models GLOBAL PROPERTY PKM_FMU_MODELS)
foreach(_id IN LISTS _models)
  # The model's table and sources, as pkm_add_fmu compiled the binary with them.
  get_target_property(_def ${_id} PKM_FMI_DEFINITION)
  get_target_property(_model_src pkm_model_${_id} SOURCES)
  set(_sources ${_common_sources})
  foreach(_f IN LISTS _model_src)
    list(APPEND _sources "${_src}/models/${_f}")
  endforeach()
  set(_src_args ${_header_args})
  foreach(_f IN LISTS _sources)
    list(APPEND _src_args --source "${_f}")
  endforeach()
  foreach(_v 2 3)
    set(_bins)
    foreach(_t IN ITEMS win64 aarch64)
      list(GET _pkm_${_t} 3 _suffix)
      if(_v EQUAL 2)
        list(GET _pkm_${_t} 1 _platform)
      else()
        list(GET _pkm_${_t} 2 _platform)
      endif()
      if(_platform)
        list(APPEND _bins --binary "${_platform}=${PKM_PLATFORMS_DIR}/${_t}/fmu-binaries/${_id}${_suffix}")
      endif()
    endforeach()
    # The host's staged FMU and its archive (cmake/Fmu.cmake).
    get_target_property(_native ${_id} PKM_FMU_STAGE_FMI${_v})
    get_target_property(_native_fmu ${_id} PKM_FMU_ARCHIVE_FMI${_v})
    set(_out "${PROJECT_BINARY_DIR}/dist/fmi${_v}/${_id}.fmu")
    add_custom_command(
      OUTPUT "${_out}"
      COMMAND ${CMAKE_COMMAND} -E make_directory "${PROJECT_BINARY_DIR}/dist/fmi${_v}"
      COMMAND Python3::Interpreter "${PROJECT_SOURCE_DIR}/cmake/merge_fmu.py" --out "${_out}"
              --stage "${PROJECT_BINARY_DIR}/dist/stage/fmi${_v}/${_id}" --native-stage "${_native}"
              --fmi-version ${_v} --id ${_id} --definition ${_def} ${_bins} ${_src_args}
      DEPENDS "${_native_fmu}" pkm_source_stamp "${PKM_SOURCE_STAMP}" ${PKM_win64_BINARIES} ${PKM_aarch64_BINARIES} ${_sources} ${_headers}
              "${PROJECT_SOURCE_DIR}/cmake/merge_fmu.py" "${PKM_PACK_FMU}"
      COMMENT "Merging every platform and the sources into ${_out}"
      VERBATIM)
    list(APPEND _merged "${_out}")
  endforeach()
endforeach()
add_custom_target(pkm_dist_fmus ALL DEPENDS ${_merged})
add_dependencies(pkm_dist_fmus pkm_platform_win64 pkm_platform_aarch64 pkm_fmus)
