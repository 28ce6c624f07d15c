# Finds sadsplat's dependencies and defines imported targets for them.
#
# PCL is found by hand, not through Debian's PCLConfig.cmake: that file drags in VTK and MPI
# even for PCL's non-I/O libraries, and the GPU machine has neither. Only the libraries
# sadsplat uses are looked up: common, kdtree, search, octree, filters, sample_consensus
# (+ FLANN) always, io (+ io_ply) when SADSPLAT_WITH_VTK is on.

find_package(Eigen3 3.3 REQUIRED NO_MODULE)
find_package(Boost REQUIRED)
find_package(Threads REQUIRED)
# zlib: the gzip layer of .spz files.
find_package(ZLIB REQUIRED)
# Optional codecs of the web splat formats: zstd (SPZ version 4) and WebP (PlayCanvas' SOG).
find_path(SADSPLAT_ZSTD_INCLUDE_DIR zstd.h)
find_library(SADSPLAT_ZSTD_LIBRARY NAMES zstd)
if(NOT SADSPLAT_ZSTD_INCLUDE_DIR)
  set(SADSPLAT_ZSTD_LIBRARY "")
endif()
# Optional: libexif reads the photos' GPS positions (the georeference of `sadsplat sfm` / import).
find_path(SADSPLAT_EXIF_INCLUDE_DIR libexif/exif-data.h)
find_library(SADSPLAT_EXIF_LIBRARY NAMES exif)
if(NOT SADSPLAT_EXIF_INCLUDE_DIR)
  set(SADSPLAT_EXIF_LIBRARY "")
endif()
# Optional: GDAL writes the map outputs (GeoTIFF, PNG) and projects to UTM (through PROJ).
find_path(SADSPLAT_GDAL_INCLUDE_DIR gdal_priv.h PATH_SUFFIXES gdal)
find_library(SADSPLAT_GDAL_LIBRARY NAMES gdal)
if(NOT SADSPLAT_GDAL_INCLUDE_DIR)
  set(SADSPLAT_GDAL_LIBRARY "")
endif()
find_path(SADSPLAT_WEBP_INCLUDE_DIR webp/decode.h)
find_library(SADSPLAT_WEBP_LIBRARY NAMES webp)
if(NOT SADSPLAT_WEBP_INCLUDE_DIR)
  set(SADSPLAT_WEBP_LIBRARY "")
endif()

# --- LibTorch and PCL (non-I/O) as the imported targets sadsplat::torch / sadsplat::pcl ---------
# The same file defines them for a project that uses the installed package (sadsplatConfig.cmake).
find_package(Torch REQUIRED)
include(SadsplatImportedDeps)

# --- VTK: the viz module (3D views of Gaussian clouds, training plots) -----------------------
set(SADSPLAT_HAVE_VIZ OFF)
set(SADSPLAT_VTK_COMPONENTS
    CommonCore CommonDataModel CommonColor RenderingCore RenderingOpenGL2 RenderingAnnotation
    RenderingFreeType RenderingContext2D RenderingContextOpenGL2 InteractionStyle ChartsCore
    ViewsContext2D IOImage)
if(SADSPLAT_WITH_VTK)
  find_package(VTK COMPONENTS ${SADSPLAT_VTK_COMPONENTS})
  if(VTK_FOUND)
    set(SADSPLAT_HAVE_VIZ ON)
  else()
    message(FATAL_ERROR "SADSPLAT_WITH_VTK=ON but VTK (${SADSPLAT_VTK_COMPONENTS}) was not found "
                        "(install libvtk9-dev, or configure with -DSADSPLAT_WITH_VTK=OFF)")
  endif()
endif()

# --- Open3D (C++): the interop module ----------------------------------------------------
set(SADSPLAT_HAVE_OPEN3D OFF)
if(SADSPLAT_WITH_OPEN3D STREQUAL "AUTO")
  find_package(Open3D QUIET)
elseif(SADSPLAT_WITH_OPEN3D)
  find_package(Open3D REQUIRED)
endif()
if(Open3D_FOUND AND SADSPLAT_WITH_OPEN3D)
  set(SADSPLAT_HAVE_OPEN3D ON)
endif()

set(SADSPLAT_HAVE_PCL_IO OFF)
if(SADSPLAT_WITH_VTK)
  find_library(SADSPLAT_PCL_io_LIBRARY NAMES pcl_io HINTS ${_pcl_hints}
               PATH_SUFFIXES lib/x86_64-linux-gnu lib)
  find_library(SADSPLAT_PCL_io_ply_LIBRARY NAMES pcl_io_ply HINTS ${_pcl_hints}
               PATH_SUFFIXES lib/x86_64-linux-gnu lib)
  if(SADSPLAT_PCL_io_LIBRARY AND SADSPLAT_PCL_io_ply_LIBRARY)
    # Only the tests link pcl_io (to check that PCL's own readers take sadsplat's files).
    add_library(sadsplat_pcl_io INTERFACE)
    target_link_libraries(sadsplat_pcl_io INTERFACE sadsplat::pcl ${SADSPLAT_PCL_io_LIBRARY}
                                                    ${SADSPLAT_PCL_io_ply_LIBRARY})
    add_library(sadsplat::pcl_io ALIAS sadsplat_pcl_io)
    set(SADSPLAT_HAVE_PCL_IO ON)
  else()
    message(FATAL_ERROR "SADSPLAT_WITH_VTK=ON but pcl_io was not found "
                        "(install libpcl-dev, or configure with -DSADSPLAT_WITH_VTK=OFF)")
  endif()
endif()

# --- OpenCV ---------------------------------------------------------------------------------
set(SADSPLAT_HAVE_OPENCV OFF)
if(SADSPLAT_WITH_OPENCV)
  find_package(OpenCV REQUIRED COMPONENTS core imgproc imgcodecs calib3d)
  set(SADSPLAT_HAVE_OPENCV ON)
endif()

# --- header-only helpers: JSON and CLI ------------------------------------------------------
find_package(nlohmann_json 3.10 REQUIRED)
find_package(CLI11 REQUIRED)

# --- CUDA -----------------------------------------------------------------------------------
# SADSPLAT_COMPILE_CUDA: nvcc is there, the CUDA sources are compiled (CI checks they build).
# SADSPLAT_HAVE_CUDA: LibTorch also has CUDA, so the CUDA backend is linked and usable. Debian's
# LibTorch is CPU-only: there the CUDA sources compile into an object library and stop.
set(SADSPLAT_COMPILE_CUDA OFF)
set(SADSPLAT_HAVE_CUDA OFF)
if(SADSPLAT_WITH_CUDA STREQUAL "AUTO")
  include(CheckLanguage)
  check_language(CUDA)
  if(CMAKE_CUDA_COMPILER)
    set(SADSPLAT_COMPILE_CUDA ON)
  endif()
elseif(SADSPLAT_WITH_CUDA)
  set(SADSPLAT_COMPILE_CUDA ON)
endif()
if(SADSPLAT_COMPILE_CUDA)
  if(NOT DEFINED CMAKE_CUDA_ARCHITECTURES)
    set(CMAKE_CUDA_ARCHITECTURES 90)
  endif()
  # The rasterizer's backward uses TF32 tensor cores (mma.sync m16n8k8): compute capability 8.0+.
  foreach(arch IN LISTS CMAKE_CUDA_ARCHITECTURES)
    string(REGEX MATCH "^[0-9]+" arch_number "${arch}")
    if(arch_number AND arch_number LESS 80)
      message(FATAL_ERROR "CMAKE_CUDA_ARCHITECTURES: '${arch}' is below 80; sadsplat's CUDA "
                          "kernels need compute capability 8.0 or newer (TF32 tensor cores)")
    endif()
  endforeach()
  enable_language(CUDA)
  set(CMAKE_CUDA_STANDARD 17)
  set(CMAKE_CUDA_STANDARD_REQUIRED ON)
  # nvcc flags of every module's kernels.
  set(SADSPLAT_CUDA_FLAGS $<$<COMPILE_LANGUAGE:CUDA>:--expt-relaxed-constexpr -lineinfo>)
  if(TARGET c10_cuda)
    set(SADSPLAT_HAVE_CUDA ON)
  endif()
endif()

# A module's CUDA kernels: sadsplat_add_cuda_sources(target SOURCES a.cu ... INCLUDES dir ...).
# With a CUDA LibTorch they are part of the target. With nvcc but a CPU-only LibTorch they compile
# into an object library nobody links (INCLUDES: the module include folders the kernels need,
# since an object library gets none from the target), so a CPU-only build still sees them build.
# With or without CUDA, the target and the kernels see modules/common/cuda
# (sadsplat/common/cuda_support.h: internal, not installed).
function(sadsplat_add_cuda_sources target)
  cmake_parse_arguments(ARG "" "" "SOURCES;INCLUDES" ${ARGN})
  set(support ${PROJECT_SOURCE_DIR}/modules/common/cuda)
  target_include_directories(${target} PRIVATE $<BUILD_INTERFACE:${support}>)
  if(SADSPLAT_HAVE_CUDA)
    target_sources(${target} PRIVATE ${ARG_SOURCES})
    target_compile_options(${target} PRIVATE ${SADSPLAT_CUDA_FLAGS})
  elseif(SADSPLAT_COMPILE_CUDA)
    # One translation unit that includes every kernel file: each .cu spent most of its 16-21 s
    # parsing LibTorch's headers (the five gaussians kernels: 87 s one by one, 23 s together, 2
    # cores). The files keep their own namespaces, so they compile together; the CUDA build above
    # still compiles each on its own.
    set(combined ${CMAKE_CURRENT_BINARY_DIR}/${target}_cuda_compile_check.cu)
    set(includes "// Generated by sadsplat_add_cuda_sources: the kernels' compile check.\n")
    foreach(source IN LISTS ARG_SOURCES)
      get_filename_component(source ${source} ABSOLUTE)
      string(APPEND includes "#include \"${source}\"\n")
    endforeach()
    file(CONFIGURE OUTPUT ${combined} CONTENT "${includes}")
    add_library(${target}_cuda_compile_check OBJECT ${combined})
    target_include_directories(${target}_cuda_compile_check PRIVATE ${support} ${ARG_INCLUDES})
    target_link_libraries(${target}_cuda_compile_check PRIVATE sadsplat::torch
                          sadsplat::build_flags)
    target_compile_options(${target}_cuda_compile_check PRIVATE ${SADSPLAT_CUDA_FLAGS})
    # Nothing runs these objects: stop at PTX (no ptxas; raster_cuda.cu 54 -> 41 s on 2 cores).
    list(GET CMAKE_CUDA_ARCHITECTURES 0 first_arch)
    string(REGEX REPLACE "-.*" "" first_arch "${first_arch}")
    set_target_properties(${target}_cuda_compile_check PROPERTIES
                          CUDA_ARCHITECTURES "${first_arch}-virtual")
  endif()
endfunction()

# --- OpenMP ---------------------------------------------------------------------------------
# at::parallel_for is a header template: it runs on several threads only in code compiled with
# OpenMP, LibTorch's CPU parallel backend (without it the CPU rasterizer used one core). Not with
# a CUDA LibTorch: the PyTorch wheels bundle their own libgomp, and a second OpenMP runtime in the
# process would fight it for the cores.
set(SADSPLAT_HAVE_OPENMP OFF)
if(NOT SADSPLAT_HAVE_CUDA)
  find_package(OpenMP COMPONENTS CXX)
  if(OpenMP_CXX_FOUND)
    set(SADSPLAT_HAVE_OPENMP ON)
  endif()
endif()
# Modules whose sources call at::parallel_for: sadsplat_link_openmp(target).
function(sadsplat_link_openmp target)
  if(SADSPLAT_HAVE_OPENMP)
    target_link_libraries(${target} PRIVATE OpenMP::OpenMP_CXX)
  endif()
endfunction()

# --- Distributed training (c10d Gloo) ---------------------------------------------------------
# LibTorch's ProcessGroupGloo header includes gloo's own headers (Debian: libgloo-dev); the PyTorch
# wheels ship none, so there the distributed module builds without a backend.
find_path(SADSPLAT_GLOO_INCLUDE_DIR gloo/config.h)
find_file(SADSPLAT_TORCH_GLOO_HEADER torch/csrc/distributed/c10d/ProcessGroupGloo.hpp
          PATHS ${TORCH_INCLUDE_DIRS} NO_DEFAULT_PATH)
set(SADSPLAT_HAVE_GLOO OFF)
# Not in a CUDA build: the PyTorch wheels' LibTorch was built without Debian's gloo.
if(SADSPLAT_GLOO_INCLUDE_DIR AND SADSPLAT_TORCH_GLOO_HEADER AND NOT SADSPLAT_HAVE_CUDA)
  set(SADSPLAT_HAVE_GLOO ON)
endif()

# --- Distributed training on GPUs (c10d NCCL) --------------------------------------------------
# A CUDA LibTorch built with USE_C10D_NCCL has ProcessGroupNCCL; its header includes nccl.h, which
# the PyTorch wheels keep in the nvidia-nccl package beside torch (site-packages/nvidia/...).
set(SADSPLAT_HAVE_NCCL OFF)
if(SADSPLAT_HAVE_CUDA)
  find_file(SADSPLAT_TORCH_NCCL_HEADER torch/csrc/distributed/c10d/ProcessGroupNCCL.hpp
            PATHS ${TORCH_INCLUDE_DIRS} NO_DEFAULT_PATH)
  file(GLOB _sadsplat_nccl_hints "${TORCH_INSTALL_PREFIX}/../nvidia/nccl"
       "${TORCH_INSTALL_PREFIX}/../nvidia/cu*")
  find_path(SADSPLAT_NCCL_INCLUDE_DIR nccl.h HINTS ${_sadsplat_nccl_hints}
            ${CUDAToolkit_INCLUDE_DIRS} PATH_SUFFIXES include)
  find_library(SADSPLAT_NCCL_LIBRARY NAMES nccl libnccl.so.2 HINTS ${_sadsplat_nccl_hints}
               PATH_SUFFIXES lib lib64)
  if(SADSPLAT_TORCH_NCCL_HEADER AND SADSPLAT_NCCL_INCLUDE_DIR)
    set(SADSPLAT_HAVE_NCCL ON)
  endif()
endif()

# --- GoogleTest -----------------------------------------------------------------------------
if(SADSPLAT_BUILD_TESTS)
  find_package(GTest REQUIRED)
  include(GoogleTest)
endif()

# Compile definitions every sadsplat target sees, so headers can say what the build has.
add_library(sadsplat_build_flags INTERFACE)
target_compile_definitions(sadsplat_build_flags INTERFACE
  SADSPLAT_HAVE_OPENCV=$<BOOL:${SADSPLAT_HAVE_OPENCV}>
  SADSPLAT_HAVE_PCL_IO=$<BOOL:${SADSPLAT_HAVE_PCL_IO}>
  SADSPLAT_HAVE_CUDA=$<BOOL:${SADSPLAT_HAVE_CUDA}>
  SADSPLAT_HAVE_VIZ=$<BOOL:${SADSPLAT_HAVE_VIZ}>
  SADSPLAT_COMPILE_CUDA=$<BOOL:${SADSPLAT_COMPILE_CUDA}>)
target_compile_options(sadsplat_build_flags INTERFACE
  $<$<COMPILE_LANGUAGE:CXX>:-Wall -Wextra -Wno-unused-parameter>)
# Modules link it as $<BUILD_INTERFACE:...>: a project using the installed package gets neither
# these warnings nor these definitions (no public header reads them).
add_library(sadsplat::build_flags ALIAS sadsplat_build_flags)

# A module library: public headers from include/ (installed to include/), exported as
# sadsplat::<export_name>.
include(GNUInstallDirs)
function(sadsplat_module_target target export_name)
  target_include_directories(${target} PUBLIC
    $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>
    $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
  set_target_properties(${target} PROPERTIES EXPORT_NAME ${export_name})
  set_property(GLOBAL APPEND PROPERTY SADSPLAT_MODULE_TARGETS ${target})
  install(DIRECTORY ${CMAKE_CURRENT_SOURCE_DIR}/include/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
endfunction()
