// NIfTI-1 (.nii, .nii.gz) through niftilib. The 348-byte header is read and checked here first, so
// every problem gets a specific message and nothing the header promises is allocated before it is
// checked against the file; niftilib then converts the header (quaternions, sform) both ways. The
// bytes are written here: a .nii.gz as gzip members on every core (io/gzip_members.h).
#include <nifti2_io.h>
#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <mutex>
#include <sstream>
#include <vector>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/input_file.h"
#include "core/progress.h"
#include "io/gzip_members.h"
#include "io/volume_io.h"

namespace pneumo {

namespace {

constexpr int kNifti1HeaderBytes = 348;
// libdeflate's fastest level for .nii.gz: a CT compresses little better at higher ones.
constexpr int kNiftiGzipLevel = 1;
// gzip's deflate cannot expand more than about 1032:1; a .gz file smaller than payload/1032 is
// truncated whatever it says.
constexpr uint64_t kMaxDeflateRatio = 1032;

void quiet_niftilib() {
  static std::once_flag once;
  std::call_once(once, [] { nifti_set_debug_level(0); });
}

// zlib's gz reader serves both .nii (read transparently) and .nii.gz, and, unlike niftilib's znz
// layer, reports a stream that ends early or fails its checksum.
struct GzCloser {
  void operator()(gzFile f) const { if (f) gzclose_r(f); }
};
using GzPtr = std::unique_ptr<gzFile_s, GzCloser>;

/// zlib reads the descriptor the regular-file check opened (core/input_file.h): never a FIFO's.
GzPtr open_for_reading(const std::string& path) {
  InputFile file(path);
  GzPtr f(gzdopen(file.fd(), "rb"));
  if (!f) throw file_error(path, "cannot open: " + std::string(std::strerror(errno)));
  file.release();   // gzclose_r closes it
  return f;
}

std::string gz_problem(gzFile f) {
  int code = Z_OK;
  const char* msg = gzerror(f, &code);
  return code == Z_OK ? "unexpected end of file" : std::string(msg ? msg : "zlib error");
}

/// Reads up to n bytes; returns how many were read, or throws on a corrupt stream.
uint64_t read_bytes(const std::string& path, gzFile f, void* dst, uint64_t n) {
  constexpr uint64_t kChunk = 16ull << 20;   // gzread takes an unsigned count; progress per chunk
  Progress progress("read " + path, int64_t(n >> 20));
  uint64_t done = 0;
  char* out = static_cast<char*>(dst);
  while (done < n) {
    const unsigned want = static_cast<unsigned>(std::min(kChunk, n - done));
    const int got = gzread(f, out + done, want);
    if (got < 0) throw file_error(path, "corrupt compressed data: " + gz_problem(f));
    done += static_cast<uint64_t>(got);
    progress.update(int64_t(done >> 20), "MiB");
    if (static_cast<unsigned>(got) < want) break;
  }
  return done;
}

/// A .nii.gz must end where its gzip stream says (length and CRC checked): reading past the
/// voxels to the end makes zlib verify both.
void check_clean_end(const std::string& path, GzPtr f) {
  char sink[1 << 16];
  int got;
  while ((got = gzread(f.get(), sink, sizeof sink)) > 0) {}
  if (got < 0) throw file_error(path, "corrupt compressed data: " + gz_problem(f.get()));
  int code = Z_OK;
  gzerror(f.get(), &code);
  const int closed = gzclose_r(f.release());
  if (code != Z_OK || closed != Z_OK) throw file_error(path, "truncated compressed data (the gzip stream ends early)");
}

struct NimDeleter {
  void operator()(nifti_image* n) const {
    if (n) { n->data = nullptr; nifti_image_free(n); }
  }
};
using NimPtr = std::unique_ptr<nifti_image, NimDeleter>;

bool is_gz(const std::string& path) { return volume_format_from_path(path) == VolumeFormat::NiftiGz; }

VoxelType voxel_type_from_nifti(const std::string& path, int datatype) {
  switch (datatype) {
    case DT_INT8: return VoxelType::Int8;
    case DT_UINT8: return VoxelType::UInt8;
    case DT_INT16: return VoxelType::Int16;
    case DT_UINT16: return VoxelType::UInt16;
    case DT_INT32: return VoxelType::Int32;
    case DT_UINT32: return VoxelType::UInt32;
    case DT_FLOAT32: return VoxelType::Float32;
    case DT_FLOAT64: return VoxelType::Float64;
    default: break;
  }
  const char* name = nifti_datatype_to_string(datatype);
  throw file_error(path, std::string("unsupported voxel type ") + (name ? name : "?") + " (datatype " +
                             std::to_string(datatype) + "); pneumo reads int8/16/32, uint8/16/32, float32/64");
}

int nifti_datatype_of(VoxelType t) {
  switch (t) {
    case VoxelType::Int8: return DT_INT8;
    case VoxelType::UInt8: return DT_UINT8;
    case VoxelType::Int16: return DT_INT16;
    case VoxelType::UInt16: return DT_UINT16;
    case VoxelType::Int32: return DT_INT32;
    case VoxelType::UInt32: return DT_UINT32;
    case VoxelType::Float32: return DT_FLOAT32;
    case VoxelType::Float64: return DT_FLOAT64;
  }
  return DT_UNKNOWN;
}

/// Reads and checks the raw header; returns it in file byte order plus whether it must be swapped.
nifti_1_header read_checked_header(const std::string& path, bool* swapped) {
  GzPtr f = open_for_reading(path);
  nifti_1_header raw{};
  const uint64_t got = read_bytes(path, f.get(), &raw, sizeof raw);
  if (got != sizeof raw)
    throw file_error(path, "file too short for a NIfTI-1 header (" + std::to_string(got) + " of 348 bytes)");

  nifti_1_header h = raw;
  *swapped = false;
  if (h.sizeof_hdr != kNifti1HeaderBytes) {
    nifti_swap_as_nifti1(&h);
    *swapped = true;
    if (h.sizeof_hdr != kNifti1HeaderBytes) {
      if (raw.sizeof_hdr == 540 || h.sizeof_hdr == 540)
        throw file_error(path, "NIfTI-2 files are not supported (write NIfTI-1)");
      throw file_error(path, "not a NIfTI-1 file (header size field is " + std::to_string(raw.sizeof_hdr) + ", expected 348)");
    }
  }
  if (std::memcmp(h.magic, "n+1", 4) != 0) {
    if (std::memcmp(h.magic, "ni1", 4) == 0)
      throw file_error(path, "a NIfTI .hdr/.img pair is not supported (use a single .nii or .nii.gz)");
    throw file_error(path, "bad NIfTI magic (expected \"n+1\"): not a NIfTI-1 file or a corrupt header");
  }
  if (h.dim[0] < 1 || h.dim[0] > 7)
    throw file_error(path, "corrupt header: dim[0] = " + std::to_string(h.dim[0]) + " (must be 1..7)");
  // niftilib prints "** ERROR ... bad dim" to stderr for these before failing: refuse them first, so
  // the user sees one line.
  for (int a = 1; a <= h.dim[0]; ++a)
    if (h.dim[a] < 1)
      throw file_error(path, "dimension " + std::to_string(a - 1) + " is " + std::to_string(h.dim[a]) +
                                 " (dim[" + std::to_string(a) + "], must be at least 1)");
  for (int a = 4; a <= h.dim[0]; ++a)
    if (h.dim[a] > 1) {
      std::ostringstream os;
      os << a << "-D volumes are not supported (dim[" << a << "] = " << h.dim[a] << "); pneumo reads 3-D volumes";
      throw file_error(path, os.str());
    }
  voxel_type_from_nifti(path, h.datatype);  // throws for unsupported types
  int nbyper = 0, swapsize = 0;
  nifti_datatype_sizes(h.datatype, &nbyper, &swapsize);
  if (h.bitpix != 8 * nbyper)
    throw file_error(path, "corrupt header: bitpix " + std::to_string(h.bitpix) + " does not match datatype " +
                               std::to_string(h.datatype));
  if (!std::isfinite(h.vox_offset) || h.vox_offset < 352.0f)
    throw file_error(path, "corrupt header: vox_offset " + std::to_string(h.vox_offset) + " (must be at least 352)");
  return raw;
}

void check_spacing_and_transform(const std::string& path, const nifti_1_header& raw, bool swapped) {
  nifti_1_header h = raw;
  if (swapped) nifti_swap_as_nifti1(&h);
  if (h.sform_code > 0) {
    for (float v : {h.srow_x[0], h.srow_x[1], h.srow_x[2], h.srow_x[3], h.srow_y[0], h.srow_y[1], h.srow_y[2],
                    h.srow_y[3], h.srow_z[0], h.srow_z[1], h.srow_z[2], h.srow_z[3]})
      if (!std::isfinite(v)) throw file_error(path, "the sform affine (srow_x/y/z) is not finite");
    return;  // columns are checked by Geometry::from_affine
  }
  // qform or no transform at all: spacing comes from pixdim, which niftilib would silently replace by 1.
  for (int a = 1; a <= 3; ++a)
    if (!std::isfinite(h.pixdim[a]) || !(h.pixdim[a] > 0.0f)) {
      std::ostringstream os;
      os << "spacing pixdim[" << a << "] is " << h.pixdim[a] << " mm (must be finite and > 0)";
      throw file_error(path, os.str());
    }
  for (float v : {h.quatern_b, h.quatern_c, h.quatern_d, h.qoffset_x, h.qoffset_y, h.qoffset_z})
    if (!std::isfinite(v)) throw file_error(path, "the qform (quaternion or offset) is not finite");
}

Geometry geometry_from_nim(const std::string& path, const nifti_image& nim) {
  Index3 dims{nim.nx, nim.ny, nim.nz};
  Mat4 a = Mat4::Identity();
  const nifti_dmat44* m = nullptr;
  if (nim.sform_code > 0) m = &nim.sto_xyz;       // sform preferred (ITK, nibabel, Slicer)
  else if (nim.qform_code > 0) m = &nim.qto_xyz;
  if (m) {
    for (int r = 0; r < 4; ++r)
      for (int c = 0; c < 4; ++c) a(r, c) = m->m[r][c];
  } else {
    // Analyze-style: no transform; voxel spacing along the axes, origin at voxel 0 (as ITK).
    a(0, 0) = nim.dx; a(1, 1) = nim.dy; a(2, 2) = nim.dz;
  }
  return Geometry::from_affine(dims, a, path);
}

void read_payload(const std::string& path, uint64_t offset, uint64_t payload, void* dst) {
  // pneumo's own .nii.gz (gzip members that carry their lengths) inflate on every core; any other
  // file, or one of ours that is truncated or corrupt, is read as a stream, which says what is wrong.
  if (is_gz(path) && inflate_gzip_members(path, offset, payload, dst)) return;
  GzPtr f = open_for_reading(path);
  if (gzseek(f.get(), static_cast<z_off_t>(offset), SEEK_SET) < 0)
    throw file_error(path, "truncated: no voxel data at offset " + std::to_string(offset));
  const uint64_t got = read_bytes(path, f.get(), dst, payload);
  if (got != payload) {
    std::ostringstream os;
    os << "truncated or corrupt voxel data: header promises " << payload << " bytes, file holds " << got;
    throw file_error(path, os.str());
  }
  if (is_gz(path)) check_clean_end(path, std::move(f));
}

template <class T>
void byte_swap_all(T* p, int64_t n) {
  for (int64_t i = 0; i < n; ++i) {
    auto* b = reinterpret_cast<unsigned char*>(p + i);
    std::reverse(b, b + sizeof(T));
  }
}

Volume apply_scaling(Volume v, double slope, double inter) {
  const bool wide = v.type() == VoxelType::Int32 || v.type() == VoxelType::UInt32 || v.type() == VoxelType::Float64;
  Volume out(v.geometry(), wide ? VoxelType::Float64 : VoxelType::Float32);
  const int64_t n = v.voxel_count();
  dispatch_voxel_type(v.type(), v.raw(), [&](auto* src) {
    dispatch_voxel_type(out.type(), out.raw(), [&](auto* dst) {
      using D = std::remove_pointer_t<decltype(dst)>;
#pragma omp parallel for schedule(static)
      for (int64_t i = 0; i < n; ++i) dst[i] = static_cast<D>(slope * static_cast<double>(src[i]) + inter);
    });
  });
  return out;
}

}  // namespace

Volume read_nifti(const std::string& path) {
  quiet_niftilib();
  const uint64_t on_disk = require_regular_file(path);
  bool swapped = false;
  const nifti_1_header raw = read_checked_header(path, &swapped);
  check_spacing_and_transform(path, raw, swapped);

  NimPtr nim(nifti_convert_n1hdr2nim(raw, path.c_str()));
  if (!nim) throw file_error(path, "corrupt NIfTI-1 header (niftilib refused it)");
  const VoxelType type = voxel_type_from_nifti(path, nim->datatype);
  const int64_t dims[3] = {nim->nx, nim->ny, nim->nz};
  const uint64_t payload = checked_payload_bytes(path, dims, voxel_size(type));
  const uint64_t needed = static_cast<uint64_t>(nim->iname_offset) + payload;
  if (!is_gz(path) && on_disk < needed) {
    std::ostringstream os;
    os << "truncated: header promises " << needed << " bytes, file holds " << on_disk;
    throw file_error(path, os.str());
  }
  if (is_gz(path) && on_disk * kMaxDeflateRatio + 1024 < needed) {
    std::ostringstream os;
    os << "truncated or absurd header: it promises " << needed << " bytes, more than " << on_disk
       << " compressed bytes can hold";
    throw file_error(path, os.str());
  }
  const Geometry g = geometry_from_nim(path, *nim);

  require_volume_memory(path, g, type);
  Volume v(g, type);
  read_payload(path, static_cast<uint64_t>(nim->iname_offset), payload, v.raw());
  if (swapped) dispatch_voxel_type(type, v.raw(), [&](auto* p) { byte_swap_all(p, v.voxel_count()); });

  const double slope = nim->scl_slope, inter = nim->scl_inter;
  const bool scaled = std::isfinite(slope) && slope != 0.0 && (slope != 1.0 || (std::isfinite(inter) && inter != 0.0));
  if (scaled) return apply_scaling(std::move(v), slope, std::isfinite(inter) ? inter : 0.0);
  return v;
}

NiftiExtensions read_nifti_extensions(const std::string& path) {
  quiet_niftilib();
  require_regular_file(path);
  NiftiExtensions out;
  const nifti_1_header raw = read_checked_header(path, &out.swapped);
  nifti_1_header h = raw;
  if (out.swapped) nifti_swap_as_nifti1(&h);
  // The 4 bytes after the header: extension[0] != 0 when extensions follow, up to vox_offset.
  constexpr uint64_t kMaxExtensionBytes = 16u << 20;   // 65,536 long label names fit in far less
  if (!(h.vox_offset >= 0.0f && h.vox_offset <= float(352 + (64u << 20))))   // NaN, negative or absurd
    throw file_error(path, "vox_offset " + std::to_string(h.vox_offset) + " is not a data offset");
  const uint64_t end = uint64_t(h.vox_offset);
  if (end <= 352) return out;
  if (end - 352 > kMaxExtensionBytes)
    throw file_error(path, "header extensions of " + std::to_string(end - 352) + " bytes (at most 16 MB are read)");
  GzPtr f = open_for_reading(path);
  std::string head(352, '\0');
  if (read_bytes(path, f.get(), head.data(), 352) != 352 || head[348] == 0) return out;
  out.bytes.resize(end - 352);
  if (read_bytes(path, f.get(), out.bytes.data(), out.bytes.size()) != out.bytes.size())
    throw file_error(path, "truncated: the header extensions end before vox_offset");
  return out;
}

namespace {

/// Writes `data` (`payload` bytes, NIfTI order) under the header `dims` and `datatype` describe, on
/// grid `g`: sform (and qform where the direction is a rotation), millimetres, atomically.
void write_nifti_image(const Geometry& g, const int64_t dims[8], int datatype, const void* data, uint64_t payload,
                       const std::string& path, int intent_code, const char* intent_name) {
  quiet_niftilib();
  check_writable_target(path);
  g.validate(path);
  NimPtr nim(nifti_make_new_nim(dims, datatype, 0));
  if (!nim) throw std::runtime_error(path + ": niftilib could not create an image header");

  nim->nifti_type = NIFTI_FTYPE_NIFTI1_1;
  nim->xyz_units = NIFTI_UNITS_MM;
  nim->dx = nim->pixdim[1] = g.spacing_mm[0];
  nim->dy = nim->pixdim[2] = g.spacing_mm[1];
  nim->dz = nim->pixdim[3] = g.spacing_mm[2];
  nim->scl_slope = 1.0;
  nim->scl_inter = 0.0;
  nim->intent_code = intent_code;
  std::snprintf(nim->intent_name, sizeof nim->intent_name, "%s", intent_name);
  const Mat4 a = g.index_to_world();
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) nim->sto_xyz.m[r][c] = a(r, c);
  nim->sform_code = NIFTI_XFORM_SCANNER_ANAT;
  // A qform can hold only a rotation (with one reflection flag): write it when the direction is one.
  const bool orthonormal = (g.direction.transpose() * g.direction - Mat3::Identity()).cwiseAbs().maxCoeff() < 1e-6;
  if (orthonormal) {
    nim->qform_code = NIFTI_XFORM_SCANNER_ANAT;
    nim->qto_xyz = nim->sto_xyz;
    double dx, dy, dz;
    nifti_dmat44_to_quatern(nim->qto_xyz, &nim->quatern_b, &nim->quatern_c, &nim->quatern_d, &nim->qoffset_x,
                            &nim->qoffset_y, &nim->qoffset_z, &dx, &dy, &dz, &nim->qfac);
    nim->pixdim[0] = nim->qfac;
  } else {
    nim->qform_code = NIFTI_XFORM_UNKNOWN;
  }
  std::snprintf(nim->descrip, sizeof nim->descrip, "pneumo %s", PNEUMO_VERSION);

  // The header as niftilib fills it in; the bytes written here: the 348-byte header, the 4-byte
  // extender (no extensions), the voxels from byte 352. A .nii.gz as gzip members deflated on every
  // core (io/gzip_members.h) at the fastest level, where niftilib's gzwrite used one core (a CT
  // compresses little better at zlib's default 6).
  nifti_set_iname_offset(nim.get(), 1);
  nifti_1_header header{};
  if (nifti_convert_nim2n1hdr(nim.get(), &header) != 0 || header.vox_offset != 352.0f)
    throw std::runtime_error(path + ": niftilib could not fill a NIfTI-1 header");
  const unsigned char extender[4] = {0, 0, 0, 0};
  AtomicFile out(path);
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> file(std::fopen(out.temp_path().c_str(), "wb"), &std::fclose);
  if (!file) throw file_error(path, "cannot create " + out.temp_path() + ": " + std::strerror(errno));
  unsigned char head[sizeof header + sizeof extender];
  std::memcpy(head, &header, sizeof header);
  std::memcpy(head + sizeof header, extender, sizeof extender);
  if (is_gz(path)) {
    write_gzip_members(file.get(), path, {{head, sizeof head}, {data, payload}}, kNiftiGzipLevel);
  } else if (std::fwrite(head, 1, sizeof head, file.get()) != sizeof head ||
             std::fwrite(data, 1, payload, file.get()) != payload) {
    throw std::runtime_error(path + ": writing failed: " + std::strerror(errno) + " (disk full?)");
  }
  if (std::fflush(file.get()) != 0 || std::fclose(file.release()) != 0)
    throw std::runtime_error(path + ": writing failed: " + std::strerror(errno) + " (disk full?); nothing was written "
                             "under this name");
  out.commit();
}

}  // namespace

void write_nifti(const Volume& v, const std::string& path) {
  const Geometry& g = v.geometry();
  const int64_t dims[8] = {3, g.dims[0], g.dims[1], g.dims[2], 1, 1, 1, 1};
  write_nifti_image(g, dims, nifti_datatype_of(v.type()), v.raw(), v.byte_count(), path, NIFTI_INTENT_NONE, "");
}

void write_nifti_vectors(const Geometry& g, const float* interleaved, int components, const std::string& path,
                         const std::string& intent_name) {
  if (components < 1 || components > 16) throw std::invalid_argument("write_nifti_vectors: 1 to 16 components");
  // NIfTI-1 §dim: a vector per voxel is dimension 5, after a singleton time axis (dim[4] = 1), and the
  // components are the slowest index, so each one is a whole volume in the file.
  const int64_t dims[8] = {5, g.dims[0], g.dims[1], g.dims[2], 1, components, 1, 1};
  const std::size_t n = std::size_t(g.voxel_count()), m = std::size_t(components);
  std::vector<float> planar(n * m);
  for (std::size_t c = 0; c < m; ++c)
    for (std::size_t v = 0; v < n; ++v) planar[c * n + v] = interleaved[v * m + c];
  write_nifti_image(g, dims, NIFTI_TYPE_FLOAT32, planar.data(), planar.size() * sizeof(float), path,
                    NIFTI_INTENT_VECTOR, intent_name.c_str());
}

}  // namespace pneumo
