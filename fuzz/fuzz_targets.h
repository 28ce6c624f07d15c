#pragma once
// The body of every fuzz target, shared by the libFuzzer programs (fuzz_<name>.cpp) and the
// corpus test (tests/fuzz/test_fuzz_corpus.cpp), which replays the committed seeds and
// regression inputs in the ordinary build. Each gives a reader one input and accepts only
// success or a sadsplat::Error (anything else aborts).
#include <algorithm>
#include <cstring>
#include <filesystem>
#include <vector>

#include "fuzz_support.h"
#include "sadsplat/gaussians/tensor_archive.h"
#include "sadsplat/gaussians/train_config.h"
#include "sadsplat/io/colmap.h"
#include "sadsplat/io/file_info.h"
#include "sadsplat/io/gaussian_ply.h"
#include "sadsplat/io/georeference.h"
#include "sadsplat/io/las.h"
#include "sadsplat/io/pcd.h"
#include "sadsplat/io/scene.h"
#include "sadsplat/io/scene_cache.h"
#include "sadsplat/io/scene_import.h"
#include "sadsplat/io/semantic_ply.h"
#include "sadsplat/io/splat_formats.h"
#include "sadsplat/io/train_log.h"

#if SADSPLAT_HAVE_OPENCV
#include <opencv2/imgcodecs.hpp>
#endif

namespace sadsplat {
namespace fuzz {

// Fuzz target: the 3DGS PLY reader (ascii and binary), and the semantic and PlayCanvas
// compressed PLY readers on the same input.
inline void fuzz_gaussian_ply(const std::uint8_t* data, std::size_t size) {
  const std::string path = fuzz::inputFile("input.ply");
  fuzz::writeInput(path, data, size);
  fuzz::expectOnlySadsplatErrors([&] { io::readGaussianPly(path); });
  fuzz::expectOnlySadsplatErrors([&] { io::readSemanticPly(path); });
  fuzz::expectOnlySadsplatErrors([&] { io::readCompressedPly(path); });
}

// Fuzz target: the PCD codec (ascii, binary, binary_compressed), as Gaussians and as a semantic
// cloud.
inline void fuzz_pcd(const std::uint8_t* data, std::size_t size) {
  const std::string path = fuzz::inputFile("input.pcd");
  fuzz::writeInput(path, data, size);
  fuzz::expectOnlySadsplatErrors([&] { io::loadGaussianPcd(path); });
  fuzz::expectOnlySadsplatErrors([&] { io::loadSemanticPcd(path); });
}

// Fuzz target: the web splat readers: every input is tried as .spz (versions 2-4), .splat and
// .sog (a ZIP of WebP images).
inline void fuzz_splat_formats(const std::uint8_t* data, std::size_t size) {
  const std::string spz = fuzz::inputFile("input.spz");
  fuzz::writeInput(spz, data, size);
  fuzz::expectOnlySadsplatErrors([&] { io::readSpz(spz); });
  const std::string splat = fuzz::inputFile("input.splat");
  fuzz::writeInput(splat, data, size);
  fuzz::expectOnlySadsplatErrors([&] { io::readSplat(splat); });
  const std::string sog = fuzz::inputFile("input.sog");
  fuzz::writeInput(sog, data, size);
  fuzz::expectOnlySadsplatErrors([&] { io::readSog(sog); });
}

// Fuzz target: the scene cache, structure-aware: the input is the payload (chunks, including
// the pseudo-label chunk), given a valid header with its size and checksum, so that the fuzzer
// reaches the chunk parsers instead of stopping at the checksum.
inline void fuzz_scene_cache(const std::uint8_t* data, std::size_t size) {
  std::vector<std::uint8_t> file(32 + size);
  std::memcpy(file.data(), "SADSCENE", 8);
  // The version is taken from the committed fixture's header by the seed corpus's first file;
  // it is read here from the build's own writer: 4 bytes after the magic.
  static const std::uint32_t version = [] {
    io::Scene empty;
    empty.classes.push_back({"a", {1, 2, 3}, "a"});
    const std::string probe = fuzz::inputFile("probe.cache");
    io::writeSceneCache(probe, empty);
    std::ifstream in(probe, std::ios::binary);
    char head[12];
    in.read(head, 12);
    std::uint32_t v;
    std::memcpy(&v, head + 8, 4);
    return v;
  }();
  const std::uint32_t flags = 0;
  const std::uint64_t payload = size;
  const std::uint64_t checksum = io::fnv1a64(data, size);
  std::memcpy(file.data() + 8, &version, 4);
  std::memcpy(file.data() + 12, &flags, 4);
  std::memcpy(file.data() + 16, &payload, 8);
  std::memcpy(file.data() + 24, &checksum, 8);
  if (size > 0) std::memcpy(file.data() + 32, data, size);
  const std::string path = fuzz::inputFile("input.cache");
  fuzz::writeInput(path, file.data(), file.size());
  fuzz::expectOnlySadsplatErrors([&] { io::readSceneCache(path); });
}

// Fuzz target: COLMAP models, text and binary. The input is split at the first two bytes 0xff
// 0xfe into cameras / images / points3D; its first byte chooses text (even) or binary (odd).
inline void fuzz_colmap(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return;
  const bool binary = data[0] & 1;
  std::vector<std::pair<const std::uint8_t*, std::size_t>> parts;
  const std::uint8_t* begin = data + 1;
  const std::uint8_t* end = data + size;
  for (int k = 0; k < 2; ++k) {
    const std::uint8_t sep[2] = {0xff, 0xfe};
    const std::uint8_t* at = std::search(begin, end, sep, sep + 2);
    parts.emplace_back(begin, static_cast<std::size_t>(at - begin));
    begin = at == end ? end : at + 2;
  }
  parts.emplace_back(begin, static_cast<std::size_t>(end - begin));
  const std::string dir = fuzz::inputFile(binary ? "bin" : "text");
  // The same three files are rewritten each time (no shell: the fuzzer runs ~100x faster).
  std::filesystem::create_directories(dir);
  const char* names[3] = {"cameras", "images", "points3D"};
  for (int k = 0; k < 3; ++k) {
    fuzz::writeInput(dir + "/" + names[k] + (binary ? ".bin" : ".txt"), parts[k].first,
                     parts[k].second);
  }
  fuzz::expectOnlySadsplatErrors([&] { io::readColmapModel(dir); });
}

// Fuzz target: the JSON readers of a scene directory and a run: classes.json, split.json and
// train_log.jsonl.
inline void fuzz_json(const std::uint8_t* data, std::size_t size) {
  const std::string path = fuzz::inputFile("input.json");
  fuzz::writeInput(path, data, size);
  fuzz::expectOnlySadsplatErrors([&] { io::readClassesJson(path); });
  fuzz::expectOnlySadsplatErrors([&] { io::readSplitJson(path); });
  fuzz::expectOnlySadsplatErrors([&] { io::readTrainLog(path); });
}

// Fuzz target: the training configuration (train --config FILE.json, a run's config.json).
inline void fuzz_train_config(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  fuzz::expectOnlySadsplatErrors([&] { gaussians::TrainConfig::fromJson(text, "config.json"); });
}

// Fuzz target: the training checkpoint (checkpoint.bin, read by --resume and eval).
inline void fuzz_checkpoint(const std::uint8_t* data, std::size_t size) {
  const std::string path = fuzz::inputFile("checkpoint.bin");
  fuzz::writeInput(path, data, size);
  fuzz::expectOnlySadsplatErrors([&] { gaussians::readTensorArchive(path); });
}

// Fuzz target: a LAS file, as read by `convert` / `info` (readLas, and the streaming summary).
inline void fuzz_las(const std::uint8_t* data, std::size_t size) {
  const std::string path = fuzz::inputFile("input.las");
  fuzz::writeInput(path, data, size);
  fuzz::expectOnlySadsplatErrors([&] { io::readLas(path); });
  fuzz::expectOnlySadsplatErrors([&] { io::describeFile(path); });
}

// Fuzz target: georeference.json (a scene's or a run's frame on the Earth).
inline void fuzz_georeference(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  fuzz::expectOnlySadsplatErrors([&] { io::georeferenceFromJson(text, "georeference.json"); });
}

#if SADSPLAT_HAVE_OPENCV
// The fixture scene (data/tiny_scene) copied once into `name`, for the targets that replace one
// of its files and import it.
inline std::string fixtureSceneCopy(const std::string& name) {
  const std::string dir = fuzz::inputFile(name);
  std::filesystem::remove_all(dir);
  std::filesystem::copy(std::string(SADSPLAT_SOURCE_DIR) + "/data/tiny_scene", dir,
                        std::filesystem::copy_options::recursive);
  return dir;
}

// Fuzz target: transforms.json (nerfstudio / instant-ngp poses) in place of the fixture scene's
// COLMAP model, imported as `sadsplat import` does (so the cameras it gives are checked too).
inline void fuzz_transforms_json(const std::uint8_t* data, std::size_t size) {
  static const std::string scene = [] {
    const std::string dir = fixtureSceneCopy("transforms_scene");
    std::filesystem::remove_all(dir + "/sparse");
    std::filesystem::remove(dir + "/split.json");
    return dir;
  }();
  fuzz::writeInput(scene + "/transforms.json", data, size);
  io::ImportOptions options;
  options.test_every = 0;
  fuzz::expectOnlySadsplatErrors([&] { io::importScene(scene, options); });
}

// Fuzz target: LabelMe / COCO annotations (`import --annotations FILE`) on the fixture scene
// without its label maps (image names view_000.png .. view_007.png, 64x48).
inline void fuzz_annotations(const std::uint8_t* data, std::size_t size) {
  static const std::string scene = [] {
    const std::string dir = fixtureSceneCopy("annotated_scene");
    std::filesystem::remove_all(dir + "/labels");
    std::filesystem::remove(dir + "/split.json");
    return dir;
  }();
  const std::string path = fuzz::inputFile("annotations.json");
  fuzz::writeInput(path, data, size);
  io::ImportOptions options;
  options.test_every = 0;
  options.annotations = path;
  fuzz::expectOnlySadsplatErrors([&] { io::importScene(scene, options); });
}

// Fuzz target: a photo of the fixture scene (any format OpenCV reads, under the name
// view_000.png), imported: the header's size is checked before anything is decoded.
inline void fuzz_photo(const std::uint8_t* data, std::size_t size) {
  static const std::string scene = fixtureSceneCopy("photo_scene");
  fuzz::writeInput(scene + "/images/view_000.png", data, size);
  fuzz::expectOnlySadsplatErrors([&] { io::importScene(scene, io::ImportOptions()); });
}

// A valid PNG built from fuzz bytes, so that the label checks (size, channels, bit depth, class
// ids and colours) see what a mutated PNG file rarely gets past (libpng's CRC and zlib checks):
// byte 0 picks the channels (1, 3, 4) and the depth (8 or 16 bit); bit 0 of byte 1 says whether
// bytes 2-3 give the size (1-96 x 1-96) or the fixture's 64x48 is used; the rest are the pixel
// bytes, repeated until the image is full.
inline std::vector<unsigned char> labelPngFromBytes(const std::uint8_t* data, std::size_t size) {
  const std::uint8_t mode = size > 0 ? data[0] : 0;
  const int channels[] = {1, 3, 4};
  const int depth = (mode / 3) % 2 == 1 ? CV_16U : CV_8U;
  int width = 64, height = 48;
  std::size_t pixels = std::min<std::size_t>(size, 2);
  if (size > 3 && (data[1] & 1) == 1) {
    width = 1 + data[2] % 96;
    height = 1 + data[3] % 96;
    pixels = 4;
  }
  cv::Mat image(height, width, CV_MAKETYPE(depth, channels[mode % 3]));
  const std::size_t bytes = image.total() * image.elemSize();
  for (std::size_t i = 0; i < bytes; ++i) {
    image.data[i] = pixels < size ? data[pixels + i % (size - pixels)] : 0;
  }
  std::vector<unsigned char> png;
  cv::imencode(".png", image, png);
  return png;
}

// Fuzz target: a label map PNG, imported with a scene (`sadsplat import`, `train SCENE_DIR`): the
// fixture scene is copied once, the input replaces its first label map. An input that starts
// with PNG's signature is written as it is; any other is made into a valid PNG first
// (labelPngFromBytes).
inline void fuzz_label_png(const std::uint8_t* data, std::size_t size) {
  static const std::string scene = fixtureSceneCopy("scene");
  const std::string path = scene + "/labels/view_000.png";
  static const std::uint8_t kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (size >= 8 && std::memcmp(data, kSignature, 8) == 0) {
    fuzz::writeInput(path, data, size);
  } else {
    const std::vector<unsigned char> png = labelPngFromBytes(data, size);
    fuzz::writeInput(path, png.data(), png.size());
  }
  fuzz::expectOnlySadsplatErrors([&] { io::importScene(scene, io::ImportOptions()); });
}
#endif

}  // namespace fuzz
}  // namespace sadsplat
