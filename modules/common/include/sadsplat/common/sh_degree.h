#pragma once
/// \file sh_degree.h
/// \brief The spherical-harmonics coefficient count of a degree: one definition for the point
/// type, the rasterizers (host and CUDA: constexpr functions are callable in device code under
/// nvcc's --expt-relaxed-constexpr, which the build sets) and the file formats. No PCL here, so
/// CUDA sources can include it.

namespace sadsplat {

/// \brief Number of SH coefficients per colour channel for a degree: (degree + 1)^2, i.e.
/// 1, 4, 9 or 16 for degrees 0 to 3.
constexpr int shCoefficientsForDegree(int degree) { return (degree + 1) * (degree + 1); }

}  // namespace sadsplat
