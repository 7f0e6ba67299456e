#include "io/volume.h"

#include <cmath>
#include <limits>

namespace pneumo {

std::size_t voxel_size(VoxelType t) {
  switch (t) {
    case VoxelType::Int8: case VoxelType::UInt8: return 1;
    case VoxelType::Int16: case VoxelType::UInt16: return 2;
    case VoxelType::Int32: case VoxelType::UInt32: case VoxelType::Float32: return 4;
    case VoxelType::Float64: return 8;
  }
  return 0;
}

const char* voxel_type_name(VoxelType t) {
  switch (t) {
    case VoxelType::Int8: return "int8";
    case VoxelType::UInt8: return "uint8";
    case VoxelType::Int16: return "int16";
    case VoxelType::UInt16: return "uint16";
    case VoxelType::Int32: return "int32";
    case VoxelType::UInt32: return "uint32";
    case VoxelType::Float32: return "float32";
    case VoxelType::Float64: return "float64";
  }
  return "?";
}

bool is_integer(VoxelType t) { return t != VoxelType::Float32 && t != VoxelType::Float64; }

double Volume::value(int64_t n) const {
  return dispatch_voxel_type(type_, const_cast<uint8_t*>(bytes_.data()),
                             [n](auto* p) { return static_cast<double>(p[n]); });
}

std::vector<float> Volume::to_float32() const {
  std::vector<float> out(voxel_count());
  dispatch_voxel_type(type_, const_cast<uint8_t*>(bytes_.data()), [&](auto* p) {
    const int64_t n = voxel_count();
#pragma omp parallel for schedule(static)
    for (int64_t i = 0; i < n; ++i) out[i] = static_cast<float>(p[i]);
  });
  return out;
}

Volume::Range Volume::range() const {
  Range r;
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  dispatch_voxel_type(type_, const_cast<uint8_t*>(bytes_.data()), [&](auto* p) {
    const int64_t n = voxel_count();
    for (int64_t i = 0; i < n; ++i) {
      const double v = static_cast<double>(p[i]);
      if (std::isnan(v)) { ++r.nan_count; continue; }
      lo = v < lo ? v : lo;
      hi = v > hi ? v : hi;
    }
  });
  if (lo <= hi) { r.min = lo; r.max = hi; }
  return r;
}

}  // namespace pneumo
