# Run at build time (cmake -P) by the abuopt_build_info target (common/CMakeLists.txt): writes
# OUTPUT (a C++ source with the abuopt version and the git commit of SOURCE_DIR) only when its text
# changes, so a new commit relinks abuopt but an unchanged tree rebuilds nothing.
# Inputs: SOURCE_DIR, OUTPUT, VERSION. The commit is `git describe --always --dirty --tags`
# ("1ab36e3", "v0.1.0-3-g1ab36e3-dirty"), or "unknown" outside a git checkout or without git.
set(ABUOPT_GIT_COMMIT "unknown")
find_program(_abuopt_git git)
if(_abuopt_git)
  execute_process(COMMAND ${_abuopt_git} -C ${SOURCE_DIR} describe --always --dirty --tags
                  OUTPUT_VARIABLE _commit RESULT_VARIABLE _rc OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
  if(_rc EQUAL 0 AND NOT _commit STREQUAL "")
    set(ABUOPT_GIT_COMMIT "${_commit}")
  endif()
endif()
set(ABUOPT_VERSION "${VERSION}")
configure_file(${CMAKE_CURRENT_LIST_DIR}/build_info.cpp.in ${OUTPUT} @ONLY)
