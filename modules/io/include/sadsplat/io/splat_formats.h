#pragma once
/// \file splat_formats.h
/// \brief The compact formats web splat viewers load: `.splat`, `.spz`, PlayCanvas' `.sog` and
/// `.compressed.ply`. They keep only what a viewer draws (no semantic feature, gate, confidence
/// or label): export formats. Every reader checks the values it returns (gaussian_checks.h).
///
/// `.splat` (the 32-byte record of antimatter15's WebGL viewer, read by most web viewers), per
/// Gaussian, little endian: float32 x y z; float32 scale x y z (linear: exp of the log-scale);
/// uint8 r g b a (r = 255 (0.5 + C0 f_dc_0) clamped, a = 255 sigmoid(opacity)); uint8 rotation
/// w x y z (128 + 128 q of the normalised quaternion, clamped). No header: count = size / 32; a
/// 0-byte file is refused. Axes as the PLY (RDF). Lost: SH degrees 1..3. Round trip: positions
/// and scales exact (to float rounding of exp/log), colour and alpha to 1/255 in [0, 1],
/// quaternion components to 1/128.
///
/// `.spz` (Niantic's open format, github.com/nianticlabs/spz): positions 24-bit fixed point,
/// alphas uint8 (255 sigmoid), colours uint8 (127.5 + 0.15 x 255 f_dc), scales uint8
/// (16 (log-scale + 10)), rotations (version 2: x y z bytes; 3 and 4: the largest component's
/// index and the other three as sign + 9 bits), SH rest uint8 (128 + 128 c, coefficient outer and
/// channel inner; 5 significant bits for degree 1, 4 above). Versions 2 and 3 are one gzip stream
/// with a 16-byte header; version 4 a plain 32-byte header, a table of contents and one zstd
/// stream per attribute. **Axes: SPZ stores RUB** (y up, z back); sadsplat's clouds are RDF like
/// the PLY, so y and z are negated, the quaternion becomes (w, x, -y, -z) and the SH coefficients
/// odd in y or z change sign, on writing and on reading. Positions use 12 fractional bits (1/4096,
/// |x| < 2048) as SPZ's own writer, fewer when the scene is larger (stated in the header). Round
/// trip: positions to half a fixed-point step, log-scales to 1/32 inside [-10, 5.9] (clamped
/// outside), alpha to 1/510, f_dc to 0.0131, quaternion components to 0.002, SH to 1/32 (degree 1)
/// and 1/16 (degrees 2, 3) inside [-1, 1] (clamped outside). An alpha byte of 0 or 255 reads as a
/// finite logit (+-5.5). SH degree 4 (version 4) is read without its band 4.
///
/// `.sog` (PlayCanvas' streamed format, version 2: a ZIP of meta.json and lossless WebP images,
/// positions as 16-bit log-encoded values, scales and colours through 256-entry codebooks, SH
/// through a palette): read and written. Axes as the PLY.
///
/// `.compressed.ply` (PlayCanvas/SuperSplat: chunks of 256 Gaussians with min/max ranges, packed
/// 32-bit position, rotation, scale and colour, optional uint8 SH): read only. Axes as the PLY.

#include <pcl/point_cloud.h>

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "sadsplat/common/gaussian_point.h"

namespace sadsplat {
namespace io {

/// \brief What reading a `.splat` changed.
struct SplatFileInfo {
  std::size_t clamped_opacities = 0;  ///< always 0 for .splat (alpha bytes give finite logits)
};

/// \brief Writes `.splat` (atomically).
/// \throws sadsplat::Error when a value is not writable (gaussian_checks.h)
void writeSplat(const std::string& path, const pcl::PointCloud<GaussianPoint>& cloud);
/// \brief Reads `.splat`; SH rest, features, gate and confidence are zero, labels unlabelled.
/// \throws sadsplat::Error when the file is empty, its size not a multiple of 32 or a value is
/// not finite
pcl::PointCloud<GaussianPoint> readSplat(const std::string& path, SplatFileInfo* info = nullptr);

/// \brief How to write `.spz`.
struct SpzWriteOptions {
  int sh_degree = kMaxShDegree;  ///< SH degree kept, 0..3
  /// 3 (gzip, read by every SPZ reader), 4 (zstd, the format's current version) or 2 (x y z
  /// quaternion bytes: what older viewers read, e.g. @mkkellogg/gaussian-splats-3d 0.4.7)
  int version = 3;
  bool antialiased = false;  ///< the header flag: the model was trained with antialiasing
  /// store the cloud's axes as they are instead of RDF -> RUB (the glTF SPZ payload, whose
  /// reader takes the axes as stored: gltf_splats.h)
  bool axes_as_stored = false;
};

/// \brief What an `.spz` file's header says, and what reading it changed.
struct SpzFileInfo {
  int version = 0;
  int sh_degree = 0;           ///< as stored (4 is read without its band 4)
  int fractional_bits = 0;
  bool antialiased = false;    ///< the header's antialiasing flag
  bool extensions = false;     ///< version 4 extension records present (skipped)
  std::size_t num_points = 0;
  std::size_t clamped_opacities = 0;
};

/// \brief Writes `.spz` (atomically) in RUB axes.
/// \throws sadsplat::Error on bad options or values that are not writable
void writeSpz(const std::string& path, const pcl::PointCloud<GaussianPoint>& cloud,
              const SpzWriteOptions& options = {});
/// \brief The bytes writeSpz writes (`path` names the data in errors).
std::vector<std::uint8_t> encodeSpz(const std::string& path,
                                    const pcl::PointCloud<GaussianPoint>& cloud,
                                    const SpzWriteOptions& options = {});
/// \brief Decodes `.spz` bytes as readSpz does (`path` names them in errors); with
/// `axes_as_stored`, the axes are not turned RUB -> RDF.
pcl::PointCloud<GaussianPoint> decodeSpz(const std::string& path, const std::string& bytes,
                                         SpzFileInfo* info = nullptr, bool axes_as_stored = false);
/// \brief Reads `.spz` version 2, 3 or 4 into RDF axes.
/// \throws sadsplat::Error naming the file and the field on a bad header, corrupt or truncated
/// data, a count the data does not match (decompression stops at what the count needs) or a
/// build without zstd for version 4
pcl::PointCloud<GaussianPoint> readSpz(const std::string& path, SpzFileInfo* info = nullptr);

/// \brief What a `.sog` file holds.
struct SogFileInfo {
  int version = 0;
  int sh_bands = 0;
  std::size_t num_points = 0;
  std::size_t clamped_opacities = 0;
};

/// \brief How to write `.sog`.
struct SogWriteOptions {
  /// SH degree kept, 0..3; degrees 1..3 are written (as a palette of one entry per Gaussian) only
  /// for models of at most 65536 Gaussians
  int sh_degree = kMaxShDegree;
};

/// \brief Whether this build reads and writes `.sog` (it needs libwebp).
bool haveSogSupport();
/// \brief Writes PlayCanvas' `.sog` version 2 (atomically): a stored ZIP of meta.json and lossless
/// WebP images, one pixel per Gaussian: positions as 16-bit sign(x) log(1 + |x|) between the
/// per-axis min and max, log-scales and SH-0 colours through 256-entry codebooks (1D k-means),
/// opacity as 8 bits, the quaternion as its three smaller components (see readSog); SH degrees
/// 1..3 as a palette with one entry per Gaussian through a 256-entry codebook (models of up to
/// 65536 Gaussians; larger ones are written with SH degree 0).
/// \throws sadsplat::Error on bad options, values that are not writable or a build without libwebp
void writeSog(const std::string& path, const pcl::PointCloud<GaussianPoint>& cloud,
              const SogWriteOptions& options = {});
/// \brief Reads PlayCanvas' `.sog` (version 2; a ZIP with meta.json and WebP images).
/// \throws sadsplat::Error naming the file and the entry or field that is wrong, or "not
/// supported" for version 1 or a build without libwebp
pcl::PointCloud<GaussianPoint> readSog(const std::string& path, SogFileInfo* info = nullptr);

/// \brief What a `.compressed.ply` holds.
struct CompressedPlyInfo {
  std::size_t chunks = 0;
  int sh_degree = 0;
  std::size_t clamped_opacities = 0;
};

/// \brief Whether the PLY file at `path` is PlayCanvas' compressed layout (reads its header).
bool isCompressedPly(const std::string& path);
/// \brief Reads PlayCanvas' `.compressed.ply`.
/// \throws sadsplat::Error naming the file, element and property that do not match the layout
pcl::PointCloud<GaussianPoint> readCompressedPly(const std::string& path,
                                                 CompressedPlyInfo* info = nullptr);

}  // namespace io
}  // namespace sadsplat
