# What `cmake --install build --prefix P` puts in P (docs/install.md):
#   P/bin/raybench
#   P/include/raybench/plugin.h
#   P/share/raybench/suites/procedural.toml, P/share/raybench/gate.toml
#   P/lib/cmake/raybench/  raybenchConfig.cmake, raybenchConfigVersion.cmake,
#                          raybenchTargets.cmake, raybench_add_plugin.cmake,
#                          raybench_plugin.map
# The installed binary finds its share folder relative to itself
# (harness/src/io/default_paths.h) and the package names no path of this
# build: P can be moved. Tests and test-only targets are not installed.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(RAYBENCH_INSTALL_SHAREDIR ${CMAKE_INSTALL_DATADIR}/raybench)
set(RAYBENCH_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/raybench)
# The share folder's place is fixed relative to bin/ (../share/raybench),
# which is where the binary looks.
if(NOT CMAKE_INSTALL_BINDIR STREQUAL "bin" OR NOT CMAKE_INSTALL_DATADIR STREQUAL "share")
  message(WARNING "raybench: an installed raybench finds its suite in <bindir>/../share/raybench; "
                  "CMAKE_INSTALL_BINDIR=${CMAKE_INSTALL_BINDIR} and CMAKE_INSTALL_DATADIR=${CMAKE_INSTALL_DATADIR} break that")
endif()

install(TARGETS raybench EXPORT raybenchTargets RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(TARGETS raybench_plugin EXPORT raybenchTargets)
install(FILES ${PROJECT_SOURCE_DIR}/plugin/include/raybench/plugin.h DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/raybench)
install(FILES ${PROJECT_SOURCE_DIR}/meshes/procedural.toml DESTINATION ${RAYBENCH_INSTALL_SHAREDIR}/suites)
install(FILES ${PROJECT_SOURCE_DIR}/results/gate.toml DESTINATION ${RAYBENCH_INSTALL_SHAREDIR})

install(EXPORT raybenchTargets NAMESPACE raybench:: DESTINATION ${RAYBENCH_INSTALL_CMAKEDIR})
file(STRINGS ${PROJECT_SOURCE_DIR}/plugin/include/raybench/plugin.h _abi REGEX "^#define RAYBENCH_PLUGIN_ABI_VERSION ")
string(REGEX REPLACE ".* ([0-9]+).*" "\\1" RAYBENCH_PLUGIN_ABI_VERSION "${_abi}")
configure_package_config_file(${PROJECT_SOURCE_DIR}/plugin/cmake/raybenchConfig.cmake.in
  ${PROJECT_BINARY_DIR}/package/raybenchConfig.cmake
  INSTALL_DESTINATION ${RAYBENCH_INSTALL_CMAKEDIR}
  PATH_VARS CMAKE_INSTALL_INCLUDEDIR RAYBENCH_INSTALL_SHAREDIR)
write_basic_package_version_file(${PROJECT_BINARY_DIR}/package/raybenchConfigVersion.cmake
  VERSION ${PROJECT_VERSION} COMPATIBILITY SameMajorVersion)
install(FILES
  ${PROJECT_BINARY_DIR}/package/raybenchConfig.cmake
  ${PROJECT_BINARY_DIR}/package/raybenchConfigVersion.cmake
  ${PROJECT_SOURCE_DIR}/plugin/cmake/raybench_add_plugin.cmake
  ${PROJECT_SOURCE_DIR}/plugin/cmake/raybench_plugin.map
  DESTINATION ${RAYBENCH_INSTALL_CMAKEDIR})
