# raybench_add_plugin(NAME [NATIVE] [OUTPUT_DIRECTORY DIR] SOURCES...)
#
# Builds a raybench plugin (include/raybench/plugin.h): a MODULE library
# named NAME.so (no "lib" prefix), loaded with
# `raybench run --backend plugin:path/to/NAME.so[:options]`. C and C++
# sources alike (enable the languages in your project()). What it sets:
# - links raybench::plugin (the header; nothing else of raybench);
# - hidden visibility for everything (-fvisibility=hidden, inline functions
#   too, symbols of static libraries linked in: --exclude-libs, and a linker
#   version script: raybench_plugin.map), so the only exported symbol is the
#   entry point raybench_plugin (mark it RAYBENCH_PLUGIN_EXPORT);
# - -O3 in every configuration but Debug (also with no CMAKE_BUILD_TYPE),
#   never -ffast-math (it deletes NaN/Inf handling; add it yourself if you
#   must);
# - undefined symbols fail at link time (-z defs), not when raybench loads it.
# Options:
#   NATIVE            also -march=native: for the machine it is built on, as
#                     raybench's own kernels are unless configured with
#                     -DRAYBENCH_NATIVE=OFF (a fair comparison wants both alike)
#   OUTPUT_DIRECTORY  where NAME.so goes (default: CMAKE_CURRENT_BINARY_DIR)
# NAME is a normal CMake target: add include directories, libraries and
# definitions to it as usual.
function(raybench_add_plugin name)
  cmake_parse_arguments(PARSE_ARGV 1 arg "NATIVE" "OUTPUT_DIRECTORY" "")
  set(_raybench_plugin_map ${CMAKE_CURRENT_FUNCTION_LIST_DIR}/raybench_plugin.map)
  if(NOT arg_UNPARSED_ARGUMENTS)
    message(FATAL_ERROR "raybench_add_plugin(${name}): no source files")
  endif()
  add_library(${name} MODULE ${arg_UNPARSED_ARGUMENTS})
  target_link_libraries(${name} PRIVATE raybench::plugin)
  set_target_properties(${name} PROPERTIES
    PREFIX ""
    C_VISIBILITY_PRESET hidden
    CXX_VISIBILITY_PRESET hidden
    VISIBILITY_INLINES_HIDDEN ON
    POSITION_INDEPENDENT_CODE ON)
  if(arg_OUTPUT_DIRECTORY)
    set_target_properties(${name} PROPERTIES LIBRARY_OUTPUT_DIRECTORY ${arg_OUTPUT_DIRECTORY})
  endif()
  set(gnu_like "$<OR:$<C_COMPILER_ID:GNU,Clang,AppleClang>,$<CXX_COMPILER_ID:GNU,Clang,AppleClang>>")
  target_compile_options(${name} PRIVATE "$<$<AND:${gnu_like},$<NOT:$<CONFIG:Debug>>>:-O3>")
  if(arg_NATIVE)
    target_compile_options(${name} PRIVATE "$<${gnu_like}:-march=native>")
  endif()
  if(CMAKE_SYSTEM_NAME STREQUAL "Linux")
    target_link_options(${name} PRIVATE "LINKER:-z,defs" "LINKER:--exclude-libs,ALL"
      "LINKER:--version-script=${_raybench_plugin_map}")
    set_property(TARGET ${name} APPEND PROPERTY LINK_DEPENDS ${_raybench_plugin_map})
  endif()
endfunction()
