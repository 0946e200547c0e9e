# SPDX-License-Identifier: BSD-2-Clause
# Runs a program and checks its exit status and output (cmake -P):
#   -DPROGRAM=<path> -DARGS=<arguments, separated by |> -DEXIT=<expected status>
#   [-DSTDERR=<regex stderr must match>] [-DSTDOUT=<regex stdout must match>]
#   [-DNOT_STDOUT=<regex stdout must not match>] [-DREMOVE=<path> removed first]
#   [-DREAD_ONLY_DIR=<path>: created read-only first; the program then runs
#    through without_privileges.sh, so that it is read-only to root too]
#   [-DFILE=<path> -DFILE_MATCHES=<regex its content must match>]
string(REPLACE "|" ";" args "${ARGS}")
if(DEFINED REMOVE)
  file(REMOVE_RECURSE "${REMOVE}")
endif()
set(runner)
if(DEFINED READ_ONLY_DIR)
  file(REMOVE_RECURSE "${READ_ONLY_DIR}")
  file(MAKE_DIRECTORY "${READ_ONLY_DIR}")
  file(CHMOD "${READ_ONLY_DIR}" PERMISSIONS OWNER_READ OWNER_EXECUTE)
  set(runner "${CMAKE_CURRENT_LIST_DIR}/without_privileges.sh")
endif()
execute_process(COMMAND ${runner} "${PROGRAM}" ${args} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err
                TIMEOUT 300)
message("exit status ${rc}\nstdout:\n${out}\nstderr:\n${err}")
if(DEFINED READ_ONLY_DIR)
  file(CHMOD "${READ_ONLY_DIR}" PERMISSIONS OWNER_READ OWNER_WRITE OWNER_EXECUTE)
endif()
if(NOT rc STREQUAL "${EXIT}")
  message(FATAL_ERROR "exit status ${rc}, expected ${EXIT}")
endif()
if(DEFINED STDERR AND NOT err MATCHES "${STDERR}")
  message(FATAL_ERROR "stderr does not match '${STDERR}'")
endif()
if(DEFINED STDOUT AND NOT out MATCHES "${STDOUT}")
  message(FATAL_ERROR "stdout does not match '${STDOUT}'")
endif()
if(DEFINED NOT_STDOUT AND out MATCHES "${NOT_STDOUT}")
  message(FATAL_ERROR "stdout matches '${NOT_STDOUT}'")
endif()
if(DEFINED FILE)
  file(READ "${FILE}" content)
  if(NOT content MATCHES "${FILE_MATCHES}")
    message(FATAL_ERROR "${FILE} does not match '${FILE_MATCHES}':\n${content}")
  endif()
endif()
