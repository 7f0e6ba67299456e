#include "solve/newton_cl.h"

#include <cmath>

#include "mesh/adjacency.h"
#include "solve/force_field.h"
#include "solve/forces_cl.h"
#include "solve/pressure_stiffness.h"

namespace pneumo {

namespace {

constexpr std::size_t kLocal = ocl::kWorkGroupSize;
constexpr std::size_t kDotGroups = 256;   // partial sums per dot product

std::vector<cl_float4> columns(const std::vector<Mat3>& blocks) {
  std::vector<cl_float4> out(std::max<std::size_t>(3 * blocks.size(), 1), cl_float4{{0, 0, 0, 0}});
  for (std::size_t n = 0; n < blocks.size(); ++n)
    for (int a = 0; a < 3; ++a)
      out[3 * n + a] = {{float(blocks[n](0, a)), float(blocks[n](1, a)), float(blocks[n](2, a)), 0.0f}};
  return out;
}

class ClNewtonLinearSolver final : public NewtonLinearSolver {
 public:
  ClNewtonLinearSolver(ocl::Context& ctx, const Mesh& m, DeviceStiffness k, std::vector<TiedPair> ties)
      : ctx_(ctx), m_(m), k_(std::move(k)), ties_(std::move(ties)), N_(m.node_count()),
        R_(int64_t(m.load_tet.size())) {
    ctx.check_fits(newton_linear_solver_cl_bytes(m, ties_.size()), uint64_t(std::max<int64_t>(R_, 1)) * 6 * 16,
                   "Newton's conjugate gradients on this mesh (" + std::to_string(N_) + " nodes)");
    const Adjacency adj = Adjacency::of(m);
    std::vector<cl_int4> load_nodes(std::max<int64_t>(R_, 1), cl_int4{{0, 0, 0, 0}});
    for (int64_t l = 0; l < R_; ++l) {
      const auto& q = m.tets[m.load_tet[l]];
      load_nodes[l] = {{q[0], q[1], q[2], q[3]}};
    }
    load_nodes_ = ocl::upload(ctx, load_nodes);
    load_start_ = ocl::upload(ctx, adj.loads.start);
    load_item_ = ocl::upload(ctx, adj.loads.item);
    hold_ = ocl::upload(ctx, m.hold);
    std::vector<cl_int2> pairs(std::max<std::size_t>(ties_.size(), 1), cl_int2{{0, 0}});
    std::vector<float> pair_k(pairs.size(), 0.0f);
    for (std::size_t i = 0; i < ties_.size(); ++i) {
      pairs[i] = {{ties_[i].wall, ties_[i].viscera}};
      pair_k[i] = float(ties_[i].stiffness_n_per_m);
    }
    pairs_ = ocl::upload(ctx, pairs);
    pair_k_ = ocl::upload(ctx, pair_k);
    auto rw = [&](std::size_t bytes) { return cl::Buffer(ctx.context(), CL_MEM_READ_WRITE, std::max<std::size_t>(bytes, 16)); };
    const std::size_t vec = std::size_t(N_) * sizeof(cl_float4);
    b_ = rw(vec), r_ = rw(vec), z_ = rw(vec), p_ = rw(vec), ap_ = rw(vec), d_ = rw(vec);
    blocks_ = rw(3 * vec), precond_ = rw(3 * vec);
    u_ = rw(std::size_t(6 * R_) * sizeof(cl_float4));
    load_out_ = rw(std::size_t(4 * R_) * sizeof(cl_float4));
    partial_ = rw(kDotGroups * sizeof(float));
    k_precondition_ = ctx.kernel("newton_cg.cl", "cg_precondition");
    k_update_ = ctx.kernel("newton_cg.cl", "cg_update");
    k_direction_ = ctx.kernel("newton_cg.cl", "cg_direction");
    k_dot_ = ctx.kernel("newton_cg.cl", "cg_dot");
    k_pressure_ = ctx.kernel("newton_cg.cl", "cg_pressure_product");
    k_gather_loads_ = ctx.kernel("newton_cg.cl", "cg_gather_loads");
    k_tie_ = ctx.kernel("newton_cg.cl", "cg_tie_product");
    k_shift_hold_ = ctx.kernel("newton_cg.cl", "cg_shift_and_hold");
  }

  void linearize(const ForceModel& model, const std::vector<Vec3>& x) override {
    k_.field->linearize(model, x);
    PressureStiffness pressure;
    pressure.linearize(m_, x, model.pressure_pa);
    pressure_on_ = !pressure.pairs().empty();
    if (pressure_on_) {
      std::vector<cl_float4> u(6 * pressure.pairs().size());
      for (std::size_t l = 0; l < pressure.pairs().size(); ++l)
        for (int k = 0; k < 6; ++k) {
          const Vec3& v = pressure.pairs()[l][k];
          u[6 * l + k] = {{float(v[0]), float(v[1]), float(v[2]), 0.0f}};
        }
      ctx_.queue().enqueueWriteBuffer(u_, CL_TRUE, 0, u.size() * sizeof(cl_float4), u.data());
    }
    std::vector<Mat3> blocks;
    k_.field->stiffness_diagonal(blocks);
    for (const TiedPair& p : ties_) {   // the bonds' diagonal (interface_tie.cpp)
      blocks[p.wall] += p.stiffness_n_per_m * Mat3::Identity();
      blocks[p.viscera] += p.stiffness_n_per_m * Mat3::Identity();
    }
    write(blocks_, columns(blocks));
    write(precond_, columns(block_jacobi(m_, blocks)));
  }

  CgOutcome solve(const std::vector<Vec3>& b, double eta, int max_iterations, Shift& shift,
                  std::vector<Vec3>& d) override {
    write(b_, to_float4(b));
    double bb = 0.0;
    for (const Vec3& v : b) bb += v.squaredNorm();
    const double stop = eta * std::sqrt(bb);
    const CgOutcome cg =
        with_growing_shift(shift, [&](double sigma) { return conjugate_gradients(sigma, stop, max_iterations); });
    std::vector<cl_float4> raw(N_);
    ctx_.queue().enqueueReadBuffer(d_, CL_TRUE, 0, N_ * sizeof(cl_float4), raw.data());
    d.resize(N_);
    for (int64_t n = 0; n < N_; ++n) d[n] = Vec3(raw[n].s[0], raw[n].s[1], raw[n].s[2]);
    return cg;
  }

 private:
  // conjugate_gradients.cpp, step for step, on the device.
  CgOutcome conjugate_gradients(double sigma, double stop, int max_iterations) {
    auto& q = ctx_.queue();
    CgOutcome out;
    const std::size_t vec = std::size_t(N_) * sizeof(cl_float4);
    q.enqueueCopyBuffer(b_, r_, 0, 0, vec);
    q.enqueueFillBuffer(d_, cl_float4{{0, 0, 0, 0}}, 0, vec);
    run(k_precondition_, N_, r_, precond_, cl_int(N_), z_);
    q.enqueueCopyBuffer(z_, p_, 0, 0, vec);
    double rz = dot(r_, z_);
    for (int it = 0; it < max_iterations; ++it) {
      apply(sigma);
      const double pap = dot(p_, ap_);
      if (!(pap > 0.0)) {
        out.negative_curvature = true;
        break;
      }
      run(k_update_, N_, d_, r_, p_, ap_, float(rz / pap), cl_int(N_));
      out.iterations = it + 1;
      if (std::sqrt(dot(r_, r_)) <= stop) break;
      run(k_precondition_, N_, r_, precond_, cl_int(N_), z_);
      const double rz_next = dot(r_, z_);
      const double beta = rz_next / rz;
      rz = rz_next;
      run(k_direction_, N_, p_, z_, float(beta), cl_int(N_));
    }
    return out;
  }

  // ap = (K + σD) p with held axes zeroed: the field's K, the pressure's, the bonds'.
  void apply(double sigma) {
    k_.product(p_, ap_);
    if (pressure_on_ && R_ > 0) {
      run(k_pressure_, R_, p_, load_nodes_, u_, cl_int(R_), load_out_);
      run(k_gather_loads_, N_, load_out_, load_start_, load_item_, cl_int(N_), ap_);
    }
    if (!ties_.empty()) run(k_tie_, int64_t(ties_.size()), p_, pairs_, pair_k_, cl_int(ties_.size()), ap_);
    run(k_shift_hold_, N_, ap_, blocks_, p_, float(sigma), hold_, cl_int(N_));
  }

  double dot(const cl::Buffer& a, const cl::Buffer& b) {
    ocl::set_args(k_dot_, a, b, cl_int(N_), partial_);
    ctx_.queue().enqueueNDRangeKernel(k_dot_, cl::NullRange, cl::NDRange(kDotGroups * kLocal), cl::NDRange(kLocal));
    float partial[kDotGroups];
    ctx_.queue().enqueueReadBuffer(partial_, CL_TRUE, 0, sizeof partial, partial);
    double s = 0.0;
    for (float v : partial) s += v;
    return s;
  }

  template <class... A>
  void run(cl::Kernel& k, int64_t items, const A&... args) {
    ocl::set_args(k, args...);
    ctx_.queue().enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(ocl::global_size(items)), cl::NDRange(kLocal));
  }

  void write(cl::Buffer& buf, const std::vector<cl_float4>& v) {
    ctx_.queue().enqueueWriteBuffer(buf, CL_TRUE, 0, v.size() * sizeof(cl_float4), v.data());
  }

  ocl::Context& ctx_;
  const Mesh& m_;
  DeviceStiffness k_;
  std::vector<TiedPair> ties_;
  int64_t N_, R_;
  bool pressure_on_ = false;
  cl::Buffer load_nodes_, load_start_, load_item_, hold_, pairs_, pair_k_;
  cl::Buffer b_, r_, z_, p_, ap_, d_, blocks_, precond_, u_, load_out_, partial_;
  cl::Kernel k_precondition_, k_update_, k_direction_, k_dot_, k_pressure_, k_gather_loads_, k_tie_, k_shift_hold_;
};

}  // namespace

uint64_t newton_linear_solver_cl_bytes(const Mesh& m, std::size_t ties) {
  const uint64_t N = uint64_t(m.node_count()), R = uint64_t(m.load_tet.size());
  // Per node: six vectors and two 3-column blocks of float4 (192 bytes), the hold mask, its load rows.
  // Per load: its nodes, six pair vectors and four contributions (176 bytes) and its 4 adjacency items.
  // Per bond: two node indices and a stiffness.
  // Every buffer holds one entry at least: 16 bytes for each of the 16 an empty mesh would still create.
  return N * (12 * 16 + 1 + 8) + 8 + R * (16 + 6 * 16 + 4 * 16 + 4 * 4) + ties * 12 + kDotGroups * 4 + 16 * 16;
}

std::unique_ptr<NewtonLinearSolver> make_newton_linear_solver_cl(ocl::Context& ctx, const Mesh& m, DeviceStiffness k,
                                                                 std::vector<TiedPair> ties) {
  return std::make_unique<ClNewtonLinearSolver>(ctx, m, std::move(k), std::move(ties));
}

}  // namespace pneumo
