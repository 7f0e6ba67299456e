#pragma once
// The force evaluation of forces.h on an OpenCL device (kernels/msd_forces.cl), float32, with the
// mesh and the state resident on the device. The per-node gather runs on blocks of nodes of equal
// degree (see msd_forces.cl); their tables are built once.
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
  /// That estimate (bytes): at least what the constructor allocates, plus the extra per node.
  static uint64_t device_bytes(const Mesh& mesh, uint64_t extra_bytes_per_node = 0);

  /// Positions x (metres) go up as displacements x − x₀, formed in double.
  void upload_state(const std::vector<Vec3>& x, const std::vector<Vec3>& v);
  /// Positions x₀ + u (double) from a device displacement buffer.
  std::vector<Vec3> download_positions(cl::Buffer& u);
  /// Evaluates into the device force buffer. Nodes::Free skips the nodes held on all three axes
  /// (their entries keep what they held: zero unless an All evaluation wrote them): what the solvers
  /// need, since they mask forces by the hold mask; on a CT a third or more of the nodes are fixed.
  enum class Nodes { All, Free };
  void evaluate(const ForceModel& model, Nodes which = Nodes::All);
  void download_forces(std::vector<Vec3>& f);

  cl::Buffer& positions() { return x_; }   // displacements u
  cl::Buffer& velocities() { return v_; }
  cl::Buffer& forces() { return f_; }
  /// Spring records an evaluation reads per mesh node, padding included (a node's own springs on
  /// average, plus the padding its block's widest node adds): what the gather moves from the table.
  double spring_records_per_node(Nodes which = Nodes::All) const;
  /// The share of the mesh's node blocks an evaluation gathers.
  double gathered_fraction(Nodes which = Nodes::All) const;

 private:
  ocl::Context& ctx_;
  int64_t nodes_, loads_, tets_, blocks_ = 0, free_blocks_ = 0;
  std::vector<int> spring_begin_host_;
  cl::Buffer x_, v_, rest_x_, mass_, f_;
  cl::Buffer block_nodes_, spring_begin_, spring_node_, spring_k_, spring_c_, spring_rest_[4];   // rest: x, y, z, length
  cl::Buffer load_nodes_, load_c_, load_force_, load_begin_, node_load_, tet_fraction_;
  cl::Buffer tets_buf_, tet_force_, tet_begin_, node_tet_;
  std::vector<Vec3> rest_m_;
  cl::Kernel k_load_, k_tet_, k_node_;
};

/// float4 packing of node vectors (x, y, z, 0).
std::vector<cl_float4> to_float4(const std::vector<Vec3>& v);

}  // namespace pneumo
