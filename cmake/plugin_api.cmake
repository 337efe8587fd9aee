# The plugin interface as a target: raybench::plugin carries the include
# directory of <raybench/plugin.h>, in the source tree here and in
# <prefix>/include once installed (cmake/install.cmake exports it).
# raybench_add_plugin() is the same function the installed package gives
# users (plugin/cmake/raybench_add_plugin.cmake), so an in-tree plugin can be
# built with exactly the flags a user's gets.
add_library(raybench_plugin INTERFACE)
add_library(raybench::plugin ALIAS raybench_plugin)
set_target_properties(raybench_plugin PROPERTIES EXPORT_NAME plugin)
target_include_directories(raybench_plugin INTERFACE
  $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}/plugin/include>
  $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
include(${PROJECT_SOURCE_DIR}/plugin/cmake/raybench_add_plugin.cmake)
