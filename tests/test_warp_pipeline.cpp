// `pneumo warp SCENE --out DIR` after `pneumo simulate SCENE --out DIR`, on the small phantom at
// 12 mmHg, as a user meets it: the outputs on the input's grid, a gas cavity between the wall and
// the viscera reported in metrics.json, the label ids kept plus the cavity's, the device equal to
// the CPU reference on the real deformation; identity through the whole chain (padding included)
// bit for bit; deformation.bin's round trip and its refusals; bad input as exit code 2.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <set>

#include "cli_test_support.h"
#include "grid_test_support.h"
#include "core/error.h"
#include "core/progress.h"
#include "io/volume_io.h"
#include "mesh/deformation_file.h"
#include "opencl_test_support.h"
#include "pipeline/scene_stages.h"
#include "pipeline/warp_stage.h"
#include "warp_test_support.h"

using namespace pneumo;
using testing_support::CliResult;
using testing_support::run_pneumo;
using testing_support::ScratchDir;

namespace {

namespace fs = std::filesystem;

/// The small phantom, shared by the tests of this file; simulate() inflates it at 12 mmHg (about
/// two seconds) and warps it on the CPU, for the one test that needs the real deformation.
class WarpPipeline : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    Progress::set_enabled(false);
    root_ = new fs::path(fs::temp_directory_path() / ("pneumo_warp_pipeline_" + std::to_string(::getpid())));
    fs::remove_all(*root_);
    fs::create_directories(*root_);
    setup_ok_ = run_pneumo("-q phantom --size small --out " + path("case")).code == 0;
  }
  static void TearDownTestSuite() {
    std::error_code ec;
    fs::remove_all(*root_, ec);
    delete root_;
  }
  void SetUp() override {
    Progress::set_enabled(false);
    ASSERT_TRUE(setup_ok_) << "pneumo phantom failed";
  }
  static void simulate() {
    const CliResult sim = run_pneumo("-q simulate " + path("case/scene.json") + " --out " + path("sim"));
    ASSERT_EQ(sim.code, 0) << sim.err;
    warp_ = run_pneumo("warp " + path("case/scene.json") + " --out " + path("sim"));
    ASSERT_EQ(warp_.code, 0) << warp_.err;
  }
  /// The phantom's mesh with a zero deformation.bin and an empty metrics.json in `dir`.
  static Mesh zero_deformation_in(const std::string& dir) {
    const Scene scene = load_scene(path("case/scene.json"));
    const RoleVolume roles = load_roles(scene);
    Mesh mesh = build_scene_mesh(VoxelRoles{roles.geometry, roles.role.data(), roles.label.data()}, scene);
    Deformation zero;
    zero.displacement_m.assign(std::size_t(mesh.node_count()), Vec3::Zero());
    fs::create_directories(dir);
    write_deformation(dir + "/deformation.bin", mesh, zero);
    std::ofstream(dir + "/metrics.json") << "{}";
    return mesh;
  }
  static std::string path(const std::string& rel) { return (*root_ / rel).string(); }
  static nlohmann::json metrics() {
    std::ifstream is(path("sim/metrics.json"));
    return nlohmann::json::parse(is);
  }

  static fs::path* root_;
  static bool setup_ok_;
  static CliResult warp_;
};
fs::path* WarpPipeline::root_ = nullptr;
bool WarpPipeline::setup_ok_ = false;
CliResult WarpPipeline::warp_;

std::set<int> ids_of(const Volume& v) {
  std::set<int> ids;
  for (int64_t n = 0; n < v.voxel_count(); ++n) ids.insert(int(v.value(n)));
  return ids;
}

}  // namespace

// The phantom at 12 mmHg through `pneumo simulate` and `pneumo warp`, checked in one go (the
// simulation is the slow part):
//  - the outputs lie on the input's grid (dims, spacing, origin, direction within 1e-4 mm, the
//    NIfTI round trip's float precision) in the input's voxel types, so they overlay it in a viewer;
//  - the gas opens a cavity: gas voxels (−1000 HU, label 250) between the wall and the viscera
//    (method.md §7), at least 90 % of them: their anterior-posterior column holds the wall anterior and
//    viscera posterior, or, in the lateral gutters where the gas reaches round the viscera, their
//    left-right row holds the wall on one side and viscera on the other (with the default elements,
//    whose viscera give way: 82.6 % by the column alone, 98.8 % with the row);
//    its volume is in metrics.json as cavity_volume_ml, beside the mesh's own estimate from the
//    enclosed volume of the cavity surfaces: they agree within a factor of two (they differ by the
//    staircase of the surfaces and by gas outside the CT's field of view);
//  - no label id is lost or invented: the deformed map holds the input's ids plus the cavity's;
//  - every OpenCL device gives the same outcome counts, labels equal on all but 1e-4 of the voxels
//    (ties; measured 0 on PoCL) and CT within 0.1 HU where both carry a voxel (the tolerance of
//    test_warp_cl_vs_ref.cpp);
//  - a second warp into the folder needs --force.
TEST_F(WarpPipeline, ThePhantomAt12MmHgOpensAGasCavityBetweenWallAndViscera) {
  ASSERT_NO_FATAL_FAILURE(simulate());
  for (const char* f : {"deformed_ct.nii.gz", "deformed_labels.nii.gz", "slices_before_after.png", "deformation.bin"})
    EXPECT_TRUE(fs::exists(path(std::string("sim/") + f))) << f;
  const Volume ct_in = read_volume(path("case/ct.nii.gz")), lab_in = read_volume(path("case/labels.nii.gz"));
  const Volume ct = read_volume(path("sim/deformed_ct.nii.gz")), lab = read_volume(path("sim/deformed_labels.nii.gz"));
  testing_support::expect_holds_grid(ct.geometry(), ct_in.geometry(), "deformed CT");
  testing_support::expect_holds_grid(lab.geometry(), ct_in.geometry(), "deformed labels");
  EXPECT_TRUE(ct.geometry().same_grid(lab.geometry()));
  EXPECT_EQ(ct.type(), ct_in.type());
  EXPECT_EQ(lab.type(), lab_in.type());
  EXPECT_NE(warp_.out.find("cavity"), std::string::npos) << warp_.out;
  for (const auto& e : fs::directory_iterator(path("sim"))) EXPECT_NE(e.path().filename().string()[0], '.') << e.path();

  const nlohmann::json m = metrics();
  ASSERT_TRUE(m.contains("cavity_voxels") && m.contains("cavity_volume_ml") && m.contains("mesh_cavity_volume_ml"));
  const int64_t voxels = m["cavity_voxels"];
  const double ml = m["cavity_volume_ml"], mesh_ml = m["mesh_cavity_volume_ml"];
  EXPECT_GT(voxels, 0);
  EXPECT_NEAR(ml, double(voxels) * 0.064, 1e-9);   // 4 mm voxels: 0.064 ml each
  EXPECT_GT(ml, 50.0);
  EXPECT_GT(ml, 0.5 * mesh_ml);
  EXPECT_LT(ml, 2.0 * mesh_ml);

  const Scene scene = load_scene(path("case/scene.json"));
  const std::vector<Role> role_of = scene.roles.label_roles();
  const Index3 d = lab.geometry().dims;
  ASSERT_EQ(lab.geometry().direction(1, 1), 1.0);   // the phantom's j axis points anterior
  int64_t gas = 0, between = 0;
  for (int64_t k = 0; k < d[2]; ++k)
    for (int64_t i = 0; i < d[0]; ++i)
      for (int64_t j = 0; j < d[1]; ++j) {
        if (lab.value(i, j, k) != 250) continue;
        ++gas;
        EXPECT_EQ(ct.value(i, j, k), -1000.0);
        // Whether a role lies somewhere along the row from (i, j, k) in steps of (di, dj), past the gas.
        const auto finds = [&](int64_t di, int64_t dj, Role role) {
          for (int64_t ii = i + di, jj = j + dj; ii >= 0 && jj >= 0 && ii < d[0] && jj < d[1]; ii += di, jj += dj) {
            const int l = int(lab.value(ii, jj, k));
            if (l != 250 && role_of[l] == role) return true;
          }
          return false;
        };
        // In front of the viscera: wall anterior, viscera posterior. In the lateral gutters, where going back
        // meets the flank wall again: wall on one side along left-right, viscera on the other.
        between += (finds(0, 1, Role::Wall) && finds(0, -1, Role::Viscera)) ||
                   (finds(1, 0, Role::Wall) && finds(-1, 0, Role::Viscera)) ||
                   (finds(-1, 0, Role::Wall) && finds(1, 0, Role::Viscera));
      }
  EXPECT_EQ(gas, voxels);
  EXPECT_GE(double(between), 0.9 * double(gas)) << "gas voxels between wall and viscera";
  std::printf("phantom small at 12 mmHg: cavity %lld voxels = %.0f ml (mesh estimate %.0f ml), %.1f %% between wall "
              "and viscera\n", (long long)voxels, ml, mesh_ml, 100.0 * double(between) / double(gas));

  std::set<int> expected = ids_of(lab_in);
  expected.insert(250);
  EXPECT_EQ(ids_of(lab), expected);

  Scene on = scene;
  const WarpedCase cpu = warp_scene(on, path("sim"));
  EXPECT_EQ(cpu.cavity_voxels(), voxels);
  for (const std::string& spec : testing_support::opencl_device_specs()) {
    on.device = spec;
    const WarpedCase dev = warp_scene(on, path("sim"));
    // As in test_warp_cl_vs_ref.cpp: CT within 0.1 HU where both carry a voxel, outcome and label
    // exactly equal except at measured ties.
    ASSERT_EQ(dev.output_grid.dims, cpu.output_grid.dims) << spec;
    const Index3 dims = cpu.output_grid.dims, lo = cpu.box.lo;
    int64_t ties = 0, untied = 0;
    double worst = 0.0;
    for (int64_t k = 0; k < dims[2]; ++k)
      for (int64_t j = 0; j < dims[1]; ++j)
        for (int64_t i = 0; i < dims[0]; ++i) {
          const std::size_t v = std::size_t(i + dims[0] * (j + dims[1] * k));
          if (cpu.result.outcome[v] == WarpOutcome::Carried && dev.result.outcome[v] == WarpOutcome::Carried)
            worst = std::max(worst, double(std::abs(cpu.result.ct_hu[v] - dev.result.ct_hu[v])));
          if (cpu.result.outcome[v] == dev.result.outcome[v] && cpu.result.labels[v] == dev.result.labels[v]) continue;
          ++(testing_support::measured_tie(cpu.warp_mesh, Vec3(double(i + lo[0]), double(j + lo[1]), double(k + lo[2])))
                 ? ties
                 : untied);
        }
    EXPECT_LE(worst, 0.1) << spec;
    EXPECT_EQ(untied, 0) << spec << ": voxels whose outcome or label differ without a tie";
    std::printf("%s on the phantom: max |Δ| %.2e HU, %lld tie mismatches in outcome or label\n",
                dev.result.device.c_str(), worst, (long long)ties);
  }

  CliResult r = run_pneumo("-q warp " + path("case/scene.json") + " --out " + path("sim"));
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--force"), std::string::npos) << r.err;
  r = run_pneumo("-q warp " + path("case/scene.json") + " --out " + path("sim") + " --force");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(metrics()["mesh_cavity_volume_ml"], mesh_ml);   // the mesh's estimate is kept, not overwritten
}

// A scene whose mesh differs from the one simulated (another cube size) is refused, naming
// deformation.bin; so are a truncated file and a folder without a simulation.
TEST_F(WarpPipeline, DeformationOfAnotherMeshOrTruncatedIsBadInput) {
  ScratchDir dir;
  nlohmann::json scene;
  {
    std::ifstream is(path("case/scene.json"));
    scene = nlohmann::json::parse(is);
  }
  scene["inputs"]["ct"] = path("case/ct.nii.gz");
  scene["inputs"]["labels"] = path("case/labels.nii.gz");
  scene["inputs"]["label_names"] = path("case/label_names.csv");
  scene["mesh"]["cube_voxels"] = 3;
  std::ofstream(dir.file("other.json")) << scene.dump();
  const std::string sim = dir.file("sim");
  zero_deformation_in(sim);
  CliResult r = run_pneumo("-q warp " + dir.file("other.json") + " --out " + sim);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("deformation.bin"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("another mesh"), std::string::npos) << r.err;

  const std::string copy = dir.file("truncated");
  fs::create_directories(copy);
  fs::copy_file(sim + "/metrics.json", copy + "/metrics.json");
  const std::string bytes = testing_support::read_bytes(sim + "/deformation.bin");
  testing_support::write_bytes(copy + "/deformation.bin", bytes.substr(0, bytes.size() - 8));
  r = run_pneumo("-q warp " + path("case/scene.json") + " --out " + copy);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("truncated"), std::string::npos) << r.err;

  r = run_pneumo("-q warp " + path("case/scene.json") + " --out " + dir.file("nothing"));
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("metrics.json"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << "one line: " << r.err;
}

// deformation.bin round-trips bit for bit (a seeded random field), a rebuilt mesh has the same
// fingerprint, and moving one rest position by a picometre changes it (and the file is refused).
TEST_F(WarpPipeline, DeformationFileRoundTripsAndFingerprintsTheMesh) {
  ScratchDir dir;
  const Mesh mesh = zero_deformation_in(dir.file("a"));
  const Mesh again = zero_deformation_in(dir.file("b"));
  EXPECT_EQ(mesh_fingerprint(again), mesh_fingerprint(mesh));
  std::mt19937 rng(41);
  std::normal_distribution<double> mm(0.0, 5.0);
  Deformation d;
  d.pressure_pa = 1599.87;
  d.converged = true;
  for (int64_t n = 0; n < mesh.node_count(); ++n) d.displacement_m.push_back(1e-3 * Vec3(mm(rng), mm(rng), mm(rng)));
  write_deformation(dir.file("d.bin"), mesh, d);
  const Deformation back = read_deformation(dir.file("d.bin"), again);
  EXPECT_EQ(back.displacement_m, d.displacement_m);
  EXPECT_EQ(back.pressure_pa, d.pressure_pa);
  EXPECT_TRUE(back.converged);
  Mesh moved = mesh;
  moved.rest_m[7].x() += 1e-12;
  EXPECT_NE(mesh_fingerprint(moved), mesh_fingerprint(mesh));
  EXPECT_THROW(read_deformation(dir.file("d.bin"), moved), InputError);
}

// Identity through the whole chain, on a scene that pads the CT: with output.grid "input" (the output
// box inside the working grid) a zero deformation writes the input CT and labels back bit for bit, same
// types; with "working" (the default) it writes the padded CT: the input's voxels at the padding's offset,
// air (−1000 HU) and label 0 around them, on the input's spacing and direction.
TEST_F(WarpPipeline, ZeroDeformationWritesTheInputBackBitForBit) {
  Scene scene = load_scene(path("case/scene.json"));
  scene.roles.pad_anterior_mm = 20.0;
  scene.roles.pad_superior_mm = 8.0;
  scene.output.grid = OutputGrid::Input;
  const RoleVolume roles = load_roles(scene);
  ASSERT_FALSE(roles.pad.empty());
  const Mesh mesh = build_scene_mesh(VoxelRoles{roles.geometry, roles.role.data(), roles.label.data()}, scene);
  ScratchDir dir;
  Deformation zero;
  zero.displacement_m.assign(std::size_t(mesh.node_count()), Vec3::Zero());
  write_deformation(dir.file("deformation.bin"), mesh, zero);
  std::ofstream(dir.file("metrics.json")) << "{}";
  const WarpedCase w = warp_scene(scene, dir.path().string());
  write_warp(scene, w, dir.path().string());
  EXPECT_EQ(w.cavity_voxels(), 0);
  EXPECT_EQ(w.outside_grid_mm, 0.0);   // the rest mesh lies on the grid
  EXPECT_TRUE(read_volume(dir.file("deformed_ct.nii.gz")).same_voxels(read_volume(path("case/ct.nii.gz"))));
  EXPECT_TRUE(read_volume(dir.file("deformed_labels.nii.gz")).same_voxels(read_volume(path("case/labels.nii.gz"))));

  scene.output.grid = OutputGrid::Working;
  ScratchDir grown;
  write_deformation(grown.file("deformation.bin"), mesh, zero);
  std::ofstream(grown.file("metrics.json")) << "{}";
  const WarpedCase g = warp_scene(scene, grown.path().string());
  write_warp(scene, g, grown.path().string());
  const Volume ct_in = read_volume(path("case/ct.nii.gz")), labels_in = read_volume(path("case/labels.nii.gz"));
  const Volume ct_out = read_volume(grown.file("deformed_ct.nii.gz")), labels_out = read_volume(grown.file("deformed_labels.nii.gz"));
  ASSERT_TRUE(ct_out.geometry().same_grid(roles.geometry));
  EXPECT_EQ(ct_out.type(), ct_in.type());
  const Index3& d = roles.geometry.dims;
  const Index3& lo = roles.pad.lo;
  const Index3& din = ct_in.geometry().dims;
  int64_t wrong = 0;
  for (int64_t k = 0; k < d[2]; ++k)
    for (int64_t j = 0; j < d[1]; ++j)
      for (int64_t i = 0; i < d[0]; ++i) {
        const int64_t v = roles.geometry.linear_index(i, j, k);
        const int64_t a = i - lo[0], b = j - lo[1], c = k - lo[2];
        const bool inside = a >= 0 && b >= 0 && c >= 0 && a < din[0] && b < din[1] && c < din[2];
        const int64_t src = inside ? ct_in.geometry().linear_index(a, b, c) : -1;
        wrong += ct_out.value(v) != (inside ? ct_in.value(src) : -1000.0);
        wrong += labels_out.value(v) != (inside ? labels_in.value(src) : 0.0);
      }
  EXPECT_EQ(wrong, 0);

  // Moved 1 m to the right, the body leaves any grid: the grid grows by the cap, no more, and the
  // rest is reported (at least 1 m less the grid's width and the cap).
  Deformation away = zero;
  for (Vec3& u : away.displacement_m) u = Vec3(1.0, 0.0, 0.0);
  ScratchDir moved;
  write_deformation(moved.file("deformation.bin"), mesh, away);
  std::ofstream(moved.file("metrics.json")) << "{}";
  const WarpedCase m = warp_scene(scene, moved.path().string());
  const double width_mm = double(roles.geometry.dims[0]) * roles.geometry.spacing_mm[0];
  EXPECT_GT(m.outside_grid_mm, 1000.0 - width_mm - kMaxGridGrowthMm);
  EXPECT_LE(double(m.output_grid.dims[0]) * m.output_grid.spacing_mm[0], width_mm + kMaxGridGrowthMm);
  EXPECT_GT(double(m.output_grid.dims[0] + m.warp_mesh.cube_voxels[0]) * m.output_grid.spacing_mm[0],
            width_mm + kMaxGridGrowthMm);   // the cap, less under a cube on a low-index side
}
