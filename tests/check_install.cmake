# SPDX-License-Identifier: BSD-2-Clause
# ctest distribution_install_consumer: `cmake --install` of this build into
# a temporary prefix, the prefix moved elsewhere (the packages must be
# relocatable), then the outside C project tests/consumer (no C++ enabled)
# configured, built and run against it: find_package(pkm4puu CONFIG) with
# the shared and with the static library, and pkg-config when it is there,
# the shared library and `pkg-config --static` in a fully static link. Each
# program is the documentation's C program (PROGRAM: getting started's code
# block, extracted by the build), whose output must match EXPECT (a regular
# expression).
# With -DMODE=add_subdirectory (ctest distribution_add_subdirectory): the
# consumer adds this source tree with add_subdirectory() instead, builds both
# libraries inside its own build and runs the snippet on each.
#   cmake -DBUILD=... -DSOURCE=... -DWORK=... -DGENERATOR=... -DPROGRAM=... -DEXPECT=... [-DWITH_FMUS=1]
#         [-DMODE=...]
#         -P check_install.cmake
file(REMOVE_RECURSE "${WORK}")
function(run what)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${what} failed (${rc}):\n${out}\n${err}")
  endif()
  message(STATUS "${what}: ok\n${out}")
  set(out "${out}" PARENT_SCOPE)
endfunction()
# run_snippet(what program): runs the C snippet, whose output must match EXPECT.
function(run_snippet what program)
  run("run ${what}" "${program}")
  if(NOT out MATCHES "${EXPECT}")
    message(FATAL_ERROR "${what}: the output does not match '${EXPECT}':\n${out}")
  endif()
endfunction()
if(MODE STREQUAL "add_subdirectory")
  run("configure the consumer with add_subdirectory" ${CMAKE_COMMAND} -S "${SOURCE}/tests/consumer" -B "${WORK}"
      -G "${GENERATOR}" -DCMAKE_BUILD_TYPE=Release "-DPKM4PUU_SOURCE_DIR=${SOURCE}" "-DPKM4PUU_C_PROGRAM=${PROGRAM}" -DPKM_LTO=OFF)
  run("build the consumer with add_subdirectory" ${CMAKE_COMMAND} --build "${WORK}" -j2 --target first_c first_c_static)
  run_snippet("the consumer with add_subdirectory (shared)" "${WORK}/first_c")
  run_snippet("the consumer with add_subdirectory (static)" "${WORK}/first_c_static")
  file(REMOVE_RECURSE "${WORK}")
  return()
endif()
run("install" ${CMAKE_COMMAND} --install "${BUILD}" --prefix "${WORK}/staging")
file(RENAME "${WORK}/staging" "${WORK}/prefix")
set(prefix "${WORK}/prefix")
set(expected include/pkm4puu/pkm.h include/pkm4puu/version.h lib/libpkm.a lib/cmake/pkm4puu/pkm4puuConfig.cmake
    lib/cmake/pkm4puu/pkm4puuConfigVersion.cmake lib/pkgconfig/pkm4puu.pc share/doc/pkm4puu/LICENSE
    share/doc/pkm4puu/licenses/SUNDIALS.txt share/doc/pkm4puu/licenses/Eigen.txt)
if(WITH_FMUS)  # the archives, when the build packs them (it takes Python)
  foreach(v 2 3)
    list(APPEND expected share/pkm4puu/fmi${v}/PKM4PUU.fmu share/pkm4puu/fmi${v}/PKM4PUU_Inverse.fmu)
  endforeach()
endif()
foreach(f IN LISTS expected)
  if(NOT EXISTS "${prefix}/${f}")
    message(FATAL_ERROR "cmake --install did not install ${f}")
  endif()
endforeach()
file(GLOB sonames "${prefix}/lib/libpkm.so.*")
list(LENGTH sonames n)
if(n LESS 2)  # libpkm.so.<ABI> -> libpkm.so.<ABI>.0.0 (pkm.h's PKM_ABI_VERSION)
  message(FATAL_ERROR "libpkm without its SOVERSION link: ${sonames}")
endif()
set(variants shared static)
find_program(PKG_CONFIG pkg-config)
if(PKG_CONFIG)
  list(APPEND variants pkg-config pkg-config-static)
endif()
foreach(name IN LISTS variants)
  set(options)
  if(name MATCHES "^pkg-config")
    list(APPEND options -DUSE_PKG_CONFIG=ON)
  endif()
  if(name MATCHES "static$")
    list(APPEND options -DUSE_STATIC=ON)
  endif()
  set(b "${WORK}/consumer-${name}")
  run("configure the consumer (${name})" ${CMAKE_COMMAND} -S "${SOURCE}/tests/consumer" -B "${b}" -G "${GENERATOR}"
      -DCMAKE_BUILD_TYPE=Release "-DCMAKE_PREFIX_PATH=${prefix}" "-DPKM4PUU_C_PROGRAM=${PROGRAM}" ${options})
  run("build the consumer (${name})" ${CMAKE_COMMAND} --build "${b}")
  # The shared library is found through the consumer's RPATH into the prefix.
  run_snippet("the consumer (${name})" "${b}/first_c")
endforeach()
file(REMOVE_RECURSE "${WORK}")
