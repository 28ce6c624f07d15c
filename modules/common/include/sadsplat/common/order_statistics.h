#pragma once
/// \file order_statistics.h
/// \brief Quantiles and medians of samples, in place (std::nth_element: linear time, the
/// vector's order changed). One definition for the library's robust statistics: the ground under
/// a DSM, the GPS fit's spread, the cloud's and the map's error summaries.

#include <algorithm>
#include <cstddef>
#include <vector>

namespace sadsplat {

/// \brief The q-quantile by nearest rank: the element of rank round(q (n - 1)) (q = 0.5: the
/// upper of the two middle values for an even n); 0 for no samples.
template <typename T>
T quantileInPlace(std::vector<T>& v, double q) {
  if (v.empty()) return T(0);
  const double r = q * static_cast<double>(v.size() - 1) + 0.5;
  const std::size_t k = std::min(v.size() - 1, static_cast<std::size_t>(r > 0 ? r : 0));
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
  return v[k];
}

/// \brief The median as statistics defines it: the mean of the two middle values for an even
/// count; 0 for no samples.
template <typename T>
double medianInPlace(std::vector<T>& v) {
  if (v.empty()) return 0.0;
  const std::size_t n = v.size();
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(n / 2), v.end());
  const double upper = static_cast<double>(v[n / 2]);
  if (n % 2) return upper;
  return 0.5 * (upper + static_cast<double>(*std::max_element(
                            v.begin(), v.begin() + static_cast<std::ptrdiff_t>(n / 2))));
}

}  // namespace sadsplat
