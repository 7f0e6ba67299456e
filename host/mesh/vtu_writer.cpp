#include "mesh/vtu_writer.h"

#include <zlib.h>

#include <cerrno>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/units.h"

namespace pneumo {

// Written here rather than through VTK's vtkXMLUnstructuredGridWriter: linking libvtk (hundreds of
// MB, an OpenGL stack of its own) into pneumo for one file format would outweigh the ~100 lines the
// format takes. The layout is VTK's own (VTK's "VTK File Formats", XML, appended data):
// header_type UInt64, vtkZLibDataCompressor, raw appended data after an underscore. Each array there
// is [number of blocks, block size, size of the last block (0 when full), compressed size of each
// block] as UInt64, then the blocks, each deflated on its own. tests/test_vtu_vtk.cpp reads the
// files with VTK's reader.
namespace {

constexpr std::size_t kBlockBytes = 1 << 15;   // VTK's own block size (vtkXMLWriter's BlockSize)

/// One data array: its XML attributes and its bytes, compressed as VTK lays them out.
struct Array {
  std::string type, name;
  int components = 1;
  std::string bytes;   // the compressed record (header and blocks)
};

std::string compress_record(const void* data, std::size_t n) {
  const std::size_t blocks = (n + kBlockBytes - 1) / kBlockBytes;
  std::vector<std::string> out(blocks);
  bool failed = false;
  // Blocks are independent deflate streams: compressed in parallel, in order in the file.
#pragma omp parallel for schedule(dynamic, 4) reduction(|| : failed)
  for (int64_t b = 0; b < int64_t(blocks); ++b) {
    const std::size_t begin = std::size_t(b) * kBlockBytes, len = std::min(kBlockBytes, n - begin);
    uLongf dest_len = compressBound(uLong(len));
    out[b].resize(dest_len);
    // Level 1: the meshes compress about as well as at 6 (mostly small integers and smooth
    // coordinates) in a fraction of the time.
    failed = failed || compress2(reinterpret_cast<Bytef*>(&out[b][0]), &dest_len,
                                 static_cast<const Bytef*>(data) + begin, uLong(len), 1) != Z_OK;
    out[b].resize(dest_len);
  }
  if (failed) throw std::runtime_error("zlib could not compress a mesh array");
  std::vector<uint64_t> header = {uint64_t(blocks), uint64_t(kBlockBytes), uint64_t(n % kBlockBytes)};
  for (const std::string& s : out) header.push_back(s.size());
  std::string record(reinterpret_cast<const char*>(header.data()), header.size() * sizeof(uint64_t));
  for (const std::string& s : out) record += s;
  return record;
}

template <class T>
Array make_array(const char* type, const char* name, int components, const std::vector<T>& values) {
  return {type, name, components, compress_record(values.data(), values.size() * sizeof(T))};
}

void declare(std::ostringstream& os, const Array& a, uint64_t& offset) {
  os << "        <DataArray type=\"" << a.type << "\" Name=\"" << a.name << "\" NumberOfComponents=\""
     << a.components << "\" format=\"appended\" offset=\"" << offset << "\"/>\n";
  offset += a.bytes.size();
}

}  // namespace

void write_vtu(const Mesh& m, const std::vector<Vec3>& x_in, const std::string& path) {
  static_assert(sizeof(double) == 8 && sizeof(int64_t) == 8, "VTK's Float64 and Int64");
  const std::vector<Vec3>& x = x_in.empty() ? m.rest_m : x_in;
  const int64_t N = m.node_count(), T = int64_t(m.tets.size());
  if (int64_t(x.size()) != N) throw std::logic_error("write_vtu: positions do not match the mesh's nodes");

  std::vector<double> position(3 * N), displacement(3 * N);
  std::vector<uint8_t> role(N), fixed(N);
  for (int64_t i = 0; i < N; ++i)
    for (int c = 0; c < 3; ++c) {
      position[3 * i + c] = units::m_to_mm(x[i][c]);
      displacement[3 * i + c] = units::m_to_mm(x[i][c] - m.rest_m[i][c]);
      role[i] = uint8_t(m.node_part[i]);   // 0 wall, 1 viscera
      fixed[i] = m.hold[i] == kHoldAll;
    }
  std::vector<uint8_t> part(T), types(T, 10);   // 10: VTK_TETRA
  std::vector<uint16_t> label(m.tet_label.begin(), m.tet_label.end());
  std::vector<float> young_kpa(T, 0.0f);   // the tetrahedron's modulus (§4), once the material is assigned
  if (int64_t(m.tet_young_pa.size()) == T)
    for (int64_t t = 0; t < T; ++t) young_kpa[t] = float(m.tet_young_pa[t] / units::kPaPerKPa);
  std::vector<int64_t> connectivity(4 * T), offsets(T);
  for (int64_t t = 0; t < T; ++t) {
    part[t] = uint8_t(m.tet_part[t]);
    for (int k = 0; k < 4; ++k) connectivity[4 * t + k] = m.tets[t][k];
    offsets[t] = 4 * (t + 1);
  }
  const Array points = make_array("Float64", "position_mm", 3, position);
  const std::vector<Array> point_data = {make_array("Float64", "displacement_mm", 3, displacement),
                                         make_array("UInt8", "role", 1, role), make_array("UInt8", "fixed", 1, fixed)};
  const std::vector<Array> cell_data = {make_array("UInt8", "part", 1, part), make_array("UInt16", "label", 1, label),
                                        make_array("Float32", "young_kpa", 1, young_kpa)};
  const std::vector<Array> cells = {make_array("Int64", "connectivity", 1, connectivity),
                                    make_array("Int64", "offsets", 1, offsets), make_array("UInt8", "types", 1, types)};

  std::ostringstream os;
  uint64_t offset = 0;
  os << "<?xml version=\"1.0\"?>\n"
     << "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\" "
        "compressor=\"vtkZLibDataCompressor\">\n"
     << "  <UnstructuredGrid>\n"
     << "    <Piece NumberOfPoints=\"" << N << "\" NumberOfCells=\"" << T << "\">\n"
     << "      <PointData Vectors=\"displacement_mm\" Scalars=\"role\">\n";
  for (const Array& a : point_data) declare(os, a, offset);
  os << "      </PointData>\n      <CellData Scalars=\"part\">\n";
  for (const Array& a : cell_data) declare(os, a, offset);
  os << "      </CellData>\n      <Points>\n";
  declare(os, points, offset);
  os << "      </Points>\n      <Cells>\n";
  for (const Array& a : cells) declare(os, a, offset);
  os << "      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n  <AppendedData encoding=\"raw\">\n   _";

  check_writable_target(path);
  AtomicFile file(path);
  {
    std::ofstream out(file.temp_path(), std::ios::binary);
    out << os.str();
    for (const auto* group : {&point_data, &cell_data})
      for (const Array& a : *group) out.write(a.bytes.data(), std::streamsize(a.bytes.size()));
    out.write(points.bytes.data(), std::streamsize(points.bytes.size()));
    for (const Array& a : cells) out.write(a.bytes.data(), std::streamsize(a.bytes.size()));
    out << "\n  </AppendedData>\n</VTKFile>\n";
    out.flush();
    if (!out) throw std::runtime_error(path + ": writing failed: " + std::strerror(errno) + " (disk full?)");
  }
  file.commit();
}

}  // namespace pneumo
