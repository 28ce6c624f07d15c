#pragma once
/// \file gltf_splats.h
/// \brief Gaussians as glTF 2.0 binary (`.glb`) with `KHR_gaussian_splatting`, the Khronos
/// extension web-GIS clients (CesiumJS) render, SPZ-compressed by
/// `KHR_gaussian_splatting_compression_spz_2` or in plain accessors, and every splat's class as
/// an `EXT_mesh_features` feature ID whose names are an `EXT_structural_metadata` property table.
///
/// One mesh, one `POINTS` primitive, one node without a transform. The cloud is given in glTF
/// axes (y up; 3D Tiles turns y-up content to its z-up frame). Attributes:
/// - `POSITION` VEC3 float (min / max); `COLOR_0` VEC4 unsigned byte normalised: 0.5 + C0 f_dc
///   and the opacity (the fallback a points renderer draws);
/// - `KHR_gaussian_splatting:ROTATION` VEC4 float, unit quaternion (x, y, z, w);
///   `KHR_gaussian_splatting:SCALE` VEC3 float, **linear** (exp of the log-scale: what the SPZ
///   extension's mapping, CesiumJS and splat-transform's writer use; one draft of the base text
///   says log-space); `KHR_gaussian_splatting:OPACITY` SCALAR float, sigmoid of the logit;
///   `KHR_gaussian_splatting:SH_DEGREE_0_COEF_0` VEC3 float (f_dc) and `SH_DEGREE_l_COEF_n` for
///   l = 1..sh_degree (r, g, b of coefficient n; 3DGS's basis). Extension object: kernel
///   `ellipse`, colorSpace `srgb_rec709_display`, sortingMethod `cameraDistance`, projection
///   `perspective`.
/// - SPZ (default): the accessors of POSITION, COLOR_0, SCALE, ROTATION and SH degrees >= 1 have
///   no bufferView; their values are the SPZ (version 3, gzip) stream in the bufferView named by
///   `KHR_gaussian_splatting_compression_spz_2`, required by `extensionsRequired`. The payload's
///   axes are the glTF axes **as stored** (SPZ's own RDF/RUB turn not applied): CesiumJS 1.145
///   decodes it with coordinateSystem UNSPECIFIED and draws it as glTF content. The extension
///   text asks for LUF packing (x and z negated in the payload); docs/formats.md says what CesiumJS
///   shows for each.
/// - `_FEATURE_ID_0` SCALAR float (whole numbers; vertex attributes must be 4-byte aligned, which
///   packed 16-bit IDs are not): the class id, 65535 (`nullFeatureId`) for an
///   unlabelled splat; the property table `semantic_class` has one row per class: `name`
///   (STRING) and `color` (VEC3 UINT8). Written when classes are given and some splat has one.
/// Buffer views are 8-byte aligned (EXT_structural_metadata asks it); JSON padded with spaces,
/// the binary chunk with zeros.

#include <pcl/point_cloud.h>

#include <cstdint>
#include <string>
#include <vector>

#include "sadsplat/common/class_info.h"
#include "sadsplat/common/gaussian_point.h"

namespace sadsplat {
namespace io {

/// \brief How a `.glb` of Gaussians is written.
struct GltfSplatOptions {
  bool spz = true;                 ///< SPZ-compressed payload (else plain float accessors)
  int sh_degree = kMaxShDegree;    ///< SH degrees kept, 0..3
  std::vector<ClassInfo> classes;  ///< names of the labels (empty: no feature IDs)
  std::string generator = "sadsplat";
};

/// \brief What a `.glb` of Gaussians holds.
struct GltfSplatInfo {
  bool spz = false;
  int sh_degree = 0;
  std::size_t count = 0;
  std::vector<std::string> class_names;      ///< the property table's names (empty: none)
  std::vector<std::string> extensions_used;
};

/// \brief The `.glb` bytes of `cloud` (glTF axes); `name` names the output in errors.
/// \throws sadsplat::Error on bad options or values that are not writable
std::vector<std::uint8_t> encodeSplatGlb(const std::string& name,
                                         const pcl::PointCloud<GaussianPoint>& cloud,
                                         const GltfSplatOptions& options);
/// \brief Writes encodeSplatGlb's bytes atomically.
void writeSplatGlb(const std::string& path, const pcl::PointCloud<GaussianPoint>& cloud,
                   const GltfSplatOptions& options);
/// \brief Reads a `.glb` of Gaussians as written here (plain float accessors or the SPZ
/// payload); labels from `_FEATURE_ID_0` (kUnlabelled for the null ID).
/// \throws sadsplat::Error naming the file and the chunk, accessor or field that is wrong
pcl::PointCloud<GaussianPoint> readSplatGlb(const std::string& path,
                                            GltfSplatInfo* info = nullptr);

}  // namespace io
}  // namespace sadsplat
