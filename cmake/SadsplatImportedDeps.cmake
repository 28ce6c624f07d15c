# Defines the imported targets sadsplat::torch and sadsplat::pcl. Used by sadsplat's own build
# and by sadsplatConfig.cmake, so that a project using the installed package finds LibTorch and
# PCL on its own machine, the same way.
#
# PCL is found by hand, not through Debian's PCLConfig.cmake: that file drags in VTK and MPI
# even for PCL's non-I/O libraries (and fails unless the project enables language C), and the
# GPU machine has neither. Only the libraries sadsplat uses are looked up: common, kdtree,
# search, octree, filters, sample_consensus (+ FLANN, LZ4). SADSPLAT_PCL_ROOT may name the prefix
# of an unpacked PCL. Expects find_package(Torch) to have run.

if(NOT TARGET sadsplat::torch)
  # TORCH_LIBRARIES carries the whole of libtorch; modules link it PRIVATE unless a header needs it.
  add_library(sadsplat::torch INTERFACE IMPORTED)
  set_target_properties(sadsplat::torch PROPERTIES
    INTERFACE_LINK_LIBRARIES "${TORCH_LIBRARIES}"
    INTERFACE_SYSTEM_INCLUDE_DIRECTORIES "${TORCH_INCLUDE_DIRS}"
    INTERFACE_INCLUDE_DIRECTORIES "${TORCH_INCLUDE_DIRS}")
endif()

if(NOT TARGET sadsplat::pcl)
  find_package(Eigen3 3.3 REQUIRED NO_MODULE)
  find_package(Boost REQUIRED)
  set(_pcl_hints)
  if(SADSPLAT_PCL_ROOT)
    list(APPEND _pcl_hints ${SADSPLAT_PCL_ROOT}/usr ${SADSPLAT_PCL_ROOT})
  endif()
  find_path(SADSPLAT_PCL_INCLUDE_DIR pcl/point_types.h
            HINTS ${_pcl_hints} PATH_SUFFIXES include/pcl-1.13 include/pcl-1.14 include/pcl-1.12
            REQUIRED)
  find_path(SADSPLAT_FLANN_INCLUDE_DIR flann/flann.hpp HINTS ${_pcl_hints} PATH_SUFFIXES include
            REQUIRED)
  find_path(SADSPLAT_LZ4_INCLUDE_DIR lz4.h HINTS ${_pcl_hints} PATH_SUFFIXES include REQUIRED)
  set(_pcl_libs)
  foreach(_lib common kdtree search octree filters sample_consensus)
    find_library(SADSPLAT_PCL_${_lib}_LIBRARY NAMES pcl_${_lib}
                 HINTS ${_pcl_hints} PATH_SUFFIXES lib/x86_64-linux-gnu lib REQUIRED)
    list(APPEND _pcl_libs ${SADSPLAT_PCL_${_lib}_LIBRARY})
  endforeach()
  find_library(SADSPLAT_FLANN_LIBRARY NAMES flann_cpp HINTS ${_pcl_hints}
               PATH_SUFFIXES lib/x86_64-linux-gnu lib REQUIRED)
  # FLANN's headers call LZ4 (index serialisation), so code instantiating KdTreeFLANN needs it.
  find_library(SADSPLAT_LZ4_LIBRARY NAMES lz4 HINTS ${_pcl_hints}
               PATH_SUFFIXES lib/x86_64-linux-gnu lib REQUIRED)
  add_library(sadsplat::pcl INTERFACE IMPORTED)
  set_target_properties(sadsplat::pcl PROPERTIES
    INTERFACE_INCLUDE_DIRECTORIES
      "${SADSPLAT_PCL_INCLUDE_DIR};${SADSPLAT_FLANN_INCLUDE_DIR};${SADSPLAT_LZ4_INCLUDE_DIR}"
    INTERFACE_SYSTEM_INCLUDE_DIRECTORIES
      "${SADSPLAT_PCL_INCLUDE_DIR};${SADSPLAT_FLANN_INCLUDE_DIR};${SADSPLAT_LZ4_INCLUDE_DIR}"
    INTERFACE_LINK_LIBRARIES
      "Eigen3::Eigen;Boost::headers;${_pcl_libs};${SADSPLAT_FLANN_LIBRARY};${SADSPLAT_LZ4_LIBRARY}")
endif()
