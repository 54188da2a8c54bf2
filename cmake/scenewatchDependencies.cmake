# The Debian packages scenewatch's libraries use, each wrapped in one target (scenewatch::pcl,
# scenewatch::octomap, scenewatch::cgal, scenewatch::opencv) so that modules link what they use and
# nothing else. Included by the build (cmake/Dependencies.cmake) and, installed, by the CMake package
# (scenewatchConfig.cmake), so that a project using find_package(scenewatch) finds the same things
# again. The wrappers are IMPORTED targets: the exported libraries name them, and this file makes
# them on either side.
include(CMakeFindDependencyMacro)

# In the package config a missing dependency makes find_package(scenewatch) fail with its name
# (find_dependency returns from this file); in the build it stops the configure.
macro(scenewatch_find_dependency)
  if(SCENEWATCH_FINDING_PACKAGE)
    find_dependency(${ARGN})
  else()
    find_package(${ARGN} REQUIRED)
  endif()
endmacro()

scenewatch_find_dependency(Eigen3 3.3 NO_MODULE)
scenewatch_find_dependency(Threads)
scenewatch_find_dependency(Boost 1.74)

# PCL's config pulls in VTK, whose CMake config requires the MPI::MPI_C target, and FindMPI can only
# provide it when the C language is enabled (bookworm's VTK 9.1): without it, generating a project
# that links PCL's libraries fails in VTK-targets.cmake. scenewatch's project() enables C for this;
# a project that enabled only C++ gets C enabled here (needs gcc, which g++ brings).
get_property(_scenewatch_languages GLOBAL PROPERTY ENABLED_LANGUAGES)
if(NOT "C" IN_LIST _scenewatch_languages)
  message(STATUS "scenewatch: enabling the C language: PCL's config pulls in VTK, which needs FindMPI's MPI::MPI_C")
  enable_language(C)
endif()
unset(_scenewatch_languages)

# find_package(PCL) appends VTK, Qt, OpenNI and every other optional dependency to PCL_LIBRARIES.
# We link only the component libraries we use, so binaries do not drag VTK in.
scenewatch_find_dependency(PCL 1.12 COMPONENTS common io search kdtree filters sample_consensus segmentation octree features)
if(NOT TARGET scenewatch::pcl)
  add_library(scenewatch::pcl INTERFACE IMPORTED)
  set_target_properties(scenewatch::pcl PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${PCL_INCLUDE_DIRS}")
  target_link_libraries(scenewatch::pcl INTERFACE
    ${PCL_COMMON_LIBRARIES} ${PCL_IO_LIBRARIES} ${PCL_SEARCH_LIBRARIES} ${PCL_KDTREE_LIBRARIES}
    ${PCL_FILTERS_LIBRARIES} ${PCL_SAMPLE_CONSENSUS_LIBRARIES} ${PCL_SEGMENTATION_LIBRARIES}
    ${PCL_OCTREE_LIBRARIES} ${PCL_FEATURES_LIBRARIES} Eigen3::Eigen)
endif()

scenewatch_find_dependency(octomap 1.9)
if(NOT TARGET scenewatch::octomap)
  add_library(scenewatch::octomap INTERFACE IMPORTED)
  set_target_properties(scenewatch::octomap PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${OCTOMAP_INCLUDE_DIRS}")
  target_link_libraries(scenewatch::octomap INTERFACE ${OCTOMAP_LIBRARIES})
endif()

# CGAL 5 is header-only (Debian: libcgal-dev, which pulls GMP and MPFR). Only lib/ontology links it,
# and only src/efficient_ransac.cpp includes it. Its Shape_detection package is GPL-3.0-or-later.
set(CGAL_DO_NOT_WARN_ABOUT_CMAKE_BUILD_TYPE TRUE)
scenewatch_find_dependency(CGAL 5)
if(NOT TARGET scenewatch::cgal)
  add_library(scenewatch::cgal INTERFACE IMPORTED)
  target_link_libraries(scenewatch::cgal INTERFACE CGAL::CGAL)
endif()

scenewatch_find_dependency(OpenCV 4 COMPONENTS core imgproc imgcodecs features2d)
if(NOT TARGET scenewatch::opencv)
  add_library(scenewatch::opencv INTERFACE IMPORTED)
  set_target_properties(scenewatch::opencv PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${OpenCV_INCLUDE_DIRS}")
  target_link_libraries(scenewatch::opencv INTERFACE opencv_core opencv_imgproc opencv_imgcodecs opencv_features2d)
endif()

scenewatch_find_dependency(Protobuf 3)
scenewatch_find_dependency(yaml-cpp)
# The ontology's store (lib/ontology/src/class_store.cpp); Debian: libsqlite3-dev.
scenewatch_find_dependency(SQLite3)
# lib/io's bag reader (src/bag/decompress.cpp): bz2 chunks of ROS 1 bags (Debian: libbz2-dev) and
# zstd chunks of MCAP files (libzstd-dev); lz4 chunks use scenewatch::lz4 below.
scenewatch_find_dependency(BZip2)
scenewatch_find_dependency(zstd)
scenewatch_find_dependency(nlohmann_json 3)
scenewatch_find_dependency(tsl-robin-map)

# lib/foreground's nearest_search.cpp uses FLANN's k-d tree directly (header-only, as PCL ships it);
# its headers reference LZ4 (FLANN's index serialisation), which PCL's own libraries link privately.
find_library(SCENEWATCH_LZ4_LIBRARY NAMES lz4)
if(NOT SCENEWATCH_LZ4_LIBRARY)
  if(SCENEWATCH_FINDING_PACKAGE)
    set(scenewatch_NOT_FOUND_MESSAGE "liblz4 not found (Debian: liblz4-dev)")
    set(scenewatch_FOUND FALSE)
    return()
  endif()
  message(FATAL_ERROR "liblz4 not found (Debian: liblz4-dev)")
endif()
if(NOT TARGET scenewatch::lz4)
  add_library(scenewatch::lz4 UNKNOWN IMPORTED)
  set_target_properties(scenewatch::lz4 PROPERTIES IMPORTED_LOCATION "${SCENEWATCH_LZ4_LIBRARY}")
endif()
