#include "plan/port_ranking.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <optional>

#include "core/error.h"
#include "plan/distance_map.h"
#include "anatomy/anatomical_axes.h"

namespace pneumo {

namespace {

constexpr double kDeg = 180.0 / M_PI;

/// Exposed target points a candidate's path may aim at when the path to the centroid is closed.
constexpr std::size_t kAimTries = 48;
/// A label is one of the wall's layers when at least this many paths, and half of those reaching
/// the gas, cross it before the gas: a rib that one path meets is an obstacle, not a layer.
constexpr int kMinWallVotes = 3;

/// 0 at a, rising linearly to 1 at b (a < b), 1 beyond.
double ramp_up(double v, double a, double b) { return std::clamp((v - a) / (b - a), 0.0, 1.0); }
/// 1 over [b, c], linear to 0 at a and at d.
double plateau(double v, double a, double b, double c, double d) {
  return std::min(ramp_up(v, a, b), 1.0 - ramp_up(v, c, d));
}

/// Voxel lookups along straight lines through the grid: millions per ranking, so the world-to-index
/// map is inverted once here, not per point (Geometry::to_index inverts it each call).
struct Grid {
  Grid(const uint16_t* l, const Geometry& geometry, double step)
      : labels(l), g(geometry), step_mm(step),
        to_index((geometry.direction * geometry.spacing_mm.asDiagonal()).inverse()) {}
  const uint16_t* labels;
  const Geometry& g;
  double step_mm;
  Mat3 to_index;

  /// The linear index of the voxel holding `p`, -1 outside the grid.
  int64_t voxel(const Vec3& p) const {
    const Vec3 ijk = to_index * (p - g.origin_mm);
    const int64_t i = std::llround(ijk.x()), j = std::llround(ijk.y()), k = std::llround(ijk.z());
    if (i < 0 || j < 0 || k < 0 || i >= g.dims[0] || j >= g.dims[1] || k >= g.dims[2]) return -1;
    return g.linear_index(i, j, k);
  }
  /// -1 outside the grid (air: what lies beyond the grown grid is outside the body).
  int label_at(const Vec3& p) const {
    const int64_t v = voxel(p);
    return v < 0 ? -1 : int(labels[v]);
  }
  /// The world position of voxel `v`'s centre.
  Vec3 world_of(int64_t v) const {
    const int64_t i = v % g.dims[0], j = (v / g.dims[0]) % g.dims[1], k = v / (g.dims[0] * g.dims[1]);
    return g.to_world(Vec3(double(i), double(j), double(k)));
  }
};

/// At most `count` of `voxels`, evenly spread through the list, as world points.
std::vector<Vec3> evenly_spread(const Grid& grid, const std::vector<int64_t>& voxels, std::size_t count) {
  std::vector<Vec3> out;
  count = std::min(count, voxels.size());
  for (std::size_t s = 0; s < count; ++s) out.push_back(grid.world_of(voxels[s * voxels.size() / count]));
  return out;
}

/// What the straight path from the skin point towards the aim point meets.
struct PathWalk {
  PortProblem problem = PortProblem::None;
  int blocking_label = 0;
  std::vector<int> wall_labels;   // the labels crossed between the skin and the gas (distinct)
  bool reached_gas = false;
  Vec3 gas_entry = Vec3::Zero(), target_hit = Vec3::Zero();
  double wall_mm = 0.0;
};

PathWalk walk_path(const Grid& grid, const Vec3& skin, const Vec3& aim, int target, int gas, double max_wall_mm) {
  PathWalk w;
  const Vec3 dir = (aim - skin).normalized();
  const double length = (aim - skin).norm();
  // A voxel's extent along the path (its box's width in that direction): the tolerance follows the
  // voxels the path crosses, not the coarsest spacing (a 0.7×0.7×5 mm CT crossed in-plane).
  const Vec3 index_dir = grid.g.direction.transpose() * dir;
  const double voxel_along = std::abs(index_dir.x()) * grid.g.spacing_mm.x() +
                             std::abs(index_dir.y()) * grid.g.spacing_mm.y() +
                             std::abs(index_dir.z()) * grid.g.spacing_mm.z();
  const double block_mm = kBlockToleranceVoxels * voxel_along;
  bool in_gas = false;
  double tissue_run_mm = 0.0;
  int tissue_label = 0;
  for (double t = 0.0; t <= length + grid.step_mm; t += grid.step_mm) {
    const Vec3 p = skin + std::min(t, length) * dir;
    const int l = grid.label_at(p);
    if (!in_gas) {
      if (l == gas) {
        in_gas = true;
        w.reached_gas = true;
        w.gas_entry = p;
        w.wall_mm = t;
        continue;
      }
      if (t > max_wall_mm) {
        w.problem = PortProblem::WallTooThick;
        return w;
      }
      if (l == target) {
        w.problem = PortProblem::NoGas;   // the target lies against the wall here
        return w;
      }
      if (l > 0 && std::find(w.wall_labels.begin(), w.wall_labels.end(), l) == w.wall_labels.end())
        w.wall_labels.push_back(l);
      continue;
    }
    if (l == target) {
      w.target_hit = p;
      return w;
    }
    if (l == gas) {
      tissue_run_mm = 0.0;
      continue;
    }
    if (tissue_run_mm == 0.0) tissue_label = std::max(l, 0);
    tissue_run_mm += grid.step_mm;
    if (tissue_run_mm > block_mm) {
      w.problem = PortProblem::Blocked;
      w.blocking_label = tissue_label;
      return w;
    }
  }
  // The aim point is a target voxel: a walk that reached it in gas has hit it above.
  w.problem = in_gas ? PortProblem::Blocked : PortProblem::NoGas;
  return w;
}

/// The fraction of `samples` (target surface voxels' centres) a scope at `eye` looking along `axis`
/// sees: within the half angle of its field of view, with nothing but gas before the ray reaches the
/// sample's own voxel (the first non-gas point lies within a voxel of it). Samples behind other
/// organs, and those on the target's far or buried side (behind its own front), are not seen.
double visible_fraction(const Grid& grid, const Vec3& eye, const Vec3& axis, double half_fov_rad,
                        const std::vector<Vec3>& samples, int target, int gas) {
  if (samples.empty()) return 0.0;
  const double cos_half = std::cos(half_fov_rad);
  const double reach = grid.g.spacing_mm.maxCoeff() + grid.step_mm;   // the sample's voxel, entered at a corner
  int64_t seen = 0;
  for (const Vec3& q : samples) {
    const Vec3 v = q - eye;
    const double d = v.norm();
    if (d < 1e-9) {
      ++seen;
      continue;
    }
    const Vec3 u = v / d;
    if (u.dot(axis) < cos_half) continue;
    for (double t = 0.0; t <= d + grid.step_mm; t += grid.step_mm) {
      const int l = grid.label_at(eye + std::min(t, d) * u);
      if (l == gas) continue;
      if (l == target && d - t <= reach) ++seen;
      break;
    }
  }
  return double(seen) / double(samples.size());
}

/// The labelled voxel nearest `p` within `radius_mm` (0 when none): which structure the clearance names.
int nearest_labelled(const Grid& grid, const std::vector<uint8_t>& obstacle, const Vec3& p, double radius_mm) {
  const Geometry& g = grid.g;
  const Vec3 c = grid.to_index * (p - g.origin_mm);
  int best = 0;
  double best_d2 = std::numeric_limits<double>::infinity();
  std::array<int64_t, 3> lo{}, hi{};
  for (int a = 0; a < 3; ++a) {
    const double r = radius_mm / g.spacing_mm[a] + 1.0;
    lo[std::size_t(a)] = std::max<int64_t>(0, int64_t(std::floor(c[a] - r)));
    hi[std::size_t(a)] = std::min<int64_t>(g.dims[std::size_t(a)] - 1, int64_t(std::ceil(c[a] + r)));
  }
  for (int64_t k = lo[2]; k <= hi[2]; ++k)
    for (int64_t j = lo[1]; j <= hi[1]; ++j)
      for (int64_t i = lo[0]; i <= hi[0]; ++i) {
        const int64_t n = g.linear_index(i, j, k);
        if (!obstacle[std::size_t(n)]) continue;
        const Vec3 d((double(i) - c.x()) * g.spacing_mm.x(), (double(j) - c.y()) * g.spacing_mm.y(),
                     (double(k) - c.z()) * g.spacing_mm.z());
        if (d.squaredNorm() < best_d2) {
          best_d2 = d.squaredNorm();
          best = grid.labels[n];
        }
      }
  return best;
}

}  // namespace

const char* port_problem_name(PortProblem p) {
  switch (p) {
    case PortProblem::None: return "none";
    case PortProblem::NoGas: return "no_gas";
    case PortProblem::WallTooThick: return "wall_too_thick";
    case PortProblem::CrossesOrgan: return "crosses_organ";
    case PortProblem::Blocked: return "blocked";
  }
  return "?";
}

double visibility_term(double f) { return std::clamp(f, 0.0, 1.0); }
double clearance_term(double mm) { return ramp_up(mm, 0.0, 20.0); }
double distance_term(double mm) { return plateau(mm, 60.0, 180.0, 240.0, 300.0); }
double elevation_term(double deg) { return plateau(deg, 0.0, 30.0, 60.0, 90.0); }
double spacing_term(double mm) { return ramp_up(mm, 20.0, 50.0); }
double manipulation_term(double deg) { return plateau(deg, 15.0, 45.0, 75.0, 105.0); }

void check_rank_options(const PortRankOptions& o) {
  if (o.target_label <= 0 || o.target_label > 65535) throw InputError("the target label must be 1 to 65535");
  if (o.target_label == o.gas_label)
    throw InputError("the target label " + std::to_string(o.target_label) + " is the cavity's own label");
  if (!(o.grid_mm >= 2.0 && o.grid_mm <= 200.0)) throw InputError("the candidates' grid must be 2 to 200 mm");
  if (!(o.fov_deg > 0.0 && o.fov_deg < 180.0)) throw InputError("fov_deg must be above 0 and below 180");
}

PortRanking rank_ports(const uint16_t* labels, const float* ct_hu, const Geometry& g, const PortRankOptions& o) {
  check_rank_options(o);
  const int target = o.target_label, gas = o.gas_label;
  const int64_t n = g.voxel_count();
  PortRanking r;

  // The target: its voxels, centroid and boundary; the boundary voxels touching the gas are what a
  // scope can see and an instrument reach.
  const Grid grid(labels, g, 0.5 * g.spacing_mm.minCoeff());
  Vec3 sum = Vec3::Zero();
  std::vector<int64_t> surface, exposed;
  const std::array<int64_t, 3> stride{1, g.dims[0], g.dims[0] * g.dims[1]};
  for (int64_t k = 0; k < g.dims[2]; ++k)
    for (int64_t j = 0; j < g.dims[1]; ++j)
      for (int64_t i = 0; i < g.dims[0]; ++i) {
        const int64_t v = g.linear_index(i, j, k);
        if (labels[v] != target) continue;
        ++r.target_voxels;
        sum += g.to_world(Vec3(double(i), double(j), double(k)));
        const std::array<int64_t, 3> idx{i, j, k};
        bool boundary = false, touches_gas = false;   // over the 6 face neighbours; the grid's edge is boundary
        for (std::size_t a = 0; a < 3; ++a)
          for (int s : {-1, 1}) {
            const int64_t q = idx[a] + s;
            const int l = q < 0 || q >= g.dims[a] ? -1 : int(labels[v + s * stride[a]]);
            boundary |= l != target;
            touches_gas |= l == gas;
          }
        if (boundary) surface.push_back(v);
        if (touches_gas) exposed.push_back(v);
      }
  if (r.target_voxels == 0)
    throw InputError("label " + std::to_string(target) + " holds no voxel in the deformed labels: no target to rank ports for");
  r.target_centroid_mm = sum / double(r.target_voxels);
  // Where paths aim first: the centroid when it lies inside the target, else the boundary voxel
  // nearest it.
  r.target_aim_mm = r.target_centroid_mm;
  if (grid.label_at(r.target_centroid_mm) != target) {
    double best = std::numeric_limits<double>::infinity();
    for (int64_t v : surface)
      if (const double d = (grid.world_of(v) - r.target_centroid_mm).squaredNorm(); d < best)
        best = d, r.target_aim_mm = grid.world_of(v);
  }
  r.exposed_voxels = int64_t(exposed.size());
  r.surface_voxels = int64_t(surface.size());
  const double exposed_share = surface.empty() ? 0.0 : double(exposed.size()) / double(surface.size());
  // The points an instrument may aim at when the path to the centroid is closed (each candidate
  // tries them nearest its line to the centroid first), and the points visibility is measured on:
  // the gas-facing surface, the only part any scope can see.
  const std::vector<Vec3> aims = evenly_spread(grid, exposed, kAimTries);
  const std::vector<Vec3> samples = evenly_spread(grid, exposed, std::size_t(std::max(o.target_samples, 1)));

  // The candidates: the anterior skin, one point per grid_mm laterally and cranio-caudally, in
  // front of the target's centroid (beside the body the first solid voxel is the couch beneath).
  const SliceFrame f = slice_frame(g);
  const int64_t step_lat = std::max<int64_t>(1, std::llround(o.grid_mm / f.h_lat));
  const int64_t step_si = std::max<int64_t>(1, std::llround(o.grid_mm / f.h_si));
  std::vector<Vec3> skins;
  for (int64_t s = step_si / 2; s < f.n_si; s += step_si)
    for (int64_t l = step_lat / 2; l < f.n_lat; l += step_lat)
      for (int64_t A = f.n_ap - 1; A >= 0; --A) {
        const int64_t a = f.ant(A);
        const int64_t v = f.index(l, a, s);
        if (ct_hu[v] < o.skin_hu) continue;
        std::array<int64_t, 3> idx{};
        idx[std::size_t(f.lat)] = l, idx[std::size_t(f.ap)] = a, idx[std::size_t(f.si)] = s;
        const Vec3 skin = g.to_world(Vec3(double(idx[0]), double(idx[1]), double(idx[2])));
        if (skin.y() > r.target_centroid_mm.y()) skins.push_back(skin);   // y: anterior (RAS)
        break;
      }
  if (skins.empty()) throw InputError("no skin found (no voxel at or above " + std::to_string(o.skin_hu) + " HU)");

  // Pass 1: the wall's own layers, the labels that most trocars cross on their way to the gas (the
  // straight paths to the centroid that reach it; at least kMinWallVotes of them).
  std::vector<PathWalk> to_centre(skins.size());
#pragma omp parallel for schedule(dynamic, 4)
  for (int64_t c = 0; c < int64_t(skins.size()); ++c)
    to_centre[std::size_t(c)] = walk_path(grid, skins[std::size_t(c)], r.target_aim_mm, target, gas, o.max_wall_mm);
  std::map<int, int> crossed;
  int reaching = 0;
  for (const PathWalk& w : to_centre) {
    if (!w.reached_gas) continue;
    ++reaching;
    for (int l : w.wall_labels) ++crossed[l];
  }
  for (const auto& [l, count] : crossed)
    if (count >= kMinWallVotes && 2 * count >= reaching) r.wall_layer_labels.push_back(l);
  const auto is_wall_layer = [&](int l) {
    return std::find(r.wall_layer_labels.begin(), r.wall_layer_labels.end(), l) != r.wall_layer_labels.end();
  };
  // A path is open when it reaches the target through gas and crosses nothing but the wall's layers
  // before the gas.
  const auto open = [&](PathWalk& w) {
    if (w.problem != PortProblem::None) return false;
    for (int l : w.wall_labels)
      if (!is_wall_layer(l)) {
        w.problem = PortProblem::CrossesOrgan;
        w.blocking_label = l;
        return false;
      }
    return true;
  };

  // Pass 2: each candidate's path: to the centroid when open, else to the exposed point nearest that
  // line whose path is open; a candidate with none keeps the problem of the path to the centroid.
  std::vector<PathWalk> walks(skins.size());
  std::vector<Vec3> aim_of(skins.size(), r.target_aim_mm);
#pragma omp parallel for schedule(dynamic, 4)
  for (int64_t c = 0; c < int64_t(skins.size()); ++c) {
    const Vec3 skin = skins[std::size_t(c)];
    PathWalk& w = walks[std::size_t(c)];
    w = to_centre[std::size_t(c)];
    if (open(w)) continue;
    const Vec3 centre_dir = (r.target_aim_mm - skin).normalized();
    std::vector<std::pair<double, std::size_t>> order;
    for (std::size_t a = 0; a < aims.size(); ++a) order.push_back({-(aims[a] - skin).normalized().dot(centre_dir), a});
    std::sort(order.begin(), order.end());
    for (const auto& [cos_neg, a] : order) {
      PathWalk tried = walk_path(grid, skin, aims[a], target, gas, o.max_wall_mm);
      if (open(tried)) {
        w = std::move(tried);
        aim_of[std::size_t(c)] = aims[a];
        break;
      }
    }
  }

  // The obstacles: every other labelled structure; their distance map gives each path's clearance.
  std::vector<uint8_t> obstacle(std::size_t(n), 0);
  for (int64_t v = 0; v < n; ++v) {
    const int l = labels[v];
    obstacle[std::size_t(v)] = l != 0 && l != target && l != gas && !is_wall_layer(l);
  }
  const std::vector<float> clearance = distance_to_mask_mm(obstacle, g);

  // Pass 3: the terms of every candidate whose path is open.
  const double half_fov = 0.5 * o.fov_deg / kDeg;
  r.candidates.resize(skins.size());
#pragma omp parallel for schedule(dynamic, 2)
  for (int64_t ci = 0; ci < int64_t(skins.size()); ++ci) {
    PortCandidate& c = r.candidates[std::size_t(ci)];
    const PathWalk& w = walks[std::size_t(ci)];
    c.skin_mm = skins[std::size_t(ci)];
    c.problem = w.problem;
    c.blocking_label = w.blocking_label;
    c.aim_mm = aim_of[std::size_t(ci)];
    const Vec3 axis = (c.aim_mm - c.skin_mm).normalized();
    c.elevation_deg = std::asin(std::min(1.0, std::abs(axis.y()))) * kDeg;   // y: anterior, the vertical when supine
    c.wall_mm = w.wall_mm;
    if (!c.feasible()) continue;
    c.gas_entry_mm = w.gas_entry;
    c.skin_to_target_mm = (w.target_hit - c.skin_mm).norm();
    const double in_gas = (w.target_hit - w.gas_entry).norm();
    const Vec3 eye = w.gas_entry + std::min(o.eye_depth_mm, 0.5 * in_gas) * axis;
    // Of the gas-facing surface sampled, the share seen, as a share of the whole surface.
    c.visible_fraction = visible_fraction(grid, eye, axis, half_fov, samples, target, gas) * exposed_share;
    // Clearance along the path in the gas, short of the target's own neighbourhood (the last 10 mm,
    // where the instrument works on the target and touches what lies beside it).
    c.clearance_mm = std::numeric_limits<double>::infinity();
    Vec3 closest = w.gas_entry;
    for (double t = 0.0; t <= std::max(0.0, in_gas - 10.0); t += grid.step_mm) {
      const Vec3 p = w.gas_entry + t * axis;
      const int64_t v = grid.voxel(p);
      if (v < 0) continue;
      if (clearance[std::size_t(v)] < c.clearance_mm) c.clearance_mm = clearance[std::size_t(v)], closest = p;
    }
    if (std::isfinite(c.clearance_mm)) c.nearest_label = nearest_labelled(grid, obstacle, closest, c.clearance_mm + 1.0);
    // Triangulation with the ports already placed.
    for (const Vec3& other : o.other_ports_mm) {
      const double d = (other - c.skin_mm).norm();
      c.spacing_mm = std::isnan(c.spacing_mm) ? d : std::min(c.spacing_mm, d);
      const Vec3 a = (c.skin_mm - c.aim_mm).normalized(), b = (other - c.aim_mm).normalized();
      const double angle = std::acos(std::clamp(a.dot(b), -1.0, 1.0)) * kDeg;
      if (std::isnan(c.manipulation_deg) || manipulation_term(angle) > manipulation_term(c.manipulation_deg))
        c.manipulation_deg = angle;
    }
    c.t_clearance = clearance_term(c.clearance_mm);
    c.t_distance = distance_term(c.skin_to_target_mm);
    c.t_elevation = elevation_term(c.elevation_deg);
    if (!o.other_ports_mm.empty())
      c.t_triangulation = spacing_term(c.spacing_mm) * manipulation_term(c.manipulation_deg);
  }
  // Visibility against the best port's: how much of what any candidate sees this one sees, so the
  // term weighs the same whether the organ shows a tenth of its surface to the gas or all of it.
  double best_visible = 0.0;
  for (const PortCandidate& c : r.candidates)
    if (c.feasible()) best_visible = std::max(best_visible, c.visible_fraction);
  const PortRankWeights& wt = o.weights;
  for (PortCandidate& c : r.candidates) {
    if (!c.feasible()) continue;
    c.t_visibility = best_visible > 0.0 ? visibility_term(c.visible_fraction / best_visible) : 0.0;
    double num = wt.visibility * c.t_visibility + wt.clearance * c.t_clearance + wt.distance * c.t_distance +
                 wt.elevation * c.t_elevation;
    double den = wt.visibility + wt.clearance + wt.distance + wt.elevation;
    if (!o.other_ports_mm.empty()) {
      num += wt.triangulation * c.t_triangulation;
      den += wt.triangulation;
    }
    c.score = den > 0.0 ? num / den : 0.0;
  }
  std::stable_sort(r.candidates.begin(), r.candidates.end(), [](const PortCandidate& a, const PortCandidate& b) {
    if (a.feasible() != b.feasible()) return a.feasible();
    return a.score > b.score;
  });
  return r;
}

}  // namespace pneumo
