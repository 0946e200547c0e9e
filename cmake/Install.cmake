# SPDX-License-Identifier: BSD-2-Clause
# `cmake --install`: the C API (include/pkm4puu/pkm.h and version.h, libpkm
# shared and static), a relocatable CMake package (pkm4puuConfig.cmake,
# pkm4puuConfigVersion.cmake, targets pkm4puu::pkm and pkm4puu::pkm_static),
# pkg-config's pkm4puu.pc, the FMUs under share/pkm4puu/fmi2 and fmi3 (those
# built), and the licences under share/doc/pkm4puu/.
include_guard(GLOBAL)
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)
set(PKM_INSTALL_CMAKEDIR "${CMAKE_INSTALL_LIBDIR}/cmake/pkm4puu")
set(PKM_INSTALL_DATADIR "${CMAKE_INSTALL_DATADIR}/pkm4puu")

install(TARGETS pkm pkm_static EXPORT pkm4puuTargets
        RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR}
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR} NAMELINK_COMPONENT Development
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT Development)
install(FILES "${PROJECT_SOURCE_DIR}/include/pkm4puu/pkm.h" "${PROJECT_BINARY_DIR}/include/pkm4puu/version.h"
        DESTINATION "${CMAKE_INSTALL_INCLUDEDIR}/pkm4puu" COMPONENT Development)
install(EXPORT pkm4puuTargets NAMESPACE pkm4puu:: DESTINATION "${PKM_INSTALL_CMAKEDIR}" COMPONENT Development)
configure_package_config_file("${CMAKE_CURRENT_LIST_DIR}/pkm4puuConfig.cmake.in"
                              "${PROJECT_BINARY_DIR}/cmake/pkm4puuConfig.cmake"
                              INSTALL_DESTINATION "${PKM_INSTALL_CMAKEDIR}"
                              PATH_VARS CMAKE_INSTALL_INCLUDEDIR PKM_INSTALL_DATADIR)
# 0.x: a minor release may break the API.
write_basic_package_version_file("${PROJECT_BINARY_DIR}/cmake/pkm4puuConfigVersion.cmake"
                                 COMPATIBILITY SameMinorVersion)
install(FILES "${PROJECT_BINARY_DIR}/cmake/pkm4puuConfig.cmake" "${PROJECT_BINARY_DIR}/cmake/pkm4puuConfigVersion.cmake"
              "${CMAKE_CURRENT_LIST_DIR}/pkm4puuSundials.cmake"
        DESTINATION "${PKM_INSTALL_CMAKEDIR}" COMPONENT Development)
# pkg-config: relative to the .pc file's own place, so the prefix can move.
# Libs.private (`pkg-config --static`): what the static library's users link
# besides (pkm_static's link interface: SUNDIALS' static CVODE by its path,
# the C++ runtime and libm by name).
get_target_property(_pkm_static_libs pkm_static INTERFACE_LINK_LIBRARIES)
set(PKM_PC_LIBS_PRIVATE)
foreach(_l IN LISTS _pkm_static_libs)
  if(_l MATCHES "^\\$<BUILD_INTERFACE:")  # the build tree's own (the version header)
    continue()
  elseif(TARGET ${_l})
    list(APPEND PKM_PC_LIBS_PRIVATE "$<TARGET_LINKER_FILE:${_l}>")
  elseif(IS_ABSOLUTE "${_l}" OR _l MATCHES "^-")
    list(APPEND PKM_PC_LIBS_PRIVATE "${_l}")
  else()
    list(APPEND PKM_PC_LIBS_PRIVATE "-l${_l}")
  endif()
endforeach()
list(JOIN PKM_PC_LIBS_PRIVATE " " PKM_PC_LIBS_PRIVATE)
configure_file("${CMAKE_CURRENT_LIST_DIR}/pkm4puu.pc.in" "${PROJECT_BINARY_DIR}/cmake/pkm4puu.pc.in" @ONLY)
file(GENERATE OUTPUT "${PROJECT_BINARY_DIR}/pkm4puu.pc" INPUT "${PROJECT_BINARY_DIR}/cmake/pkm4puu.pc.in")
install(FILES "${PROJECT_BINARY_DIR}/pkm4puu.pc" DESTINATION "${CMAKE_INSTALL_LIBDIR}/pkgconfig"
        COMPONENT Development)

# The FMUs that this build packs: the merged archives (every platform and
# the sources) under PKM_PLATFORMS, else the host's.
if(Python3_Interpreter_FOUND)
  get_property(_pkm_models GLOBAL PROPERTY PKM_FMU_MODELS)
  foreach(_id IN LISTS _pkm_models)
    if(PKM_PLATFORMS AND NOT CMAKE_CROSSCOMPILING)
      set(_fmi2 "${PROJECT_BINARY_DIR}/dist/fmi2/${_id}.fmu")
      set(_fmi3 "${PROJECT_BINARY_DIR}/dist/fmi3/${_id}.fmu")
    else()
      get_target_property(_fmi2 ${_id} PKM_FMU_ARCHIVE_FMI2)
      get_target_property(_fmi3 ${_id} PKM_FMU_ARCHIVE_FMI3)
    endif()
    install(FILES "${_fmi2}" DESTINATION "${PKM_INSTALL_DATADIR}/fmi2" COMPONENT FMUs)
    install(FILES "${_fmi3}" DESTINATION "${PKM_INSTALL_DATADIR}/fmi3" COMPONENT FMUs)
  endforeach()
endif()

# The licences: the project's, and the notices of what libpkm links
# (SUNDIALS statically, Eigen's compiled templates); the FMUs carry their own.
install(FILES "${PROJECT_SOURCE_DIR}/LICENSE" "${PROJECT_SOURCE_DIR}/CHANGELOG.md"
        DESTINATION "${CMAKE_INSTALL_DATADIR}/doc/pkm4puu")
install(FILES "${PKM_LICENSES_DIR}/SUNDIALS.txt" "${PKM_LICENSES_DIR}/Eigen.txt"
        DESTINATION "${CMAKE_INSTALL_DATADIR}/doc/pkm4puu/licenses")

# The Python wheel (PKM_WHEEL, set by pyproject.toml): component Wheel, with
# destinations relative to the wheel's platlib, inside the package pkm4puu
# that scikit-build-core copies there from python/: libpkm as
# pkm4puu/lib/libpkm.so (pkm.dll, libpkm.dylib: one file, the name
# pkm4puu.locate.LIBRARY; cffi opens it by path) with pkm_cdef.h beside it
# (pkm.h as the binding reads it), the host's FMU archives as pkm4puu/fmus/fmi2|fmi3/, and
# the notices of what libpkm links as pkm4puu/licenses/ (the project's
# LICENSE goes into the wheel's .dist-info; each FMU carries its own). The
# target pkm_wheel builds only these (pyproject.toml's build.targets).
if(PKM_WHEEL)
  set(_pkm_wheel_library "${CMAKE_SHARED_LIBRARY_PREFIX}pkm${CMAKE_SHARED_LIBRARY_SUFFIX}")
  if(WIN32)
    set(_pkm_wheel_library pkm.dll)
  endif()
  install(FILES "$<TARGET_FILE:pkm>" DESTINATION pkm4puu/lib RENAME "${_pkm_wheel_library}" COMPONENT Wheel)
  install(FILES "${PROJECT_BINARY_DIR}/lib/pkm_cdef.h" DESTINATION pkm4puu/lib COMPONENT Wheel)
  install(FILES "${PKM_LICENSES_DIR}/SUNDIALS.txt" "${PKM_LICENSES_DIR}/Eigen.txt"
          DESTINATION pkm4puu/licenses COMPONENT Wheel)
  add_custom_target(pkm_wheel DEPENDS pkm)
  if(NOT Python3_Interpreter_FOUND)
    message(FATAL_ERROR "PKM_WHEEL: the wheel holds the FMU archives, which take a Python to pack (Python3_EXECUTABLE)")
  endif()
  get_property(_pkm_models GLOBAL PROPERTY PKM_FMU_MODELS)
  foreach(_id IN LISTS _pkm_models)
    install(FILES "$<TARGET_PROPERTY:${_id},PKM_FMU_ARCHIVE_FMI2>" DESTINATION pkm4puu/fmus/fmi2 COMPONENT Wheel)
    install(FILES "$<TARGET_PROPERTY:${_id},PKM_FMU_ARCHIVE_FMI3>" DESTINATION pkm4puu/fmus/fmi3 COMPONENT Wheel)
    add_dependencies(pkm_wheel ${_id}_fmu ${_id}_fmu3)
  endforeach()
endif()
