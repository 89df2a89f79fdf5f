# The git commit of the source tree, for `sheardiff --version` and every summary.json:
# `git rev-parse --short HEAD`, with "-dirty" if a tracked file differs from HEAD, or "unknown"
# where SOURCE_DIR is not the top of a git checkout (a tarball, an unpacked copy inside another
# repository) or git is missing. Evaluated at every build (the target sheardiff_git_version
# rewrites the generated version.cpp only when the text changes, so an unchanged hash recompiles
# nothing): a binary built from edited sources says "-dirty" even when CMake did not re-run.
#
# Script mode: cmake -DSOURCE_DIR=DIR -P cmake/GitVersion.cmake   (prints the hash; for tests)
#              cmake -DSOURCE_DIR=DIR -DTEMPLATE=IN -DOUTPUT=OUT -DPROJECT_VERSION=V -P ...
#              (writes OUT from IN with @PROJECT_VERSION@ and @SHEARDIFF_GIT_HASH@)

# sheardiff_git_hash(SOURCE_DIR HASH_VAR GIT_DIR_VAR): HASH_VAR as above, GIT_DIR_VAR the
# repository's (or worktree's) .git directory, empty outside a checkout.
function(sheardiff_git_hash source_dir hash_var git_dir_var)
  set(hash "unknown")
  set(git_dir "")
  find_program(SHEARDIFF_GIT_EXECUTABLE git)
  if(SHEARDIFF_GIT_EXECUTABLE)
    execute_process(COMMAND ${SHEARDIFF_GIT_EXECUTABLE} rev-parse --show-toplevel
                    WORKING_DIRECTORY ${source_dir} OUTPUT_VARIABLE top RESULT_VARIABLE rc
                    OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
    if(rc EQUAL 0)
      file(REAL_PATH "${top}" top)
      file(REAL_PATH "${source_dir}" source_real)
    endif()
    if(rc EQUAL 0 AND top STREQUAL source_real)
      execute_process(COMMAND ${SHEARDIFF_GIT_EXECUTABLE} rev-parse --short HEAD
                      WORKING_DIRECTORY ${source_dir} OUTPUT_VARIABLE head RESULT_VARIABLE rc
                      OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
      if(rc EQUAL 0 AND NOT head STREQUAL "")
        set(hash "${head}")
        execute_process(COMMAND ${SHEARDIFF_GIT_EXECUTABLE} status --porcelain
                                --untracked-files=no
                        WORKING_DIRECTORY ${source_dir} OUTPUT_VARIABLE changes RESULT_VARIABLE rc
                        OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
        if(NOT rc EQUAL 0 OR NOT changes STREQUAL "")
          set(hash "${hash}-dirty")
        endif()
        execute_process(COMMAND ${SHEARDIFF_GIT_EXECUTABLE} rev-parse --absolute-git-dir
                        WORKING_DIRECTORY ${source_dir} OUTPUT_VARIABLE git_dir
                        OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
      endif()
    endif()
  endif()
  set(${hash_var} "${hash}" PARENT_SCOPE)
  set(${git_dir_var} "${git_dir}" PARENT_SCOPE)
endfunction()

if(CMAKE_SCRIPT_MODE_FILE STREQUAL CMAKE_CURRENT_LIST_FILE)
  if(NOT DEFINED SOURCE_DIR)
    message(FATAL_ERROR "usage: cmake -DSOURCE_DIR=DIR -P GitVersion.cmake")
  endif()
  sheardiff_git_hash("${SOURCE_DIR}" hash git_dir)
  if(DEFINED OUTPUT)
    set(SHEARDIFF_GIT_HASH "${hash}")
    configure_file("${TEMPLATE}" "${OUTPUT}" @ONLY)
  else()
    execute_process(COMMAND ${CMAKE_COMMAND} -E echo "${hash}")
  endif()
endif()
