#pragma once
// Reading and writing volumes: NIfTI-1 (.nii, .nii.gz), MetaImage (.mha, .mhd + raw) and NRRD (.nrrd;
// .nhdr + data, read only; io/nrrd_io.h), chosen by the file name, and a DICOM CT series read from
// its folder (io/dicom_io.h). Every reader checks a header against the file before allocating what it promises,
// and reports any problem as an InputError naming the file. Every writer is atomic.
#include <string>
#include <vector>

#include "io/volume.h"

namespace pneumo {

enum class VolumeFormat { Nifti, NiftiGz, MetaImageSingle, MetaImageSplit, Nrrd, NrrdDetached };

/// The format implied by the file name; throws InputError for an unknown extension.
VolumeFormat volume_format_from_path(const std::string& path);

/// Reads a volume: a folder as a DICOM CT series (float32 HU), a file by its name. Scaled integer data (NIfTI scl_slope/scl_inter other than 1/0) is returned as
/// float32 with the scaling applied (float64 where float32 would round the source type).
Volume read_volume(const std::string& path);

struct WriteOptions {
  bool compress_metaimage = false;   // zlib-compress MetaImage voxel data (NIfTI: by .gz name)
};
/// Writes atomically: a failed or interrupted write leaves no file at `path`.
void write_volume(const Volume& v, const std::string& path, const WriteOptions& opt = {});

/// Every file write_volume(v, path, opt) writes: `path`, and for a .mhd the data file beside it. A
/// command that must not overwrite a file unasked checks each of them.
std::vector<std::string> files_written_by(const std::string& path, const WriteOptions& opt = {});

/// The data file a .mhd header names and is written beside: its name with .raw, or .zraw compressed.
std::string metaimage_data_path(const std::string& mhd_path, bool compressed);

// Per-format entry points (used by the dispatchers above and by tests).
Volume read_nifti(const std::string& path);
/// The bytes of a NIfTI-1 file's header extensions (from byte 352 to vox_offset; empty when its
/// extension flag is 0) and whether the file's byte order is swapped. The header is checked as
/// read_nifti checks it.
struct NiftiExtensions {
  std::string bytes;
  bool swapped = false;
};
NiftiExtensions read_nifti_extensions(const std::string& path);
void write_nifti(const Volume& v, const std::string& path);
Volume read_metaimage(const std::string& path);
void write_metaimage(const Volume& v, const std::string& path, bool compress);
/// A float32 vector per voxel as a NIfTI-1 vector image (dim 5, intent NIFTI_INTENT_VECTOR, the
/// components written as given, `intent_name` at most 15 characters): `interleaved` holds `components`
/// values per voxel of `g`, voxels i fastest. Atomic, as every writer here.
void write_nifti_vectors(const Geometry& g, const float* interleaved, int components, const std::string& path,
                         const std::string& intent_name);

/// Largest voxel payload pneumo agrees to read (bytes): a header promising more is refused
/// before anything is allocated. 32 GiB: larger than any clinical CT, smaller than absurd.
constexpr uint64_t kMaxVolumeBytes = 32ull << 30;

/// Checks dims from a header (each ≥ 1, product × voxel bytes ≤ kMaxVolumeBytes) and returns
/// the payload size in bytes; throws InputError naming `path` otherwise. Overflow-safe.
uint64_t checked_payload_bytes(const std::string& path, const int64_t dims[3], std::size_t bytes_per_voxel);

/// Before a reader allocates the voxels a header promises: InputError naming `path`, the
/// dimensions and both figures when they exceed the memory this process may still take
/// (core/memory_budget.h).
void require_volume_memory(const std::string& path, const Geometry& g, VoxelType t);

}  // namespace pneumo
