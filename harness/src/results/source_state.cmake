# Run at build time (cmake -DSOURCE_DIR=... -DOUTPUT=... -P source_state.cmake):
# writes OUTPUT, a header defining RAYBENCH_BUILT_SOURCE_STATE, the source
# tree's state as results/metadata.cpp's source_state() words it (the commit,
# "-dirty" when a tracked file outside results/ differs, "unknown" outside a
# git work tree). An installed binary records this instead of reading a
# source tree that may be gone. The file is rewritten only when the state
# changes, so an unchanged tree recompiles nothing.
set(state "unknown")
find_program(GIT_EXECUTABLE git)
if(GIT_EXECUTABLE)
  execute_process(COMMAND ${GIT_EXECUTABLE} -C ${SOURCE_DIR} rev-parse HEAD
    OUTPUT_VARIABLE commit OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET RESULT_VARIABLE failed)
  if(NOT failed AND commit)
    set(state "${commit}")
    execute_process(COMMAND ${GIT_EXECUTABLE} -C ${SOURCE_DIR} status --porcelain --untracked-files=no -- . ":(exclude,top)results"
      OUTPUT_VARIABLE changes OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
    if(changes)
      string(APPEND state "-dirty")
    endif()
  endif()
endif()
set(content "// Generated at build time by harness/src/results/source_state.cmake.\n#pragma once\n#define RAYBENCH_BUILT_SOURCE_STATE \"${state}\"\n")
set(old "")
if(EXISTS "${OUTPUT}")
  file(READ "${OUTPUT}" old)
endif()
if(NOT old STREQUAL content)
  file(WRITE "${OUTPUT}" "${content}")
endif()
