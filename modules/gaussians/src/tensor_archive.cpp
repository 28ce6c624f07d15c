#include "sadsplat/gaussians/tensor_archive.h"

#include <cstring>

#include "sadsplat/common/error.h"
#include "sadsplat/io/atomic_file.h"

namespace sadsplat {
namespace gaussians {
namespace {

constexpr char kMagic[8] = {'S', 'A', 'D', 'S', 'C', 'K', 'P', 'T'};

template <typename T>
void put(std::ostream& out, const T& v) {
  out.write(reinterpret_cast<const char*>(&v), sizeof(T));
}

class Reader {
 public:
  Reader(const std::string& path, const std::string& bytes) : path_(path), bytes_(bytes) {}
  template <typename T>
  T get(const std::string& field) {
    T v;
    read(&v, sizeof(T), field);
    return v;
  }
  void read(void* dst, std::size_t n, const std::string& field) {
    if (n > bytes_.size() - pos_) {
      throw Error(path_, field, "more data (checkpoint truncated)", "end of file");
    }
    if (n > 0) std::memcpy(dst, bytes_.data() + pos_, n);
    pos_ += n;
  }
  std::size_t remaining() const { return bytes_.size() - pos_; }

 private:
  const std::string& path_;
  const std::string& bytes_;
  std::size_t pos_ = 0;
};

}  // namespace

const at::Tensor& TensorArchive::tensor(const std::string& name, const std::string& file) const {
  const auto it = tensors.find(name);
  if (it == tensors.end())
    throw Error(file, "tensor " + name, "present in the checkpoint", "missing");
  return it->second;
}

double TensorArchive::number(const std::string& name, const std::string& file) const {
  const auto it = numbers.find(name);
  if (it == numbers.end())
    throw Error(file, "number " + name, "present in the checkpoint", "missing");
  return it->second;
}

void writeTensorArchive(const std::string& path, const TensorArchive& archive) {
  io::writeFileAtomically(path, [&](std::ostream& out) {
    out.write(kMagic, 8);
    put<std::uint32_t>(out, 1);
    put<std::uint64_t>(out, archive.tensors.size() + archive.numbers.size());
    for (const auto& [name, t] : archive.tensors) {
      put<std::uint32_t>(out, static_cast<std::uint32_t>(name.size()));
      out << name;
      put<std::uint8_t>(out, 0);
      const at::Tensor c = t.detach().to(at::kCPU).contiguous();
      std::uint8_t dtype = 0;
      if (c.scalar_type() == at::kInt) {
        dtype = 1;
      } else if (c.scalar_type() == at::kLong) {
        dtype = 2;
      } else if (c.scalar_type() != at::kFloat) {
        throw Error(path, "tensor " + name, "float32, int32 or int64",
                    std::string(c10::toString(c.scalar_type())));
      }
      put<std::uint8_t>(out, dtype);
      put<std::uint32_t>(out, static_cast<std::uint32_t>(c.dim()));
      for (int64_t d = 0; d < c.dim(); ++d) put<std::int64_t>(out, c.size(d));
      out.write(static_cast<const char*>(c.data_ptr()),
                static_cast<std::streamsize>(c.numel() * c.element_size()));
    }
    for (const auto& [name, v] : archive.numbers) {
      put<std::uint32_t>(out, static_cast<std::uint32_t>(name.size()));
      out << name;
      put<std::uint8_t>(out, 1);
      put<double>(out, v);
    }
  });
}

TensorArchive readTensorArchive(const std::string& path) {
  const std::string bytes = io::readWholeFile(path);
  Reader r(path, bytes);
  char magic[8];
  r.read(magic, 8, "magic");
  if (std::memcmp(magic, kMagic, 8) != 0) {
    throw Error(path, "magic", "a sadsplat checkpoint starting with \"SADSCKPT\"",
                "other bytes");
  }
  const auto version = r.get<std::uint32_t>("version");
  if (version != 1) throw Error(path, "version", "1", std::to_string(version));
  const auto count = r.get<std::uint64_t>("entry count");
  TensorArchive archive;
  for (std::uint64_t e = 0; e < count; ++e) {
    const auto len = r.get<std::uint32_t>("name length");
    if (len > 4096) {
      throw Error(path, "entry " + std::to_string(e), "a name under 4096 bytes",
                  std::to_string(len) + " bytes");
    }
    std::string name(len, '\0');
    r.read(name.data(), len, "name");
    const auto kind = r.get<std::uint8_t>(name + " kind");
    if (kind == 1) {
      archive.numbers[name] = r.get<double>(name);
      continue;
    }
    if (kind != 0) {
      throw Error(path, name + " kind", "0 (tensor) or 1 (number)", std::to_string(kind));
    }
    const auto dtype = r.get<std::uint8_t>(name + " dtype");
    const auto ndim = r.get<std::uint32_t>(name + " ndim");
    if (dtype > 2 || ndim > 8) {
      throw Error(path, name, "dtype 0..2 and at most 8 dimensions",
                  "dtype " + std::to_string(dtype) + ", " + std::to_string(ndim) + " dimensions");
    }
    std::vector<int64_t> sizes(ndim);
    // The sizes must fit the bytes left before anything is allocated.
    const std::size_t element = dtype == 2 ? 8 : 4;
    std::size_t bytes_needed = element;
    for (auto& s : sizes) {
      s = r.get<std::int64_t>(name + " size");
      if (s < 0 || s > (std::int64_t{1} << 40)) {
        throw Error(path, name + " size", "0 .. 2^40", std::to_string(s));
      }
      const auto dim = static_cast<std::size_t>(s);
      if (dim != 0 && bytes_needed > r.remaining() / dim) {
        throw Error(path, name + " sizes",
                    "a tensor that fits the " + std::to_string(r.remaining()) +
                        " bytes left (checkpoint truncated or corrupt)",
                    "a size of " + std::to_string(s) + " in dimension " +
                        std::to_string(&s - sizes.data()));
      }
      bytes_needed *= dim;
    }
    const at::ScalarType type = dtype == 0 ? at::kFloat : dtype == 1 ? at::kInt : at::kLong;
    at::Tensor t = at::empty(sizes, at::TensorOptions().dtype(type));
    r.read(t.data_ptr(), static_cast<std::size_t>(t.numel() * t.element_size()), name + " data");
    archive.tensors[name] = t;
  }
  return archive;
}

}  // namespace gaussians
}  // namespace sadsplat
