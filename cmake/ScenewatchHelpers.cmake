# Common properties of every scenewatch target: C++17, warnings on.
function(scenewatch_target_properties target)
  target_compile_features(${target} PUBLIC cxx_std_17)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wno-unused-parameter)
endfunction()

# scenewatch_app_properties(TARGET): a program of apps/. It knows the project's version and where
# the shipped files are (apps/common/install_layout.h: installed beside it, else the source tree).
function(scenewatch_app_properties target)
  scenewatch_target_properties(${target})
  target_include_directories(${target} PRIVATE ${PROJECT_SOURCE_DIR}/apps/common)
  target_compile_definitions(${target} PRIVATE
    SCENEWATCH_VERSION="${PROJECT_VERSION}"
    SCENEWATCH_SOURCE_CONFIG_DIR="${PROJECT_SOURCE_DIR}/config"
    SCENEWATCH_SOURCE_SCENARIOS_DIR="${PROJECT_SOURCE_DIR}/sample_clouds/scenarios")
endfunction()

# scenewatch_add_module(NAME SOURCES ... DEPS ... PRIVATE_DEPS ...)
# Public headers live in lib/<name>/include/scenewatch/<name>/, sources in lib/<name>/src/.
# Installed (cmake/ScenewatchInstall.cmake), the library is scenewatch::<name> of the CMake package.
function(scenewatch_add_module name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS;PRIVATE_DEPS" ${ARGN})
  add_library(scenewatch_${name} STATIC ${ARG_SOURCES})
  add_library(scenewatch::${name} ALIAS scenewatch_${name})
  target_include_directories(scenewatch_${name} PUBLIC $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>
                                                      $<INSTALL_INTERFACE:include>)
  target_link_libraries(scenewatch_${name} PUBLIC ${ARG_DEPS} PRIVATE ${ARG_PRIVATE_DEPS})
  set_target_properties(scenewatch_${name} PROPERTIES POSITION_INDEPENDENT_CODE ON EXPORT_NAME ${name})
  set_property(GLOBAL APPEND PROPERTY SCENEWATCH_MODULES ${name})
  scenewatch_target_properties(scenewatch_${name})
endfunction()

# scenewatch_add_test(NAME SOURCES ... DEPS ... [PROPERTIES ...]): one GoogleTest executable per
# module; PROPERTIES go to each of its tests (a RESOURCE_LOCK, say).
function(scenewatch_add_test name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS;PROPERTIES" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE ${ARG_DEPS} scenewatch_test_support GTest::gtest_main)
  scenewatch_target_properties(${name})
  gtest_discover_tests(${name} TEST_PREFIX "${name}." DISCOVERY_TIMEOUT 60 PROPERTIES TIMEOUT 600 ${ARG_PROPERTIES})
endfunction()
