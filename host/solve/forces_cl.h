#pragma once
// The force evaluation of forces.h on an OpenCL device (kernels/msd_forces.cl), float32, with the
// mesh and the state resident on the device. Padded, slot-major neighbour tables are built once.
// The device holds displacements u = x − x₀ (see msd_forces.cl); positions() is that buffer.
#include <memory>
#include <vector>

#include "cl/cl_runtime.h"
#include "mesh/mesh.h"
#include "solve/forces.h"

namespace pneumo {

class ClForceEvaluator {
 public:
  /// Uploads the mesh. Checks the memory it needs, plus `extra_bytes_per_node` the caller will
  /// allocate beside it, against the device first (InputError with the estimate if it does not fit).
  ClForceEvaluator(ocl::Context& ctx, const Mesh& mesh, uint64_t extra_bytes_per_node = 0);

  /// Positions x (metres) go up as displacements x − x₀, formed in double.
  void upload_state(const std::vector<Vec3>& x, const std::vector<Vec3>& v);
  /// Positions x₀ + u (double) from a device displacement buffer.
  std::vector<Vec3> download_positions(cl::Buffer& u);
  /// Evaluates into the device force buffer.
  void evaluate(const ForceModel& model);
  void download_forces(std::vector<Vec3>& f);

  cl::Buffer& positions() { return x_; }   // displacements u
  cl::Buffer& velocities() { return v_; }
  cl::Buffer& forces() { return f_; }
  int spring_slots() const { return spring_slots_; }

 private:
  ocl::Context& ctx_;
  int64_t nodes_, tris_, tets_;
  int spring_slots_ = 0, tri_slots_ = 0, tet_slots_ = 0;
  cl::Buffer x_, v_, rest_x_, mass_, f_;
  cl::Buffer spring_node_, spring_k_, spring_c_, spring_rest_;
  cl::Buffer tris_buf_, tri_force_, node_tri_;
  cl::Buffer tets_buf_, tet_force_, node_tet_;
  std::vector<Vec3> rest_m_;
  cl::Kernel k_tri_, k_tet_, k_node_;
};

/// float4 packing of node vectors (x, y, z, 0).
std::vector<cl_float4> to_float4(const std::vector<Vec3>& v);

}  // namespace pneumo
