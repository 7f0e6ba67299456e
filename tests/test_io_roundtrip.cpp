// Volume files written by pneumo read back bit-identical, with their geometry, in every format; and
// MetaImage files written by others (2-D, big-endian, split, offset data) read as ITK would read them.
#include <gtest/gtest.h>
#include <nifti1.h>
#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <ostream>
#include <random>
#include <sstream>
#include <string>
#include <type_traits>

#include "io/volume_io.h"
#include "io_test_support.h"

namespace pneumo {
namespace {

using testing_support::read_bytes;
using testing_support::ScratchDir;
using testing_support::write_bytes;

constexpr VoxelType kAllTypes[] = {VoxelType::Int8,  VoxelType::UInt8,  VoxelType::Int16,   VoxelType::UInt16,
                                   VoxelType::Int32, VoxelType::UInt32, VoxelType::Float32, VoxelType::Float64};

/// Rotated about an oblique axis, with one axis reflected, anisotropic and away from the origin.
Geometry oblique_geometry() {
  Geometry g;
  g.dims = {7, 5, 4};
  g.spacing_mm = Vec3(0.7, 1.3, 2.5);
  g.origin_mm = Vec3(-12.3, 45.6, 78.9);
  g.direction = Eigen::AngleAxisd(0.3, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  g.direction.col(1) *= -1.0;
  return g;
}

/// An oblique grid whose index-to-world affine has float32-exact entries: the rows of
/// (2 3 6; 3 -6 2; 6 2 -3) / 7 are orthonormal, and 3.5 mm spacing scales them to halves.
Geometry float_exact_geometry() {
  Mat4 a = Mat4::Identity();
  a.topLeftCorner<3, 3>() << 1.0, 1.5, 3.0,   //
      1.5, -3.0, 1.0,                          //
      3.0, 1.0, -1.5;
  a.topRightCorner<3, 1>() = Vec3(-20.25, 33.5, 7.125);
  return Geometry::from_affine({6, 5, 3}, a, "test affine");
}

template <class T>
void fill_random(T* p, int64_t n, std::mt19937_64& rng) {
  using L = std::numeric_limits<T>;
  if constexpr (std::is_integral_v<T>) {
    std::uniform_int_distribution<int64_t> dist(static_cast<int64_t>(L::min()), static_cast<int64_t>(L::max()));
    for (int64_t i = 0; i < n; ++i) p[i] = static_cast<T>(dist(rng));
    const T extremes[] = {L::min(), L::max(), T(0), T(L::min() + 1), T(L::max() - 1)};
    for (size_t i = 0; i < std::size(extremes) && int64_t(i) < n; ++i) p[i] = extremes[i];
  } else {
    std::uniform_real_distribution<T> dist(T(-1e4), T(1e4));
    for (int64_t i = 0; i < n; ++i) p[i] = dist(rng);
    const T extremes[] = {L::quiet_NaN(), L::infinity(), -L::infinity(), T(-0.0), L::denorm_min(),
                          L::max(),       L::lowest(),   L::min(),       L::epsilon()};
    for (size_t i = 0; i < std::size(extremes) && int64_t(i) < n; ++i) p[i] = extremes[i];
  }
}

Volume random_volume(const Geometry& g, VoxelType t, uint64_t seed) {
  Volume v(g, t);
  std::mt19937_64 rng(seed);
  dispatch_voxel_type(t, v.raw(), [&](auto* p) { fill_random(p, v.voxel_count(), rng); });
  return v;
}

void expect_same_geometry_exactly(const Geometry& a, const Geometry& b) {
  EXPECT_EQ(a.dims, b.dims);
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(a.spacing_mm[i], b.spacing_mm[i]) << "spacing " << i;
    EXPECT_EQ(a.origin_mm[i], b.origin_mm[i]) << "origin " << i;
    for (int j = 0; j < 3; ++j) EXPECT_EQ(a.direction(i, j), b.direction(i, j)) << "direction " << i << "," << j;
  }
}

// ---- every type x every format -------------------------------------------------------------------

struct Format {
  const char* name;
  const char* ext;
  bool compress;
  bool nifti;
};
constexpr Format kFormats[] = {{"nii", ".nii", false, true},       {"niigz", ".nii.gz", false, true},
                               {"mha", ".mha", false, false},      {"mhd", ".mhd", false, false},
                               {"mha_zlib", ".mha", true, false},  {"mhd_zlib", ".mhd", true, false}};

struct RoundtripCase {
  VoxelType type;
  Format format;
};

void PrintTo(const RoundtripCase& c, std::ostream* os) { *os << voxel_type_name(c.type) << " " << c.format.name; }

class IoRoundtripAll : public ::testing::TestWithParam<RoundtripCase> {};

TEST_P(IoRoundtripAll, WriteThenReadIsBitIdentical) {
  const RoundtripCase c = GetParam();
  ScratchDir dir;
  const std::string path = dir.file(std::string("volume") + c.format.ext);
  const Geometry g = oblique_geometry();
  const Volume v = random_volume(g, c.type, 1234 + static_cast<int>(c.type));
  write_volume(v, path, WriteOptions{c.format.compress});

  const Volume r = read_volume(path);
  EXPECT_EQ(r.type(), c.type);
  EXPECT_EQ(r.geometry().dims, g.dims);
  EXPECT_TRUE(r.same_voxels(v)) << "voxels differ after " << c.format.name;
  if (!c.format.nifti) {
    expect_same_geometry_exactly(r.geometry(), g);
    return;
  }
  // NIfTI stores the affine in float32: close to the original, and stable once rounded.
  EXPECT_TRUE(r.geometry().same_grid(g, 1e-5));
  const std::string again = dir.file(std::string("again") + c.format.ext);
  write_volume(r, again);
  const Volume r2 = read_volume(again);
  expect_same_geometry_exactly(r2.geometry(), r.geometry());
  EXPECT_TRUE(r2.same_voxels(v));
}

std::vector<RoundtripCase> all_cases() {
  std::vector<RoundtripCase> cases;
  for (VoxelType t : kAllTypes)
    for (const Format& f : kFormats) cases.push_back({t, f});
  return cases;
}

INSTANTIATE_TEST_SUITE_P(AllTypesAllFormats, IoRoundtripAll, ::testing::ValuesIn(all_cases()),
                         [](const ::testing::TestParamInfo<RoundtripCase>& info) {
                           return std::string(voxel_type_name(info.param.type)) + "_" + info.param.format.name;
                         });

// ---- geometry precision -------------------------------------------------------------------------

TEST(IoRoundtrip, NiftiGeometryIsExactWhenTheAffineIsFloat32) {
  ScratchDir dir;
  const Geometry g = float_exact_geometry();
  for (const char* ext : {".nii", ".nii.gz"}) {
    SCOPED_TRACE(ext);
    const std::string path = dir.file(std::string("exact") + ext);
    write_volume(random_volume(g, VoxelType::Int16, 7), path);
    expect_same_geometry_exactly(read_volume(path).geometry(), g);
  }
}

TEST(IoRoundtrip, MetaImageGeometryIsExactForAwkwardNumbers) {
  ScratchDir dir;
  Geometry g;
  g.dims = {3, 2, 2};
  g.spacing_mm = Vec3(1.0 / 3.0, 0.1, 123456.789e-3);
  g.origin_mm = Vec3(-0.0, 1e-300, -9876543.21);
  g.direction = Eigen::AngleAxisd(2.0, Vec3(-0.3, 0.2, 0.9).normalized()).toRotationMatrix();
  for (const char* ext : {".mha", ".mhd"}) {
    SCOPED_TRACE(ext);
    const std::string path = dir.file(std::string("awkward") + ext);
    write_volume(random_volume(g, VoxelType::Float32, 3), path);
    expect_same_geometry_exactly(read_volume(path).geometry(), g);
  }
}

// ---- orientation conventions --------------------------------------------------------------------

TEST(IoRoundtrip, NiftiWithIdentityAffineIsRAS) {
  ScratchDir dir;
  const nifti_1_header h = testing_support::nifti1_test_header(2, 3, 4, DT_UINT8, 8);
  std::string bytes(reinterpret_cast<const char*>(&h), sizeof h);
  bytes += std::string(4, '\0') + std::string(2 * 3 * 4, '\x07');
  const std::string path = dir.file("identity.nii");
  write_bytes(path, bytes);
  const Volume v = read_volume(path);
  EXPECT_EQ(v.geometry().orientation_code(), "RAS");
  EXPECT_TRUE(v.geometry().direction.isIdentity());
}

TEST(MetaImageRead, IdentityTransformMatrixIsLPS) {
  ScratchDir dir;
  const std::string path = dir.file("identity.mha");
  write_bytes(path,
              "ObjectType = Image\nNDims = 3\nTransformMatrix = 1 0 0 0 1 0 0 0 1\nOffset = 10 20 30\n"
              "DimSize = 2 2 2\nElementType = MET_UCHAR\nElementDataFile = LOCAL\n" +
                  std::string(8, '\x01'));
  const Geometry g = read_volume(path).geometry();
  EXPECT_EQ(g.orientation_code(), "LPS");
  EXPECT_EQ(g.origin_mm, Vec3(-10, -20, 30));   // LPS (10, 20, 30) in RAS
  const Mat3 lps = Vec3(-1, -1, 1).asDiagonal();
  EXPECT_EQ(g.direction, lps);
}

TEST(MetaImageRead, TransformMatrixListsOneAxisDirectionAfterAnother) {
  // Axis 0 along LPS +y (towards Posterior), axis 1 along LPS -z (Inferior), axis 2 along LPS +x (Left).
  // The matrix is not symmetric, so reading it transposed would fail.
  ScratchDir dir;
  const std::string path = dir.file("permuted.mha");
  write_bytes(path, "NDims = 3\nTransformMatrix = 0 1 0  0 0 -1  1 0 0\nDimSize = 1 1 1\n"
                    "ElementType = MET_UCHAR\nElementDataFile = LOCAL\n\x05");
  const Geometry g = read_volume(path).geometry();
  EXPECT_EQ(g.orientation_code(), "PIL");
  EXPECT_EQ(g.direction.col(0), Vec3(0, -1, 0));
  EXPECT_EQ(g.direction.col(1), Vec3(0, 0, -1));
  EXPECT_EQ(g.direction.col(2), Vec3(-1, 0, 0));
}

// ---- MetaImage files written by others ----------------------------------------------------------

TEST(MetaImageRead, TwoDimensionalImageIsOneSliceThick) {
  ScratchDir dir;
  const std::string path = dir.file("slice.mha");
  const uint16_t voxels[6] = {0, 1, 2, 65535, 1000, 7};
  std::string data(reinterpret_cast<const char*>(voxels), sizeof voxels);
  write_bytes(path,
              "ObjectType = Image\nNDims = 2\nBinaryData = True\nBinaryDataByteOrderMSB = False\n"
              "TransformMatrix = 0 -1 1 0\nOffset = 1.5 -2\nElementSpacing = 0.5 0.25\nDimSize = 3 2\n"
              "ElementType = MET_USHORT\nElementDataFile = LOCAL\n" +
                  data);
  const Volume v = read_volume(path);
  ASSERT_EQ(v.type(), VoxelType::UInt16);
  EXPECT_EQ(v.geometry().dims, (Index3{3, 2, 1}));
  EXPECT_EQ(v.geometry().spacing_mm, Vec3(0.5, 0.25, 1.0));
  EXPECT_EQ(v.geometry().origin_mm, Vec3(-1.5, 2.0, 0.0));
  EXPECT_EQ(v.geometry().direction.col(0), Vec3(0, 1, 0));    // LPS (0, -1): Anterior
  EXPECT_EQ(v.geometry().direction.col(1), Vec3(-1, 0, 0));   // LPS (1, 0): Left
  EXPECT_EQ(v.geometry().direction.col(2), Vec3(0, 0, 1));
  EXPECT_EQ(0, std::memcmp(v.raw(), voxels, sizeof voxels));
}

std::string big_endian(const void* p, size_t width, size_t count) {
  std::string out(static_cast<const char*>(p), width * count);
  for (size_t i = 0; i < count; ++i) std::reverse(out.begin() + i * width, out.begin() + (i + 1) * width);
  return out;   // the tests run on little-endian hosts
}

TEST(MetaImageRead, BigEndianDataIsSwapped) {
  ScratchDir dir;
  const int16_t shorts[6] = {1, -2, 300, -32768, 32767, 258};
  const std::string shorts_path = dir.file("msb_short.mha");
  write_bytes(shorts_path, "NDims = 3\nBinaryDataByteOrderMSB = True\nDimSize = 3 2 1\nElementType = MET_SHORT\n"
                           "ElementDataFile = LOCAL\n" + big_endian(shorts, 2, 6));
  const Volume s = read_volume(shorts_path);
  ASSERT_EQ(s.type(), VoxelType::Int16);
  EXPECT_EQ(0, std::memcmp(s.raw(), shorts, sizeof shorts));

  const double doubles[2] = {-1.5e300, std::numeric_limits<double>::denorm_min()};
  const std::string doubles_path = dir.file("msb_double.mha");
  write_bytes(doubles_path, "NDims = 3\nElementByteOrderMSB = True\nDimSize = 1 1 2\nElementType = MET_DOUBLE\n"
                            "ElementDataFile = LOCAL\n" + big_endian(doubles, 8, 2));
  const Volume d = read_volume(doubles_path);
  ASSERT_EQ(d.type(), VoxelType::Float64);
  EXPECT_EQ(0, std::memcmp(d.raw(), doubles, sizeof doubles));
}

TEST(MetaImageRead, SplitHeaderWithSkippedBytesAndAliases) {
  ScratchDir dir;
  const float voxels[4] = {1.5f, -2.0f, 0.25f, 1e30f};
  write_bytes(dir.file("data.raw"), std::string(16, 'x') + std::string(reinterpret_cast<const char*>(voxels), 16));
  const std::string path = dir.file("split.mhd");
  // Keys MetaIO tolerates: aliases, ElementSize for spacing, padding whitespace, CRLF, unknown keys.
  write_bytes(path, "ObjectType = Image\r\n  NDims=3\r\nModality = MET_MOD_CT\r\nPosition = 1 2 3\r\n"
                    "Orientation = 1 0 0 0 1 0 0 0 1\r\nElementSize = 2 2 4\r\nSomeVendorKey = whatever\r\n"
                    "HeaderSize = 16\r\nDimSize =   2 2 1 \r\nElementType = MET_FLOAT\r\n"
                    "ElementDataFile = data.raw\r\n");
  const Volume v = read_volume(path);
  EXPECT_EQ(v.geometry().spacing_mm, Vec3(2, 2, 4));
  EXPECT_EQ(v.geometry().origin_mm, Vec3(-1, -2, 3));
  EXPECT_EQ(0, std::memcmp(v.raw(), voxels, sizeof voxels));
}

TEST(MetaImageRead, DataFileNamesAreTakenLiterally) {
  // Only "LIST" as a word and %-patterns mean one file per slice; "local" in any case means LOCAL.
  ScratchDir dir;
  write_bytes(dir.file("LISTING data.raw"), "\x2a");
  write_bytes(dir.file("spaced.mhd"), "NDims = 3\nDimSize = 1 1 1\nElementType = MET_UCHAR\n"
                                      "ElementDataFile = LISTING data.raw\n");
  EXPECT_EQ(read_volume(dir.file("spaced.mhd")).value(0), 42.0);
  write_bytes(dir.file("lower.mha"), "NDims = 3\nDimSize = 1 1 1\nElementType = MET_UCHAR\n"
                                     "ElementDataFile = local\n\x07");
  EXPECT_EQ(read_volume(dir.file("lower.mha")).value(0), 7.0);
}

TEST(MetaImageRead, HeaderSizeMinusOneMeansDataEndsTheFile) {
  ScratchDir dir;
  const uint8_t voxels[3] = {9, 8, 7};
  const std::string path = dir.file("tail.mhd");
  write_bytes(dir.file("tail.raw"), "some vendor preamble" + std::string(reinterpret_cast<const char*>(voxels), 3));
  write_bytes(path, "NDims = 3\nHeaderSize = -1\nDimSize = 3 1 1\nElementType = MET_UCHAR\nElementDataFile = tail.raw");
  const Volume v = read_volume(path);
  EXPECT_EQ(0, std::memcmp(v.raw(), voxels, 3));
}

TEST(MetaImageRead, CompressedWithoutSizeReadsToTheEnd) {
  ScratchDir dir;
  const int32_t voxels[5] = {-1, 2, -3, 4, std::numeric_limits<int32_t>::min()};
  std::string packed(compressBound(sizeof voxels), '\0');
  uLongf packed_bytes = packed.size();
  ASSERT_EQ(Z_OK, compress(reinterpret_cast<Bytef*>(packed.data()), &packed_bytes,
                           reinterpret_cast<const Bytef*>(voxels), sizeof voxels));
  packed.resize(packed_bytes);
  const std::string path = dir.file("packed.mha");
  write_bytes(path, "NDims = 3\nCompressedData = True\nDimSize = 5 1 1\nElementType = MET_INT\n"
                    "ElementDataFile = LOCAL\n" + packed);
  const Volume v = read_volume(path);
  EXPECT_EQ(0, std::memcmp(v.raw(), voxels, sizeof voxels));
}

TEST(MetaImageRead, NonUnitTransformMatrixKeepsItsIndexToWorldMapping) {
  ScratchDir dir;
  const std::string path = dir.file("scaled.mha");
  write_bytes(path, "NDims = 3\nTransformMatrix = 2 0 0 0 1 0 0 0 1\nElementSpacing = 0.5 1 1\nDimSize = 1 1 1\n"
                    "ElementType = MET_UCHAR\nElementDataFile = LOCAL\n\x01");
  const Geometry g = read_volume(path).geometry();
  EXPECT_EQ(g.spacing_mm, Vec3(1, 1, 1));
  EXPECT_EQ(g.direction.col(0), Vec3(-1, 0, 0));
}

// ---- what the MetaImage writer puts on disk -----------------------------------------------------

TEST(MetaImageWrite, HeaderIsLittleEndianLpsWithAnatomicalOrientation) {
  ScratchDir dir;
  Geometry g;   // RAS identity: LPS direction diag(-1, -1, 1)
  g.dims = {2, 1, 1};
  const Volume v = random_volume(g, VoxelType::Int16, 5);
  const std::string path = dir.file("ras.mha");
  write_volume(v, path);
  const std::string text = read_bytes(path);
  EXPECT_NE(text.find("ObjectType = Image\n"), std::string::npos);
  EXPECT_NE(text.find("BinaryDataByteOrderMSB = False\n"), std::string::npos);
  EXPECT_NE(text.find("TransformMatrix = -1 0 0 0 -1 0 0 0 1\n"), std::string::npos) << text;
  EXPECT_NE(text.find("AnatomicalOrientation = LPI\n"), std::string::npos) << text;
  EXPECT_NE(text.find("ElementType = MET_SHORT\n"), std::string::npos);
  const std::string tail = "ElementDataFile = LOCAL\n" + std::string(static_cast<const char*>(v.raw()), 4);
  EXPECT_EQ(text.substr(text.size() - tail.size()), tail);
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"ras.mha"});
}

TEST(MetaImageWrite, SplitFilesSitSideBySide) {
  ScratchDir dir;
  Geometry g;
  g.dims = {4, 3, 2};
  g.direction = Vec3(-1, -1, 1).asDiagonal();   // LPS identity
  const Volume v = random_volume(g, VoxelType::UInt8, 9);
  write_volume(v, dir.file("plain.mhd"));
  write_volume(v, dir.file("packed.mhd"), WriteOptions{true});
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{"packed.mhd", "packed.zraw", "plain.mhd", "plain.raw"}));
  EXPECT_NE(read_bytes(dir.file("plain.mhd")).find("AnatomicalOrientation = RAI\n"), std::string::npos);
  EXPECT_NE(read_bytes(dir.file("plain.mhd")).find("ElementDataFile = plain.raw\n"), std::string::npos);
  EXPECT_NE(read_bytes(dir.file("packed.mhd")).find("ElementDataFile = packed.zraw\n"), std::string::npos);
  EXPECT_EQ(read_bytes(dir.file("plain.raw")), std::string(static_cast<const char*>(v.raw()), v.byte_count()));
  EXPECT_TRUE(read_volume(dir.file("packed.mhd")).same_voxels(v));
}

}  // namespace
}  // namespace pneumo
