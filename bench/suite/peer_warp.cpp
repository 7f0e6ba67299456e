#include "suite/peer_warp.h"

#include <omp.h>

#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "common/cpu_load.h"
#include "common/stats.h"
#include "core/atomic_file.h"
#include "core/stopwatch.h"
#include "core/error.h"
#include "core/log.h"
#include "io/volume_io.h"
#include "warp/point_map.h"

namespace pneumo::bench {

namespace fs = std::filesystem;
using json = nlohmann::json;
using Clock = std::chrono::steady_clock;

namespace {

// MetaImage positions are LPS+, pneumo's RAS+: x and y change sign (io/metaimage_io.cpp).
const Vec3 kLpsFlip(-1.0, -1.0, 1.0);

// vtk_tetwarp.py tet_mesh(): corners 0..7 of a cube with bit 0 = +x, bit 1 = +y, bit 2 = +z; pattern A where i+j+k is
// even (central tetrahedron {0,3,5,6}), B where odd ({1,2,4,7}); tetrahedron type outermost, then cubes with i slowest
// and k fastest (numpy's meshgrid(..., indexing="ij").ravel()).
constexpr int kPatternA[5][4] = {{1, 0, 3, 5}, {2, 0, 6, 3}, {4, 0, 5, 6}, {7, 3, 6, 5}, {0, 3, 6, 5}};
constexpr int kPatternB[5][4] = {{0, 1, 2, 4}, {3, 1, 7, 2}, {5, 1, 4, 7}, {6, 2, 7, 4}, {1, 2, 7, 4}};

double signed_volume6(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  return (b - a).cross(c - a).dot(d - a);
}

PeerLift read_lift(const std::string& path, double amp_mm) {
  std::ifstream in(path);
  if (!in) throw file_error(path, "cannot open (make it with python3 ../shared/peers/phantom.py DIR)");
  json j;
  try {
    in >> j;
    PeerLift lift;
    const auto c = j.at("body_center").get<std::array<double, 3>>();
    lift.body_center_mm = Vec3(c[0], c[1], c[2]);
    lift.anterior_inner_wall_y_mm = j.at("anterior_inner_wall_y").get<double>();
    lift.amp_mm = amp_mm;
    return lift;
  } catch (const json::exception& e) {
    throw file_error(path, std::string("not the peers' phantom.json: ") + e.what());
  }
}

/// A float32 × 3 MetaImage on `g` (vtk_tetwarp.py's disp.mhd layout: components innermost, i fastest).
void write_vector_mhd(const std::string& path, const Geometry& g, const std::vector<float>& xyz) {
  const Vec3 origin = g.origin_mm.cwiseProduct(kLpsFlip);
  const Mat3 direction = kLpsFlip.asDiagonal() * g.direction;
  std::ostringstream h;
  h.imbue(std::locale::classic());
  h.precision(17);
  h << "ObjectType = Image\nNDims = 3\nBinaryData = True\nBinaryDataByteOrderMSB = False\nCompressedData = False\n"
    << "TransformMatrix =";
  for (int axis = 0; axis < 3; ++axis)
    for (int r = 0; r < 3; ++r) h << ' ' << direction(r, axis);
  h << "\nOffset = " << origin[0] << ' ' << origin[1] << ' ' << origin[2] << "\nCenterOfRotation = 0 0 0\n"
    << "ElementSpacing = " << g.spacing_mm[0] << ' ' << g.spacing_mm[1] << ' ' << g.spacing_mm[2] << "\n"
    << "DimSize = " << g.dims[0] << ' ' << g.dims[1] << ' ' << g.dims[2] << "\n"
    << "ElementNumberOfChannels = 3\nElementType = MET_FLOAT\n";
  const std::string raw_name = fs::path(path).filename().replace_extension(".raw").string();
  h << "ElementDataFile = " << raw_name << "\n";
  const std::string raw_path = (fs::path(path).parent_path() / raw_name).string();
  AtomicFile raw(raw_path);
  {
    std::ofstream out(raw.temp_path(), std::ios::binary);
    out.write(reinterpret_cast<const char*>(xyz.data()), std::streamsize(xyz.size() * sizeof(float)));
    if (!out.flush()) throw std::runtime_error("cannot write " + raw.temp_path());
  }
  raw.commit();
  write_text_file_atomic(path, h.str());
}

Volume float_volume(const Geometry& g, const std::vector<float>& v) {
  Volume out(g, VoxelType::Float32);
  std::copy(v.begin(), v.end(), out.data<float>());
  return out;
}

/// disp_pneumo.mhd: the dense field through PointMap, the library's point mapping (independent of the warp's
/// scatter, same tetrahedra), for ITK; its time and count go into doc["point_map"].
void write_point_map_field(const PeerWarpCase& c, const Geometry& grid, const std::string& path, json& doc) {
  const auto t_field = Clock::now();
  const PointMap map(c.mesh, c.roles.data());
  const int64_t nvox = grid.voxel_count();
  std::vector<float> disp(std::size_t(3 * nvox), 0.0f);
  int64_t carried = 0;
#pragma omp parallel for schedule(dynamic, 1) reduction(+ : carried)
  for (int64_t k = 0; k < grid.dims[2]; ++k)
    for (int64_t j = 0; j < grid.dims[1]; ++j)
      for (int64_t i = 0; i < grid.dims[0]; ++i) {
        const Vec3 x = grid.to_world(Vec3(double(i), double(j), double(k)));
        const MappedPoint p = map.to_original(x);
        if (!p.carried) continue;
        ++carried;
        const Vec3 d = (p.point_mm - x).cwiseProduct(kLpsFlip);
        float* out = &disp[std::size_t(3 * grid.linear_index(i, j, k))];
        for (int a = 0; a < 3; ++a) out[a] = float(d[a]);
      }
  write_vector_mhd(path, grid, disp);
  doc["point_map"] = {{"seconds", seconds_since(t_field)}, {"carried_voxels", carried}};
}

}  // namespace

Vec3 PeerLift::displacement_mm(const Vec3& p) const {
  const double dx = (p.x() - body_center_mm.x()) / 70.0, dz = (p.z() - body_center_mm.z()) / 80.0;
  const double bump = std::exp(-0.5 * (dx * dx + dz * dz));
  const double s = std::clamp((p.y() - (anterior_inner_wall_y_mm - 30.0)) / 110.0, 0.0, 1.0);
  const double w = 1.0 - s * s * (3.0 - 2.0 * s);
  return Vec3(0.0, -amp_mm * bump * w, 0.0);
}

PeerWarpCase make_peer_warp_case(const Geometry& grid, std::vector<float> ct_hu, int node_step, const PeerLift& lift) {
  if (node_step < 1) throw InputError("node step must be at least 1 voxel, got " + std::to_string(node_step));
  if (int64_t(ct_hu.size()) != grid.voxel_count()) throw std::invalid_argument("make_peer_warp_case: CT size");
  PeerWarpCase c;
  c.ct_hu = std::move(ct_hu);
  c.roles.assign(std::size_t(grid.voxel_count()), Role::Other);
  c.box = WarpBox{{0, 0, 0}, grid.dims};

  WarpMesh& m = c.mesh;
  m.grid = grid;
  Index3 nn;
  for (int a = 0; a < 3; ++a) nn[a] = (grid.dims[a] - 1 + node_step - 1) / node_step + 1;   // ceil((n-1)/st) + 1
  const Mat3 a_inv = (grid.direction * grid.spacing_mm.asDiagonal()).inverse();
  for (int64_t k = 0; k < nn[2]; ++k)
    for (int64_t j = 0; j < nn[1]; ++j)
      for (int64_t i = 0; i < nn[0]; ++i) {
        const Vec3 ijk(double(i * node_step), double(j * node_step), double(k * node_step));
        const Vec3 p_file = grid.to_world(ijk).cwiseProduct(kLpsFlip);
        m.rest_ijk.push_back(ijk);
        m.disp_ijk.push_back(a_inv * lift.displacement_mm(p_file).cwiseProduct(kLpsFlip));
      }

  const Index3 cubes{nn[0] - 1, nn[1] - 1, nn[2] - 1};
  auto node = [&](int64_t i, int64_t j, int64_t k) { return int32_t(i + nn[0] * (j + nn[1] * k)); };
  for (int t = 0; t < 5; ++t)
    for (int64_t i = 0; i < cubes[0]; ++i)
      for (int64_t j = 0; j < cubes[1]; ++j)
        for (int64_t k = 0; k < cubes[2]; ++k) {
          const auto& pattern = ((i + j + k) % 2 == 0) ? kPatternA[t] : kPatternB[t];
          std::array<int32_t, 4> tet;
          for (int v = 0; v < 4; ++v) {
            const int corner = pattern[v];
            tet[v] = node(i + (corner & 1), j + ((corner >> 1) & 1), k + ((corner >> 2) & 1));
          }
          m.tets.push_back(tet);
        }
  m.tet_part.assign(m.tets.size(), Part::Wall);
  // The rest-space table covers the grid (ceil(dims / L) cubes: one more than the mesh has where dims − 1 is a
  // multiple of L, the last voxels lying on its boundary plane); every voxel is inside the script's rest mesh.
  m.cube_voxels = node_step;
  for (int a = 0; a < 3; ++a) m.cubes[a] = (grid.dims[a] + node_step - 1) / node_step;
  m.cube_meshed.assign(std::size_t(m.cubes[0] * m.cubes[1] * m.cubes[2]), 1);

  for (const auto& t : m.tets) {
    const double rest = signed_volume6(m.rest_ijk[t[0]], m.rest_ijk[t[1]], m.rest_ijk[t[2]], m.rest_ijk[t[3]]);
    const double now = signed_volume6(m.deformed_ijk(t[0]), m.deformed_ijk(t[1]), m.deformed_ijk(t[2]),
                                      m.deformed_ijk(t[3]));
    if ((rest > 0) != (now > 0)) ++c.inverted_tets;
  }
  return c;
}

json run_peer_warp(const PeerWarpOptions& opt) {
  const std::string ct_path = (fs::path(opt.data_dir) / "phantom.mhd").string();
  const PeerLift lift = read_lift((fs::path(opt.data_dir) / "phantom.json").string(), opt.amp_mm);
  const std::string out_dir = opt.out_dir.empty() ? (fs::path(opt.data_dir) / "pneumo").string() : opt.out_dir;
  check_creatable_folder(out_dir);

  const auto t_read = Clock::now();
  const Volume ct = read_volume(ct_path);
  const Geometry grid = ct.geometry();
  json doc;
  doc["data_dir"] = opt.data_dir;
  doc["dims"] = grid.dims;
  doc["voxels"] = grid.voxel_count();
  doc["node_step"] = opt.node_step;
  doc["amp_mm"] = opt.amp_mm;
  doc["read_s"] = seconds_since(t_read);

  const auto t_mesh = Clock::now();
  const PeerWarpCase c = make_peer_warp_case(grid, ct.to_float32(), opt.node_step, lift);
  doc["mesh_s"] = seconds_since(t_mesh);
  doc["nodes"] = c.mesh.rest_ijk.size();
  doc["tets"] = c.mesh.tet_count();
  doc["inverted_tets"] = c.inverted_tets;
  fs::create_directories(out_dir);
  log::info("peer warp: " + std::to_string(grid.dims[0]) + "x" + std::to_string(grid.dims[1]) + "x" +
            std::to_string(grid.dims[2]) + " voxels, " + std::to_string(c.mesh.tet_count()) + " tetrahedra -> " +
            out_dir);

  json runs = json::array(), notes = json::array();
  for (const std::string& device : opt.devices) {
    try {
      std::vector<double> seconds;
      double other = 0.0;
      WarpSeries series;   // as ITK's resampling is timed: its output buffer kept between updates
      for (int rep = 0; rep < opt.repeats; ++rep) {
        const CpuSample a = cpu_sample();
        const auto t0 = Clock::now();
        series.warp(device, c.mesh, c.source(), c.box, WarpOptions{});
        seconds.push_back(seconds_since(t0));
        other = std::max(other, other_cores(a, cpu_sample()));
      }
      const Summary s = summarize(seconds);
      const WarpResult& r = series.result();
      runs.push_back({{"device", r.device}, {"seconds", s.median}, {"seconds_all", seconds},
                      {"voxels_per_s", double(grid.voxel_count()) / s.median},
                      {"threads", device == "cpu" ? omp_get_max_threads() : 0}, {"other_cores_max", other},
                      {"carried_voxels", r.carried_voxels}, {"gas_voxels", r.gas_voxels},
                      {"kept_voxels", r.kept_voxels}});
      const std::string name = device.rfind("opencl", 0) == 0 ? "opencl" : device;
      write_volume(float_volume(grid, r.ct_hu), (fs::path(out_dir) / ("warped_" + name + ".mhd")).string());
      if (device == "cpu") {
        Volume outcome(grid, VoxelType::UInt8);
        uint8_t* o = outcome.data<uint8_t>();
        for (std::size_t n = 0; n < r.outcome.size(); ++n) o[n] = static_cast<uint8_t>(r.outcome[n]);
        write_volume(outcome, (fs::path(out_dir) / "outcome.mhd").string());
      }
    } catch (const InputError&) {
      throw;
    } catch (const std::exception& e) {
      notes.push_back(device + ": " + e.what());
    }
  }
  doc["warps"] = runs;

  if (!opt.skip_field) write_point_map_field(c, grid, (fs::path(out_dir) / "disp_pneumo.mhd").string(), doc);
  doc["notes"] = notes;
  write_text_file_atomic((fs::path(out_dir) / "peer_warp.json").string(), doc.dump(2) + "\n");
  return doc;
}

}  // namespace pneumo::bench
