// PNG writers (host/image/png.h): what is written reads back identically (stb_image), 16-bit
// samples keep their byte order, and a failed write leaves neither a partial file nor a temporary.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <stdexcept>

#include "core/error.h"
#include "io_test_support.h"
#include "image/png.h"

#include "stb_image_support.h"

using namespace pneumo;
using testing_support::ScratchDir;
using testing_support::read_bytes;
using testing_support::write_bytes;

namespace {

std::vector<uint8_t> gradient_rgb(int w, int h) {
  std::vector<uint8_t> rgb(std::size_t(w) * h * 3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      uint8_t* p = &rgb[(std::size_t(y) * w + x) * 3];
      p[0] = uint8_t(x * 37);
      p[1] = uint8_t(y * 51);
      p[2] = uint8_t((x + y) * 13 + 7);
    }
  return rgb;
}

}  // namespace

TEST(Png, RgbRoundTripIsExact) {
  ScratchDir dir;
  const int w = 7, h = 5;
  const std::vector<uint8_t> rgb = gradient_rgb(w, h);
  const std::string path = dir.file("a.png");
  write_png_rgb(path, w, h, rgb);
  int rw = 0, rh = 0, comp = 0;
  stbi_uc* back = stbi_load(path.c_str(), &rw, &rh, &comp, 3);
  ASSERT_NE(back, nullptr) << stbi_failure_reason();
  EXPECT_EQ(rw, w);
  EXPECT_EQ(rh, h);
  EXPECT_EQ(comp, 3);
  EXPECT_EQ(std::vector<uint8_t>(back, back + rgb.size()), rgb);
  stbi_image_free(back);
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"a.png"});  // no temporary left behind
}

TEST(Png, Gray16RoundTripKeepsAllSixteenBits) {
  ScratchDir dir;
  const int w = 4, h = 3;
  // 0x0102 and 0x0201 differ only in byte order; 0 and 65535 are the ends.
  const std::vector<uint16_t> grey{0, 1, 255, 256, 0x0102, 0x0201, 1000, 30000, 40000, 65534, 65535, 12345};
  const std::string path = dir.file("depth.png");
  write_png_gray16(path, w, h, grey);
  int rw = 0, rh = 0, comp = 0;
  stbi_us* back = stbi_load_16(path.c_str(), &rw, &rh, &comp, 1);
  ASSERT_NE(back, nullptr) << stbi_failure_reason();
  EXPECT_EQ(rw, w);
  EXPECT_EQ(rh, h);
  EXPECT_EQ(comp, 1);
  EXPECT_TRUE(stbi_is_16_bit(path.c_str()));
  EXPECT_EQ(std::vector<uint16_t>(back, back + grey.size()), grey);
  stbi_image_free(back);
}

TEST(Png, MissingFolderIsAnInputErrorNamingTheFile) {
  ScratchDir dir;
  const std::string path = dir.file("no_such_folder/x.png");
  try {
    write_png_rgb(path, 2, 2, gradient_rgb(2, 2));
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
  EXPECT_THROW(write_png_gray16(path, 1, 1, {7}), InputError);
}

TEST(Png, FailedWriteLeavesTheOldFileAndNoTemporary) {
  ScratchDir dir;
  const std::string path = dir.file("keep.png");
  write_bytes(path, "previous contents");
  // Wrong sizes fail before anything is written: the old file stays, nothing else appears.
  EXPECT_THROW(write_png_rgb(path, 3, 3, gradient_rgb(2, 2)), std::invalid_argument);
  EXPECT_THROW(write_png_rgb(path, 0, 3, {}), std::invalid_argument);
  EXPECT_THROW(write_png_gray16(path, 2, 2, {1, 2, 3}), std::invalid_argument);
  EXPECT_EQ(read_bytes(path), "previous contents");
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"keep.png"});
  // A successful write replaces it whole.
  write_png_rgb(path, 2, 2, gradient_rgb(2, 2));
  EXPECT_EQ(read_bytes(path).substr(1, 3), "PNG");
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"keep.png"});
}

TEST(Png, UnwritableFolderIsRefusedBeforeWriting) {
  if (::geteuid() == 0) GTEST_SKIP() << "root can write anywhere";
  ScratchDir dir;
  std::filesystem::create_directory(dir.file("ro"));
  std::filesystem::permissions(dir.file("ro"), std::filesystem::perms::owner_read | std::filesystem::perms::owner_exec);
  EXPECT_THROW(write_png_rgb(dir.file("ro/x.png"), 2, 2, gradient_rgb(2, 2)), InputError);
  std::filesystem::permissions(dir.file("ro"), std::filesystem::perms::owner_all);
}

// JPEG is lossy: a smooth 64×48 ramp at quality 90 reads back within 6 grey levels per channel on
// average (baseline JPEG's 8×8 DCT quantisation on a smooth image; a wrong channel order or size
// would be off by tens).
TEST(Png, JpegReadsBackCloseToWhatWasWritten) {
  ScratchDir dir;
  RgbImage im(64, 48);
  for (int y = 0; y < im.height; ++y)
    for (int x = 0; x < im.width; ++x) im.set(x, y, Rgb{uint8_t(x * 4), uint8_t(y * 5), uint8_t(200 - x - y)});
  const std::string path = dir.file("strip.jpg");
  write_jpeg(path, im, 90);
  int rw = 0, rh = 0, comp = 0;
  stbi_uc* back = stbi_load(path.c_str(), &rw, &rh, &comp, 3);
  ASSERT_NE(back, nullptr) << stbi_failure_reason();
  ASSERT_EQ(rw, im.width);
  ASSERT_EQ(rh, im.height);
  double err = 0;
  for (std::size_t i = 0; i < im.rgb.size(); ++i) err += std::abs(int(back[i]) - int(im.rgb[i]));
  stbi_image_free(back);
  EXPECT_LT(err / double(im.rgb.size()), 6.0);
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"strip.jpg"});
  EXPECT_THROW(write_jpeg(dir.file("bad.jpg"), im, 0), std::invalid_argument);
}

// The box filter: each output pixel is the rounded mean of its block; the partial edge block is
// the mean of what it holds.
TEST(Png, BoxDownscaleAveragesBlocks) {
  RgbImage im(5, 2);
  const uint8_t v[2][5] = {{0, 10, 20, 30, 101}, {40, 50, 60, 70, 103}};
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 5; ++x) im.set(x, y, Rgb{v[y][x], uint8_t(2 * v[y][x]), 255});
  const RgbImage d = box_downscale(im, 2);
  ASSERT_EQ(d.width, 3);
  ASSERT_EQ(d.height, 1);
  EXPECT_EQ(d.pixel(0, 0)[0], 25);    // (0+10+40+50)/4
  EXPECT_EQ(d.pixel(1, 0)[0], 45);    // (20+30+60+70)/4
  EXPECT_EQ(d.pixel(2, 0)[0], 102);   // (101+103)/2
  EXPECT_EQ(d.pixel(0, 0)[1], 50);
  EXPECT_EQ(d.pixel(2, 0)[2], 255);
  EXPECT_THROW(box_downscale(im, 0), std::invalid_argument);
}
