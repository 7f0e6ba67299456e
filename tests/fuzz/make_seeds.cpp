// Writes the fuzzers' seed corpora: small valid volumes of every voxel type in every format pneumo
// reads (so the fuzzers start from files that pass every header check and mutate from there), and
// the scenes shipped in scenes/; and the hostile headers of tests/hostile_headers.h, so mutation
// starts at the size checks too; request bodies and ports as `pneumo serve`'s page sends them; and
// small folders for the DICOM listing; raw HTTP connections.
// Usage: make_seeds SOURCE_DIR OUT_DIR; OUT_DIR/{nifti,metaimage,nrrd,scene,request_json,dicom_folder,http_request}.
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <string>

#include "../hostile_headers.h"
#include "io/volume_io.h"
#include "scene/scene.h"

namespace fs = std::filesystem;
using namespace pneumo;

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: make_seeds SOURCE_DIR OUT_DIR\n");
    return 2;
  }
  const fs::path source = argv[1], out = argv[2];
  for (const char* sub : {"nifti", "metaimage", "nrrd", "scene", "request_json", "dicom_folder", "http_request"})
    fs::create_directories(out / sub);
  std::mt19937 rng(20261124);
  const VoxelType types[] = {VoxelType::Int8,   VoxelType::UInt8,  VoxelType::Int16,   VoxelType::UInt16,
                             VoxelType::Int32,  VoxelType::UInt32, VoxelType::Float32, VoxelType::Float64};
  int n = 0;
  for (VoxelType t : types) {
    Geometry g;
    g.dims = {3, 2, 2};
    g.spacing_mm = Vec3(0.8, 1.0, 2.5);
    g.origin_mm = Vec3(-10.0, 4.0, 7.5);
    if (n % 2) g.direction = Mat3(Eigen::AngleAxisd(0.3, Vec3(0, 0, 1)));   // an oblique grid too
    Volume v(g, t);
    auto* bytes = static_cast<unsigned char*>(v.raw());
    for (std::size_t i = 0; i < v.byte_count(); ++i) bytes[i] = static_cast<unsigned char>(rng() & 0x3f);
    const std::string stem = "t" + std::to_string(n++);
    write_volume(v, (out / "nifti" / (stem + ".nii")).string());
    write_volume(v, (out / "nifti" / (stem + ".nii.gz")).string());
    write_volume(v, (out / "metaimage" / (stem + ".mha")).string());
    write_volume(v, (out / "metaimage" / (stem + "_z.mha")).string(), WriteOptions{true});
    write_volume(v, (out / "nrrd" / (stem + ".nrrd")).string());
  }
  for (const hostile::HostileFile& f : hostile::hostile_files()) {
    if (!f.data_file_name.empty()) continue;   // the fuzzers read one file
    const bool nifti = f.name.find(".nii") != std::string::npos, nrrd = f.name.find(".nrrd") != std::string::npos;
    std::ofstream(out / (nifti ? "nifti" : nrrd ? "nrrd" : "metaimage") / ("hostile_" + f.name), std::ios::binary)
        << f.bytes;
  }
  for (const auto& e : fs::directory_iterator(source / "scenes"))
    if (e.path().extension() == ".json")
      fs::copy_file(e.path(), out / "scene" / e.path().filename(), fs::copy_options::overwrite_existing);
  // Every key at its default (unset ones as null): each section and key is in the corpus once.
  std::ofstream(out / "scene" / "default_echo.json") << default_scene().echo().dump(2) << "\n";
  const char* requests[] = {
      R"({"pressure_mmhg": 12, "wall_young_kpa": 40, "preset": "preview"})",
      R"({"skin_point_mm": [0, 110, -20], "target_label": 5, "insertion_mm": 45, "oblique_deg": 30, "roll_deg": 0})",
      R"({"skin_point_mm": [0, 110, -20], "target_mm": [0, 0, 0], "fov_deg": 70} // a comment)",
  };
  for (std::size_t i = 0; i < std::size(requests); ++i)
    std::ofstream(out / "request_json" / ("r" + std::to_string(i) + ".json")) << requests[i];
  // Folders for fuzz_dicom_folder (entry: kind, name length, name, a file's length and bytes): files
  // and a sub-folder; the same with a FIFO among them; every kind once.
  const std::string folders[] = {std::string("\0\2\0\1\3abc\0\3\1\2\0\1\1\2\3\4", 18),
                                 std::string("\0\1\0\1xy\6\1\1\2\0\1\2\0z", 15),
                                 std::string("\0\0\1\0\1\1\1\2\2\1\3\3\1\4\4\1\5\5\1\6\6\1\0", 23)};
  int f = 0;
  for (const std::string& bytes : folders)
    std::ofstream(out / "dicom_folder" / ("folder" + std::to_string(f++)), std::ios::binary) << bytes;
  // Connections as a browser opens them: a status poll, two requests kept alive, a JSON POST, one
  // cut off in its headers.
  const char* connections[] = {
      "GET /api/status HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n",
      "GET /api/status HTTP/1.1\r\nHost: localhost\r\nConnection: keep-alive\r\n\r\n"
      "GET /api/status HTTP/1.1\r\nHost: localhost\r\n\r\n",
      "POST /api/inflate HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Type: application/json\r\n"
      "Content-Length: 21\r\n\r\n{\"pressure_mmhg\": 12}",
      "GET /api/status HTTP/1.1\r\nHost: 127.0",
  };
  for (std::size_t i = 0; i < std::size(connections); ++i)
    std::ofstream(out / "http_request" / ("c" + std::to_string(i) + ".txt"), std::ios::binary) << connections[i];
  return 0;
}
