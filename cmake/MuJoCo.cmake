# SPDX-License-Identifier: BSD-2-Clause
# MuJoCo's C library from the Python wheel that Python3_EXECUTABLE imports
# (its folder holds include/mujoco/ and libmujoco.so*), for timing MuJoCo in
# C beside this project. Defines the imported target pkm::mujoco when found;
# never required (host builds only).
include_guard(GLOBAL)
if(Python3_Interpreter_FOUND AND NOT CMAKE_CROSSCOMPILING)
  execute_process(COMMAND "${Python3_EXECUTABLE}" -c "import mujoco, os; print(os.path.dirname(mujoco.__file__))"
                  OUTPUT_VARIABLE _pkm_mujoco OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
  if(_pkm_mujoco)
    file(GLOB _pkm_mujoco_lib "${_pkm_mujoco}/libmujoco.so*")
  endif()
  if(_pkm_mujoco_lib AND EXISTS "${_pkm_mujoco}/include/mujoco/mujoco.h")
    list(GET _pkm_mujoco_lib 0 _pkm_mujoco_lib)
    add_library(pkm::mujoco SHARED IMPORTED)
    set_target_properties(pkm::mujoco PROPERTIES IMPORTED_LOCATION "${_pkm_mujoco_lib}"
                                                 INTERFACE_INCLUDE_DIRECTORIES "${_pkm_mujoco}/include")
    message(STATUS "MuJoCo's C library: ${_pkm_mujoco_lib}")
  endif()
endif()
