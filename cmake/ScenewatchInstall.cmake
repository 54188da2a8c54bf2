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
# Every module scenewatch_add_module made (a new one is installed and exported without a word here).
get_property(scenewatch_modules GLOBAL PROPERTY SCENEWATCH_MODULES)

# --- runtime ---------------------------------------------------------------------------------
install(TARGETS scenewatchd scenewatch scenewatch-sim RUNTIME DESTINATION bin COMPONENT runtime)
# The ROS 2 bridge, when Cyclone DDS was found (apps/scenewatch-ros).
if(TARGET scenewatch-ros)
  install(TARGETS scenewatch-ros RUNTIME DESTINATION bin COMPONENT runtime)
endif()
install(DIRECTORY ${PROJECT_SOURCE_DIR}/sample_clouds/scenarios/ DESTINATION share/scenewatch/scenarios
        COMPONENT runtime)
# The wire protocol, for clients in other languages (docs/protocol.md: its compatibility rules).
install(FILES ${PROJECT_SOURCE_DIR}/proto/scenewatch.proto DESTINATION share/scenewatch/proto COMPONENT runtime)
install(FILES ${PROJECT_SOURCE_DIR}/README.md ${PROJECT_SOURCE_DIR}/CHANGELOG.md ${PROJECT_SOURCE_DIR}/docs/protocol.md
        DESTINATION share/doc/scenewatch COMPONENT runtime)
# The README is a door to docs/: its pages and pictures go beside it, so its links resolve on a
# robot too (share/doc/scenewatch/docs/events.md, ...).
install(DIRECTORY ${PROJECT_SOURCE_DIR}/docs/ DESTINATION share/doc/scenewatch/docs COMPONENT runtime
        FILES_MATCHING PATTERN "*.md" PATTERN "*.png")
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
  # One staging folder per destination: installs into two prefixes at once (a test and cpack) do
  # not write each other's unit.
  string(MD5 scenewatch_key "$ENV{DESTDIR}${CMAKE_INSTALL_PREFIX}")
  configure_file("${scenewatch_unit_template}" "${scenewatch_unit_staging}/${scenewatch_key}/scenewatchd.service" @ONLY)
  file(INSTALL "${scenewatch_unit_staging}/${scenewatch_key}/scenewatchd.service" DESTINATION "${scenewatch_units}")
]] COMPONENT runtime)

# --- python ----------------------------------------------------------------------------------
# The package as the build made it (clients/python/CMakeLists.txt), on Debian's python3 path for
# the prefix /usr; for another prefix, PYTHONPATH=PREFIX/lib/python3/dist-packages (or pip install
# build/clients/python, docs/install.md).
install(DIRECTORY ${PROJECT_BINARY_DIR}/clients/python/scenewatch DESTINATION lib/python3/dist-packages
        COMPONENT python FILES_MATCHING PATTERN "*.py" PATTERN "__pycache__" EXCLUDE)
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

# --- Debian packages (CPack DEB; scripts/package) ----------------------------------------------
set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME scenewatch)
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGE_VENDOR scenewatch)
set(CPACK_PACKAGE_CONTACT "scenewatch maintainers <scenewatch@localhost>")
set(CPACK_COMPONENTS_ALL runtime dev python)
set(CPACK_DEB_COMPONENT_INSTALL ON)
# The config and unit have absolute destinations when the prefix is /usr (above): CPack installs
# with DESTDIR into its staging folder and the prefix /usr.
set(CPACK_SET_DESTDIR ON)
set(CPACK_INSTALL_PREFIX /usr)
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION science)
set(CPACK_DEBIAN_PACKAGE_CONTROL_STRICT_PERMISSION ON)

set(CPACK_DEBIAN_RUNTIME_PACKAGE_NAME scenewatch)
# Descriptions: the synopsis, then the long description (CPack indents it).
set(CPACK_DEBIAN_RUNTIME_DESCRIPTION "scenewatch perception service: scenewatchd, its CLI and the scene simulator
scenewatchd keeps a working memory of a scene (an OctoMap background, supporting planes, the \
objects on them, their appearance) and tells planners over TCP what was added, removed or moved. \
It runs as the systemd service scenewatchd.service (user scenewatch, model in /var/lib/scenewatch). \
scenewatchd and scenewatch link CGAL's Shape_detection: they are GPL-3.0-or-later.")
# Depends: what dpkg-shlibdeps finds the programs linked against, and useradd for the user.
set(CPACK_DEBIAN_RUNTIME_PACKAGE_SHLIBDEPS ON)
set(CPACK_DEBIAN_RUNTIME_PACKAGE_DEPENDS "passwd")
set(CPACK_DEBIAN_RUNTIME_PACKAGE_RECOMMENDS "libjs-three")
set(CPACK_DEBIAN_RUNTIME_PACKAGE_SUGGESTS "python3-scenewatch")
# The config files are conffiles: an upgrade keeps the administrator's edits, a purge removes them.
set(scenewatch_conffiles "")
foreach(file ${scenewatch_config_files})
  get_filename_component(name ${file} NAME)
  string(APPEND scenewatch_conffiles "/etc/scenewatch/${name}\n")
endforeach()
file(WRITE ${PROJECT_BINARY_DIR}/packaging/conffiles "${scenewatch_conffiles}")
set(CPACK_DEBIAN_RUNTIME_PACKAGE_CONTROL_EXTRA
    ${PROJECT_SOURCE_DIR}/packaging/debian/postinst ${PROJECT_SOURCE_DIR}/packaging/debian/prerm
    ${PROJECT_SOURCE_DIR}/packaging/debian/postrm ${PROJECT_BINARY_DIR}/packaging/conffiles)

set(CPACK_DEBIAN_DEV_PACKAGE_NAME scenewatch-dev)
set(CPACK_DEBIAN_DEV_PACKAGE_SECTION libdevel)
set(CPACK_DEBIAN_DEV_DESCRIPTION "scenewatch's libraries for C++: headers, static libraries, CMake package
find_package(scenewatch) gives scenewatch::pipeline (WorkingMemory) and the other modules, with \
their Debian dependencies found again. libscenewatch_ontology.a holds CGAL's Shape_detection: \
what links it is GPL-3.0-or-later.")
# The -dev packages of what the exported targets name (cmake/scenewatchDependencies.cmake).
set(CPACK_DEBIAN_DEV_PACKAGE_DEPENDS "cmake (>= 3.22), g++, gcc, libpcl-dev, liboctomap-dev, libopencv-dev, libeigen3-dev, libboost-dev, libcgal-dev, libprotobuf-dev, libyaml-cpp-dev, libsqlite3-dev, nlohmann-json3-dev, robin-map-dev, liblz4-dev, libbz2-dev, libzstd-dev")

set(CPACK_DEBIAN_PYTHON_PACKAGE_NAME python3-scenewatch)
set(CPACK_DEBIAN_PYTHON_PACKAGE_SECTION python)
set(CPACK_DEBIAN_PYTHON_PACKAGE_ARCHITECTURE all)
set(CPACK_DEBIAN_PYTHON_DESCRIPTION "Python client of scenewatchd, the scenewatch perception service
import scenewatch; scenewatch.Client(host, port): one method per call of the protocol, with the \
messages of proto/scenewatch.proto generated at build time (scenewatch.pb).")
set(CPACK_DEBIAN_PYTHON_PACKAGE_DEPENDS "python3, python3-protobuf")
include(CPack)
