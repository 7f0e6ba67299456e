#include "io/nrrd_io.h"

#include <teem/nrrd.h>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <cctype>
#include <cstdio>
#include <sstream>
#include <memory>
#include <vector>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/input_file.h"
#include "core/memory_budget.h"
#include "io/volume_io.h"

namespace pneumo {
namespace {

/// teem's error (its biff stack) as one line, and the stack cleared.
std::string teem_error() {
  char* text = biffGetDone(NRRD);
  std::string s = text ? text : "unknown error";
  std::free(text);
  // The stack is innermost last, one message per line: the last line says what was wrong.
  while (!s.empty() && (s.back() == '\n' || s.back() == ' ')) s.pop_back();
  const std::size_t last = s.rfind('\n');
  if (last != std::string::npos) s = s.substr(last + 1);
  const std::size_t bracket = s.find("] ");
  if (bracket != std::string::npos && s[0] == '[') s = s.substr(bracket + 2);
  // and teem's function name before the message ("_nrrdHeaderCheck: ...") means nothing to a user.
  const std::size_t colon = s.find(": ");
  if (colon != std::string::npos && s.find(' ') == colon + 1) s = s.substr(colon + 2);
  return s;
}

struct NrrdFree {
  void operator()(Nrrd* n) const { nrrdNuke(n); }
};
struct IoFree {
  void operator()(NrrdIoState* n) const { nrrdIoStateNix(n); }
};
using NrrdPtr = std::unique_ptr<Nrrd, NrrdFree>;
using IoPtr = std::unique_ptr<NrrdIoState, IoFree>;

VoxelType voxel_type_of_nrrd(const std::string& path, int type) {
  switch (type) {
    case nrrdTypeChar: return VoxelType::Int8;
    case nrrdTypeUChar: return VoxelType::UInt8;
    case nrrdTypeShort: return VoxelType::Int16;
    case nrrdTypeUShort: return VoxelType::UInt16;
    case nrrdTypeInt: return VoxelType::Int32;
    case nrrdTypeUInt: return VoxelType::UInt32;
    case nrrdTypeFloat: return VoxelType::Float32;
    case nrrdTypeDouble: return VoxelType::Float64;
    default: throw file_error(path, std::string("voxel type ") + airEnumStr(nrrdType, type) + " is not supported");
  }
}

int nrrd_type_of(VoxelType t) {
  switch (t) {
    case VoxelType::Int8: return nrrdTypeChar;
    case VoxelType::UInt8: return nrrdTypeUChar;
    case VoxelType::Int16: return nrrdTypeShort;
    case VoxelType::UInt16: return nrrdTypeUShort;
    case VoxelType::Int32: return nrrdTypeInt;
    case VoxelType::UInt32: return nrrdTypeUInt;
    case VoxelType::Float32: return nrrdTypeFloat;
    case VoxelType::Float64: return nrrdTypeDouble;
  }
  return nrrdTypeUnknown;
}

/// The flip from the file's patient space to RAS (each space is RAS with some axes reversed).
Vec3 to_ras_signs(const std::string& path, int space) {
  switch (space) {
    case nrrdSpaceRightAnteriorSuperior: return Vec3(1, 1, 1);
    case nrrdSpaceLeftAnteriorSuperior: return Vec3(-1, 1, 1);
    case nrrdSpaceLeftPosteriorSuperior:
    case nrrdSpaceScannerXYZ: return Vec3(-1, -1, 1);   // scanner-xyz is LPS for a supine patient (teem, DICOM)
    case nrrdSpaceUnknown:
      throw file_error(path, "has no \"space\": where it lies in the patient is unknown (3D Slicer writes "
                             "\"space: left-posterior-superior\" with \"space directions\" and \"space origin\")");
    default:
      throw file_error(path, std::string("space \"") + airEnumStr(nrrdSpace, space) +
                                 "\" is not patient-oriented: use right-anterior-superior, left-anterior-superior "
                                 "or left-posterior-superior");
  }
}

/// The grid the header promises; throws InputError for what is not a placed 3D volume.
Geometry geometry_of(const std::string& path, const Nrrd& n) {
  if (n.dim != 3)
    throw file_error(path, std::to_string(n.dim) + " dimensions: pneumo reads three-dimensional scalar volumes");
  const Vec3 sign = to_ras_signs(path, n.space);
  if (n.spaceDim != 3) throw file_error(path, "its space is not three-dimensional");
  Geometry g;
  for (int a = 0; a < 3; ++a) {
    const NrrdAxisInfo& axis = n.axis[a];
    if (axis.size > (size_t(1) << 40)) throw file_error(path, "axis " + std::to_string(a) + " is absurdly long");
    g.dims[a] = int64_t(axis.size);
    Vec3 d(axis.spaceDirection[0], axis.spaceDirection[1], axis.spaceDirection[2]);
    if (!d.allFinite())
      throw file_error(path, "axis " + std::to_string(a) + " has no space direction (a non-spatial axis?)");
    g.spacing_mm[a] = d.norm();
    if (!(g.spacing_mm[a] > 0.0)) throw file_error(path, "axis " + std::to_string(a) + " has a zero space direction");
    g.direction.col(a) = sign.asDiagonal() * (d / g.spacing_mm[a]);
  }
  const Vec3 origin(n.spaceOrigin[0], n.spaceOrigin[1], n.spaceOrigin[2]);
  if (!origin.allFinite()) throw file_error(path, "has no \"space origin\": where it lies in the patient is unknown");
  g.origin_mm = sign.asDiagonal() * origin;
  g.validate(path);
  return g;
}

/// What pneumo reads of a NRRD before teem does: the header's length and the data files it names.
struct NrrdHeaderScan {
  uint64_t header_bytes = 0;             // through the empty line that ends an attached header
  uint64_t file_bytes = 0;
  std::vector<std::string> data_files;   // a detached header's, resolved against its folder
};

// A detached header names its data files in one of three ways (teem's "data file" field): one name;
// "LIST", then one name a line to the end of the header; or a printf format with %d and min, max,
// step. A header of thousands of slices takes well under this many bytes and files.
constexpr uint64_t kMaxNrrdHeaderBytes = 16u << 20;
constexpr int64_t kMaxNrrdDataFiles = 1 << 16;

std::string trimmed(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r"), e = s.find_last_not_of(" \t\r");
  return b == std::string::npos ? "" : s.substr(b, e - b + 1);
}

/// The names "fmt min max step" gives, as teem's sprintf(fmt, n) makes them. The format must hold
/// exactly one %d (with an optional zero-padded width): it comes from the file, and anything else
/// in a printf format would read arguments that are not there.
std::vector<std::string> formatted_data_files(const std::string& path, const std::vector<std::string>& words) {
  const std::string& format = words[0];
  const std::size_t at = format.find('%');
  std::size_t d = at + 1;
  while (d < format.size() && std::isdigit(static_cast<unsigned char>(format[d]))) ++d;
  if (d >= format.size() || format[d] != 'd' || d - at > 4 || format.find('%', d) != std::string::npos)
    throw file_error(path, "its data file format \"" + format + "\" is not one name with one %d in it");
  int64_t first = 0, last = 0, step = 0;
  try {
    first = std::stoll(words[1]), last = std::stoll(words[2]), step = std::stoll(words[3]);
  } catch (const std::exception&) {
    throw file_error(path, "its data file numbers \"" + words[1] + " " + words[2] + " " + words[3] + "\" are not integers");
  }
  if (step == 0 || (last - first) / step < 0 || (last - first) / step >= kMaxNrrdDataFiles)
    throw file_error(path, "its data file numbers " + words[1] + " to " + words[2] + " by " + words[3] +
                               " do not name between 1 and " + std::to_string(kMaxNrrdDataFiles) + " files");
  std::vector<std::string> names;
  for (int64_t n = first; step > 0 ? n <= last : n >= last; n += step) {
    char name[4096];
    std::snprintf(name, sizeof name, format.c_str(), int(n));
    names.push_back(name);
  }
  return names;
}

/// Reads the header as far as its empty line, through the regular-file check, and resolves the data
/// files it names. teem opens a detached header's data files by name while it parses the header
/// (even when told to skip the data), so they are checked here first: a FIFO would block it forever.
NrrdHeaderScan scan_nrrd_header(const std::string& path) {
  InputFile file(path);
  NrrdHeaderScan scan;
  scan.file_bytes = file.size();
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> in(file.release_to_stdio(), &std::fclose);
  std::vector<std::string> lines;
  std::string line;
  for (int c; scan.header_bytes < kMaxNrrdHeaderBytes && (c = std::getc(in.get())) != EOF;) {
    ++scan.header_bytes;
    if (c != '\n') {
      line += char(c);
      continue;
    }
    if (trimmed(line).empty()) break;   // the end of the header: attached data follows
    lines.push_back(line);
    line.clear();
  }
  if (!line.empty()) lines.push_back(line);
  const std::filesystem::path folder = std::filesystem::path(path).parent_path();
  const auto resolved = [&](const std::string& name) {
    return std::filesystem::path(name).is_absolute() ? name : (folder / name).string();
  };
  for (std::size_t l = 0; l < lines.size(); ++l) {
    const std::size_t colon = lines[l].find(':');
    if (lines[l][0] == '#' || colon == std::string::npos || lines[l].compare(colon, 2, ":=") == 0) continue;
    const std::string field = trimmed(lines[l].substr(0, colon));
    if (field != "data file" && field != "datafile") continue;
    const std::string value = trimmed(lines[l].substr(colon + 1));
    std::vector<std::string> words;
    std::istringstream split(value);
    for (std::string w; split >> w;) words.push_back(w);
    std::vector<std::string> names;
    if (!words.empty() && words[0] == "LIST") {
      for (std::size_t k = l + 1; k < lines.size(); ++k)
        if (!trimmed(lines[k]).empty()) names.push_back(trimmed(lines[k]));
      l = lines.size();
    } else if (words.size() >= 4 && words[0].find('%') != std::string::npos) {
      names = formatted_data_files(path, words);
    } else {
      names.push_back(value);
    }
    for (const std::string& n : names) scan.data_files.push_back(resolved(n));
  }
  return scan;
}

/// The most voxel bytes `available` bytes of `encoding` can hold, so a header whose sizes promise
/// more is refused before teem allocates them: deflate expands at most 1032:1 (zlib's technical
/// note), hex takes two characters a byte, ASCII at least two a value (a digit and a separator).
/// bzip2 has no useful bound; its files rely on the memory check alone.
uint64_t most_voxel_bytes(const std::string& encoding, uint64_t available, std::size_t value_bytes) {
  if (encoding == "raw") return available;
  if (encoding == "gzip") return available > (UINT64_MAX - 1024) / 1032 ? UINT64_MAX : available * 1032 + 1024;
  if (encoding == "hex") return available / 2;
  if (encoding == "ascii") return (available / 2 + 1) * value_bytes;
  return UINT64_MAX;
}

/// teem's working memory beside the voxels while it reads (zlib's state and window, its line
/// buffers): a few MiB, rounded up.
constexpr uint64_t kTeemWorkingBytes = 16u << 20;

/// The memory check before the voxels are read. teem allocates them itself (nrrdLoad) and they are
/// then copied into the Volume, so both are held at the copy: the check counts two, and teem's
/// working memory. (Counting one, a limit between the two passed the check and the read ended
/// "out of memory", exit 1.)
void require_nrrd_memory(const std::string& path, const Geometry& g, VoxelType t) {
  std::ostringstream what;
  what << path << ": an image of " << g.dims[0] << " x " << g.dims[1] << " x " << g.dims[2] << " "
       << voxel_type_name(t) << " voxels, read through teem's own copy of them,";
  require_memory(2 * uint64_t(g.voxel_count()) * voxel_size(t) + kTeemWorkingBytes, what.str(),
                 "crop or resample the image, or free memory");
}

}  // namespace

Volume read_nrrd(const std::string& path) {
  const NrrdHeaderScan scan = scan_nrrd_header(path);
  for (const std::string& data : scan.data_files) require_regular_file(data, "its data file " + data, path);
  // The header first (teem reads no voxels with skipData): what it promises is checked before any
  // allocation, as every reader here does.
  Geometry g;
  VoxelType type;
  {
    NrrdPtr header(nrrdNew());
    IoPtr io(nrrdIoStateNew());
    io->skipData = AIR_TRUE;
    if (nrrdLoad(header.get(), path.c_str(), io.get()) != 0) throw file_error(path, "not a readable NRRD: " + teem_error());
    type = voxel_type_of_nrrd(path, header->type);
    g = geometry_of(path, *header);
    const int64_t dims[3] = {g.dims[0], g.dims[1], g.dims[2]};
    const uint64_t payload = checked_payload_bytes(path, dims, voxel_size(type));
    // What the file (or the detached header's data files) holds, against what the sizes promise.
    uint64_t available = 0;
    if (io->dataFNArr->len == 0) {
      available = scan.file_bytes > scan.header_bytes ? scan.file_bytes - scan.header_bytes : 0;
    } else {
      const std::filesystem::path folder = std::filesystem::path(path).parent_path();
      for (unsigned int f = 0; f < io->dataFNArr->len; ++f) {
        const std::filesystem::path data = std::filesystem::path(io->dataFN[f]).is_absolute()
                                               ? std::filesystem::path(io->dataFN[f])
                                               : folder / io->dataFN[f];
        available += require_regular_file(data.string(), "its data file " + data.string(), path);
      }
    }
    const std::string encoding = io->encoding ? io->encoding->name : "raw";
    if (most_voxel_bytes(encoding, available, voxel_size(type)) < payload) {
      std::ostringstream os;
      os << "holds " << available << " bytes of " << encoding << " data where its sizes promise " << payload
         << " bytes of voxels: truncated, or the sizes are wrong";
      throw file_error(path, os.str());
    }
  }
  require_nrrd_memory(path, g, type);

  NrrdPtr n(nrrdNew());
  IoPtr io(nrrdIoStateNew());   // ours, not one teem makes itself: its error paths then leak nothing
  if (nrrdLoad(n.get(), path.c_str(), io.get()) != 0) throw file_error(path, "not a readable NRRD: " + teem_error());
  if (voxel_type_of_nrrd(path, n->type) != type || n->dim != 3 || !geometry_of(path, *n).same_grid(g, 0.0))
    throw file_error(path, "changed while it was read");
  Volume v(g, type);
  std::memcpy(v.raw(), n->data, v.byte_count());   // teem gives host byte order, axis 0 fastest, as Volume
  return v;
}

void write_nrrd(const Volume& v, const std::string& path) {
  check_writable_target(path);
  if (volume_format_from_path(path) != VolumeFormat::Nrrd)
    throw file_error(path, "not a single-file NRRD name (expected .nrrd)");
  const Geometry& g = v.geometry();
  g.validate(path);
  const Vec3 to_lps(-1.0, -1.0, 1.0);
  double directions[NRRD_DIM_MAX][NRRD_SPACE_DIM_MAX];
  for (int a = 0; a < 3; ++a) {
    const Vec3 d = to_lps.asDiagonal() * (g.direction.col(a) * g.spacing_mm[a]);
    for (int c = 0; c < 3; ++c) directions[a][c] = d[c] + 0.0;   // + 0.0: no "-0" in the header
  }
  const Vec3 origin = to_lps.asDiagonal() * g.origin_mm;
  const int kinds[3] = {nrrdKindDomain, nrrdKindDomain, nrrdKindDomain};
  const size_t sizes[3] = {size_t(g.dims[0]), size_t(g.dims[1]), size_t(g.dims[2])};

  AtomicFile out(path);
  // teem only reads the buffer it wraps; nrrdNix frees the wrapper, not the volume's voxels.
  struct NixOnly {
    void operator()(Nrrd* n) const { nrrdNix(n); }
  };
  std::unique_ptr<Nrrd, NixOnly> n(nrrdNew());
  if (nrrdWrap_nva(n.get(), const_cast<void*>(v.raw()), nrrd_type_of(v.type()), 3, sizes) != 0 ||
      nrrdSpaceSet(n.get(), nrrdSpaceLeftPosteriorSuperior) != 0 || nrrdSpaceOriginSet(n.get(), origin.data()) != 0)
    throw std::runtime_error(path + ": cannot describe the volume to teem: " + teem_error());
  nrrdAxisInfoSet_nva(n.get(), nrrdAxisInfoSpaceDirection, directions);
  nrrdAxisInfoSet_nva(n.get(), nrrdAxisInfoKind, kinds);
  IoPtr io(nrrdIoStateNew());
  io->encoding = nrrdEncodingGzip;
  io->zlibLevel = 1;   // fast: a CT's air and soft tissue compress well at any level
  io->format = nrrdFormatNRRD;
  if (nrrdSave(out.temp_path().c_str(), n.get(), io.get()) != 0)
    throw std::runtime_error(path + ": cannot write: " + teem_error());
  out.commit();
}

}  // namespace pneumo
