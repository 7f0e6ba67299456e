#pragma once
// A dense displacement field as an ITK transform file (.h5), the form ITK's TransformFileReader,
// ANTs (antsApplyTransforms -t) and 3D Slicer's "Load transform" take as a transform rather than as
// an image. The same field as warp/displacement_field.h: LPS millimetres, pull-back, on `grid`.
//
// Layout (ITK's HDF5TransformIO, which reads nothing else): /TransformGroup/0/TransformType, the
// string "DisplacementFieldTransform_double_3_3"; /TransformGroup/0/TranformFixedParameters (ITK's
// spelling) the field's size, origin, spacing and row-major direction, all in LPS; and
// /TransformGroup/0/TranformParameters the vectors interleaved, voxels i fastest. The parameters are
// float32, chunked and deflated (ITK reads either precision; pneumo's field is float32 already).
#include <string>

#include "core/geometry.h"

namespace pneumo {

/// Writes atomically: a failed or interrupted write leaves no file at `path`.
/// `u_lps_mm` holds 3 values per voxel of `grid` (whose geometry is world RAS, as every Geometry).
void write_itk_displacement_field_transform(const Geometry& grid, const float* u_lps_mm, const std::string& path);

}  // namespace pneumo
