#include "solve/fem_force_field_cl.h"

#include <optional>
#include <stdexcept>
#include <string>

#include "mesh/adjacency.h"
#include "solve/fem_tets.h"
#include "solve/forces_cl.h"
#include "solve/newton_cl.h"

namespace pneumo {

namespace {

constexpr std::size_t kLocal = ocl::kWorkGroupSize;
// The element state's layout shared with fem_forces.cl (passed as build options): floats per
// tetrahedron, and where its dilatation e and deviatoric energy density ψ sit.
constexpr int kStateFloats = 40;
constexpr int kStateE = 27, kStatePsi = 32;
const std::string kStateOptions = "-DkStateFloats=" + std::to_string(kStateFloats) +
                                  " -DS_E=" + std::to_string(kStateE) + " -DS_PSI=" + std::to_string(kStatePsi);

class ClFemForceField final : public ForceField {
 public:
  ClFemForceField(ocl::Context& ctx, const Mesh& m, FemLaw law)
      : ctx_(ctx), m_(m), law_(law), tets_(m, law), N_(m.node_count()), T_(int64_t(m.tets.size())),
        R_(int64_t(m.load_tet.size())) {
    ctx.check_fits(fem_force_field_cl_bytes(m), uint64_t(std::max<int64_t>(T_, 1)) * kStateFloats * 4,
                   "the finite elements of this mesh (" + std::to_string(N_) + " nodes)");
    const Adjacency adj = Adjacency::of(m);
    std::vector<cl_int4> tets(std::max<int64_t>(T_, 1), cl_int4{{0, 0, 0, 0}});
    std::vector<float> dm_inv(9 * tets.size(), 0.0f), weight(tets.size(), 0.0f);
    std::vector<cl_float4> consts(tets.size(), cl_float4{{0, 0, 0, 0}}), fibre(tets.size(), cl_float4{{0, 0, 0, 0}});
    for (int64_t t = 0; t < T_; ++t) {
      const auto& q = m.tets[t];
      tets[t] = {{q[0], q[1], q[2], q[3]}};
      for (int i = 0; i < 9; ++i) dm_inv[9 * t + i] = float(tets_.rest[t].dm_inverse(i / 3, i % 3));
      const TetMaterial& mt = tets_.material[t];
      consts[t] = {{float(tets_.rest[t].volume_m3), float(mt.mu), float(tets_.kappa[t]), float(mt.fibre_k2)}};
      fibre[t] = {{float(mt.fibre[0]), float(mt.fibre[1]), float(mt.fibre[2]), float(mt.fibre_k1_pa)}};
      weight[t] = float(tets_.kappa[t] * tets_.rest[t].volume_m3);
    }
    tets_buf_ = ocl::upload(ctx, tets);
    dm_inv_ = ocl::upload(ctx, dm_inv);
    consts_ = ocl::upload(ctx, consts);
    fibre_ = ocl::upload(ctx, fibre);
    weight_ = ocl::upload(ctx, weight);
    tet_start_ = ocl::upload(ctx, adj.tets.start);
    tet_item_ = ocl::upload(ctx, adj.tets.item);
    load_start_ = ocl::upload(ctx, adj.loads.start);
    load_item_ = ocl::upload(ctx, adj.loads.item);
    std::vector<cl_int4> load_nodes(std::max<int64_t>(R_, 1), cl_int4{{0, 0, 0, 0}});
    std::vector<cl_float4> load_c(4 * load_nodes.size(), cl_float4{{0, 0, 0, 0}});
    for (int64_t l = 0; l < R_; ++l) {
      const auto& q = m.tets[m.load_tet[l]];
      load_nodes[l] = {{q[0], q[1], q[2], q[3]}};
      for (int i = 0; i < 4; ++i)
        load_c[4 * l + i] = {{float(m.load_c[l][i][0]), float(m.load_c[l][i][1]), float(m.load_c[l][i][2]), 0.0f}};
    }
    load_nodes_ = ocl::upload(ctx, load_nodes);
    load_c_ = ocl::upload(ctx, load_c);
    std::vector<float> mass(std::max<int64_t>(N_, 1), 0.0f);
    for (int64_t n = 0; n < N_ && !m.mass_kg.empty(); ++n) mass[n] = float(m.mass_kg[n]);
    mass_ = ocl::upload(ctx, mass);
    rest_x_ = ocl::upload(ctx, to_float4(m.rest_m));
    auto rw = [&](std::size_t bytes) { return cl::Buffer(ctx.context(), CL_MEM_READ_WRITE, std::max<std::size_t>(bytes, 16)); };
    u_ = rw(N_ * sizeof(cl_float4));
    p_ = rw(N_ * sizeof(cl_float4));
    f_ = rw(N_ * sizeof(cl_float4));
    state_ = rw(std::size_t(T_) * kStateFloats * sizeof(float));
    tet_force_ = rw(std::size_t(4 * T_) * sizeof(cl_float4));
    load_force_ = rw(std::size_t(4 * R_) * sizeof(cl_float4));
    dF_ = rw(std::size_t(T_) * 10 * sizeof(float));
    blocks_ = rw(std::size_t(12 * T_) * sizeof(cl_float4));
    node_blocks_ = rw(std::size_t(3 * N_) * sizeof(cl_float4));
    k_states_ = ctx.kernel("fem_forces.cl", "fem_states", kStateOptions);
    k_average_ = ctx.kernel("fem_forces.cl", "fem_group_average", kStateOptions);
    k_forces_ = ctx.kernel("fem_forces.cl", "fem_forces", kStateOptions);
    k_dF_ = ctx.kernel("fem_forces.cl", "fem_dF", kStateOptions);
    k_dforces_ = ctx.kernel("fem_forces.cl", "fem_dforces", kStateOptions);
    k_diagonal_ = ctx.kernel("fem_forces.cl", "fem_diagonal", kStateOptions);
    k_gather_ = ctx.kernel("fem_forces.cl", "fem_gather", kStateOptions);
    k_gather_diagonal_ = ctx.kernel("fem_forces.cl", "fem_gather_diagonal", kStateOptions);
    k_load_ = ctx.kernel("msd_forces.cl", "load_pressure", "-DW=8");
  }

  void evaluate(const ForceModel& model, const std::vector<Vec3>& x, const std::vector<Vec3>&,
                std::vector<Vec3>& f) override {
    update_states(model, x);
    auto& q = ctx_.queue();
    if (T_ > 0) {
      ocl::set_args(k_forces_, state_, dm_inv_, consts_, fibre_, group_of_tet_, ebar_, law_int(), cl_int(T_), tet_force_);
      q.enqueueNDRangeKernel(k_forces_, cl::NullRange, cl::NDRange(ocl::global_size(T_)), cl::NDRange(kLocal));
    }
    const bool loads = model.pressure_pa != 0.0 && R_ > 0;
    if (loads) {
      ocl::set_args(k_load_, u_, rest_x_, load_nodes_, load_c_, float(model.pressure_pa), cl_int(R_), load_force_);
      q.enqueueNDRangeKernel(k_load_, cl::NullRange, cl::NDRange(ocl::global_size(R_)), cl::NDRange(kLocal));
    }
    const Vec3& g = model.gravity_m_s2;
    ocl::set_args(k_gather_, tet_force_, tet_start_, tet_item_, load_force_, load_start_, load_item_, cl_int(loads),
                  mass_, cl_float4{{float(g[0]), float(g[1]), float(g[2]), 0.0f}}, cl_int(N_), f_);
    q.enqueueNDRangeKernel(k_gather_, cl::NullRange, cl::NDRange(ocl::global_size(N_)), cl::NDRange(kLocal));
    download(f_, f);
    ++evaluations_;
  }

  double elastic_energy(const ForceModel& model, const std::vector<Vec3>& x) override {
    update_states(model, x);
    std::vector<float> st(std::size_t(T_) * kStateFloats), ebar(groups_->weight.size());
    auto& q = ctx_.queue();
    if (T_ > 0) q.enqueueReadBuffer(state_, CL_TRUE, 0, st.size() * sizeof(float), st.data());
    if (!ebar.empty()) q.enqueueReadBuffer(ebar_, CL_TRUE, 0, ebar.size() * sizeof(float), ebar.data());
    double e = 0.0;
    for (int64_t t = 0; t < T_; ++t) e += tets_.rest[t].volume_m3 * double(st[kStateFloats * t + kStatePsi]);
    for (std::size_t g = 0; g < ebar.size(); ++g) e += 0.5 * groups_->weight[g] * double(ebar[g]) * double(ebar[g]);
    return e;
  }

  void linearize(const ForceModel& model, const std::vector<Vec3>& x) override {
    update_states(model, x);
    linear_x_ = x;
    linear_model_ = model;
    linear_version_ = states_version_;
  }

  void stiffness_product(const std::vector<Vec3>& p, std::vector<Vec3>& kp) override {
    ctx_.queue().enqueueWriteBuffer(p_, CL_TRUE, 0, N_ * sizeof(cl_float4), to_float4(p).data());
    product(p_, f_);
    download(f_, kp);
  }

  std::unique_ptr<NewtonLinearSolver> device_linear_solver(const std::vector<TiedPair>& ties) override {
    DeviceStiffness k;
    k.field = this;
    k.product = [this](const cl::Buffer& p, cl::Buffer& kp) { product(p, kp); };
    return make_newton_linear_solver_cl(ctx_, m_, std::move(k), ties);
  }

  // kp = K p on device buffers, at the last linearisation.
  void product(const cl::Buffer& p, cl::Buffer& kp) {
    at_linearization();
    auto& q = ctx_.queue();
    if (T_ > 0) {
      ocl::set_args(k_dF_, p, tets_buf_, dm_inv_, state_, law_int(), cl_int(T_), dF_);
      q.enqueueNDRangeKernel(k_dF_, cl::NullRange, cl::NDRange(ocl::global_size(T_)), cl::NDRange(kLocal));
      average(dF_, 10, 9, debar_);
      ocl::set_args(k_dforces_, state_, dm_inv_, consts_, fibre_, group_of_tet_, ebar_, debar_, dF_, law_int(), float(b_),
                    cl_int(T_), tet_force_);
      q.enqueueNDRangeKernel(k_dforces_, cl::NullRange, cl::NDRange(ocl::global_size(T_)), cl::NDRange(kLocal));
    }
    ocl::set_args(k_gather_, tet_force_, tet_start_, tet_item_, load_force_, load_start_, load_item_, cl_int(0),
                  mass_, cl_float4{{0, 0, 0, 0}}, cl_int(N_), kp);
    q.enqueueNDRangeKernel(k_gather_, cl::NullRange, cl::NDRange(ocl::global_size(N_)), cl::NDRange(kLocal));
  }

  void stiffness_diagonal(std::vector<Mat3>& blocks) override {
    at_linearization();
    auto& q = ctx_.queue();
    if (T_ > 0) {
      ocl::set_args(k_diagonal_, state_, dm_inv_, consts_, fibre_, law_int(), float(b_), cl_int(T_), blocks_);
      q.enqueueNDRangeKernel(k_diagonal_, cl::NullRange, cl::NDRange(ocl::global_size(T_)), cl::NDRange(kLocal));
    }
    ocl::set_args(k_gather_diagonal_, blocks_, tet_start_, tet_item_, cl_int(N_), node_blocks_);
    q.enqueueNDRangeKernel(k_gather_diagonal_, cl::NullRange, cl::NDRange(ocl::global_size(N_)), cl::NDRange(kLocal));
    std::vector<cl_float4> raw(3 * N_);
    q.enqueueReadBuffer(node_blocks_, CL_TRUE, 0, raw.size() * sizeof(cl_float4), raw.data());
    blocks.resize(N_);
    for (int64_t n = 0; n < N_; ++n)
      for (int a = 0; a < 3; ++a) blocks[n].col(a) = Vec3(raw[3 * n + a].s[0], raw[3 * n + a].s[1], raw[3 * n + a].s[2]);
  }

  std::vector<double> fire_masses(const ForceModel& model) override {
    // Computed once on the host, from the rest state: the bound does not depend on the device.
    return make_fem_force_field(m_, model.material)->fire_masses(model);
  }

  int64_t evaluations() const override { return evaluations_; }

 private:
  cl_int law_int() const { return law_ == FemLaw::Corotational ? 0 : 1; }

  void download(cl::Buffer& buf, std::vector<Vec3>& out) {
    std::vector<cl_float4> raw(N_);
    ctx_.queue().enqueueReadBuffer(buf, CL_TRUE, 0, N_ * sizeof(cl_float4), raw.data());
    out.resize(N_);
    for (int64_t n = 0; n < N_; ++n) out[n] = Vec3(raw[n].s[0], raw[n].s[1], raw[n].s[2]);
  }

  void average(cl::Buffer& per_tet, int stride, int offset, cl::Buffer& out) {
    const int64_t G = int64_t(groups_->weight.size());
    ocl::set_args(k_average_, per_tet, cl_int(stride), cl_int(offset), weight_, group_begin_, group_tets_,
                  inv_weight_, cl_int(G), out);
    ctx_.queue().enqueueNDRangeKernel(k_average_, cl::NullRange, cl::NDRange(ocl::global_size(G)), cl::NDRange(kLocal));
  }

  void build_groups(bool mean_dilatation) {
    groups_.emplace(m_, tets_, mean_dilatation);
    std::vector<float> inv(groups_->weight.size());
    for (std::size_t g = 0; g < inv.size(); ++g) inv[g] = groups_->weight[g] > 0.0 ? float(1.0 / groups_->weight[g]) : 0.0f;
    group_of_tet_ = ocl::upload(ctx_, groups_->group_of_tet);
    group_tets_ = ocl::upload(ctx_, groups_->tets);
    group_begin_ = ocl::upload(ctx_, groups_->begin);
    inv_weight_ = ocl::upload(ctx_, inv);
    const std::size_t bytes = std::max<std::size_t>(inv.size(), 1) * sizeof(float);
    ebar_ = cl::Buffer(ctx_.context(), CL_MEM_READ_WRITE, bytes);
    debar_ = cl::Buffer(ctx_.context(), CL_MEM_READ_WRITE, bytes);
  }

  // K at the last linearisation (force_field.h), as the CPU field keeps it: states moved since by an
  // evaluation are put back first.
  void at_linearization() {
    if (linear_version_ >= 0 && states_version_ != linear_version_) linearize(linear_model_, std::vector<Vec3>(linear_x_));
  }

  // The states at x on the device (kept with x, as the CPU field keeps its own).
  void update_states(const ForceModel& model, const std::vector<Vec3>& x) {
    if (fem_law_of(model.material) != law_)
      throw std::logic_error("ClFemForceField: built for one law, asked for another");
    if (!groups_ || groups_->by_cube != model.mean_dilatation) {
      build_groups(model.mean_dilatation);
      states_x_.clear();
    }
    if (model.stiffening == b_ && x == states_x_) return;
    ++states_version_;
    states_x_ = x;
    b_ = model.stiffening;
    std::vector<Vec3> u(N_);
    for (int64_t n = 0; n < N_; ++n) u[n] = x[n] - m_.rest_m[n];   // in double, then rounded
    auto& q = ctx_.queue();
    q.enqueueWriteBuffer(u_, CL_TRUE, 0, N_ * sizeof(cl_float4), to_float4(u).data());
    if (T_ > 0) {
      ocl::set_args(k_states_, u_, tets_buf_, dm_inv_, consts_, fibre_, law_int(), float(b_), cl_int(T_), state_);
      q.enqueueNDRangeKernel(k_states_, cl::NullRange, cl::NDRange(ocl::global_size(T_)), cl::NDRange(kLocal));
      average(state_, kStateFloats, kStateE, ebar_);
    }
  }

  ocl::Context& ctx_;
  const Mesh& m_;
  FemLaw law_;
  FemTets tets_;
  std::optional<FemGroups> groups_;
  int64_t N_, T_, R_;
  cl::Buffer tets_buf_, dm_inv_, consts_, fibre_, weight_, tet_start_, tet_item_, load_start_, load_item_, load_nodes_,
      load_c_, mass_, rest_x_, u_, p_, f_, state_, tet_force_, load_force_, dF_, blocks_, node_blocks_;
  cl::Buffer group_of_tet_, group_tets_, group_begin_, inv_weight_, ebar_, debar_;
  cl::Kernel k_states_, k_average_, k_forces_, k_dF_, k_dforces_, k_diagonal_, k_gather_, k_gather_diagonal_, k_load_;
  std::vector<Vec3> states_x_;
  double b_ = NAN;
  int64_t states_version_ = 0;        // counts the states computed
  std::vector<Vec3> linear_x_;        // the last linearisation's point, model and states' version
  ForceModel linear_model_;
  int64_t linear_version_ = -1;
  int64_t evaluations_ = 0;
};

}  // namespace

uint64_t fem_force_field_cl_bytes(const Mesh& m) {
  const uint64_t N = uint64_t(m.node_count()), T = uint64_t(m.tets.size()), R = uint64_t(m.load_tet.size());
  const Adjacency adj = Adjacency::of(m);
  const uint64_t csr = 8 * 2 * (N + 1) + 4 * (adj.tets.item.size() + adj.loads.item.size());
  // Per tetrahedron: nodes 16, D_m⁻¹ 36, constants 16, fibre 16, weight 4, state 160, 4 forces 64, δF 40,
  // diagonal blocks 192, group index and list 8, and up to one group each (ē, δē, 1/Σw, begin: 16).
  // Per node: 5 float4 vectors and 3 for its diagonal block, mass. Per load: nodes 16, c 64, forces 64.
  return T * (16 + 36 + 16 + 16 + 4 + 160 + 64 + 40 + 192 + 8 + 16) + N * (8 * 16 + 4) + R * (16 + 64 + 64) + csr;
}

std::unique_ptr<ForceField> make_fem_force_field_cl(ocl::Context& ctx, const Mesh& m, MaterialModel model) {
  if (model == MaterialModel::Msd) throw std::logic_error("make_fem_force_field_cl: the springs are not finite elements");
  return std::make_unique<ClFemForceField>(ctx, m, fem_law_of(model));
}

}  // namespace pneumo
