# SPDX-License-Identifier: BSD-2-Clause
# ctest distribution_source_stamp: what changes from commit to commit (the
# FMU archives' commit and dates) is read when the build runs, so that a
# commit does not make CMake configure again:
# 1. the build's rule that reruns CMake depends on no file under .git/;
# 2. cmake/source_stamp.cmake, run on a throw-away repository, writes the
#    commit and the commit's date (set through GIT_COMMITTER_DATE), leaves
#    the file alone (same modification time) when nothing changed, follows a
#    new commit, takes $SOURCE_DATE_EPOCH over the commit's date, and writes
#    1980-01-01 and no commit outside git.
#   cmake -DBUILD=<build tree> -DSCRIPT=<cmake/source_stamp.cmake> -DWORK=<scratch folder> -P check_source_stamp.cmake
foreach(_rules "${BUILD}/build.ninja" "${BUILD}/CMakeFiles/Makefile.cmake")
  if(EXISTS "${_rules}")
    file(STRINGS "${_rules}" _git_deps REGEX "/\\.git/")
    if(_git_deps)
      message(FATAL_ERROR "${_rules}: CMake reruns when a file under .git/ changes (a commit reconfigures):\n${_git_deps}")
    endif()
  endif()
endforeach()

find_program(GIT git REQUIRED)
file(REMOVE_RECURSE "${WORK}")
file(MAKE_DIRECTORY "${WORK}/repo")
set(_stamp "${WORK}/stamp.json")
function(git)
  execute_process(COMMAND ${CMAKE_COMMAND} -E env "GIT_COMMITTER_DATE=${_date} +0000" "GIT_AUTHOR_DATE=${_date} +0000"
                          "${GIT}" -C "${WORK}/repo" -c user.name=check -c user.email=check@invalid ${ARGN}
                  RESULT_VARIABLE _rc OUTPUT_VARIABLE _out ERROR_VARIABLE _err OUTPUT_STRIP_TRAILING_WHITESPACE)
  if(NOT _rc EQUAL 0)
    message(FATAL_ERROR "git ${ARGN}: ${_err}")
  endif()
  set(git_out "${_out}" PARENT_SCOPE)
endfunction()
# stamp([SOURCE_DATE_EPOCH]): runs the script on the repository; sets epoch, commit, mtime.
function(stamp)
  set(_env)
  if(ARGN)
    set(_env "SOURCE_DATE_EPOCH=${ARGN}")
  else()
    set(_env --unset=SOURCE_DATE_EPOCH)
  endif()
  # GIT_CEILING_DIRECTORIES: the scratch folder lies inside this checkout.
  execute_process(COMMAND ${CMAKE_COMMAND} -E env ${_env} GIT_CEILING_DIRECTORIES=${WORK}
                          ${CMAKE_COMMAND} -DSOURCE=${WORK}/repo -DOUT=${_stamp}
                          -P "${SCRIPT}" RESULT_VARIABLE _rc)
  if(NOT _rc EQUAL 0)
    message(FATAL_ERROR "${SCRIPT} failed: ${_rc}")
  endif()
  file(READ "${_stamp}" _json)
  if(NOT _json MATCHES "^{\"epoch\": ([0-9]+), \"commit\": \"([0-9a-f]*)\"}\n$")
    message(FATAL_ERROR "${_stamp}: not a source stamp: ${_json}")
  endif()
  set(epoch "${CMAKE_MATCH_1}" PARENT_SCOPE)
  set(commit "${CMAKE_MATCH_2}" PARENT_SCOPE)
  file(TIMESTAMP "${_stamp}" _mtime "%s")
  set(mtime "${_mtime}" PARENT_SCOPE)
endfunction()
function(expect what value wanted)
  if(NOT "${value}" STREQUAL "${wanted}")
    message(FATAL_ERROR "${what}: ${value}, expected ${wanted}")
  endif()
endfunction()

stamp()
expect("epoch outside git" "${epoch}" 315532800)
expect("commit outside git" "${commit}" "")

git(init -q)
file(WRITE "${WORK}/repo/a.txt" "one\n")
set(_date 1700000000)
git(add a.txt)
git(commit -q -m one)
git(rev-parse --short=12 HEAD)
set(_first "${git_out}")
stamp()
expect("epoch of the first commit" "${epoch}" 1700000000)
expect("commit" "${commit}" "${_first}")
set(_mtime "${mtime}")
execute_process(COMMAND ${CMAKE_COMMAND} -E sleep 1)  # a rewritten file would have a later time
stamp()
expect("modification time when nothing changed" "${mtime}" "${_mtime}")

file(WRITE "${WORK}/repo/a.txt" "two\n")
set(_date 1700086400)
git(commit -q -a -m two)
git(rev-parse --short=12 HEAD)
stamp()
expect("epoch of the second commit" "${epoch}" 1700086400)
expect("commit" "${commit}" "${git_out}")
stamp(1234567890)
expect("epoch under SOURCE_DATE_EPOCH" "${epoch}" 1234567890)
file(REMOVE_RECURSE "${WORK}")
message(STATUS "the source stamp is read when the build runs, and follows the commits")
