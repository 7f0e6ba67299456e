#pragma once
// Closed-form checks a user can run on their machine (method.md §4 and §10): the lattice's
// effective Young's modulus along an axis, and Lamé's thick-walled sphere under internal pressure.
#include <nlohmann/json.hpp>

#include "scene/scene.h"
#include "solve/solver.h"

namespace pneumo {

/// §4: a block of n×n×(2n) cubes, its bottom held axially, its top displaced axially by a small
/// strain, sides free; stress = reaction over area, strain measured between the planes at ¼ and ¾
/// of the length (away from the loaded faces). Young's modulus of the lattice relative to E.
struct LatticeResult {
  int cubes_across = 0;
  double young_ratio_raw = 0;        // σ/ε ÷ E for this block
  double young_ratio_axis = 0;       // corrected for free sides: raw ÷ (1 − 0.063/n)
  double expected_axis = 1.140;      // §4
  int64_t steps = 0;
  double residual = 0;
};
LatticeResult validate_lattice(int cubes_across = 6, double cube_mm = 5.0);

/// §10: hollow sphere (inner radius a, outer b), internal pressure p, E, ν (1/4 for the springs), voxelised and meshed
/// whole, as the pipeline meshes a CT: voxels finer than the cubes, each tetrahedron weighted by the
/// share of its volume the shell fills (the finite cell method, mesh.h). The closed form describes the
/// true spheres r = a and r = b, so the radial displacement is the mesh's piecewise-linear field
/// evaluated on them (8192 points each, evenly spread); the finite cell boundary lies inside the cut
/// cubes, not at their nodes, whose radii differ from a and b by up to a cube. Also reported: the
/// means over the mesh's own boundary (each node weighted by its share of the boundary's area). All
/// are averaged over `placements` positions of the sphere's centre relative to the lattice: a single
/// placement aliases the staircase by a few percent at 10 mm cubes (an aligned one, centred on a
/// node, is the worst). Compared against the nominal closed form and against the lattice's own moduli
/// (bulk 0.721·E, shear 0.432·E; for the finite elements these are the nominal moduli). Linear
/// elasticity is a small-strain theory, so the model is solved at `solve_fraction` of the pressure and
/// scaled back to p: at a tenth of 10 mmHg the neo-Hookean law's finite-strain response already adds
/// 0.5 % to the outer displacement (which is 3.6 times smaller than the inner), at a hundredth 0.05 %.
struct LameOptions {
  double cube_mm = 5.0;
  double voxel_mm = 0.0;             // the voxelisation (0: a quarter of the cube); cube_mm a whole multiple of it
  double inner_mm = 50.0, outer_mm = 100.0;
  double young_kpa = 60.0;
  double pressure_mmhg = 10.0;
  double solve_fraction = 0.01;
  double residual_tolerance = 1e-6;
  int placements = 4;                // centres from lame_placement(0 … placements − 1)
  MaterialModel model = MaterialModel::Msd;   // the finite elements are solved by Newton
  double poisson = 0.25;             // the finite elements' ν (the springs' is 1/4 whatever this says)
  bool mean_dilatation = true;
  std::string device = "cpu";        // "cpu" or an OpenCL spec (solve_on_device.h)
};
struct LameResult {
  LameOptions options;
  double u_inner_mm = 0, u_outer_mm = 0;                              // means on the true spheres, over placements
  double u_inner_boundary_mm = 0, u_outer_boundary_mm = 0;            // means over the mesh's boundary
  double inner_points_outside = 0, outer_points_outside = 0;          // share of the spheres' points in no meshed cube
  double u_inner_min_mm = 0, u_inner_max_mm = 0;                      // their range across placements
  double u_outer_min_mm = 0, u_outer_max_mm = 0;
  double u_inner_node_mean_mm = 0, u_outer_node_mean_mm = 0;          // unweighted node means, for comparison
  double u_inner_analytic_mm = 0, u_outer_analytic_mm = 0;            // nominal E, ν = 1/4
  double u_inner_lattice_mm = 0, u_outer_lattice_mm = 0;              // lattice moduli
  double rel_error_inner = 0, rel_error_outer = 0;                    // vs nominal
  double rel_error_inner_lattice = 0, rel_error_outer_lattice = 0;    // vs lattice moduli
  int64_t nodes = 0, inner_nodes = 0, outer_nodes = 0, steps = 0;     // largest over placements
  double residual = 0, wall_time_s = 0;
};
LameResult validate_lame_sphere(const LameOptions& opt);

/// Lamé's radial displacement u(r) of a thick sphere (§10) for bulk modulus K and shear modulus G
/// (E = 9KG/(3K+G), ν = (3K−2G)/(2(3K+G))): u(r) = p a³/(b³ − a³) · [r/(3K) + b³/(4 G r²)].
double lame_sphere_u(double r, double a, double b, double p, double bulk, double shear);

/// The voxel size the sphere is drawn at: voxel_mm, or a quarter of the cube when it is 0.
double lame_voxel_mm(const LameOptions& o);

/// Placement k of the sphere's centre, in cubes from a lattice node (each coordinate in [0, 1)).
Vec3 lame_placement(int k);

nlohmann::json to_json(const LatticeResult& r);
nlohmann::json to_json(const LameResult& r);

}  // namespace pneumo
