// The parallel gzip writer (io/gzip_members.h) against zlib, the reader niftilib, ITK and VTK use:
// what it writes inflates to exactly the bytes given, as one member per piece of at most
// kGzipMemberBytes (each a whole gzip stream with its own CRC and length, RFC 1952), whatever the
// thread count; and a full disk is an error, not a short file. The parallel reader
// (inflate_gzip_members) gives back exactly those bytes, and declines every other file: zlib's own
// single stream, a truncated or corrupted copy, a range that starts inside a member.
#include <gtest/gtest.h>
#include <omp.h>
#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "io/gzip_members.h"
#include "io/volume_io.h"
#include "io_test_support.h"

namespace pneumo {
namespace {

/// A file name of this process and test alone, in a folder removed when the process ends: ctest runs
/// tests side by side, each in its own process, and two that wrote one fixed name in the temporary
/// folder read each other's bytes.
std::string own_temp_path(const std::string& name) {
  static const testing_support::ScratchDir dir;
  const ::testing::TestInfo* t = ::testing::UnitTest::GetInstance()->current_test_info();
  return dir.file(std::string(t ? t->name() : "") + "_" + name);
}

struct Inflated {
  std::vector<unsigned char> bytes;
  int members = 0;
  bool clean = true;   // every member ended with a good CRC and length, nothing left over
};

// Inflates member after member (windowBits 15 + 16: gzip, one stream per call to inflateInit2).
Inflated inflate_members(const std::vector<unsigned char>& gz) {
  Inflated r;
  std::size_t at = 0;
  std::vector<unsigned char> buf(1 << 16);
  while (at < gz.size()) {
    z_stream z{};
    if (inflateInit2(&z, 15 + 16) != Z_OK) return {{}, 0, false};
    z.next_in = const_cast<unsigned char*>(gz.data() + at);
    z.avail_in = uInt(gz.size() - at);
    int ret = Z_OK;
    while (ret == Z_OK) {
      z.next_out = buf.data();
      z.avail_out = uInt(buf.size());
      ret = inflate(&z, Z_NO_FLUSH);
      r.bytes.insert(r.bytes.end(), buf.data(), buf.data() + (buf.size() - z.avail_out));
    }
    at = gz.size() - z.avail_in;
    inflateEnd(&z);
    if (ret != Z_STREAM_END) return {r.bytes, r.members, false};
    ++r.members;
  }
  return r;
}

std::vector<unsigned char> written(const std::vector<ByteSpan>& parts, int threads) {
  const std::string path = own_temp_path("gzip_members_" + std::to_string(threads) + ".gz");
  std::FILE* f = std::fopen(path.c_str(), "wb");
  EXPECT_NE(f, nullptr);
  const int saved = omp_get_max_threads();
  omp_set_num_threads(threads);
  write_gzip_members(f, path, parts, 1);
  omp_set_num_threads(saved);   // other tests in this process keep theirs
  std::fclose(f);
  std::FILE* r = std::fopen(path.c_str(), "rb");
  std::vector<unsigned char> gz;
  for (int c; (c = std::fgetc(r)) != EOF;) gz.push_back(static_cast<unsigned char>(c));
  std::fclose(r);
  std::remove(path.c_str());
  return gz;
}

TEST(GzipMembers, InflatesToTheBytesGivenOneMemberPerPiece) {
  // A CT-like payload: smooth int16 with noise, 2.5 members long, after a 352-byte header.
  std::vector<int16_t> voxels(std::size_t(kGzipMemberBytes * 5 / 2 / sizeof(int16_t)));
  std::mt19937 rng(3);
  std::normal_distribution<float> noise(0.0f, 20.0f);
  for (std::size_t n = 0; n < voxels.size(); ++n) voxels[n] = int16_t(40.0f * std::sin(float(n) * 1e-3f) + noise(rng));
  std::vector<unsigned char> head(352);
  for (std::size_t n = 0; n < head.size(); ++n) head[n] = static_cast<unsigned char>(n * 7);
  std::vector<unsigned char> expected(head);
  const auto* v = reinterpret_cast<const unsigned char*>(voxels.data());
  expected.insert(expected.end(), v, v + voxels.size() * sizeof(int16_t));

  std::vector<unsigned char> first;
  for (int threads : {1, 2, 3}) {
    const std::vector<unsigned char> gz = written({{head.data(), head.size()}, {voxels.data(), voxels.size() * 2}}, threads);
    const Inflated in = inflate_members(gz);
    EXPECT_TRUE(in.clean) << threads << " threads";
    EXPECT_EQ(in.members, 1 + 3) << "the header's member, then ceil(2.5) pieces";
    EXPECT_TRUE(in.bytes == expected) << threads << " threads";
    EXPECT_LT(gz.size(), expected.size());
    if (first.empty()) first = gz;
    EXPECT_TRUE(gz == first) << "the file depends on the thread count (" << threads << ")";
  }
}

TEST(GzipMembers, AnEmptyPartIsAnEmptyMember) {
  const unsigned char x[3] = {1, 2, 3};
  const Inflated in = inflate_members(written({{x, 0}, {x, 3}}, 2));
  EXPECT_TRUE(in.clean);
  EXPECT_EQ(in.members, 2);
  EXPECT_EQ(in.bytes, (std::vector<unsigned char>{1, 2, 3}));
}

namespace {
std::string write_file(const std::string& name, const std::vector<unsigned char>& bytes) {
  const std::string path = own_temp_path(name);
  std::FILE* f = std::fopen(path.c_str(), "wb");
  EXPECT_NE(f, nullptr);
  std::fwrite(bytes.data(), 1, bytes.size(), f);
  std::fclose(f);
  return path;
}
}  // namespace

TEST(GzipMembers, ReadBackOnEveryCoreExactlyAndOnlyTheirOwnLayout) {
  // A 352-byte header member, then 2.5 members of noisy int16.
  std::vector<int16_t> voxels(std::size_t(kGzipMemberBytes * 5 / 2 / sizeof(int16_t)));
  std::mt19937 rng(5);
  std::normal_distribution<float> noise(0.0f, 30.0f);
  for (auto& v : voxels) v = int16_t(noise(rng));
  std::vector<unsigned char> head(352, 7);
  const uint64_t payload = voxels.size() * sizeof(int16_t);
  const std::vector<unsigned char> gz = written({{head.data(), head.size()}, {voxels.data(), payload}}, 2);
  const std::string path = write_file("members_read.gz", gz);

  std::vector<int16_t> back(voxels.size(), 0);
  for (int threads : {1, 2, 3}) {
    const int saved = omp_get_max_threads();
    omp_set_num_threads(threads);
    std::fill(back.begin(), back.end(), int16_t(0));
    EXPECT_TRUE(inflate_gzip_members(path, head.size(), payload, back.data())) << threads << " threads";
    omp_set_num_threads(saved);
    EXPECT_TRUE(back == voxels) << threads << " threads";
  }
  std::vector<unsigned char> all(head.size() + payload);
  EXPECT_TRUE(inflate_gzip_members(path, 0, all.size(), all.data()));
  EXPECT_TRUE(std::equal(head.begin(), head.end(), all.begin()));

  // Not a member boundary, or not the whole file: declined.
  EXPECT_FALSE(inflate_gzip_members(path, 100, head.size() + payload - 100, all.data()));
  EXPECT_FALSE(inflate_gzip_members(path, head.size(), payload - 2, back.data()));
  // Truncated by one byte, or one byte of deflate data changed: declined.
  std::vector<unsigned char> cut(gz.begin(), gz.end() - 1);
  EXPECT_FALSE(inflate_gzip_members(write_file("members_cut.gz", cut), head.size(), payload, back.data()));
  std::vector<unsigned char> bent = gz;
  bent[bent.size() / 2] ^= 0x40;
  EXPECT_FALSE(inflate_gzip_members(write_file("members_bent.gz", bent), head.size(), payload, back.data()));
  // zlib's own gzip (one member, no lengths in its header): declined, for the stream reader.
  const std::string plain = own_temp_path("zlib_plain.gz");
  gzFile z = gzopen(plain.c_str(), "wb1");
  ASSERT_NE(z, nullptr);
  gzwrite(z, head.data(), unsigned(head.size()));
  gzwrite(z, voxels.data(), unsigned(payload));
  gzclose(z);
  EXPECT_FALSE(inflate_gzip_members(plain, head.size(), payload, back.data()));
  EXPECT_FALSE(inflate_gzip_members(own_temp_path("no_such_file.gz"), 0, 1, back.data()));
}

TEST(GzipMembers, AFullDiskIsAnError) {
  std::FILE* f = std::fopen("/dev/full", "wb");
  if (!f) GTEST_SKIP() << "no /dev/full here";
  std::vector<unsigned char> data(std::size_t(kGzipMemberBytes), 0);
  std::mt19937 rng(1);
  for (auto& b : data) b = static_cast<unsigned char>(rng());   // incompressible: one write larger than stdio's buffer
  try {
    write_gzip_members(f, "/dev/full", {{data.data(), data.size()}}, 1);
    FAIL() << "writing to a full disk succeeded";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("disk full"), std::string::npos) << e.what();
  }
  std::fclose(f);
}

}  // namespace
}  // namespace pneumo

namespace pneumo {
namespace {

TEST(GzipMembers, ANiftiPneumoWritesIsReadOnEveryCore) {
  // read_nifti falls back to the stream reader quietly when the member reader declines; had the
  // writer's layout stopped matching the reader's, every other test would still pass. A NIfTI-1
  // file's voxels start at byte 352 (its header, 348 bytes, and the 4-byte extension flag).
  Geometry g;
  g.dims = {37, 29, 11};
  Volume v(g, VoxelType::Int16);
  for (int64_t n = 0; n < v.voxel_count(); ++n) v.data<int16_t>()[n] = int16_t(n % 3001 - 1000);
  const std::string path = own_temp_path("members_volume.nii.gz");
  write_volume(v, path);
  std::vector<int16_t> back(std::size_t(v.voxel_count()), 0);
  ASSERT_TRUE(inflate_gzip_members(path, 352, v.byte_count(), back.data()));
  EXPECT_TRUE(std::equal(back.begin(), back.end(), v.data<int16_t>()));
}

}  // namespace
}  // namespace pneumo
