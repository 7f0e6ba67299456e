#include "io/itk_transform_io.h"

#include <hdf5.h>

#include <algorithm>
#include <stdexcept>
#include <vector>

#include "core/atomic_file.h"

namespace pneumo {
namespace {

/// Closes an HDF5 handle on scope exit (H5Fclose, H5Dclose, ...), so an error path leaks nothing.
class Handle {
 public:
  Handle(hid_t id, herr_t (*close)(hid_t), const char* what) : id_(id), close_(close) {
    if (id_ < 0) throw std::runtime_error(std::string("HDF5: cannot create ") + what);
  }
  ~Handle() { close_(id_); }
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  hid_t id() const { return id_; }

 private:
  hid_t id_;
  herr_t (*close_)(hid_t);
};

void check(herr_t status, const char* what) {
  if (status < 0) throw std::runtime_error(std::string("HDF5: cannot write ") + what);
}

/// A dataset of one variable-length string, as ITK writes its strings (H5T_C_S1, H5T_VARIABLE).
void write_string(hid_t file, const char* name, const std::string& value) {
  const Handle type(H5Tcopy(H5T_C_S1), H5Tclose, "a string type");
  check(H5Tset_size(type.id(), H5T_VARIABLE), "a string type");
  const hsize_t one = 1;
  const Handle space(H5Screate_simple(1, &one, nullptr), H5Sclose, "a dataspace");
  const Handle set(H5Dcreate2(file, name, type.id(), space.id(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Dclose,
                   name);
  const char* text = value.c_str();
  check(H5Dwrite(set.id(), type.id(), H5S_ALL, H5S_ALL, H5P_DEFAULT, &text), name);
}

/// A one-dimensional dataset of `n` values of `memory_type` stored as `file_type`; deflated in
/// chunks when `compress` (the field: mostly zeros and smooth), plain otherwise (18 numbers).
void write_array(hid_t file, const char* name, hid_t file_type, hid_t memory_type, const void* data, hsize_t n,
                 bool compress) {
  const Handle space(H5Screate_simple(1, &n, nullptr), H5Sclose, "a dataspace");
  const Handle properties(H5Pcreate(H5P_DATASET_CREATE), H5Pclose, "dataset properties");
  if (compress && n > 0) {
    const hsize_t chunk = std::min<hsize_t>(n, hsize_t(1) << 20);
    check(H5Pset_chunk(properties.id(), 1, &chunk), "the chunking");
    check(H5Pset_deflate(properties.id(), 1), "the compression");
  }
  const Handle set(H5Dcreate2(file, name, file_type, space.id(), H5P_DEFAULT, properties.id(), H5P_DEFAULT),
                   H5Dclose, name);
  check(H5Dwrite(set.id(), memory_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data), name);
}

}  // namespace

void write_itk_displacement_field_transform(const Geometry& grid, const float* u_lps_mm, const std::string& path) {
  // World RAS to ITK's LPS: x and y change sign, for the origin and for the direction's rows.
  const Mat3 ras_to_lps = Vec3(-1.0, -1.0, 1.0).asDiagonal();
  const Vec3 origin = ras_to_lps * grid.origin_mm;
  const Mat3 direction = ras_to_lps * grid.direction;
  // DisplacementFieldTransform's fixed parameters: size, origin, spacing, then the direction
  // matrix row by row (element [3 + 3 r + c] of the last block is direction(r, c)).
  std::vector<double> fixed;
  for (int a = 0; a < 3; ++a) fixed.push_back(double(grid.dims[a]));
  for (int a = 0; a < 3; ++a) fixed.push_back(origin[a]);
  for (int a = 0; a < 3; ++a) fixed.push_back(grid.spacing_mm[a]);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) fixed.push_back(direction(r, c));

  AtomicFile out(path);
  {
    // HDF5 prints its own error stack on failure; the exception below says what failed instead.
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
    const Handle file(H5Fcreate(out.temp_path().c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT), H5Fclose,
                      out.temp_path().c_str());
    // ITK also writes /ITKVersion, /OSName and /OSVersion, which its reader ignores; pneumo is none of them.
    write_string(file.id(), "/HDFVersion", H5_VERS_INFO);
    {
      const Handle group(H5Gcreate2(file.id(), "/TransformGroup", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose,
                         "/TransformGroup");
      const Handle first(H5Gcreate2(file.id(), "/TransformGroup/0", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose,
                         "/TransformGroup/0");
    }
    write_string(file.id(), "/TransformGroup/0/TransformType", "DisplacementFieldTransform_double_3_3");
    write_array(file.id(), "/TransformGroup/0/TranformFixedParameters", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE,
                fixed.data(), fixed.size(), false);
    write_array(file.id(), "/TransformGroup/0/TranformParameters", H5T_IEEE_F32LE, H5T_NATIVE_FLOAT, u_lps_mm,
                hsize_t(3) * hsize_t(grid.voxel_count()), true);
    check(H5Fflush(file.id(), H5F_SCOPE_GLOBAL), path.c_str());
  }
  out.commit();
}

}  // namespace pneumo
