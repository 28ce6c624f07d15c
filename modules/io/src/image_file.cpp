#include "sadsplat/io/image_file.h"

#include <algorithm>
#include <cstring>
#include <fstream>
#include <vector>

#include "sadsplat/common/error.h"
#include "sadsplat/io/filesystem.h"

#if SADSPLAT_HAVE_OPENCV
#include <unistd.h>

#include <cstdio>
#include <mutex>
#include <opencv2/imgcodecs.hpp>
#endif

namespace sadsplat {
namespace io {
namespace {

std::uint32_t bigEndian(const unsigned char* p, int bytes) {
  std::uint32_t v = 0;
  for (int i = 0; i < bytes; ++i) v = v << 8 | p[i];
  return v;
}

std::uint32_t littleEndian(const unsigned char* p, int bytes) {
  std::uint32_t v = 0;
  for (int i = bytes - 1; i >= 0; --i) v = v << 8 | p[i];
  return v;
}

// JPEG: the first start-of-frame marker (SOF0..SOF15 except DHT C4, JPG C8, DAC CC) holds height
// and width; markers before it are skipped by their lengths.
bool jpegSize(std::ifstream& in, const std::string& path, ImageHeader* h) {
  in.seekg(2);
  unsigned char m[2];
  for (int guard = 0; guard < 100000; ++guard) {
    if (!in.read(reinterpret_cast<char*>(m), 1)) return false;
    if (m[0] != 0xff) return false;
    do {
      if (!in.read(reinterpret_cast<char*>(m + 1), 1)) return false;
    } while (m[1] == 0xff);  // fill bytes
    const unsigned char marker = m[1];
    if (marker == 0xd8 || marker == 0x01 || (marker >= 0xd0 && marker <= 0xd7)) continue;
    if (marker == 0xd9 || marker == 0xda) return false;  // end, or scan data before any frame
    unsigned char len[2];
    if (!in.read(reinterpret_cast<char*>(len), 2)) return false;
    const std::uint32_t length = bigEndian(len, 2);
    if (length < 2) return false;
    const bool sof = marker >= 0xc0 && marker <= 0xcf && marker != 0xc4 && marker != 0xc8 &&
                     marker != 0xcc;
    if (sof) {
      unsigned char f[5];
      if (length < 7 || !in.read(reinterpret_cast<char*>(f), 5)) {
        throw Error(path, "JPEG frame header", "precision, height and width", "cut off");
      }
      h->height = bigEndian(f + 1, 2);
      h->width = bigEndian(f + 3, 2);
      return true;
    }
    in.seekg(length - 2, std::ios::cur);
  }
  return false;
}

}  // namespace

ImageHeader readImageHeader(const std::string& path) {
  requireRegularFile(path);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path, "file", "a readable image", "cannot open");
  unsigned char b[32] = {0};
  in.read(reinterpret_cast<char*>(b), sizeof b);
  const std::size_t got = static_cast<std::size_t>(in.gcount());
  in.clear();
  ImageHeader h;
  static const unsigned char kPng[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (got >= 8 && std::memcmp(b, kPng, 8) == 0) {
    h.format = "png";
    if (got < 26 || std::memcmp(b + 12, "IHDR", 4) != 0) {
      throw Error(path, "PNG IHDR", "the image header chunk first", "cut off or missing");
    }
    h.width = bigEndian(b + 16, 4);
    h.height = bigEndian(b + 20, 4);
    h.png_colour_type = b[25];
  } else if (got >= 3 && b[0] == 0xff && b[1] == 0xd8 && b[2] == 0xff) {
    h.format = "jpeg";
    if (!jpegSize(in, path, &h)) {
      throw Error(path, "JPEG frame header", "a start-of-frame marker before the image data",
                  "none");
    }
  } else if (got >= 30 && std::memcmp(b, "RIFF", 4) == 0 && std::memcmp(b + 8, "WEBP", 4) == 0) {
    h.format = "webp";
    if (std::memcmp(b + 12, "VP8 ", 4) == 0) {
      h.width = littleEndian(b + 26, 2) & 0x3fff;
      h.height = littleEndian(b + 28, 2) & 0x3fff;
    } else if (std::memcmp(b + 12, "VP8L", 4) == 0) {
      const std::uint32_t bits = littleEndian(b + 21, 4);
      h.width = (bits & 0x3fff) + 1;
      h.height = ((bits >> 14) & 0x3fff) + 1;
    } else if (std::memcmp(b + 12, "VP8X", 4) == 0) {
      h.width = littleEndian(b + 24, 3) + 1;
      h.height = littleEndian(b + 27, 3) + 1;
    }
  }
  return h;
}

namespace {
std::string withArticle(const std::string& noun) {
  const bool vowel = !noun.empty() && std::string("aeiou").find(noun[0]) != std::string::npos;
  return (vowel ? "an " : "a ") + noun;
}
}  // namespace

ImageHeader checkImageBudget(const std::string& path, const std::string& what) {
  const ImageHeader h = readImageHeader(path);
  if (h.format.empty()) return h;
  const std::uint64_t pixels = static_cast<std::uint64_t>(h.width) * h.height;
  const std::string size = std::to_string(h.width) + "x" + std::to_string(h.height);
  if (pixels == 0) throw Error(path, h.format + " header size", "a non-empty " + what, size);
  if (pixels > kMaxImagePixels) {
    throw Error(path, h.format + " header size",
                withArticle(what) + " of at most " + std::to_string(kMaxImagePixels) + " pixels",
                size + " (" + std::to_string(pixels) + " pixels)");
  }
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  const auto bytes = static_cast<std::uint64_t>(std::max<std::streamoff>(in.tellg(), 0));
  if (pixels > bytes * kMaxPixelsPerFileByte) {
    throw Error(path, h.format + " header size",
                "a size its " + std::to_string(bytes) + " bytes can hold (at most " +
                    std::to_string(kMaxPixelsPerFileByte) + " pixels per byte)",
                size);
  }
  return h;
}

#if SADSPLAT_HAVE_OPENCV
namespace {

// The codecs under OpenCV (libpng, libjpeg, libtiff) print their warnings and errors on the
// process's stderr themselves ("libpng warning: iCCP: ..."): while one image is decoded, stderr
// goes to a temporary file instead, and what was written there joins sadsplat's one-line error
// (a successful decode's warnings are dropped).
class StderrCapture {
 public:
  StderrCapture() : lock_(mutex()) {
    std::fflush(stderr);
    file_ = std::tmpfile();
    saved_ = file_ ? ::dup(2) : -1;
    if (saved_ >= 0) ::dup2(::fileno(file_), 2);
  }
  ~StderrCapture() { restore(); }
  // Restores stderr and returns what was written meanwhile, on one line.
  std::string restore() {
    std::string text;
    if (saved_ >= 0) {
      std::fflush(stderr);
      ::dup2(saved_, 2);
      ::close(saved_);
      saved_ = -1;
      std::rewind(file_);
      char buffer[512];
      std::size_t n;
      while ((n = std::fread(buffer, 1, sizeof buffer, file_)) > 0 && text.size() < 2000) {
        text.append(buffer, n);
      }
    }
    if (file_) {
      std::fclose(file_);
      file_ = nullptr;
    }
    for (char& c : text) {
      if (c == '\n' || c == '\r') c = ' ';
    }
    while (!text.empty() && text.back() == ' ') text.pop_back();
    return text;
  }

 private:
  static std::mutex& mutex() {
    static std::mutex m;
    return m;
  }
  std::lock_guard<std::mutex> lock_;
  std::FILE* file_ = nullptr;
  int saved_ = -1;
};

}  // namespace

cv::Mat decodeImage(const std::string& path, int imread_flags, const std::string& what,
                    ImageHeader* header) {
  const ImageHeader checked = checkImageBudget(path, what);
  if (header) *header = checked;
  cv::Mat image;
  std::string failure;
  {
    StderrCapture capture;
    try {
      image = cv::imread(path, imread_flags);
    } catch (const cv::Exception& e) {
      failure = e.msg;
    }
    const std::string said = capture.restore();
    if (image.empty() && failure.empty()) failure = "cannot decode";
    if (!failure.empty() && !said.empty()) failure += " (" + said + ")";
  }
  if (!failure.empty()) throw Error(path, "image data", "a readable " + what, failure);
  return image;
}
#endif

}  // namespace io
}  // namespace sadsplat
