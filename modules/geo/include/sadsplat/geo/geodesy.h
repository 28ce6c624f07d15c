#pragma once
/// \file geodesy.h
/// \brief WGS84 geodesy for georeferencing: local east-north-up metres (exact through ECEF),
/// the UTM zone of a position, and the robust similarity fit of a reconstruction to GPS or
/// ground control. The types (GeoPosition, Similarity, Georeference) and their files are io's.

#include <array>
#include <vector>

#include "sadsplat/io/georeference.h"

namespace sadsplat {
namespace geo {

using io::GeoPosition;
using io::Similarity;
/// io::utmEpsg: the zone numbering that georeference.json's epsg_utm field is checked against.
using io::utmEpsg;

/// \brief Local east-north-up metres around `origin` (WGS84 ellipsoid, exact through ECEF).
std::array<double, 3> toEnu(const GeoPosition& p, const GeoPosition& origin);
/// \brief The inverse of toEnu.
GeoPosition fromEnu(const std::array<double, 3>& enu, const GeoPosition& origin);
/// \brief Earth-centred, Earth-fixed (WGS84) metres of a position.
std::array<double, 3> ecefOf(const GeoPosition& p);
/// \brief The 4 x 4 matrix (column-major, as 3D Tiles' `transform`) that takes local
/// east-north-up metres around `origin` to ECEF: columns east, north, up and the origin.
std::array<double, 16> enuToEcefMatrix(const GeoPosition& origin);


/// \brief The similarity from `from` to `to` (point pairs) with the least squared error (Umeyama
/// 1991), robust to outliers: RANSAC over triples, inliers within `inlier_metres` of their target,
/// refit on the largest inlier set. When no 3 pairs agree within `inlier_metres` (no consensus),
/// the least-squares fit of all pairs.
/// \param[out] inliers if not null, which pairs lie within `inlier_metres` under the returned fit
/// \param[out] consensus if not null, whether the fit is the refit of >= 3 agreeing pairs (false:
///   the fit of all pairs, whose residuals can be far above `inlier_metres`)
/// \throws sadsplat::Error when there are fewer than 3 pairs or they are degenerate
Similarity fitSimilarity(const std::vector<std::array<double, 3>>& from,
                         const std::vector<std::array<double, 3>>& to, double inlier_metres,
                         std::vector<bool>* inliers = nullptr, bool* consensus = nullptr);

}  // namespace geo
}  // namespace sadsplat
