#pragma once
// A 3-D scalar volume: its grid in world space and its voxels in their stored type.
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "core/geometry.h"

namespace pneumo {

enum class VoxelType { Int8, UInt8, Int16, UInt16, Int32, UInt32, Float32, Float64 };

std::size_t voxel_size(VoxelType t);
const char* voxel_type_name(VoxelType t);   // "int16", "float32", ...
bool is_integer(VoxelType t);

template <class T> constexpr VoxelType voxel_type_of();
template <> constexpr VoxelType voxel_type_of<int8_t>() { return VoxelType::Int8; }
template <> constexpr VoxelType voxel_type_of<uint8_t>() { return VoxelType::UInt8; }
template <> constexpr VoxelType voxel_type_of<int16_t>() { return VoxelType::Int16; }
template <> constexpr VoxelType voxel_type_of<uint16_t>() { return VoxelType::UInt16; }
template <> constexpr VoxelType voxel_type_of<int32_t>() { return VoxelType::Int32; }
template <> constexpr VoxelType voxel_type_of<uint32_t>() { return VoxelType::UInt32; }
template <> constexpr VoxelType voxel_type_of<float>() { return VoxelType::Float32; }
template <> constexpr VoxelType voxel_type_of<double>() { return VoxelType::Float64; }

/// Calls f(T*) with the voxel pointer typed by t.
template <class F>
decltype(auto) dispatch_voxel_type(VoxelType t, void* p, F&& f) {
  switch (t) {
    case VoxelType::Int8: return f(static_cast<int8_t*>(p));
    case VoxelType::UInt8: return f(static_cast<uint8_t*>(p));
    case VoxelType::Int16: return f(static_cast<int16_t*>(p));
    case VoxelType::UInt16: return f(static_cast<uint16_t*>(p));
    case VoxelType::Int32: return f(static_cast<int32_t*>(p));
    case VoxelType::UInt32: return f(static_cast<uint32_t*>(p));
    case VoxelType::Float32: return f(static_cast<float*>(p));
    case VoxelType::Float64: return f(static_cast<double*>(p));
  }
  throw std::logic_error("unknown voxel type");
}

/// Voxels are stored in host byte order, i fastest, then j, then k.
class Volume {
 public:
  Volume() = default;
  Volume(const Geometry& g, VoxelType t) : geom_(g), type_(t), bytes_(g.voxel_count() * voxel_size(t)) {}

  const Geometry& geometry() const { return geom_; }
  Geometry& geometry() { return geom_; }
  VoxelType type() const { return type_; }
  int64_t voxel_count() const { return geom_.voxel_count(); }
  std::size_t byte_count() const { return bytes_.size(); }
  void* raw() { return bytes_.data(); }
  const void* raw() const { return bytes_.data(); }

  template <class T> T* data() { check<T>(); return reinterpret_cast<T*>(bytes_.data()); }
  template <class T> const T* data() const { check<T>(); return reinterpret_cast<const T*>(bytes_.data()); }

  /// Voxel n as a double, whatever the stored type.
  double value(int64_t n) const;
  double value(int64_t i, int64_t j, int64_t k) const { return value(geom_.linear_index(i, j, k)); }
  /// All voxels as float32 (CT in HU for the solver, warp and renderer).
  std::vector<float> to_float32() const;
  /// Minimum and maximum over the non-NaN voxels; NaN voxels are counted in nan_count.
  struct Range { double min = 0, max = 0; int64_t nan_count = 0; };
  Range range() const;
  /// Bit-identical voxels, type and grid.
  bool same_voxels(const Volume& o) const { return type_ == o.type_ && bytes_ == o.bytes_; }

 private:
  template <class T> void check() const {
    if (voxel_type_of<std::remove_cv_t<T>>() != type_)
      throw std::logic_error(std::string("volume holds ") + voxel_type_name(type_));
  }
  Geometry geom_;
  VoxelType type_ = VoxelType::UInt8;
  std::vector<uint8_t> bytes_;
};

}  // namespace pneumo
