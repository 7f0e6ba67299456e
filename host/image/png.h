#pragma once
// PNG (and JPEG) files for reports: 8-bit RGB (slice montages, renders) and 16-bit grey (depth maps).
// Every write is atomic (a temporary file beside the target, renamed into place), so a reader never
// sees half a PNG; errors are exceptions naming the file.
#include <cstdint>
#include <string>
#include <vector>

#include "image/image.h"

namespace pneumo {

/// `rgb` holds w*h*3 bytes, top row first. InputError when the target folder is missing or not
/// writable; std::runtime_error when the encoding or the write fails; std::invalid_argument
/// when the sizes do not match.
void write_png_rgb(const std::string& path, int w, int h, const std::vector<uint8_t>& rgb);
void write_png(const std::string& path, const RgbImage& image);
/// The PNG's bytes in memory (what `pneumo serve` answers a view with); std::invalid_argument when
/// the sizes do not match, std::runtime_error when the encoding fails.
std::string encode_png(const RgbImage& image);
/// Baseline JPEG at `quality` 1-100 (the report's fly-through strip: photographic frames, a tenth
/// of the PNG's bytes); the same checks and atomic write as the PNGs.
void write_jpeg(const std::string& path, const RgbImage& image, int quality);

/// 16-bit greyscale, `gray` holds w*h values, top row first (stored big-endian as PNG requires).
void write_png_gray16(const std::string& path, int w, int h, const std::vector<uint16_t>& gray);

}  // namespace pneumo
