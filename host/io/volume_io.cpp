#include "io/volume_io.h"

#include <algorithm>
#include <sstream>

#include "core/error.h"
#include "core/memory_budget.h"
#include "io/dicom_io.h"
#include "io/nrrd_io.h"

namespace pneumo {

namespace {
bool ends_with(const std::string& s, const std::string& suffix) {
  if (s.size() < suffix.size()) return false;
  return std::equal(suffix.rbegin(), suffix.rend(), s.rbegin(),
                    [](char a, char b) { return std::tolower(a) == std::tolower(b); });
}
}  // namespace

VolumeFormat volume_format_from_path(const std::string& path) {
  if (ends_with(path, ".nii.gz")) return VolumeFormat::NiftiGz;
  if (ends_with(path, ".nii")) return VolumeFormat::Nifti;
  if (ends_with(path, ".mha")) return VolumeFormat::MetaImageSingle;
  if (ends_with(path, ".mhd")) return VolumeFormat::MetaImageSplit;
  if (ends_with(path, ".nrrd")) return VolumeFormat::Nrrd;
  if (ends_with(path, ".nhdr")) return VolumeFormat::NrrdDetached;
  throw file_error(path,
                   "unknown volume format (expected .nii, .nii.gz, .mha, .mhd, .nrrd, .nhdr, or the folder of a DICOM series)");
}

Volume read_volume(const std::string& path) {
  // A folder is a DICOM series unless its name is a volume file's (a folder "ct.mha" is a mistake
  // the MetaImage reader names as such).
  const bool file_name = ends_with(path, ".nii.gz") || ends_with(path, ".nii") || ends_with(path, ".mha") ||
                         ends_with(path, ".mhd") || ends_with(path, ".nrrd") || ends_with(path, ".nhdr");
  if (!file_name && is_dicom_series_folder(path)) return read_dicom_series(path);
  switch (volume_format_from_path(path)) {
    case VolumeFormat::Nifti:
    case VolumeFormat::NiftiGz: return read_nifti(path);
    case VolumeFormat::MetaImageSingle:
    case VolumeFormat::MetaImageSplit: return read_metaimage(path);
    case VolumeFormat::Nrrd:
    case VolumeFormat::NrrdDetached: return read_nrrd(path);
  }
  throw file_error(path, "unknown volume format");
}

void write_volume(const Volume& v, const std::string& path, const WriteOptions& opt) {
  switch (volume_format_from_path(path)) {
    case VolumeFormat::Nifti:
    case VolumeFormat::NiftiGz: return write_nifti(v, path);
    case VolumeFormat::MetaImageSingle:
    case VolumeFormat::MetaImageSplit: return write_metaimage(v, path, opt.compress_metaimage);
    case VolumeFormat::Nrrd: return write_nrrd(v, path);
    case VolumeFormat::NrrdDetached:
      throw file_error(path, "pneumo writes NRRD as one file: name it .nrrd (a detached .nhdr is read, not written)");
  }
}

std::vector<std::string> files_written_by(const std::string& path, const WriteOptions& opt) {
  if (volume_format_from_path(path) == VolumeFormat::MetaImageSplit)
    return {path, metaimage_data_path(path, opt.compress_metaimage)};
  return {path};
}

uint64_t checked_payload_bytes(const std::string& path, const int64_t dims[3], std::size_t bytes_per_voxel) {
  uint64_t total = bytes_per_voxel;
  for (int a = 0; a < 3; ++a) {
    if (dims[a] < 1) {
      std::ostringstream os;
      os << "dimension " << a << " is " << dims[a] << " (must be at least 1)";
      throw file_error(path, os.str());
    }
    // Divided, not multiplied: 2^33 bytes × 2^32 voxels is 0 in 64 bits and would pass.
    if (static_cast<uint64_t>(dims[a]) > kMaxVolumeBytes / total) {
      std::ostringstream os;
      os << "dimensions " << dims[0] << " x " << dims[1] << " x " << dims[2] << " promise more than "
         << (kMaxVolumeBytes >> 30) << " GiB of voxels: refusing an absurd header";
      throw file_error(path, os.str());
    }
    total *= static_cast<uint64_t>(dims[a]);
  }
  return total;
}

void require_volume_memory(const std::string& path, const Geometry& g, VoxelType t) {
  std::ostringstream what;
  what << path << ": an image of " << g.dims[0] << " x " << g.dims[1] << " x " << g.dims[2] << " " << voxel_type_name(t)
       << " voxels";
  require_memory(uint64_t(g.voxel_count()) * voxel_size(t), what.str(), "crop or resample the image, or free memory");
}

}  // namespace pneumo
