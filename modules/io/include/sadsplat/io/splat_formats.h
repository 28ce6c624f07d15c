#pragma once
/// \file splat_formats.h
/// \brief The compact formats web splat viewers load: `.splat` and `.spz`. Both keep only what
/// a viewer draws (no semantic feature, gate, confidence or label): export formats.
///
/// `.splat` (the 32-byte record of antimatter15's WebGL viewer, read by most web viewers), per
/// Gaussian, little endian: float32 x y z; float32 scale x y z (linear: exp of the log-scale);
/// uint8 r g b a (r = 255 (0.5 + C0 f_dc_0) clamped, a = 255 sigmoid(opacity)); uint8 rotation
/// w x y z (128 + 128 q of the normalised quaternion, clamped). No header: count = size / 32.
/// Lost: SH degrees 1..3. Round trip: positions and scales exact (to float rounding of exp/log),
/// colour and alpha to 1/255 in [0, 1], quaternion components to 1/128.
///
/// `.spz` (Niantic's open format, version 3, gzip): header (magic "NGSP" 0x5053474e, version 3,
/// count, SH degree, fractional bits 12, flags, reserved), then per attribute for all Gaussians:
/// positions 24-bit fixed point (1/4096), alphas uint8 (255 sigmoid), colours uint8
/// (127.5 + 0.15 x 255 f_dc), scales uint8 (16 (log-scale + 10)), rotations 4 bytes (the
/// largest component's index, the other three as sign + 9 bits), SH rest uint8 (128 + 128 c,
/// coefficient outer and channel inner; 5 significant bits for degree 1, 4 above). Coordinates are
/// written as they are (no axis conversion). Round trip: positions to 1/8192 (|x| < 2048),
/// log-scales to 1/32, alpha to 1/510, f_dc to 0.0131, quaternion components to 0.002, SH to 1/32
/// (degree 1) and 1/16 (degrees 2, 3) inside [-1, 1] (clamped outside).

#include <pcl/point_cloud.h>

#include <string>

#include "sadsplat/common/gaussian_point.h"

namespace sadsplat {
namespace io {

/// \brief Writes `.splat` (atomically).
void writeSplat(const std::string& path, const pcl::PointCloud<GaussianPoint>& cloud);
/// \brief Reads `.splat`; SH rest, features, gate and confidence are zero, labels unlabelled.
/// \throws sadsplat::Error when the size is not a multiple of 32 or a value is not finite
pcl::PointCloud<GaussianPoint> readSplat(const std::string& path);

/// \brief Writes `.spz` (atomically) with SH up to `sh_degree` (0..3). Version 3 (default, the
/// format's current one) stores quaternions to 0.002; version 2 (x y z bytes, w derived) is
/// what older viewers read (e.g. @mkkellogg/gaussian-splats-3d 0.4.7), less precise where w is
/// small.
void writeSpz(const std::string& path, const pcl::PointCloud<GaussianPoint>& cloud,
              int sh_degree = 3, int version = 3);
/// \brief Reads `.spz` version 2 (x y z quaternion bytes) or 3 (smallest three).
/// \throws sadsplat::Error naming the file and the field on a bad header, corrupt gzip data, or
/// a size that does not match the count
pcl::PointCloud<GaussianPoint> readSpz(const std::string& path);

}  // namespace io
}  // namespace sadsplat
