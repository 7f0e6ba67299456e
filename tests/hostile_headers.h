#pragma once
// A generator of volume files whose headers promise sizes that are zero, negative, overflowing or
// absurd, in every format pneumo reads (NIfTI-1, plain and gzip; MetaImage with local, compressed
// and separate data; NRRD raw, gzip and with a detached header; NIfTI-2 is refused by its magic
// before any size is read), each with a payload of a few bytes. The hand-written cases of
// test_io_bad_input.cpp each hit one check; this crosses every size with every format and voxel
// type, so a reader added later (NRRD, DICOM) is held to the same by adding its writer here.
// Used by test_hostile_headers.cpp and by the fuzzers' seed corpus (fuzz/make_seeds.cpp).
#include <nifti1.h>
#include <zlib.h>

#include <algorithm>

#include <array>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "nifti_test_header.h"

namespace pneumo::hostile {

struct HostileFile {
  std::string name;   // file name; its extension picks the format
  std::string bytes;  // the whole file
  std::string data_file_name, data_bytes;   // a separate data file (MetaImage .mhd), or empty
};

/// Sizes no reader may accept or allocate: each axis in turn zero, negative or beyond 2^20, and
/// products that overflow 64 bits or exceed every cap (as int64; the NIfTI-1 writer clamps to 16 bits).
inline std::vector<std::array<int64_t, 3>> hostile_dims() {
  const int64_t big = int64_t(1) << 32, huge = std::numeric_limits<int64_t>::max();
  std::vector<std::array<int64_t, 3>> out;
  for (int64_t bad : {int64_t(0), int64_t(-1), int64_t(-32768), (int64_t(1) << 20) + 1, big, huge})
    for (int axis = 0; axis < 3; ++axis) {
      std::array<int64_t, 3> d{4, 4, 4};
      d[axis] = bad;
      out.push_back(d);
    }
  out.push_back({big, big, 16});                  // 2^68 voxels: 0 in 64 bits
  out.push_back({int64_t(1) << 21, int64_t(1) << 21, int64_t(1) << 22});   // 2^64 exactly
  out.push_back({32767, 32767, 32767});           // NIfTI-1's largest: 3.5e13 voxels
  out.push_back({1 << 20, 1 << 12, 1 << 4});      // 2^36 voxels: within the axis caps, past the total
  out.push_back({1 << 14, 1 << 14, 1 << 5});      // 2^33 voxels: many GiB promised, 64 bytes held
  return out;
}

/// The voxel types, as NIfTI codes with their bits, MetaImage and NRRD names.
struct HostileType {
  short nifti_code, bits;
  const char* meta_name;
  const char* nrrd_name;
};
inline std::vector<HostileType> hostile_types() {
  return {{DT_UINT8, 8, "MET_UCHAR", "uchar"}, {DT_INT16, 16, "MET_SHORT", "short"},
          {DT_FLOAT32, 32, "MET_FLOAT", "float"}, {DT_FLOAT64, 64, "MET_DOUBLE", "double"}};
}

inline const std::string& small_payload() {
  static const std::string p(64, '\x01');
  return p;
}

inline std::string gzip(const std::string& data) {
  z_stream s{};
  deflateInit2(&s, 6, Z_DEFLATED, 15 + 16, 8, Z_DEFAULT_STRATEGY);   // 15 + 16: a gzip wrapper
  std::string out(deflateBound(&s, uLong(data.size())) + 32, '\0');
  s.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(data.data()));
  s.avail_in = uInt(data.size());
  s.next_out = reinterpret_cast<Bytef*>(out.data());
  s.avail_out = uInt(out.size());
  deflate(&s, Z_FINISH);
  out.resize(s.total_out);
  deflateEnd(&s);
  return out;
}

inline std::string nifti1_bytes(const std::array<int64_t, 3>& d, const HostileType& t) {
  auto clamp16 = [](int64_t v) {
    return int(std::max<int64_t>(std::numeric_limits<short>::min(), std::min<int64_t>(v, 32767)));
  };
  const nifti_1_header h =
      testing_support::nifti1_test_header(clamp16(d[0]), clamp16(d[1]), clamp16(d[2]), t.nifti_code, t.bits);
  return std::string(reinterpret_cast<const char*>(&h), sizeof h) + std::string(4, '\0') + small_payload();
}

inline std::string meta_header(const std::array<int64_t, 3>& d, const HostileType& t, const std::string& extra,
                               const std::string& data_file) {
  return "ObjectType = Image\nNDims = 3\nBinaryData = True\nBinaryDataByteOrderMSB = False\nDimSize = " +
         std::to_string(d[0]) + " " + std::to_string(d[1]) + " " + std::to_string(d[2]) +
         "\nElementSpacing = 1 1 1\nElementType = " + t.meta_name + "\n" + extra + "ElementDataFile = " + data_file +
         "\n";
}

inline std::string nrrd_header(const std::array<int64_t, 3>& d, const HostileType& t, const std::string& encoding,
                               const std::string& data_file) {
  return "NRRD0004\ntype: " + std::string(t.nrrd_name) + "\ndimension: 3\nspace: left-posterior-superior\nsizes: " +
         std::to_string(d[0]) + " " + std::to_string(d[1]) + " " + std::to_string(d[2]) +
         "\nspace directions: (1,0,0) (0,1,0) (0,0,1)\nspace origin: (0,0,0)\nendian: little\nencoding: " + encoding +
         "\n" + (data_file.empty() ? "\n" : "data file: " + data_file + "\n");
}

/// The formats, by the suffix their file names end with.
inline const std::vector<std::string>& hostile_formats() {
  static const std::vector<std::string> f{"_n1.nii",   "_n1.nii.gz", "_local.mha", "_z.mha",
                                          "_split.mhd", "_raw.nrrd", "_gz.nrrd",   "_split.nhdr"};
  return f;
}

/// One file: `stem` + the format's suffix, of size `d` and type `t`, holding small_payload().
inline HostileFile hostile_file(const std::string& stem, const std::string& format, const std::array<int64_t, 3>& d,
                                const HostileType& t) {
  const std::string name = stem + format;
  if (format == "_n1.nii") return {name, nifti1_bytes(d, t), "", ""};
  if (format == "_n1.nii.gz") return {name, gzip(nifti1_bytes(d, t)), "", ""};
  if (format == "_local.mha") return {name, meta_header(d, t, "", "LOCAL") + small_payload(), "", ""};
  if (format == "_z.mha") {
    const std::string z = gzip(small_payload());
    return {name, meta_header(d, t, "CompressedData = True\nCompressedDataSize = " + std::to_string(z.size()) + "\n", "LOCAL") + z,
            "", ""};
  }
  if (format == "_split.mhd") return {name, meta_header(d, t, "", stem + "_split.raw"), stem + "_split.raw", small_payload()};
  if (format == "_raw.nrrd") return {name, nrrd_header(d, t, "raw", "") + small_payload(), "", ""};
  if (format == "_gz.nrrd") return {name, nrrd_header(d, t, "gzip", "") + gzip(small_payload()), "", ""};
  return {name, nrrd_header(d, t, "raw", stem + "_nrrd.raw"), stem + "_nrrd.raw", small_payload()};
}

/// Every format × every size × every type: 8 formats, 23 sizes, 4 types.
inline std::vector<HostileFile> hostile_files() {
  std::vector<HostileFile> out;
  const auto dims = hostile_dims();
  for (std::size_t i = 0; i < dims.size(); ++i)
    for (const HostileType& t : hostile_types())
      for (const std::string& format : hostile_formats())
        out.push_back(hostile_file("d" + std::to_string(i) + "_" + std::to_string(t.bits), format, dims[i], t));
  return out;
}

/// The control: dims whose voxels fill small_payload() exactly (64 bytes) for type t, which every
/// format must read. Without it a generator whose files were broken some other way would pass.
inline std::array<int64_t, 3> fitting_dims(const HostileType& t) {
  const int64_t n = 512 / t.bits;   // voxels in 64 bytes: 8 to 64
  return {4, std::min<int64_t>(4, n / 4), std::max<int64_t>(1, n / 16)};
}

}  // namespace pneumo::hostile
