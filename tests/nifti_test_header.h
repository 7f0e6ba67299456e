#pragma once
// A NIfTI-1 header written by hand, for the tests that build files byte by byte (no gtest, so the
// fuzzers' seed writer can use it too).
#include <nifti1.h>

#include <cstring>

namespace pneumo::testing_support {

/// A valid NIfTI-1 header (RAS identity sform, 1 mm, data at 352) for nx × ny × nz voxels of one
/// type, to be spoiled or sized by the tests that write files by hand.
inline nifti_1_header nifti1_test_header(int nx, int ny, int nz, short datatype, short bitpix) {
  nifti_1_header h;
  std::memset(&h, 0, sizeof h);
  h.sizeof_hdr = 348;
  h.dim[0] = 3;
  h.dim[1] = static_cast<short>(nx);
  h.dim[2] = static_cast<short>(ny);
  h.dim[3] = static_cast<short>(nz);
  for (int i = 4; i < 8; ++i) h.dim[i] = 1;
  h.datatype = datatype;
  h.bitpix = bitpix;
  for (int i = 0; i < 8; ++i) h.pixdim[i] = 1.0f;
  h.vox_offset = 352.0f;
  h.scl_slope = 1.0f;
  h.xyzt_units = NIFTI_UNITS_MM;
  h.sform_code = NIFTI_XFORM_SCANNER_ANAT;
  h.srow_x[0] = h.srow_y[1] = h.srow_z[2] = 1.0f;
  std::memcpy(h.magic, "n+1\0", 4);
  return h;
}

}  // namespace pneumo::testing_support
