# Precompiled headers. Nearly every translation unit parses PCL's point types, nlohmann/json and,
# in the LibTorch modules, ATen (~9 s alone per unity source on the CI's cores); parsing them once
# per kind of target saves a large part of a clean build. A kind is what makes GCC accept or
# reject a precompiled header: the macros the headers test (LibTorch's flags, OpenMP), -fPIC
# against -fPIE, GoogleTest. One small object library per kind (sadsplat_pch_<kind>) compiles the
# header; the targets of that kind reuse it (REUSE_FROM). A target whose flags no kind matches
# (Open3D's ABI macro in interop) gets none: GCC would ignore the header and parse its text
# again (-Winvalid-pch says so), still correct, only slower. Each header is 0.35-0.6 GB and takes
# 30-70 s to make on 2 cores; a clean Release build there took 581 instead of 685 s (compiler
# time 1817 instead of 2104 s, 2026-11-28). The sanitizer build gains nothing and leaves them.
#   sadsplat_precompile_headers(PLAIN targets... TORCH targets... TORCH_OPENMP targets...)
# TORCH: links LibTorch; TORCH_OPENMP: LibTorch and OpenMP (sadsplat_link_openmp). Executables
# and test suites are told apart by their target type and a link to GoogleTest. CMake
# precompiles for C and C++ only (sadsplat has no C sources); a source compiled for another
# instruction set sets SKIP_PRECOMPILE_HEADERS.
option(SADSPLAT_PRECOMPILE_HEADERS "Precompile the third-party headers most sources parse" ON)

set(_sadsplat_pch_plain <pcl/point_types.h> <pcl/point_cloud.h> <nlohmann/json.hpp>)
set(_sadsplat_pch_torch <ATen/ATen.h> ${_sadsplat_pch_plain})

# The object library that compiles the header of one kind (torch: ATen too; omp: OpenMP's flag as
# well; exe: -fPIE as executables are compiled; test: GoogleTest too; levels: the users' own -O).
function(_sadsplat_pch_host host torch omp exe test levels)
  if(TARGET ${host})
    return()
  endif()
  set(source ${CMAKE_BINARY_DIR}/pch/${host}.cpp)
  file(MAKE_DIRECTORY ${CMAKE_BINARY_DIR}/pch)
  file(WRITE ${source}
       "// The precompiled header of one kind of target: cmake/SadsplatPrecompiledHeaders.cmake\n")
  add_library(${host} OBJECT ${source})
  # What sadsplat_common passes on (PCL, the build's definitions), not sadsplat_common itself:
  # it reuses a host too.
  target_link_libraries(${host} PRIVATE sadsplat::pcl sadsplat::build_flags
                                        nlohmann_json::nlohmann_json)
  set(headers ${_sadsplat_pch_plain})
  if(torch)
    target_link_libraries(${host} PRIVATE sadsplat::torch)
    set(headers ${_sadsplat_pch_torch})
  endif()
  if(omp)
    sadsplat_link_openmp(${host})
  endif()
  if(test)
    target_link_libraries(${host} PRIVATE GTest::gtest)
    list(APPEND headers <gtest/gtest.h>)
  endif()
  if(exe)
    set_target_properties(${host} PROPERTIES POSITION_INDEPENDENT_CODE OFF)
    target_compile_options(${host} PRIVATE -fPIE)
  endif()
  if(levels)
    target_compile_options(${host} PRIVATE ${levels})
  endif()
  target_precompile_headers(${host} PRIVATE ${headers})
endfunction()

function(_sadsplat_pch_reuse target torch omp)
  get_target_property(type ${target} TYPE)
  set(exe OFF)
  set(test OFF)
  set(kind plain)
  if(torch)
    set(kind torch)
  endif()
  if(omp)
    string(APPEND kind _omp)
  endif()
  if(type STREQUAL "EXECUTABLE")
    set(exe ON)
    get_target_property(links ${target} LINK_LIBRARIES)
    if("GTest::gtest" IN_LIST links)
      set(test ON)
      string(APPEND kind _test)
    else()
      string(APPEND kind _exe)
    endif()
  else()
    string(APPEND kind _lib)
  endif()
  # A target's own optimisation level (the sanitizer build's -O1 for gaussians) changes the
  # predefined macros (__OPTIMIZE__, __NO_INLINE__): part of the kind.
  get_target_property(options ${target} COMPILE_OPTIONS)
  set(levels "")
  foreach(option IN LISTS options)
    if(option MATCHES "^-O[0-3sg]?$")
      list(APPEND levels ${option})
      string(REPLACE "-" "_" suffix ${option})
      string(APPEND kind ${suffix})
    endif()
  endforeach()
  _sadsplat_pch_host(sadsplat_pch_${kind} ${torch} ${omp} ${exe} ${test} "${levels}")
  target_precompile_headers(${target} REUSE_FROM sadsplat_pch_${kind})
  target_compile_options(${target} PRIVATE $<$<COMPILE_LANGUAGE:CXX>:-Winvalid-pch>)
endfunction()

function(sadsplat_precompile_headers)
  if(NOT SADSPLAT_PRECOMPILE_HEADERS OR NOT CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
    return()
  endif()
  cmake_parse_arguments(ARG "" "" "PLAIN;TORCH;TORCH_OPENMP" ${ARGN})
  # Each group with its (torch, omp) flags.
  foreach(group IN ITEMS "PLAIN;OFF;OFF" "TORCH;ON;OFF" "TORCH_OPENMP;ON;ON")
    list(GET group 0 name)
    list(GET group 1 torch)
    list(GET group 2 omp)
    foreach(target IN LISTS ARG_${name})
      if(TARGET ${target})
        _sadsplat_pch_reuse(${target} ${torch} ${omp})
      endif()
    endforeach()
  endforeach()
endfunction()
