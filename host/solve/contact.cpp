// Frictionless penalty contact between viscera and wall or bone (contact.h).
#include "solve/contact.h"

#include <algorithm>
#include <cmath>

#include "solve/force_field.h"

namespace pneumo {

namespace {

/// cof(D_s)·c for the tetrahedron's edges at x: the face's deformed area vector (mesh.h).
Vec3 deformed_area(const Mesh& m, int32_t face, const std::vector<Vec3>& x) {
  const auto& q = m.tets[m.contact.tet[face]];
  return cofactor_times(x[q[1]] - x[q[0]], x[q[2]] - x[q[0]], x[q[3]] - x[q[0]], m.contact.c[face]);
}

/// out += w·v on the slave's vertices and −w·v on the master's (none for bone): how a force along the
/// pair, or a stiffness product, reaches the nodes.
void spread(const Mesh& m, const ContactPair& p, const Vec3& v, std::vector<Vec3>& out) {
  const auto& qs = m.tets[m.contact.tet[p.slave]];
  for (int i = 0; i < 4; ++i) out[qs[i]] += m.contact.w[p.slave][i] * v;
  if (p.master < 0) return;
  const auto& qm = m.tets[m.contact.tet[p.master]];
  for (int i = 0; i < 4; ++i) out[qm[i]] -= m.contact.w[p.master][i] * v;
}

Vec3 embedded_point(const Mesh& m, int32_t face, const std::vector<Vec3>& x) {
  const auto& q = m.tets[m.contact.tet[face]];
  const auto& w = m.contact.w[face];
  return w[0] * x[q[0]] + w[1] * x[q[1]] + w[2] * x[q[2]] + w[3] * x[q[3]];
}

/// Points binned by Teschner et al.'s (2003) spatial hash of cubic cells, by a counting sort: the points
/// of a cell and its 26 neighbours are `for_near`'s candidates (others of the same hash come along and
/// are told apart by distance).
class SpatialHash {
 public:
  SpatialHash(const std::vector<Vec3>& points, double cell_m) : cell_m_(cell_m) {
    uint64_t table = 1;
    while (table < 2 * points.size()) table <<= 1;
    mask_ = table - 1;
    start_.assign(table + 1, 0);
    order_.resize(points.size());
    std::vector<uint64_t> key(points.size());
    for (std::size_t i = 0; i < points.size(); ++i) {
      const auto c = cell_of(points[i]);
      key[i] = hash(c[0], c[1], c[2]);
      ++start_[key[i] + 1];
    }
    for (uint64_t h = 0; h < table; ++h) start_[h + 1] += start_[h];
    std::vector<uint32_t> fill(start_.begin(), start_.end() - 1);
    for (std::size_t i = 0; i < points.size(); ++i) order_[fill[key[i]]++] = uint32_t(i);
  }
  /// Calls visit(i) for every point i binned within one cell of p.
  template <class Visit>
  void for_near(const Vec3& p, Visit&& visit) const {
    const auto c = cell_of(p);
    for (int64_t dz = -1; dz <= 1; ++dz)
      for (int64_t dy = -1; dy <= 1; ++dy)
        for (int64_t dx = -1; dx <= 1; ++dx) {
          const uint64_t h = hash(c[0] + dx, c[1] + dy, c[2] + dz);
          for (uint32_t o = start_[h]; o < start_[h + 1]; ++o) visit(order_[o]);
        }
  }

 private:
  std::array<int64_t, 3> cell_of(const Vec3& p) const {
    return {int64_t(std::floor(p[0] / cell_m_)), int64_t(std::floor(p[1] / cell_m_)), int64_t(std::floor(p[2] / cell_m_))};
  }
  uint64_t hash(int64_t i, int64_t j, int64_t k) const {
    return (uint64_t(i) * 73856093u ^ uint64_t(j) * 19349663u ^ uint64_t(k) * 83492791u) & mask_;
  }
  double cell_m_;
  uint64_t mask_ = 0;
  std::vector<uint32_t> start_, order_;
};

}  // namespace

ContactSearch::ContactSearch(const Mesh& m, double kappa) : m_(m), kappa_(kappa) {
  const double spacing_m = m.grid.spacing_mm.maxCoeff() * 1e-3;
  // The cube's longest edge (L per axis, core/cube_voxels.h): the reach and the depth limit cover it.
  cube_edge_m_ = 0.0;
  for (int a = 0; a < 3; ++a)
    cube_edge_m_ = std::max(cube_edge_m_, m.grid.spacing_mm[a] * 1e-3 * std::max(1, m.cube_voxels[a]));
  // A cell of two voxels: the nearest opposed face of a slave within half a cube of sliding is in its
  // own or a neighbouring cell.
  cell_m_ = 2.0 * spacing_m;
  depth_limit_m_ = cube_edge_m_;
  touch_m_ = 1e-6 * cube_edge_m_;
  const ContactFaces& cf = m.contact;
  rest_area_m2_.resize(cf.size());
  tissue_young_pa_.resize(cf.size());
  for (std::size_t f = 0; f < cf.size(); ++f) {
    (cf.part[f] == Part::Viscera ? slaves_ : masters_).push_back(int32_t(f));
    rest_area_m2_[f] = deformed_area(m, int32_t(f), m.rest_m).norm();
    const int32_t t = cf.tet[f];
    tissue_young_pa_[f] = m.tet_young_pa.empty() ? 0.0 : m.tet_young_pa[t] / m.tet_fraction[t];
  }
}

double ContactSearch::pair_stiffness(int32_t slave, double master_young_pa) const {
  return kappa_ * std::max(tissue_young_pa_[slave], master_young_pa) / cube_edge_m_ * rest_area_m2_[slave];
}

std::vector<double> ContactSearch::stiffness_bounds() const {
  // At rest, the partners a face may meet are the other side's faces within a cube of it (the one it
  // coincides with, and those sliding may bring).
  std::vector<Vec3> slave_at(slaves_.size()), master_at(masters_.size());
  for (std::size_t k = 0; k < slaves_.size(); ++k) slave_at[k] = embedded_point(m_, slaves_[k], m_.rest_m);
  for (std::size_t k = 0; k < masters_.size(); ++k) master_at[k] = embedded_point(m_, masters_[k], m_.rest_m);
  const double reach = std::max(cell_m_, cube_edge_m_);
  const SpatialHash slave_grid(slave_at, reach), master_grid(master_at, reach);
  std::vector<double> bound(m_.contact.size(), 0.0);
  for (std::size_t k = 0; k < slaves_.size(); ++k) {
    const int32_t s = slaves_[k];
    double partner = 0.0;   // bone, or no wall near: the slave's own modulus
    master_grid.for_near(slave_at[k], [&](uint32_t o) {
      if ((master_at[o] - slave_at[k]).norm() <= cube_edge_m_)
        partner = std::max(partner, tissue_young_pa_[masters_[o]]);
    });
    bound[s] = pair_stiffness(s, partner);
  }
  for (std::size_t k = 0; k < masters_.size(); ++k) {
    const int32_t f = masters_[k];
    slave_grid.for_near(master_at[k], [&](uint32_t o) {
      if ((slave_at[o] - master_at[k]).norm() <= cube_edge_m_)
        bound[f] = std::max(bound[f], pair_stiffness(slaves_[o], tissue_young_pa_[f]));
    });
  }
  return bound;
}

std::vector<ContactPair> ContactSearch::find(const std::vector<Vec3>& x) const {
  const ContactFaces& cf = m_.contact;
  // Masters at x: wall faces (deformed) and bone faces (static), as (centre, unit normal, size).
  struct Master {
    Vec3 centre, normal;
    double size_m;
    int32_t id;   // ContactFaces index, or −1 − fixed index
  };
  std::vector<Master> masters;
  masters.reserve(masters_.size() + cf.fixed_centre_m.size());
  for (int32_t f : masters_) {
    const Vec3 a = deformed_area(m_, f, x);
    const double area = a.norm();
    if (!(area > 0.0)) continue;
    masters.push_back({embedded_point(m_, f, x), a / area, std::sqrt(area), f});
  }
  for (std::size_t f = 0; f < cf.fixed_centre_m.size(); ++f) {
    const double area = cf.fixed_area_m2[f].norm();
    masters.push_back({cf.fixed_centre_m[f], cf.fixed_area_m2[f] / area, std::sqrt(area), -1 - int32_t(f)});
  }
  if (masters.empty() || slaves_.empty()) return {};

  std::vector<Vec3> centres(masters.size());
  for (std::size_t i = 0; i < masters.size(); ++i) centres[i] = masters[i].centre;
  const SpatialHash grid(centres, cell_m_);

  const int64_t S = int64_t(slaves_.size());
  std::vector<ContactPair> found(S);
  std::vector<uint8_t> active(S, 0);
#pragma omp parallel for schedule(static) if (S > 20000)
  for (int64_t k = 0; k < S; ++k) {
    const int32_t s = slaves_[k];
    const Vec3 a = deformed_area(m_, s, x);
    const double area = a.norm();
    if (!(area > 0.0)) continue;
    const Vec3 ns = a / area, ps = embedded_point(m_, s, x);
    double best = INFINITY;
    const Master* partner = nullptr;
    grid.for_near(ps, [&](uint32_t i) {
      const Master& mf = masters[i];
      if (ns.dot(mf.normal) >= -0.5) return;   // not facing the slave
      const double d2 = (ps - mf.centre).squaredNorm();
      if (d2 < best) { best = d2; partner = &mf; }
    });
    if (!partner) continue;
    const Vec3 d = ps - partner->centre;
    const double gap = d.dot(partner->normal);
    if (!(gap < touch_m_) || gap < -depth_limit_m_) continue;
    if ((d - gap * partner->normal).norm() > 0.75 * partner->size_m) continue;   // beside the face
    ContactPair& p = found[k];
    p.slave = s;
    p.master = partner->id;
    p.normal = partner->normal;
    p.gap_m = gap;
    p.stiffness_n_per_m = pair_stiffness(s, partner->id >= 0 ? tissue_young_pa_[partner->id] : 0.0);
    active[k] = 1;
  }
  std::vector<ContactPair> pairs;
  for (int64_t k = 0; k < S; ++k)
    if (active[k]) pairs.push_back(found[k]);
  return pairs;
}

Vec3 relative_motion(const Mesh& m, const ContactPair& p, const std::vector<Vec3>& v) {
  const Vec3 slave = embedded_point(m, p.slave, v);
  return p.master >= 0 ? Vec3(slave - embedded_point(m, p.master, v)) : slave;
}

Vec3 contact_offset(const Mesh& m, const ContactPair& p, const std::vector<Vec3>& x) {
  const Vec3 r = relative_motion(m, p, x);
  return p.master >= 0 ? r : Vec3(r - m.contact.fixed_centre_m[-1 - p.master]);
}

void add_contact_forces(const Mesh& m, const std::vector<ContactPair>& pairs, const std::vector<Vec3>& x,
                        std::vector<Vec3>& f) {
  for (const ContactPair& p : pairs) {
    const double gap = contact_offset(m, p, x).dot(p.normal);
    if (!(gap < 0.0)) continue;
    spread(m, p, -p.stiffness_n_per_m * gap * p.normal, f);   // on the slave, out of the master
  }
}

double contact_energy(const Mesh& m, const std::vector<ContactPair>& pairs, const std::vector<Vec3>& x) {
  double e = 0.0;
  for (const ContactPair& p : pairs) {
    const double gap = contact_offset(m, p, x).dot(p.normal);
    if (gap < 0.0) e += 0.5 * p.stiffness_n_per_m * gap * gap;
  }
  return e;
}

namespace {

/// A force field with the contact term on top of another (contact.h).
class ContactForceField final : public ForceField {
 public:
  ContactForceField(const Mesh& m, double kappa, std::unique_ptr<ForceField> inner)
      : m_(m), search_(m, kappa), inner_(std::move(inner)) {}

  void evaluate(const ForceModel& model, const std::vector<Vec3>& x, const std::vector<Vec3>& v,
                std::vector<Vec3>& f) override {
    inner_->evaluate(model, x, v, f);
    add_contact_forces(m_, pairs_at(x), x, f);
  }

  double elastic_energy(const ForceModel& model, const std::vector<Vec3>& x) override {
    return inner_->elastic_energy(model, x) + contact_energy(m_, pairs_at(x), x);
  }

  void linearize(const ForceModel& model, const std::vector<Vec3>& x) override {
    inner_->linearize(model, x);
    pairs_ = pairs_at(x);
  }

  void stiffness_product(const std::vector<Vec3>& p, std::vector<Vec3>& kp) override {
    inner_->stiffness_product(p, kp);
    for (const ContactPair& c : pairs_)
      spread(m_, c, c.stiffness_n_per_m * relative_motion(m_, c, p).dot(c.normal) * c.normal, kp);
  }

  void stiffness_diagonal(std::vector<Mat3>& blocks) override {
    inner_->stiffness_diagonal(blocks);
    for (const ContactPair& c : pairs_) {
      const Mat3 nn = c.stiffness_n_per_m * c.normal * c.normal.transpose();
      const auto& qs = m_.tets[m_.contact.tet[c.slave]];
      for (int i = 0; i < 4; ++i) blocks[qs[i]] += m_.contact.w[c.slave][i] * m_.contact.w[c.slave][i] * nn;
      if (c.master < 0) continue;
      const auto& qm = m_.tets[m_.contact.tet[c.master]];
      for (int i = 0; i < 4; ++i) blocks[qm[i]] += m_.contact.w[c.master][i] * m_.contact.w[c.master][i] * nn;
    }
  }

  std::vector<double> fire_masses(const ForceModel& model) override {
    // Gershgorin (force_field.h): a pair adds k A |w_i| |n_a| Σ_j |w_j| Σ_b |n_b| ≤ 2√3 k A |w_i| to row
    // (i, a) of each of its 8 vertices, so half of it to the mass, with k A the stiffest pair the face may
    // form (stiffness_bounds). A slave has one partner; a wall face meets about one slave (they
    // coincide at rest), counted twice to allow for sliding.
    std::vector<double> mass = inner_->fire_masses(model);
    const std::vector<double> bound = search_.stiffness_bounds();
    for (std::size_t f = 0; f < m_.contact.size(); ++f) {
      const double share = std::sqrt(3.0) * (m_.contact.part[f] == Part::Viscera ? 1.0 : 2.0) * bound[f];
      const auto& q = m_.tets[m_.contact.tet[f]];
      for (int i = 0; i < 4; ++i) mass[q[i]] += share * std::abs(m_.contact.w[f][i]);
    }
    return mass;
  }

  int64_t evaluations() const override { return inner_->evaluations(); }

 private:
  /// The pairs at x, searched again only when x is not the state last searched: Newton linearises at
  /// the trial it has just evaluated, so one search serves both.
  const std::vector<ContactPair>& pairs_at(const std::vector<Vec3>& x) {
    if (x != searched_x_) {
      searched_ = search_.find(x);
      searched_x_ = x;
    }
    return searched_;
  }

  const Mesh& m_;
  ContactSearch search_;
  std::unique_ptr<ForceField> inner_;
  std::vector<ContactPair> pairs_;                  // at the last linearisation
  std::vector<ContactPair> searched_;               // at searched_x_
  std::vector<Vec3> searched_x_;
};

}  // namespace

std::unique_ptr<ForceField> with_contact(const Mesh& m, const ForceModel& model, std::unique_ptr<ForceField> inner) {
  if (!(model.contact_stiffness > 0.0) || m.contact.size() == 0) return inner;
  return std::make_unique<ContactForceField>(m, model.contact_stiffness, std::move(inner));
}

}  // namespace pneumo
