# `cmake --install build --prefix P`: the CLI, the module libraries, their public headers and a
# CMake package (lib/cmake/sadsplat: sadsplatConfig.cmake, version file, exported targets
# sadsplat::common, ::io, ::gaussians, ...). `cpack -G DEB` (in build/) packs the same files.
include(CMakePackageConfigHelpers)

get_property(_sadsplat_modules GLOBAL PROPERTY SADSPLAT_MODULE_TARGETS)
install(TARGETS ${_sadsplat_modules} EXPORT sadsplatTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
        INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(TARGETS sadsplat RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})

set(SADSPLAT_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/sadsplat)
install(EXPORT sadsplatTargets NAMESPACE sadsplat:: DESTINATION ${SADSPLAT_CMAKE_DIR})
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/sadsplatConfig.cmake.in
                              ${PROJECT_BINARY_DIR}/sadsplatConfig.cmake
                              INSTALL_DESTINATION ${SADSPLAT_CMAKE_DIR})
write_basic_package_version_file(${PROJECT_BINARY_DIR}/sadsplatConfigVersion.cmake
                                 COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/sadsplatConfig.cmake
              ${PROJECT_BINARY_DIR}/sadsplatConfigVersion.cmake
              ${PROJECT_SOURCE_DIR}/cmake/SadsplatImportedDeps.cmake
        DESTINATION ${SADSPLAT_CMAKE_DIR})
install(FILES ${PROJECT_SOURCE_DIR}/README.md DESTINATION ${CMAKE_INSTALL_DOCDIR})
install(DIRECTORY ${PROJECT_SOURCE_DIR}/examples/ DESTINATION ${CMAKE_INSTALL_DOCDIR}/examples)

# --- Debian package -------------------------------------------------------------------------
set(CPACK_PACKAGE_NAME sadsplat)
set(CPACK_PACKAGE_VENDOR "sadsplat developers")
set(CPACK_PACKAGE_CONTACT "sadsplat developers <sadsplat@localhost>")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY
    "Compact semantic 3D Gaussian Splatting for aerial scenes, as PCL point clouds")
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION science)
# The libraries are static and the package config finds LibTorch, PCL, Eigen, JSON (and OpenCV,
# VTK when built with them) on the user's machine: the -dev packages are the dependencies.
set(_sadsplat_deb_depends
    "libtorch-dev, libpcl-dev, libflann-dev, liblz4-dev, libeigen3-dev, libboost-dev, nlohmann-json3-dev, zlib1g-dev")
if(SADSPLAT_HAVE_OPENCV)
  string(APPEND _sadsplat_deb_depends ", libopencv-dev")
endif()
if(SADSPLAT_HAVE_VIZ)
  string(APPEND _sadsplat_deb_depends ", libvtk9-dev")
endif()
if(SADSPLAT_HAVE_OPEN3D)
  string(APPEND _sadsplat_deb_depends ", libopen3d-dev")
endif()
set(CPACK_DEBIAN_PACKAGE_DEPENDS "${_sadsplat_deb_depends}")
set(CPACK_GENERATOR DEB)
include(CPack)
