// stb_image_write encodes the 8-bit images; it has no 16-bit PNG, so the grey16 writer builds its
// few chunks itself with zlib (which pneumo links anyway for .nii.gz).
#include "image/png.h"

#include <zlib.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <stdexcept>

#include "core/atomic_file.h"

#include <stb/stb_image_write.h>   // its implementation: stb_image_write_impl.cpp

namespace pneumo {

namespace {

void check_size(const std::string& path, int w, int h, std::size_t have, std::size_t per_pixel) {
  if (w <= 0 || h <= 0)
    throw std::invalid_argument(path + ": cannot write a " + std::to_string(w) + "x" + std::to_string(h) + " PNG");
  if (have != std::size_t(w) * std::size_t(h) * per_pixel)
    throw std::invalid_argument(path + ": " + std::to_string(have) + " values given for a " + std::to_string(w) +
                                "x" + std::to_string(h) + " image of " + std::to_string(per_pixel) +
                                " per pixel");
}

/// Writes `bytes` to `path` atomically: the folder is checked first, the temporary file is removed
/// on any failure, the target appears only when complete.
void write_bytes_atomic(const std::string& path, const std::string& bytes) {
  check_writable_target(path);
  AtomicFile file(path);
  std::FILE* f = std::fopen(file.temp_path().c_str(), "wb");
  if (!f) throw std::runtime_error(path + ": cannot create " + file.temp_path() + ": " + std::strerror(errno));
  const std::size_t written = std::fwrite(bytes.data(), 1, bytes.size(), f);
  const int err = written == bytes.size() ? 0 : errno;
  if (std::fclose(f) != 0 || written != bytes.size())
    throw std::runtime_error(path + ": cannot write the PNG: " + std::strerror(err ? err : errno));
  file.commit();
}

void append_to_string(void* context, void* data, int size) {
  static_cast<std::string*>(context)->append(static_cast<const char*>(data), std::size_t(size));
}

void put_be32(std::string& s, uint32_t v) {
  for (int shift = 24; shift >= 0; shift -= 8) s.push_back(char((v >> shift) & 0xff));
}

void put_chunk(std::string& png, const char type[4], const std::string& data) {
  put_be32(png, uint32_t(data.size()));
  const std::size_t start = png.size();
  png.append(type, 4);
  png += data;
  const uLong crc = crc32(0L, reinterpret_cast<const Bytef*>(png.data() + start), uInt(png.size() - start));
  put_be32(png, uint32_t(crc));
}

std::string encode_gray16(const std::string& path, int w, int h, const std::vector<uint16_t>& gray) {
  // Raw scanlines: a filter byte (0 = none) then big-endian samples.
  std::string raw;
  raw.reserve(std::size_t(h) * (1 + 2 * std::size_t(w)));
  for (int y = 0; y < h; ++y) {
    raw.push_back(0);
    for (int x = 0; x < w; ++x) {
      const uint16_t v = gray[std::size_t(y) * w + x];
      raw.push_back(char(v >> 8));
      raw.push_back(char(v & 0xff));
    }
  }
  uLongf zlen = compressBound(uLong(raw.size()));
  std::string z(zlen, '\0');
  if (compress2(reinterpret_cast<Bytef*>(z.data()), &zlen, reinterpret_cast<const Bytef*>(raw.data()),
                uLong(raw.size()), Z_DEFAULT_COMPRESSION) != Z_OK)
    throw std::runtime_error(path + ": zlib failed to compress the PNG data");
  z.resize(zlen);

  std::string ihdr;
  put_be32(ihdr, uint32_t(w));
  put_be32(ihdr, uint32_t(h));
  ihdr += std::string("\x10\x00\x00\x00\x00", 5);  // bit depth 16, colour type 0 (grey), deflate, filter 0, no interlace
  std::string png("\x89PNG\r\n\x1a\n", 8);
  put_chunk(png, "IHDR", ihdr);
  put_chunk(png, "IDAT", z);
  put_chunk(png, "IEND", "");
  return png;
}

}  // namespace

namespace {
std::string encode_png_rgb(const std::string& what, int w, int h, const std::vector<uint8_t>& rgb) {
  check_size(what, w, h, rgb.size(), 3);
  std::string bytes;
  if (!stbi_write_png_to_func(append_to_string, &bytes, w, h, 3, rgb.data(), w * 3))
    throw std::runtime_error(what + ": stb_image_write failed to encode the PNG");
  return bytes;
}
}  // namespace

void write_png_rgb(const std::string& path, int w, int h, const std::vector<uint8_t>& rgb) {
  check_size(path, w, h, rgb.size(), 3);
  check_writable_target(path);
  write_bytes_atomic(path, encode_png_rgb(path, w, h, rgb));
}

std::string encode_png(const RgbImage& image) { return encode_png_rgb("PNG", image.width, image.height, image.rgb); }

void write_jpeg(const std::string& path, const RgbImage& image, int quality) {
  check_size(path, image.width, image.height, image.rgb.size(), 3);
  if (quality < 1 || quality > 100) throw std::invalid_argument(path + ": JPEG quality must be 1 to 100");
  check_writable_target(path);
  std::string bytes;
  if (!stbi_write_jpg_to_func(append_to_string, &bytes, image.width, image.height, 3, image.rgb.data(), quality))
    throw std::runtime_error(path + ": stb_image_write failed to encode the JPEG");
  write_bytes_atomic(path, bytes);
}

void write_png(const std::string& path, const RgbImage& image) {
  write_png_rgb(path, image.width, image.height, image.rgb);
}

void write_png_gray16(const std::string& path, int w, int h, const std::vector<uint16_t>& gray) {
  check_size(path, w, h, gray.size(), 1);
  check_writable_target(path);
  write_bytes_atomic(path, encode_gray16(path, w, h, gray));
}

}  // namespace pneumo
