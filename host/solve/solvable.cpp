#include "solve/solvable.h"

#include <cmath>
#include <numeric>
#include <sstream>

#include "core/error.h"
#include "core/units.h"

namespace pneumo {

namespace {
int32_t find_root(std::vector<int32_t>& parent, int32_t n) {
  while (parent[n] != n) n = parent[n] = parent[parent[n]];   // path halving
  return n;
}
}  // namespace

MeshComponents connected_components(const Mesh& m) {
  const int64_t N = m.node_count();
  std::vector<int32_t> parent(N);
  std::iota(parent.begin(), parent.end(), 0);
  for (const auto& s : m.springs) {
    const int32_t a = find_root(parent, s[0]), b = find_root(parent, s[1]);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  }
  MeshComponents c;
  c.part_of.assign(N, -1);
  std::vector<int32_t> index_of_root(N, -1);
  for (int64_t n = 0; n < N; ++n) {
    int32_t& idx = index_of_root[find_root(parent, int32_t(n))];
    if (idx < 0) idx = c.count++;
    c.part_of[n] = idx;
  }
  return c;
}

void check_solvable(const Mesh& m, const SolveOptions& opt, const std::string& what) {
  const int64_t N = m.node_count();
  int64_t free_nodes = 0;
  for (int64_t n = 0; n < N; ++n) free_nodes += m.hold[n] != kHoldAll;
  if (free_nodes == 0)
    throw InputError(what + ": every one of the mesh's " + std::to_string(N) +
                     " nodes is fixed, so nothing can move; fewer voxels must be fixed (roles.fixed_labels), or a "
                     "smaller mesh.cube_voxels (a node is fixed where a fixed voxel touches it)");

  // The load at rest, per node: pressure on the cavity faces and gravity.
  const double pressure_pa = std::max(std::abs(opt.start_pressure_pa), std::abs(opt.forces.pressure_pa));
  std::vector<Vec3> f = pressure_forces(m, m.rest_m, pressure_pa);
  if (opt.forces.gravity_m_s2.squaredNorm() > 0.0)
    for (int64_t n = 0; n < N; ++n) f[n] += m.mass_kg[n] * opt.forces.gravity_m_s2;

  const MeshComponents c = connected_components(m);
  std::vector<Vec3> net(c.count, Vec3::Zero()), centroid(c.count, Vec3::Zero());
  std::vector<double> load(c.count, 0.0);
  std::vector<uint8_t> held(c.count, 0);
  std::vector<int64_t> nodes(c.count, 0);
  for (int64_t n = 0; n < N; ++n) {
    const int32_t p = c.part_of[n];
    net[p] += f[n];
    load[p] += f[n].norm();
    held[p] |= m.hold[n];
    centroid[p] += m.rest_m[n];
    ++nodes[p];
  }
  for (int32_t p = 0; p < c.count; ++p) {
    // A closed surface's pressure forces cancel to rounding (~1e-16 of their sum); an open one's
    // leave a net force of the order of the sum.
    constexpr double kNetFraction = 1e-6;
    std::string axes;
    double worst = 0.0;
    for (int a = 0; a < 3; ++a)
      if (!(held[p] & (1 << a)) && std::abs(net[p][a]) > kNetFraction * load[p] && load[p] > 0.0) {
        axes += axes.empty() ? "" : ", ";
        axes += "xyz"[a];
        worst = std::max(worst, std::abs(net[p][a]));
      }
    if (axes.empty()) continue;
    int64_t first = 0;
    while (c.part_of[first] != p) ++first;
    const Vec3 centre = units::m_to_mm(1.0) * centroid[p] / double(nodes[p]);
    std::ostringstream os;
    os.precision(3);
    os << what << ": a " << part_name(m.node_part[first]) << " part of " << nodes[p] << " nodes (centre " << centre[0]
       << ", " << centre[1] << ", " << centre[2] << " mm) is attached to no fixed node along " << axes
       << ", and the load pushes it with a net " << worst << " N: it would drift away as a rigid body (no "
       << "equilibrium exists); mark the tissue it rests on as fixed (roles.fixed_labels) or check mesh.roi_min_mm/"
       << "roi_max_mm";
    throw InputError(os.str());
  }
}

}  // namespace pneumo
