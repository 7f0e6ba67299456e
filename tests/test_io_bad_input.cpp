// Every malformed volume file is refused with an InputError that names the file and the problem,
// quickly and without allocating what the header promises; failed writes leave nothing behind.
#include <gtest/gtest.h>
#include <nifti1.h>
#include <zlib.h>

#include <cstring>
#include <functional>
#include <limits>
#include <ostream>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "core/error.h"
#include "io/volume_io.h"
#include "io_test_support.h"

namespace pneumo {
namespace {

using testing_support::read_bytes;
using testing_support::ScratchDir;
using testing_support::write_bytes;

std::string random_bytes(size_t n, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::string s(n, '\0');
  for (char& c : s) c = static_cast<char>(rng() & 0xff);
  return s;
}

std::string zlib_compress(const std::string& data) {
  std::string out(compressBound(data.size()), '\0');
  uLongf n = out.size();
  compress(reinterpret_cast<Bytef*>(out.data()), &n, reinterpret_cast<const Bytef*>(data.data()), data.size());
  out.resize(n);
  return out;
}

// ---- MetaImage ---------------------------------------------------------------------------------

/// A valid header for 10 x 10 x 10 MET_SHORT with LOCAL data, to be spoiled one key at a time.
class MetaText {
 public:
  MetaText() {
    lines_ = {{"ObjectType", "Image"},  {"NDims", "3"},           {"BinaryData", "True"},
              {"DimSize", "10 10 10"}, {"ElementSpacing", "1 1 1"}, {"ElementType", "MET_SHORT"},
              {"ElementDataFile", "LOCAL"}};
  }
  MetaText& set(const std::string& key, const std::string& value) {
    for (auto& kv : lines_)
      if (kv.first == key) { kv.second = value; return *this; }
    lines_.insert(lines_.end() - 1, {key, value});
    return *this;
  }
  MetaText& erase(const std::string& key) {
    for (auto it = lines_.begin(); it != lines_.end(); ++it)
      if (it->first == key) { lines_.erase(it); break; }
    return *this;
  }
  std::string str() const {
    std::string s;
    for (const auto& kv : lines_) s += kv.first + " = " + kv.second + "\n";
    return s;
  }

 private:
  std::vector<std::pair<std::string, std::string>> lines_;
};

constexpr size_t kShortVolumeBytes = 10 * 10 * 10 * 2;
const std::string kGoodShortData(kShortVolumeBytes, '\x01');

/// Writes `name` holding header + data into the folder and returns its path.
std::string meta_file(const ScratchDir& dir, const std::string& name, const MetaText& header,
                      const std::string& data = kGoodShortData) {
  const std::string path = dir.file(name);
  write_bytes(path, header.str() + data);
  return path;
}

// ---- NIfTI -------------------------------------------------------------------------------------

nifti_1_header nifti_header(int nx, int ny, int nz, short datatype, short bitpix) {
  return testing_support::nifti1_test_header(nx, ny, nz, datatype, bitpix);
}

nifti_1_header good_nifti_header() { return nifti_header(10, 10, 10, DT_INT16, 16); }

std::string nifti_bytes(const nifti_1_header& h, const std::string& data = kGoodShortData) {
  return std::string(reinterpret_cast<const char*>(&h), sizeof h) + std::string(4, '\0') + data;
}

std::string nifti_file(const ScratchDir& dir, const std::string& name, const nifti_1_header& h,
                       const std::string& data = kGoodShortData) {
  const std::string path = dir.file(name);
  write_bytes(path, nifti_bytes(h, data));
  return path;
}

/// A valid .nii.gz of random voxels (so it barely compresses), cut to half its length.
std::string truncated_nifti_gz(const ScratchDir& dir) {
  const std::string path = dir.file("cut.nii.gz");
  const nifti_1_header h = nifti_header(20, 20, 20, DT_INT16, 16);
  const std::string whole = nifti_bytes(h, random_bytes(20 * 20 * 20 * 2, 11));
  gzFile gz = gzopen(path.c_str(), "wb");
  EXPECT_NE(gz, nullptr);
  gzwrite(gz, whole.data(), static_cast<unsigned>(whole.size()));
  gzclose(gz);
  const std::string packed = read_bytes(path);
  write_bytes(path, packed.substr(0, packed.size() / 2));
  return path;
}

// ---- the table ---------------------------------------------------------------------------------

struct BadInput {
  std::string name;
  std::function<std::string(const ScratchDir&)> make;   // writes the bad file, returns the path to read
  std::string expected;                                  // a substring of the error message
};

std::vector<BadInput> bad_inputs() {
  using D = const ScratchDir&;
  return {
      // MetaImage
      {"meta_truncated_data", [](D d) { return meta_file(d, "a.mha", MetaText(), std::string(100, '\x01')); },
       "truncated"},
      {"meta_absurd_dims",
       [](D d) { return meta_file(d, "a.mha", MetaText().set("DimSize", "100000 100000 100000")); }, "absurd"},
      // 2 bytes × 2^32 × 2^32 × 16 is 0 in 64 bits: once read as "0 voxels", then a crash in the padding.
      {"meta_overflowing_dims",
       [](D d) { return meta_file(d, "a.mha", MetaText().set("DimSize", "4294967296 4294967296 16")); }, "absurd"},
      {"meta_zero_dim", [](D d) { return meta_file(d, "a.mha", MetaText().set("DimSize", "10 0 10")); },
       "must be at least 1"},
      {"meta_zero_spacing", [](D d) { return meta_file(d, "a.mha", MetaText().set("ElementSpacing", "1 0 1")); },
       "ElementSpacing along axis 1 is 0"},
      {"meta_negative_spacing",
       [](D d) { return meta_file(d, "a.mha", MetaText().set("ElementSpacing", "1 1 -2")); },
       "ElementSpacing along axis 2 is -2"},
      {"meta_nan_offset", [](D d) { return meta_file(d, "a.mha", MetaText().set("Offset", "0 nan 0")); },
       "Offset value 'nan' is not finite"},
      {"meta_infinite_matrix",
       [](D d) { return meta_file(d, "a.mha", MetaText().set("TransformMatrix", "1 0 0 0 inf 0 0 0 1")); },
       "not finite"},
      {"meta_degenerate_matrix",
       [](D d) { return meta_file(d, "a.mha", MetaText().set("TransformMatrix", "1 0 0 1 0 0 0 0 1")); },
       "degenerate"},
      {"meta_zero_matrix_column",
       [](D d) { return meta_file(d, "a.mha", MetaText().set("TransformMatrix", "1 0 0 0 0 0 0 0 1")); },
       "degenerate"},
      {"meta_unknown_element_type",
       [](D d) { return meta_file(d, "a.mha", MetaText().set("ElementType", "MET_BANANA")); },
       "unknown ElementType"},
      {"meta_long_element_type", [](D d) { return meta_file(d, "a.mha", MetaText().set("ElementType", "MET_LONG")); },
       "unsupported ElementType MET_LONG"},
      {"meta_missing_element_data_file",
       [](D d) { return meta_file(d, "a.mha", MetaText().erase("ElementDataFile")); }, "missing ElementDataFile"},
      {"meta_missing_element_data_file_text_only",
       [](D d) { return meta_file(d, "a.mha", MetaText().erase("ElementDataFile"), ""); }, "missing ElementDataFile"},
      {"meta_array_element_type",
       [](D d) { return meta_file(d, "a.mha", MetaText().set("ElementType", "MET_FLOAT_ARRAY")); },
       "unsupported ElementType"},
      {"meta_missing_dim_size", [](D d) { return meta_file(d, "a.mha", MetaText().erase("DimSize")); },
       "missing DimSize"},
      {"meta_missing_element_type", [](D d) { return meta_file(d, "a.mha", MetaText().erase("ElementType")); },
       "missing ElementType"},
      {"meta_missing_ndims", [](D d) { return meta_file(d, "a.mha", MetaText().erase("NDims")); }, "missing NDims"},
      {"meta_four_ndims",
       [](D d) { return meta_file(d, "a.mha", MetaText().set("NDims", "4").set("DimSize", "10 10 10 1")); },
       "NDims is 4"},
      {"meta_too_few_dims", [](D d) { return meta_file(d, "a.mha", MetaText().set("DimSize", "10 10")); },
       "DimSize has 2 values, expected 3"},
      {"meta_too_many_spacings",
       [](D d) { return meta_file(d, "a.mha", MetaText().set("ElementSpacing", "1 1 1 1")); },
       "ElementSpacing has 4 values"},
      {"meta_non_numeric_spacing",
       [](D d) { return meta_file(d, "a.mha", MetaText().set("ElementSpacing", "1 abc 1")); }, "not a number"},
      {"meta_fractional_dim", [](D d) { return meta_file(d, "a.mha", MetaText().set("DimSize", "10 10.5 10")); },
       "not an integer"},
      {"meta_huge_dim_value",
       [](D d) { return meta_file(d, "a.mha", MetaText().set("DimSize", "10 99999999999999999999999 10")); },
       "not an integer"},
      {"meta_missing_raw",
       [](D d) { return meta_file(d, "a.mhd", MetaText().set("ElementDataFile", "gone.raw"), ""); },
       "data file 'gone.raw' does not exist"},
      {"meta_raw_is_a_folder",
       [](D d) {
         std::filesystem::create_directory(d.file("folder.raw"));
         return meta_file(d, "a.mhd", MetaText().set("ElementDataFile", "folder.raw"), "");
       },
       "is a folder"},
      {"meta_short_raw",
       [](D d) {
         write_bytes(d.file("short.raw"), std::string(kShortVolumeBytes - 1, '\0'));
         return meta_file(d, "a.mhd", MetaText().set("ElementDataFile", "short.raw"), "");
       },
       "truncated"},
      {"meta_corrupt_compressed",
       [](D d) { return meta_file(d, "a.mha", MetaText().set("CompressedData", "True"), random_bytes(300, 1)); },
       "corrupt/truncated compressed data"},
      {"meta_compressed_too_short",
       [](D d) {
         return meta_file(d, "a.mha", MetaText().set("CompressedData", "True"),
                          zlib_compress(std::string(kShortVolumeBytes / 2, '\x02')));
       },
       "corrupt/truncated compressed data"},
      {"meta_compressed_too_long",
       [](D d) {
         return meta_file(d, "a.mha", MetaText().set("CompressedData", "True"),
                          zlib_compress(std::string(kShortVolumeBytes + 2, '\x02')));
       },
       "corrupt/truncated compressed data"},
      {"meta_compressed_stream_cut",
       [](D d) {
         const std::string packed = zlib_compress(random_bytes(kShortVolumeBytes, 2));
         const std::string cut = packed.substr(0, packed.size() / 2);
         return meta_file(d, "a.mha",
                          MetaText().set("CompressedData", "True").set("CompressedDataSize", std::to_string(cut.size())),
                          cut);
       },
       "corrupt/truncated compressed data"},
      {"meta_compressed_size_beyond_file",
       [](D d) {
         return meta_file(d, "a.mha", MetaText().set("CompressedData", "True").set("CompressedDataSize", "100000"),
                          zlib_compress(kGoodShortData));
       },
       "truncated"},
      {"meta_compression_ratio_impossible",
       [](D d) {
         return meta_file(d, "a.mha",
                          MetaText().set("DimSize", "1000 1000 500").set("CompressedData", "True")
                              .set("CompressedDataSize", "10"),
                          std::string(10, '\0'));
       },
       "compressed bytes cannot hold"},
      {"meta_header_size_beyond_file",
       [](D d) { return meta_file(d, "a.mha", MetaText().set("HeaderSize", "100000")); }, "truncated"},
      {"meta_header_size_negative", [](D d) { return meta_file(d, "a.mha", MetaText().set("HeaderSize", "-7")); },
       "HeaderSize is -7"},
      {"meta_binary_garbage",
       [](D d) {
         const std::string path = d.file("garbage.mha");
         write_bytes(path, random_bytes(4096, 3));
         return path;
       },
       "not a MetaImage header"},
      {"meta_plain_text",
       [](D d) {
         const std::string path = d.file("text.mha");
         write_bytes(path, "hello world\nthis is not an image\n");
         return path;
       },
       "not a MetaImage header"},
      {"meta_endless_header",
       [](D d) {
         std::string text;
         while (text.size() <= (1u << 20)) text += "Comment = padding padding padding padding padding\n";
         const std::string path = d.file("endless.mha");
         write_bytes(path, text);
         return path;
       },
       "not a MetaImage header"},
      {"meta_empty_file",
       [](D d) {
         const std::string path = d.file("empty.mha");
         write_bytes(path, "");
         return path;
       },
       "empty"},
      {"meta_folder_instead_of_file",
       [](D d) {
         std::filesystem::create_directory(d.file("dir.mha"));
         return d.file("dir.mha");
       },
       "is a folder"},
      {"meta_missing_file", [](D d) { return d.file("nowhere.mha"); }, "does not exist"},
      {"meta_four_channels",
       [](D d) {
         return meta_file(d, "a.mha", MetaText().set("ElementNumberOfChannels", "4"), kGoodShortData + kGoodShortData +
                                                                                      kGoodShortData + kGoodShortData);
       },
       "ElementNumberOfChannels is 4"},
      {"meta_list_of_slices",
       [](D d) { return meta_file(d, "a.mhd", MetaText().set("ElementDataFile", "LIST"), "slice0.raw\n"); },
       "unsupported"},
      {"meta_slice_pattern",
       [](D d) { return meta_file(d, "a.mhd", MetaText().set("ElementDataFile", "slice%03d.raw 1 10 1"), ""); },
       "unsupported"},
      {"meta_not_an_image", [](D d) { return meta_file(d, "a.mha", MetaText().set("ObjectType", "Mesh")); },
       "ObjectType"},
      {"meta_ascii_data", [](D d) { return meta_file(d, "a.mha", MetaText().set("BinaryData", "False")); },
       "BinaryData = False"},
      {"meta_bad_boolean",
       [](D d) { return meta_file(d, "a.mha", MetaText().set("BinaryDataByteOrderMSB", "maybe")); },
       "expected True or False"},

      // NIfTI: the header is written by hand from nifti_1_header
      {"nifti_truncated_data", [](D d) { return nifti_file(d, "a.nii", good_nifti_header(), std::string(100, '\1')); },
       "truncated"},
      {"nifti_bad_magic",
       [](D d) {
         nifti_1_header h = good_nifti_header();
         std::memcpy(h.magic, "xyz\0", 4);
         return nifti_file(d, "a.nii", h);
       },
       "magic"},
      {"nifti_zero_pixdim_qform_only",
       [](D d) {
         nifti_1_header h = good_nifti_header();
         h.sform_code = NIFTI_XFORM_UNKNOWN;
         h.qform_code = NIFTI_XFORM_SCANNER_ANAT;
         h.pixdim[2] = 0.0f;
         return nifti_file(d, "a.nii", h);
       },
       "pixdim"},
      {"nifti_nonfinite_sform",
       [](D d) {
         nifti_1_header h = good_nifti_header();
         h.srow_y[3] = std::numeric_limits<float>::quiet_NaN();
         return nifti_file(d, "a.nii", h);
       },
       "not finite"},
      {"nifti_terabytes",
       [](D d) { return nifti_file(d, "a.nii", nifti_header(30000, 30000, 30000, DT_FLOAT64, 64)); }, "absurd"},
      {"nifti_four_dimensional",
       [](D d) {
         nifti_1_header h = good_nifti_header();
         h.dim[0] = 4;
         h.dim[4] = 3;
         return nifti_file(d, "a.nii", h, kGoodShortData + kGoodShortData + kGoodShortData);
       },
       "4-D"},
      {"nifti_gz_truncated", [](D d) { return truncated_nifti_gz(d); }, "truncated"},
      {"nifti_random_garbage",
       [](D d) {
         const std::string path = d.file("garbage.nii");
         write_bytes(path, random_bytes(4096, 4));
         return path;
       },
       "NIfTI"},
      {"nifti_empty_file",
       [](D d) {
         const std::string path = d.file("empty.nii");
         write_bytes(path, "");
         return path;
       },
       "too short"},
      {"nifti_complex64",
       [](D d) { return nifti_file(d, "a.nii", nifti_header(10, 10, 10, DT_COMPLEX64, 64), std::string(8000, '\0')); },
       "unsupported"},
  };
}

void PrintTo(const BadInput& row, std::ostream* os) { *os << row.name; }

class IoBadInput : public ::testing::TestWithParam<BadInput> {};

TEST_P(IoBadInput, IsRefusedWithAnInputErrorNamingTheFile) {
  const BadInput& row = GetParam();
  ScratchDir dir;
  const std::string path = row.make(dir);
  // No timing here (tests never assert on time): the absurd-header rows prove the refusal comes
  // before allocation by their message, which only the pre-allocation check writes.
  try {
    const Volume v = read_volume(path);
    ADD_FAILURE() << "read " << v.voxel_count() << " voxels from a bad file";
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_EQ(message.rfind(path + ": ", 0), 0u) << "message does not start with the path: " << message;
    EXPECT_NE(message.find(row.expected), std::string::npos)
        << "message lacks '" << row.expected << "': " << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << "message is not one line: " << message;
  } catch (const std::exception& e) {
    ADD_FAILURE() << "not an InputError: " << e.what();
  }
}

INSTANTIATE_TEST_SUITE_P(Table, IoBadInput, ::testing::ValuesIn(bad_inputs()),
                         [](const ::testing::TestParamInfo<BadInput>& info) { return info.param.name; });

Volume random_int16_volume() {
  Geometry g;
  g.dims = {4, 3, 2};
  g.spacing_mm = Vec3(0.5, 0.75, 2.0);
  g.origin_mm = Vec3(-10.0, 20.0, 30.5);
  Volume v(g, VoxelType::Int16);
  const std::string voxels = random_bytes(v.byte_count(), 5);
  std::memcpy(v.raw(), voxels.data(), voxels.size());
  return v;
}

/// Replaces `cut_path` by each proper prefix of `whole` in turn and expects `read_path` to be refused.
void expect_every_prefix_refused(const std::string& whole, const std::string& cut_path, const std::string& read_path) {
  for (size_t n = 0; n < whole.size(); ++n) {
    write_bytes(cut_path, whole.substr(0, n));
    try {
      read_volume(read_path);
      ADD_FAILURE() << "read a file cut to " << n << " of " << whole.size() << " bytes";
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()).rfind(read_path + ": ", 0), 0u) << e.what();
    } catch (const std::exception& e) {
      ADD_FAILURE() << "cut to " << n << " bytes: not an InputError: " << e.what();
    }
  }
}

/// Every proper prefix of a valid file (the usual result of an interrupted copy) must be refused
/// cleanly, wherever the cut falls: inside a key, a number, the data-file name or the voxels.
TEST(IoBadInputTruncation, EveryPrefixOfAValidFileIsAnInputError) {
  const Volume v = random_int16_volume();
  const struct {
    const char* name;
    bool compress;
  } kFiles[] = {{"whole.mha", false}, {"whole.mha", true}, {"whole.nii", false}};
  for (const auto& f : kFiles) {
    SCOPED_TRACE(std::string(f.name) + (f.compress ? " compressed" : ""));
    ScratchDir dir;
    write_volume(v, dir.file(f.name), WriteOptions{f.compress});
    ASSERT_TRUE(read_volume(dir.file(f.name)).same_voxels(v));
    const std::string cut = dir.file(std::string("cut_") + f.name);
    expect_every_prefix_refused(read_bytes(dir.file(f.name)), cut, cut);
  }
}

TEST(IoBadInputTruncation, EveryPrefixOfASplitDataFileIsAnInputError) {
  const Volume v = random_int16_volume();
  for (const bool compress : {false, true}) {
    SCOPED_TRACE(compress ? "zraw" : "raw");
    ScratchDir dir;
    write_volume(v, dir.file("split.mhd"), WriteOptions{compress});
    const std::string data = dir.file(compress ? "split.zraw" : "split.raw");
    expect_every_prefix_refused(read_bytes(data), data, dir.file("split.mhd"));
  }
}

/// Includes cuts inside gzip's 8-byte trailer (CRC-32 and length): the voxels may all be there, but
/// the file is still incomplete and its checksum unverified.
TEST(IoBadInputTruncation, EveryPrefixOfANiftiGzIsAnInputError) {
  const Volume v = random_int16_volume();
  ScratchDir dir;
  write_volume(v, dir.file("whole.nii.gz"));
  ASSERT_TRUE(read_volume(dir.file("whole.nii.gz")).same_voxels(v));
  const std::string cut = dir.file("cut.nii.gz");
  expect_every_prefix_refused(read_bytes(dir.file("whole.nii.gz")), cut, cut);
}

// ---- writes that fail --------------------------------------------------------------------------

Volume small_volume() {
  Geometry g;
  g.dims = {3, 2, 2};
  Volume v(g, VoxelType::Int16);
  std::memset(v.raw(), 0x11, v.byte_count());
  return v;
}

struct Target {
  const char* name;
  bool compress;
};
constexpr Target kTargets[] = {{"x.nii", false}, {"x.nii.gz", false}, {"x.mha", false},
                               {"x.mha", true},  {"x.mhd", false},    {"x.mhd", true}};

TEST(IoBadInputWrite, MissingFolderIsAnInputErrorAndLeavesNothing) {
  ScratchDir dir;
  for (const Target& t : kTargets) {
    SCOPED_TRACE(t.name);
    const std::string path = dir.file(std::string("no_such_folder/") + t.name);
    try {
      write_volume(small_volume(), path, WriteOptions{t.compress});
      ADD_FAILURE() << "wrote into a missing folder";
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()).rfind(path + ": ", 0), 0u) << e.what();
    } catch (const std::exception& e) {
      ADD_FAILURE() << "not an InputError: " << e.what();
    }
    EXPECT_TRUE(dir.entries().empty());
  }
}

TEST(IoBadInputWrite, FailedWriteLeavesNoTemporaryFile) {
  for (const Target& t : kTargets) {
    SCOPED_TRACE(std::string(t.name) + (t.compress ? " compressed" : ""));
    ScratchDir dir;
    // A folder where the file should go: everything is written, then the final rename fails.
    std::filesystem::create_directory(dir.file(t.name));
    EXPECT_ANY_THROW(write_volume(small_volume(), dir.file(t.name), WriteOptions{t.compress}));
    EXPECT_EQ(dir.entries(), std::vector<std::string>{t.name});
    EXPECT_TRUE(std::filesystem::is_empty(dir.file(t.name)));
  }
}

TEST(IoBadInputWrite, UnknownExtensionIsAnInputError) {
  ScratchDir dir;
  EXPECT_THROW(write_volume(small_volume(), dir.file("x.png")), InputError);
  EXPECT_THROW(read_volume(dir.file("x.png")), InputError);
  EXPECT_TRUE(dir.entries().empty());
}

}  // namespace
}  // namespace pneumo
