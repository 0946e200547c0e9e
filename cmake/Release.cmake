# SPDX-License-Identifier: BSD-2-Clause
# `cmake --build build --target release`: build/release/pkm4puu-<version>/
# with the FMUs (merged under PKM_PLATFORMS, else the host's, as its
# MANIFEST.txt says), the wheel, the sdist, the installed C package and
# SHA256SUMS (cmake/make_release.py; ctest distribution_release checks one).
include_guard(GLOBAL)
# Only in this project's own build: a project that adds this one
# (add_subdirectory, FetchContent) keeps the target name `release` for itself.
if(NOT Python3_Interpreter_FOUND OR CMAKE_CROSSCOMPILING OR NOT _pkm_top_level)
  return()
endif()
set(_pkm_release_fmus pkm_fmus)
if(PKM_PLATFORMS)
  list(APPEND _pkm_release_fmus pkm_dist_fmus)
endif()
set(PKM_RELEASE_COMMAND
    Python3::Interpreter ${PROJECT_SOURCE_DIR}/cmake/make_release.py --build ${PROJECT_BINARY_DIR}
    --source ${PROJECT_SOURCE_DIR} --version ${PROJECT_VERSION} --platforms $<IF:$<BOOL:${PKM_PLATFORMS}>,ON,OFF>
    --stamp ${PKM_SOURCE_STAMP})
add_custom_target(release
  COMMAND ${PKM_RELEASE_COMMAND} --out ${PROJECT_BINARY_DIR}/release
  DEPENDS pkm pkm_static ${_pkm_release_fmus} pkm_source_stamp
  COMMENT "Writing the release into ${PROJECT_BINARY_DIR}/release/pkm4puu-${PROJECT_VERSION}"
  USES_TERMINAL VERBATIM)
