# install(): the programs, the shipped config, the simulator's scenarios, the proto file, the Python
# client, and the libraries with their headers as the CMake package `scenewatch`
# (find_package(scenewatch): scenewatch::pipeline and the other modules). Three components, which
# CPack makes into three Debian packages (scripts/package):
#   runtime -> scenewatch           programs, config in /etc/scenewatch, systemd unit, scenarios, proto
#   dev     -> scenewatch-dev       headers, static libraries, CMake package
#   python  -> python3-scenewatch   the Python client with its generated scenewatch_pb2.py
# The paths bin/ and share/scenewatch/ are what apps/common/install_layout.h looks for.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

# Installing takes what the build made: scripts/package builds what it packages, and neither it
# nor `cmake --install` builds the tests and benchmarks first.
set(CMAKE_SKIP_INSTALL_ALL_DEPENDENCY ON)

set(scenewatch_cmake_dir ${CMAKE_INSTALL_LIBDIR}/cmake/scenewatch)
set(scenewatch_modules core io background segmentation ontology surprise change foreground sim pipeline service)

# --- runtime ---------------------------------------------------------------------------------
install(TARGETS scenewatchd scenewatch scenewatch-sim RUNTIME DESTINATION bin COMPONENT runtime)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/sample_clouds/scenarios/ DESTINATION share/scenewatch/scenarios
        COMPONENT runtime)
# The wire protocol, for clients in other languages (docs/protocol.md: its compatibility rules).
install(FILES ${PROJECT_SOURCE_DIR}/proto/scenewatch.proto DESTINATION share/scenewatch/proto COMPONENT runtime)
install(FILES ${PROJECT_SOURCE_DIR}/README.md ${PROJECT_SOURCE_DIR}/CHANGELOG.md ${PROJECT_SOURCE_DIR}/docs/protocol.md
        DESTINATION share/doc/scenewatch COMPONENT runtime)
install(FILES ${PROJECT_SOURCE_DIR}/packaging/copyright DESTINATION share/doc/scenewatch COMPONENT runtime)
# The live view's page is compiled into scenewatchd (lib/service embeds web/live_view.html); its one
# asset, three.js, is Debian's libjs-three (server.http_three_js), which the package recommends.

# The config and the systemd unit, placed when installing: /etc/scenewatch and /lib/systemd/system
# for the prefixes /usr and / (GNUInstallDirs' rule for sysconfdir, and Debian's place for units),
# PREFIX/etc/scenewatch and PREFIX/lib/systemd/system for any other prefix. The unit names the
# installed daemon and config, so it is written then too.
file(GLOB scenewatch_config_files CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/config/*.yaml)
install(CODE "
  set(scenewatch_config_files \"${scenewatch_config_files}\")
  set(scenewatch_unit_template \"${PROJECT_SOURCE_DIR}/packaging/scenewatchd.service.in\")
  set(scenewatch_unit_staging \"${PROJECT_BINARY_DIR}/packaging\")" COMPONENT runtime)
install(CODE [[
  if(CMAKE_INSTALL_PREFIX STREQUAL "/usr" OR CMAKE_INSTALL_PREFIX STREQUAL "/")
    set(scenewatch_etc "/etc/scenewatch")
    set(scenewatch_units "/lib/systemd/system")
  else()
    set(scenewatch_etc "${CMAKE_INSTALL_PREFIX}/etc/scenewatch")
    set(scenewatch_units "${CMAKE_INSTALL_PREFIX}/lib/systemd/system")
  endif()
  file(INSTALL ${scenewatch_config_files} DESTINATION "${scenewatch_etc}")
  string(REGEX REPLACE "/$" "" scenewatch_bin "${CMAKE_INSTALL_PREFIX}/bin")
  configure_file("${scenewatch_unit_template}" "${scenewatch_unit_staging}/scenewatchd.service" @ONLY)
  file(INSTALL "${scenewatch_unit_staging}/scenewatchd.service" DESTINATION "${scenewatch_units}")
]] COMPONENT runtime)

# --- python ----------------------------------------------------------------------------------
# The package as the build made it (clients/python/CMakeLists.txt), on Debian's python3 path for
# the prefix /usr; for another prefix, PYTHONPATH=PREFIX/lib/python3/dist-packages (or pip install
# build/clients/python, README "Install on a robot").
install(DIRECTORY ${PROJECT_BINARY_DIR}/clients/python/scenewatch DESTINATION lib/python3/dist-packages
        COMPONENT python FILES_MATCHING PATTERN "*.py")
install(FILES ${PROJECT_SOURCE_DIR}/packaging/copyright DESTINATION share/doc/python3-scenewatch COMPONENT python)

# --- dev -------------------------------------------------------------------------------------
set(scenewatch_library_targets scenewatch_proto)
foreach(module ${scenewatch_modules})
  list(APPEND scenewatch_library_targets scenewatch_${module})
  install(DIRECTORY ${PROJECT_SOURCE_DIR}/lib/${module}/include/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR} COMPONENT dev)
endforeach()
install(TARGETS ${scenewatch_library_targets} EXPORT scenewatchTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT dev)
install(FILES ${PROJECT_BINARY_DIR}/proto/scenewatch.pb.h DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/scenewatch/proto
        COMPONENT dev)
install(EXPORT scenewatchTargets NAMESPACE scenewatch:: DESTINATION ${scenewatch_cmake_dir} COMPONENT dev)
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/scenewatchConfig.cmake.in
                              ${PROJECT_BINARY_DIR}/scenewatchConfig.cmake INSTALL_DESTINATION ${scenewatch_cmake_dir})
# 0.x: a new minor version may change the C++ API (CHANGELOG.md says what changed).
write_basic_package_version_file(${PROJECT_BINARY_DIR}/scenewatchConfigVersion.cmake COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/scenewatchConfig.cmake ${PROJECT_BINARY_DIR}/scenewatchConfigVersion.cmake
              ${PROJECT_SOURCE_DIR}/cmake/scenewatchDependencies.cmake
        DESTINATION ${scenewatch_cmake_dir} COMPONENT dev)
install(FILES ${PROJECT_SOURCE_DIR}/packaging/copyright DESTINATION share/doc/scenewatch-dev COMPONENT dev)
