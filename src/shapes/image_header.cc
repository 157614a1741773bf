#include "shapes/image_header.h"

#include <array>
#include <cstdint>
#include <fstream>

namespace hj {
namespace {

// Reads n bytes at offset, false if the file is shorter.
bool read_at(std::ifstream& in, std::uint64_t offset, unsigned char* out, std::size_t n) {
  in.clear();
  in.seekg(static_cast<std::streamoff>(offset));
  in.read(reinterpret_cast<char*>(out), static_cast<std::streamsize>(n));
  return in.gcount() == static_cast<std::streamsize>(n);
}

std::uint32_t unpack(const unsigned char* b, int n, bool big_endian) {
  std::uint32_t v = 0;
  for (int k = 0; k < n; ++k) v |= std::uint32_t(b[big_endian ? k : n - 1 - k]) << (8 * (n - 1 - k));
  return v;
}

std::optional<ImageSize> png_size(std::ifstream& in) {
  // Signature (8), IHDR length (4), "IHDR" (4), width (4), height (4), big-endian.
  std::array<unsigned char, 24> h{};
  if (!read_at(in, 0, h.data(), h.size())) return std::nullopt;
  if (h[12] != 'I' || h[13] != 'H' || h[14] != 'D' || h[15] != 'R') return std::nullopt;
  return ImageSize{long(unpack(&h[20], 4, true)), long(unpack(&h[16], 4, true))};
}

std::optional<ImageSize> tiff_size(std::ifstream& in, bool big_endian) {
  std::array<unsigned char, 4> b{};
  if (!read_at(in, 4, b.data(), 4)) return std::nullopt;
  const std::uint64_t ifd = unpack(b.data(), 4, big_endian);
  if (!read_at(in, ifd, b.data(), 2)) return std::nullopt;
  const std::uint32_t entries = unpack(b.data(), 2, big_endian);
  ImageSize size;
  // Entry: tag (2), type (2), count (4), value (4; a SHORT sits in its first 2 bytes).
  for (std::uint32_t k = 0; k < entries; ++k) {
    std::array<unsigned char, 12> e{};
    if (!read_at(in, ifd + 2 + 12 * std::uint64_t(k), e.data(), e.size())) return std::nullopt;
    const std::uint32_t tag = unpack(&e[0], 2, big_endian), type = unpack(&e[2], 2, big_endian);
    if (tag != 256 && tag != 257) continue;
    const long value = type == 3 ? long(unpack(&e[8], 2, big_endian))
                       : type == 4 ? long(unpack(&e[8], 4, big_endian))
                                   : -1;
    if (value < 0) return std::nullopt;
    (tag == 256 ? size.cols : size.rows) = value;
  }
  if (size.rows == 0 || size.cols == 0) return std::nullopt;
  return size;
}

}  // namespace

std::optional<ImageSize> peek_image_size(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::array<unsigned char, 8> sig{};
  if (!in || !read_at(in, 0, sig.data(), sig.size())) return std::nullopt;
  static constexpr std::array<unsigned char, 8> kPng{0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  if (sig == kPng) return png_size(in);
  if (sig[0] == 'I' && sig[1] == 'I' && sig[2] == 42 && sig[3] == 0) return tiff_size(in, false);
  if (sig[0] == 'M' && sig[1] == 'M' && sig[2] == 0 && sig[3] == 42) return tiff_size(in, true);
  return std::nullopt;  // BigTIFF, another format or garbage
}

}  // namespace hj
