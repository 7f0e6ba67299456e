// MetaImage (.mha, or .mhd + .raw/.zraw), read and written by hand: ITK is not a dependency.
// The header is text, `Key = Value` lines up to ElementDataFile; the voxels follow in the same file
// (LOCAL) or sit in a file beside the header. Every promise the header makes (sizes, offsets,
// compressed lengths) is checked against the file before anything it promises is allocated.
//
// World frame: ITK/MetaIO positions are LPS+, pneumo's Geometry is RAS+, so the x and y components of
// the origin and of each direction column change sign on the way in and out.
//
// TransformMatrix layout, checked against ITK's itkMetaImageIO.cxx (InsightSoftwareConsortium/ITK,
// Modules/IO/Meta/src/itkMetaImageIO.cxx): ReadImageInformation() does
//   directionAxis[jj] = transformMatrix[ii * nDims + jj];  SetDirection(ii, directionAxis);
// and Write() does transformMatrix[ii * nDims + jj] = GetDirection(ii)[jj]. So the values list the
// direction of voxel axis 0, then axis 1, then axis 2: row r of the written matrix is column r of
// ITK's direction matrix. AnatomicalOrientation is informational: MetaIO writes, per axis, the first
// letter of its from-to pair (MET_OrientationTypeName in metaTypes.h), i.e. the side the axis comes
// from, so an identity (LPS) direction is written "RAI".
#include <zlib.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <iterator>
#include <locale>
#include <map>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <system_error>
#include <vector>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/input_file.h"
#include "io/volume_io.h"

namespace fs = std::filesystem;

namespace pneumo {

namespace {

constexpr uint64_t kMaxHeaderBytes = 1ull << 20;
// Deflate cannot expand more than about 1032:1; a stream promising more is corrupt or truncated.
constexpr uint64_t kMaxDeflateRatio = 1032;
constexpr uint64_t kDeflateSlackBytes = 1024;
// zlib counts bytes in 32-bit uInt, and stdio reads are clearer in bounded pieces.
constexpr uint64_t kIoChunkBytes = 64ull << 20;
constexpr int kCompressionLevel = 2;   // ITK's default for MetaImage: fast, most of the gain on CT

using Fields = std::map<std::string, std::string>;

struct FileCloser {
  void operator()(std::FILE* f) const { if (f) std::fclose(f); }
};
using FilePtr = std::unique_ptr<std::FILE, FileCloser>;

bool host_is_msb() {
  const uint16_t one = 1;
  unsigned char first = 0;
  std::memcpy(&first, &one, 1);
  return first == 0;
}

std::string trim(const std::string& s) {
  const char* ws = " \t\r\n\f\v";
  const auto b = s.find_first_not_of(ws);
  if (b == std::string::npos) return "";
  return s.substr(b, s.find_last_not_of(ws) - b + 1);
}

std::vector<std::string> split_words(const std::string& s) {
  std::istringstream is(s);
  std::vector<std::string> words;
  for (std::string w; is >> w;) words.push_back(w);
  return words;
}

/// Size of a regular file (core/input_file.h): folders, FIFOs and devices are refused before they
/// are opened (reading one could block forever, or never end).
uint64_t regular_file_size(const std::string& reported_path, const std::string& path, const std::string& what) {
  return require_regular_file(path, what, reported_path);
}

/// The file opened as the regular-file check opens it: what is read is what was checked.
FilePtr open_for_reading(const std::string& reported_path, const std::string& path, const std::string& what) {
  return FilePtr(InputFile(path, what, reported_path).release_to_stdio());
}

void seek_to(const std::string& reported_path, std::FILE* f, uint64_t offset) {
  if (::fseeko(f, static_cast<off_t>(offset), SEEK_SET) != 0)
    throw file_error(reported_path, "cannot seek to the voxel data: " + std::string(std::strerror(errno)));
}

/// Reads exactly n bytes; a short read means the file shrank or failed under us.
void read_exactly(const std::string& reported_path, std::FILE* f, void* dst, uint64_t n) {
  auto* out = static_cast<unsigned char*>(dst);
  for (uint64_t done = 0; done < n;) {
    const size_t want = static_cast<size_t>(std::min(kIoChunkBytes, n - done));
    const size_t got = std::fread(out + done, 1, want, f);
    done += got;
    if (got != want) {
      std::ostringstream os;
      os << "truncated voxel data: read " << done << " of " << n << " bytes";
      throw file_error(reported_path, os.str());
    }
  }
}

// ---- header text -------------------------------------------------------------------------------

struct RawHeader {
  Fields fields;              // every key before ElementDataFile (the last occurrence wins, as in MetaIO)
  std::string data_file;      // the ElementDataFile value
  uint64_t end_bytes = 0;     // offset just past the ElementDataFile line: where LOCAL data starts
};

bool is_text_byte(unsigned char c) { return c >= 0x20 || c == '\t' || c == '\r' || c == '\n'; }

RawHeader read_raw_header(const std::string& path) {
  const uint64_t size = regular_file_size(path, path, "the file");
  if (size == 0) throw file_error(path, "the file is empty: not a MetaImage header");
  FilePtr f = open_for_reading(path, path, "the file");
  std::string text(static_cast<size_t>(std::min(size, kMaxHeaderBytes)), '\0');
  read_exactly(path, f.get(), text.data(), text.size());
  const bool whole_file = text.size() == size;

  RawHeader h;
  size_t pos = 0;
  int line_no = 0;
  while (pos < text.size()) {
    size_t eol = text.find('\n', pos);
    if (eol == std::string::npos) {
      if (!whole_file) break;   // a line cut at the 1 MiB limit: no complete header
      eol = text.size();
    }
    ++line_no;
    const std::string line = text.substr(pos, eol - pos);
    pos = std::min(eol + 1, text.size());
    if (!std::all_of(line.begin(), line.end(), [](char c) { return is_text_byte(static_cast<unsigned char>(c)); })) {
      if (h.fields.empty())
        throw file_error(path, "not a MetaImage header: binary data on line " + std::to_string(line_no));
      throw file_error(path, "missing ElementDataFile: binary data on line " + std::to_string(line_no) +
                                 " where the header should have ended");
    }
    if (trim(line).empty()) continue;
    const auto eq = line.find('=');
    const std::string key = eq == std::string::npos ? "" : trim(line.substr(0, eq));
    if (key.empty())
      throw file_error(path, "not a MetaImage header: line " + std::to_string(line_no) + " is not 'Key = Value'");
    const std::string value = trim(line.substr(eq + 1));
    if (key == "ElementDataFile") {
      h.data_file = value;
      h.end_bytes = pos;
      return h;
    }
    h.fields[key] = value;
  }
  if (!whole_file) throw file_error(path, "not a MetaImage header: no ElementDataFile line in the first 1 MiB");
  throw file_error(path, "missing ElementDataFile (the header must end with it)");
}

// ---- typed values ------------------------------------------------------------------------------

const std::string* find_field(const Fields& fields, std::initializer_list<const char*> names, std::string* found) {
  for (const char* n : names) {
    const auto it = fields.find(n);
    if (it != fields.end()) {
      *found = n;
      return &it->second;
    }
  }
  return nullptr;
}

// from_chars/to_chars, unlike strtod/printf, ignore the C locale: a host application that sets a
// comma-decimal locale must not change what the header means.
double parse_number(const std::string& path, const std::string& key, const std::string& word) {
  const char* first = word.data();
  const char* last = word.data() + word.size();
  if (first != last && *first == '+') ++first;
  double v = 0.0;
  const auto [end, ec] = std::from_chars(first, last, v);
  if (ec == std::errc::result_out_of_range) throw file_error(path, key + " value '" + word + "' is out of range");
  if (ec != std::errc() || end != last || first == last)
    throw file_error(path, key + " value '" + word + "' is not a number");
  if (!std::isfinite(v)) throw file_error(path, key + " value '" + word + "' is not finite");
  return v;
}

int64_t parse_integer(const std::string& path, const std::string& key, const std::string& word) {
  errno = 0;
  char* end = nullptr;
  const long long v = std::strtoll(word.c_str(), &end, 10);
  if (end == word.c_str() || *end != '\0' || errno == ERANGE)
    throw file_error(path, key + " value '" + word + "' is not an integer");
  return v;
}

std::vector<std::string> words_of(const std::string& path, const std::string& key, const std::string& value,
                                  size_t count) {
  std::vector<std::string> w = split_words(value);
  if (w.size() != count) {
    std::ostringstream os;
    os << key << " has " << w.size() << " values, expected " << count;
    throw file_error(path, os.str());
  }
  return w;
}

std::vector<double> numbers_of(const std::string& path, const std::string& key, const std::string& value,
                               size_t count) {
  std::vector<double> out;
  for (const std::string& w : words_of(path, key, value, count)) out.push_back(parse_number(path, key, w));
  return out;
}

int64_t single_integer(const std::string& path, const std::string& key, const std::string& value) {
  return parse_integer(path, key, words_of(path, key, value, 1)[0]);
}

bool parse_bool(const std::string& path, const std::string& key, const std::string& value) {
  // MetaIO looks at the first letter only: True, true, T, 1 / False, false, F, 0.
  const char c = value.empty() ? '\0' : value[0];
  if (c == 'T' || c == 't' || c == '1') return true;
  if (c == 'F' || c == 'f' || c == '0') return false;
  throw file_error(path, key + " is '" + value + "' (expected True or False)");
}

VoxelType voxel_type_from_met(const std::string& path, const std::string& name) {
  static const std::map<std::string, VoxelType> kTypes = {
      {"MET_CHAR", VoxelType::Int8},     {"MET_UCHAR", VoxelType::UInt8},  {"MET_SHORT", VoxelType::Int16},
      {"MET_USHORT", VoxelType::UInt16}, {"MET_INT", VoxelType::Int32},    {"MET_UINT", VoxelType::UInt32},
      {"MET_FLOAT", VoxelType::Float32}, {"MET_DOUBLE", VoxelType::Float64}};
  const auto it = kTypes.find(name);
  if (it != kTypes.end()) return it->second;
  const std::string supported = "pneumo reads MET_CHAR, MET_UCHAR, MET_SHORT, MET_USHORT, MET_INT, MET_UINT, "
                                "MET_FLOAT and MET_DOUBLE";
  static const char* const kOtherMetaIoTypes[] = {"MET_NONE",      "MET_ASCII_CHAR", "MET_LONG",   "MET_ULONG",
                                                   "MET_LONG_LONG", "MET_ULONG_LONG", "MET_STRING", "MET_FLOAT_MATRIX",
                                                   "MET_OTHER"};
  const bool array = name.size() > 6 && name.compare(name.size() - 6, 6, "_ARRAY") == 0;
  if (array || std::find(std::begin(kOtherMetaIoTypes), std::end(kOtherMetaIoTypes), name) != std::end(kOtherMetaIoTypes))
    throw file_error(path, "unsupported ElementType " + name + " (" + supported + ")");
  throw file_error(path, "unknown ElementType '" + name + "' (" + supported + ")");
}

const char* met_name(VoxelType t) {
  switch (t) {
    case VoxelType::Int8: return "MET_CHAR";
    case VoxelType::UInt8: return "MET_UCHAR";
    case VoxelType::Int16: return "MET_SHORT";
    case VoxelType::UInt16: return "MET_USHORT";
    case VoxelType::Int32: return "MET_INT";
    case VoxelType::UInt32: return "MET_UINT";
    case VoxelType::Float32: return "MET_FLOAT";
    case VoxelType::Float64: return "MET_DOUBLE";
  }
  return "MET_OTHER";
}

// ---- the header's meaning ----------------------------------------------------------------------

struct MetaHeader {
  Geometry geometry;               // RAS+
  VoxelType type = VoxelType::UInt8;
  bool data_msb = false;
  bool compressed = false;
  int64_t compressed_bytes = -1;   // -1: not given
  int64_t header_size = 0;         // >0: skip that many bytes; -1: the data ends the file
  std::string data_file;
  uint64_t local_data_offset = 0;
};

const std::string& required(const std::string& path, const Fields& fields, const char* key) {
  const auto it = fields.find(key);
  if (it == fields.end()) throw file_error(path, std::string("missing ") + key);
  return it->second;
}

int read_ndims(const std::string& path, const Fields& fields) {
  const int64_t n = single_integer(path, "NDims", required(path, fields, "NDims"));
  if (n != 2 && n != 3)
    throw file_error(path, "NDims is " + std::to_string(n) + ": pneumo reads 2-D and 3-D images");
  return static_cast<int>(n);
}

void check_scalar_image(const std::string& path, const Fields& fields) {
  std::string key;
  if (const std::string* v = find_field(fields, {"ObjectType"}, &key); v && *v != "Image")
    throw file_error(path, "ObjectType is '" + *v + "': pneumo reads only Image");
  if (const std::string* v = find_field(fields, {"ElementNumberOfChannels"}, &key)) {
    const int64_t channels = single_integer(path, key, *v);
    if (channels != 1)
      throw file_error(path, "ElementNumberOfChannels is " + std::to_string(channels) +
                                 ": pneumo reads only single-channel (scalar) images");
  }
  if (const std::string* v = find_field(fields, {"BinaryData"}, &key); v && !parse_bool(path, key, *v))
    throw file_error(path, "ASCII voxel data (BinaryData = False) is not supported");
}

/// The LPS geometry as the header states it, converted to pneumo's RAS.
Geometry read_geometry(const std::string& path, const Fields& fields, int ndims) {
  Geometry g;
  std::string key;
  const std::vector<std::string> dim_words = words_of(path, "DimSize", required(path, fields, "DimSize"), ndims);
  for (int a = 0; a < ndims; ++a) g.dims[a] = parse_integer(path, "DimSize", dim_words[a]);

  if (const std::string* v = find_field(fields, {"ElementSpacing", "ElementSize"}, &key)) {
    const std::vector<double> s = numbers_of(path, key, *v, ndims);
    for (int a = 0; a < ndims; ++a) {
      if (!(s[a] > 0.0)) {
        std::ostringstream os;
        os << key << " along axis " << a << " is " << s[a] << " (must be > 0)";
        throw file_error(path, os.str());
      }
      g.spacing_mm[a] = s[a];
    }
  }

  Vec3 origin_lps = Vec3::Zero();
  if (const std::string* v = find_field(fields, {"Offset", "Position", "Origin"}, &key)) {
    const std::vector<double> o = numbers_of(path, key, *v, ndims);
    for (int a = 0; a < ndims; ++a) origin_lps[a] = o[a];
  }

  Mat3 direction_lps = Mat3::Identity();
  if (const std::string* v = find_field(fields, {"TransformMatrix", "Rotation", "Orientation"}, &key)) {
    const std::vector<double> m = numbers_of(path, key, *v, ndims * ndims);
    for (int axis = 0; axis < ndims; ++axis)
      for (int r = 0; r < ndims; ++r) direction_lps(r, axis) = m[axis * ndims + r];
  }
  // ITK maps index to world with the matrix as given; keep that mapping if a column is not unit length.
  for (int a = 0; a < 3; ++a) {
    const double len = direction_lps.col(a).norm();
    if (!(len > 0.0)) {
      std::ostringstream os;
      os << "the TransformMatrix is degenerate: the direction of axis " << a << " is zero";
      throw file_error(path, os.str());
    }
    if (std::abs(len - 1.0) > 1e-9) {
      direction_lps.col(a) /= len;
      g.spacing_mm[a] *= len;
    }
  }

  const Vec3 flip(-1.0, -1.0, 1.0);
  g.origin_mm = origin_lps.cwiseProduct(flip);
  g.direction = flip.asDiagonal() * direction_lps;
  return g;
}

MetaHeader interpret(const std::string& path, const RawHeader& raw) {
  const Fields& fields = raw.fields;
  check_scalar_image(path, fields);
  MetaHeader h;
  const int ndims = read_ndims(path, fields);
  h.type = voxel_type_from_met(path, trim(required(path, fields, "ElementType")));
  h.geometry = read_geometry(path, fields, ndims);
  checked_payload_bytes(path, h.geometry.dims.data(), voxel_size(h.type));
  h.geometry.validate(path);

  std::string key;
  if (const std::string* v = find_field(fields, {"BinaryDataByteOrderMSB", "ElementByteOrderMSB"}, &key))
    h.data_msb = parse_bool(path, key, *v);
  if (const std::string* v = find_field(fields, {"CompressedData"}, &key)) h.compressed = parse_bool(path, key, *v);
  if (const std::string* v = find_field(fields, {"CompressedDataSize"}, &key); v && h.compressed) {
    h.compressed_bytes = single_integer(path, key, *v);
    if (h.compressed_bytes < 1) throw file_error(path, "CompressedDataSize is " + *v + " (must be at least 1)");
  }
  if (const std::string* v = find_field(fields, {"HeaderSize"}, &key)) {
    h.header_size = single_integer(path, key, *v);
    if (h.header_size < -1) throw file_error(path, "HeaderSize is " + *v + " (must be -1 or at least 0)");
  }

  if (raw.data_file.empty()) throw file_error(path, "ElementDataFile is empty");
  std::string upper = raw.data_file;
  std::transform(upper.begin(), upper.end(), upper.begin(), [](unsigned char c) { return std::toupper(c); });
  if (split_words(raw.data_file)[0] == "LIST" || raw.data_file.find('%') != std::string::npos)
    throw file_error(path, "ElementDataFile '" + raw.data_file +
                               "' (one file per slice) is unsupported: store the voxels in one file");
  h.data_file = upper == "LOCAL" ? "LOCAL" : raw.data_file;
  h.local_data_offset = raw.end_bytes;
  return h;
}

// ---- voxel data --------------------------------------------------------------------------------

struct DataLocation {
  std::string path;
  std::string what;            // how messages name it
  uint64_t offset = 0;
  uint64_t stored_bytes = 0;   // on disk: payload, or the compressed stream
};

DataLocation locate_data(const std::string& path, const MetaHeader& h, uint64_t payload) {
  DataLocation d;
  if (h.data_file == "LOCAL") {
    d.path = path;
    d.what = "the file";
    d.offset = h.local_data_offset;
  } else {
    const fs::path name(h.data_file);
    d.path = name.is_absolute() ? name.string() : (fs::path(path).parent_path() / name).string();
    d.what = "data file '" + h.data_file + "'";
  }
  const uint64_t size = regular_file_size(path, d.path, d.what);
  if (h.header_size > 0) d.offset = static_cast<uint64_t>(h.header_size);

  if (h.compressed) {
    if (h.compressed_bytes > 0) {
      d.stored_bytes = static_cast<uint64_t>(h.compressed_bytes);
    } else {
      if (h.header_size == -1) throw file_error(path, "HeaderSize = -1 with compressed data needs CompressedDataSize");
      d.stored_bytes = size > d.offset ? size - d.offset : 0;
    }
  } else {
    d.stored_bytes = payload;
  }
  if (h.header_size == -1) {
    if (d.stored_bytes > size) {
      std::ostringstream os;
      os << "truncated: the header promises " << d.stored_bytes << " bytes of voxel data, " << d.what << " holds "
         << size;
      throw file_error(path, os.str());
    }
    d.offset = size - d.stored_bytes;
  }
  if (d.offset > size || d.stored_bytes > size - d.offset || (h.compressed && d.stored_bytes == 0)) {
    std::ostringstream os;
    os << "truncated: the header promises " << d.stored_bytes << " bytes of " << (h.compressed ? "compressed " : "")
       << "voxel data at offset " << d.offset << ", " << d.what << " holds " << size << " bytes";
    throw file_error(path, os.str());
  }
  if (h.compressed && payload > d.stored_bytes * kMaxDeflateRatio + kDeflateSlackBytes) {
    std::ostringstream os;
    os << "corrupt header: " << d.stored_bytes << " compressed bytes cannot hold the " << payload
       << " bytes of voxels DimSize promises";
    throw file_error(path, os.str());
  }
  return d;
}

struct InflateEnd {
  void operator()(z_stream* z) const { inflateEnd(z); }
};

[[noreturn]] void corrupt_stream(const std::string& path, const z_stream& z, uint64_t produced, uint64_t payload) {
  std::ostringstream os;
  os << "corrupt/truncated compressed data (inflated " << produced << " of " << payload << " bytes";
  if (z.msg) os << ": " << z.msg;
  os << ")";
  throw file_error(path, os.str());
}

void inflate_into(const std::string& path, std::FILE* f, uint64_t stored_bytes, void* dst, uint64_t payload) {
  z_stream z{};
  // 15 + 32: zlib or gzip wrapper, detected from the stream's first bytes.
  if (inflateInit2(&z, 15 + 32) != Z_OK) throw std::runtime_error(path + ": zlib could not start inflating");
  std::unique_ptr<z_stream, InflateEnd> guard(&z);
  std::vector<unsigned char> in(static_cast<size_t>(std::min<uint64_t>(stored_bytes, 1ull << 20)));
  auto* out = static_cast<unsigned char*>(dst);
  uint64_t in_left = stored_bytes, out_given = 0;
  for (;;) {
    if (z.avail_in == 0 && in_left > 0) {
      const uint64_t n = std::min<uint64_t>(in.size(), in_left);
      read_exactly(path, f, in.data(), n);
      in_left -= n;
      z.next_in = in.data();
      z.avail_in = static_cast<uInt>(n);
    }
    if (z.avail_out == 0 && out_given < payload) {
      const uint64_t n = std::min(kIoChunkBytes, payload - out_given);
      z.next_out = out + out_given;
      z.avail_out = static_cast<uInt>(n);
      out_given += n;
    }
    const int ret = inflate(&z, Z_NO_FLUSH);
    if (ret == Z_STREAM_END) break;
    // Z_BUF_ERROR: no progress possible, i.e. the input ran out early or the output is full.
    if (ret != Z_OK) corrupt_stream(path, z, out_given - z.avail_out, payload);
  }
  const uint64_t produced = out_given - z.avail_out;
  if (produced != payload) corrupt_stream(path, z, produced, payload);
}

void swap_bytes(void* data, uint64_t count, size_t width) {
  auto* p = static_cast<unsigned char*>(data);
  for (uint64_t i = 0; i < count; ++i, p += width) std::reverse(p, p + width);
}

// ---- writing -----------------------------------------------------------------------------------

std::string format_doubles(const double* v, int n) {
  std::string s;
  char buf[40];
  for (int i = 0; i < n; ++i) {
    // 17 significant digits (%.17g) read back bit-identical; + 0.0 writes "0", never "-0".
    const auto [end, ec] = std::to_chars(buf, buf + sizeof buf, v[i] + 0.0, std::chars_format::general, 17);
    if (ec != std::errc()) throw std::logic_error("cannot format a header number");
    if (i) s += ' ';
    s.append(buf, end);
  }
  return s;
}

/// MetaIO's AnatomicalOrientation letters: per axis, the side it comes from (opposite of where it points).
std::string anatomical_orientation(const Geometry& g) {
  std::string code = g.orientation_code();
  for (char& c : code) {
    switch (c) {
      case 'R': c = 'L'; break;
      case 'L': c = 'R'; break;
      case 'A': c = 'P'; break;
      case 'P': c = 'A'; break;
      case 'S': c = 'I'; break;
      case 'I': c = 'S'; break;
      default: break;
    }
  }
  return code;
}

std::string header_text(const Volume& v, bool compressed, uint64_t compressed_bytes, const std::string& data_file) {
  const Geometry& g = v.geometry();
  const Vec3 flip(-1.0, -1.0, 1.0);
  const Vec3 origin_lps = g.origin_mm.cwiseProduct(flip);
  const Mat3 direction_lps = flip.asDiagonal() * g.direction;
  double matrix[9];
  for (int axis = 0; axis < 3; ++axis)
    for (int r = 0; r < 3; ++r) matrix[axis * 3 + r] = direction_lps(r, axis);
  const double spacing[3] = {g.spacing_mm[0], g.spacing_mm[1], g.spacing_mm[2]};
  const double origin[3] = {origin_lps[0], origin_lps[1], origin_lps[2]};

  std::ostringstream os;
  os.imbue(std::locale::classic());   // no digit grouping in DimSize, whatever the global locale
  os << "ObjectType = Image\n"
     << "NDims = 3\n"
     << "BinaryData = True\n"
     << "BinaryDataByteOrderMSB = False\n"
     << "CompressedData = " << (compressed ? "True" : "False") << "\n";
  if (compressed) os << "CompressedDataSize = " << compressed_bytes << "\n";
  os << "TransformMatrix = " << format_doubles(matrix, 9) << "\n"
     << "Offset = " << format_doubles(origin, 3) << "\n"
     << "CenterOfRotation = 0 0 0\n"
     << "AnatomicalOrientation = " << anatomical_orientation(g) << "\n"
     << "ElementSpacing = " << format_doubles(spacing, 3) << "\n"
     << "DimSize = " << g.dims[0] << " " << g.dims[1] << " " << g.dims[2] << "\n"
     << "ElementType = " << met_name(v.type()) << "\n"
     << "ElementDataFile = " << data_file << "\n";
  return os.str();
}

std::vector<unsigned char> deflate_bytes(const std::string& path, const unsigned char* src, uint64_t n) {
  z_stream z{};
  if (deflateInit(&z, kCompressionLevel) != Z_OK) throw std::runtime_error(path + ": zlib could not start deflating");
  std::unique_ptr<z_stream, decltype(&deflateEnd)> guard(&z, &deflateEnd);
  std::vector<unsigned char> out;
  std::vector<unsigned char> chunk(1u << 20);
  uint64_t in_left = n;
  int ret = Z_OK;
  do {
    if (z.avail_in == 0 && in_left > 0) {
      const uint64_t take = std::min(kIoChunkBytes, in_left);
      z.next_in = const_cast<unsigned char*>(src + (n - in_left));
      z.avail_in = static_cast<uInt>(take);
      in_left -= take;
    }
    z.next_out = chunk.data();
    z.avail_out = static_cast<uInt>(chunk.size());
    ret = deflate(&z, in_left == 0 ? Z_FINISH : Z_NO_FLUSH);
    if (ret == Z_STREAM_ERROR) throw std::runtime_error(path + ": zlib failed while compressing");
    out.insert(out.end(), chunk.data(), chunk.data() + (chunk.size() - z.avail_out));
  } while (ret != Z_STREAM_END);
  return out;
}

void write_or_throw(std::FILE* f, const std::string& temp_path, const void* data, uint64_t n) {
  const auto* p = static_cast<const unsigned char*>(data);
  for (uint64_t done = 0; done < n;) {
    const size_t want = static_cast<size_t>(std::min(kIoChunkBytes, n - done));
    if (std::fwrite(p + done, 1, want, f) != want)
      throw std::runtime_error("cannot write " + temp_path + ": " + std::strerror(errno));
    done += want;
  }
}

/// Writes the pieces, in order, to `target` atomically.
void write_atomic(const std::string& target, std::initializer_list<std::pair<const void*, uint64_t>> pieces) {
  AtomicFile out(target);
  {
    FilePtr f(std::fopen(out.temp_path().c_str(), "wb"));
    if (!f) throw std::runtime_error("cannot create " + out.temp_path() + ": " + std::strerror(errno));
    for (const auto& [data, n] : pieces) write_or_throw(f.get(), out.temp_path(), data, n);
    std::FILE* raw = f.release();
    if (std::fclose(raw) != 0) throw std::runtime_error("cannot write " + out.temp_path() + ": " + std::strerror(errno));
  }
  out.commit();
}

}  // namespace

Volume read_metaimage(const std::string& path) {
  const MetaHeader h = interpret(path, read_raw_header(path));
  const uint64_t payload = h.geometry.voxel_count() * voxel_size(h.type);
  const DataLocation d = locate_data(path, h, payload);

  require_volume_memory(path, h.geometry, h.type);
  Volume v(h.geometry, h.type);
  FilePtr f = open_for_reading(path, d.path, d.what);
  seek_to(path, f.get(), d.offset);
  if (h.compressed) inflate_into(path, f.get(), d.stored_bytes, v.raw(), payload);
  else read_exactly(path, f.get(), v.raw(), payload);
  if (h.data_msb != host_is_msb() && voxel_size(h.type) > 1)
    swap_bytes(v.raw(), static_cast<uint64_t>(v.voxel_count()), voxel_size(h.type));
  return v;
}

std::string metaimage_data_path(const std::string& mhd_path, bool compressed) {
  return fs::path(mhd_path).replace_extension(compressed ? ".zraw" : ".raw").string();
}

void write_metaimage(const Volume& v, const std::string& path, bool compress) {
  check_writable_target(path);
  const VolumeFormat format = volume_format_from_path(path);
  if (format != VolumeFormat::MetaImageSingle && format != VolumeFormat::MetaImageSplit)
    throw file_error(path, "not a MetaImage file name (expected .mha or .mhd)");
  v.geometry().validate(path);

  // Files are always little-endian.
  const unsigned char* voxels = static_cast<const unsigned char*>(v.raw());
  std::vector<unsigned char> swapped;
  if (host_is_msb() && voxel_size(v.type()) > 1) {
    swapped.assign(voxels, voxels + v.byte_count());
    swap_bytes(swapped.data(), static_cast<uint64_t>(v.voxel_count()), voxel_size(v.type()));
    voxels = swapped.data();
  }
  std::vector<unsigned char> packed;
  if (compress) packed = deflate_bytes(path, voxels, v.byte_count());
  const void* data = compress ? static_cast<const void*>(packed.data()) : voxels;
  const uint64_t data_bytes = compress ? packed.size() : v.byte_count();

  if (format == VolumeFormat::MetaImageSingle) {
    const std::string header = header_text(v, compress, data_bytes, "LOCAL");
    write_atomic(path, {{header.data(), header.size()}, {data, data_bytes}});
    return;
  }
  const std::string data_path = metaimage_data_path(path, compress);
  const std::string data_name = fs::path(data_path).filename().string();
  const std::string header = header_text(v, compress, data_bytes, data_name);
  write_atomic(data_path, {{data, data_bytes}});
  try {
    write_atomic(path, {{header.data(), header.size()}});
  } catch (...) {
    std::remove(data_path.c_str());   // no data file without the header that names it
    throw;
  }
}

}  // namespace pneumo
