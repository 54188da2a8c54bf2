# All third-party packages come from Debian. What the libraries need is found by
# scenewatchDependencies.cmake, which the installed CMake package includes too; what only the
# programs, tests and benchmarks need follows.
include(${CMAKE_CURRENT_LIST_DIR}/scenewatchDependencies.cmake)
find_package(CLI11 REQUIRED)

if(SCENEWATCH_BUILD_TESTS)
  find_package(GTest REQUIRED)
  include(GoogleTest)
endif()
if(SCENEWATCH_BUILD_BENCHMARKS)
  find_package(benchmark REQUIRED)
endif()
