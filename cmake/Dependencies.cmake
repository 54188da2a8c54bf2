# All third-party packages come from Debian. Each is wrapped in one target so that modules link
# what they use and nothing else.
find_package(Eigen3 3.3 REQUIRED NO_MODULE)
find_package(Threads REQUIRED)
find_package(Boost 1.74 REQUIRED)

# PCL: find_package(PCL) appends VTK, Qt, OpenNI and every other optional dependency to
# PCL_LIBRARIES. We link only the component libraries we use, so binaries do not drag VTK in.
find_package(PCL 1.12 REQUIRED COMPONENTS common io search kdtree filters sample_consensus segmentation octree features)
add_library(scenewatch_pcl INTERFACE)
target_include_directories(scenewatch_pcl SYSTEM INTERFACE ${PCL_INCLUDE_DIRS})
target_link_libraries(scenewatch_pcl INTERFACE
  ${PCL_COMMON_LIBRARIES} ${PCL_IO_LIBRARIES} ${PCL_SEARCH_LIBRARIES} ${PCL_KDTREE_LIBRARIES}
  ${PCL_FILTERS_LIBRARIES} ${PCL_SAMPLE_CONSENSUS_LIBRARIES} ${PCL_SEGMENTATION_LIBRARIES}
  ${PCL_OCTREE_LIBRARIES} ${PCL_FEATURES_LIBRARIES} Eigen3::Eigen)
add_library(scenewatch::pcl ALIAS scenewatch_pcl)

find_package(octomap 1.9 REQUIRED)
add_library(scenewatch_octomap INTERFACE)
target_include_directories(scenewatch_octomap SYSTEM INTERFACE ${OCTOMAP_INCLUDE_DIRS})
target_link_libraries(scenewatch_octomap INTERFACE ${OCTOMAP_LIBRARIES})
add_library(scenewatch::octomap ALIAS scenewatch_octomap)

# CGAL 5 is header-only (Debian: libcgal-dev, which pulls GMP and MPFR). Only lib/ontology links it,
# and only src/efficient_ransac.cpp includes it. Its Shape_detection package is GPL-3.0-or-later.
set(CGAL_DO_NOT_WARN_ABOUT_CMAKE_BUILD_TYPE TRUE)
find_package(CGAL 5 REQUIRED)
add_library(scenewatch_cgal INTERFACE)
target_link_libraries(scenewatch_cgal INTERFACE CGAL::CGAL)
add_library(scenewatch::cgal ALIAS scenewatch_cgal)

find_package(OpenCV 4 REQUIRED COMPONENTS core imgproc imgcodecs)
add_library(scenewatch_opencv INTERFACE)
target_include_directories(scenewatch_opencv SYSTEM INTERFACE ${OpenCV_INCLUDE_DIRS})
target_link_libraries(scenewatch_opencv INTERFACE opencv_core opencv_imgproc opencv_imgcodecs)
add_library(scenewatch::opencv ALIAS scenewatch_opencv)

find_package(Protobuf 3 REQUIRED)
find_package(yaml-cpp REQUIRED)
# The ontology's store (lib/ontology/src/class_store.cpp); Debian: libsqlite3-dev.
find_package(SQLite3 REQUIRED)
find_package(nlohmann_json 3 REQUIRED)
find_package(CLI11 REQUIRED)
find_package(tsl-robin-map REQUIRED)

if(SCENEWATCH_BUILD_TESTS)
  find_package(GTest REQUIRED)
  include(GoogleTest)
endif()
if(SCENEWATCH_BUILD_BENCHMARKS)
  find_package(benchmark REQUIRED)
endif()
