#include "mesh/vtu_writer.h"

#include <cstdio>
#include <sstream>

#include "core/atomic_file.h"
#include "core/units.h"

namespace pneumo {

namespace {
// ASCII data arrays: portable and readable; the meshes pneumo writes are small (≤ a few 100k nodes).
template <class F>
void data_array(std::ostringstream& os, const char* type, const char* name, int components, int64_t count, F&& value) {
  os << "        <DataArray type=\"" << type << "\" Name=\"" << name << "\" NumberOfComponents=\"" << components
     << "\" format=\"ascii\">\n";
  for (int64_t i = 0; i < count; ++i) {
    os << "          ";
    value(os, i);
    os << "\n";
  }
  os << "        </DataArray>\n";
}
}  // namespace

void write_vtu(const Mesh& m, const std::vector<Vec3>& x_in, const std::string& path) {
  const std::vector<Vec3>& x = x_in.empty() ? m.rest_m : x_in;
  const int64_t N = m.node_count(), T = int64_t(m.tets.size());
  std::ostringstream os;
  os.precision(9);
  os << "<?xml version=\"1.0\"?>\n"
     << "<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
     << "  <UnstructuredGrid>\n"
     << "    <Piece NumberOfPoints=\"" << N << "\" NumberOfCells=\"" << T << "\">\n"
     << "      <Points>\n";
  data_array(os, "Float64", "position_mm", 3, N, [&](auto& o, int64_t i) {
    o << units::m_to_mm(x[i][0]) << " " << units::m_to_mm(x[i][1]) << " " << units::m_to_mm(x[i][2]);
  });
  os << "      </Points>\n      <PointData Vectors=\"displacement_mm\" Scalars=\"role\">\n";
  data_array(os, "Float64", "displacement_mm", 3, N, [&](auto& o, int64_t i) {
    const Vec3 d = units::m_to_mm(1.0) * (x[i] - m.rest_m[i]);
    o << d[0] << " " << d[1] << " " << d[2];
  });
  data_array(os, "UInt8", "role", 1, N, [&](auto& o, int64_t i) { o << int(m.node_part[i]); });   // 0 wall, 1 viscera
  data_array(os, "UInt8", "fixed", 1, N, [&](auto& o, int64_t i) { o << int(m.hold[i] == kHoldAll); });
  os << "      </PointData>\n      <CellData Scalars=\"part\">\n";
  data_array(os, "UInt8", "part", 1, T, [&](auto& o, int64_t t) { o << int(m.tet_part[t]); });
  data_array(os, "UInt16", "label", 1, T, [&](auto& o, int64_t t) { o << m.tet_label[t]; });
  os << "      </CellData>\n      <Cells>\n";
  data_array(os, "Int64", "connectivity", 4, T, [&](auto& o, int64_t t) {
    o << m.tets[t][0] << " " << m.tets[t][1] << " " << m.tets[t][2] << " " << m.tets[t][3];
  });
  data_array(os, "Int64", "offsets", 1, T, [&](auto& o, int64_t t) { o << 4 * (t + 1); });
  data_array(os, "UInt8", "types", 1, T, [&](auto& o, int64_t) { o << 10; });   // VTK_TETRA
  os << "      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n</VTKFile>\n";
  write_text_file_atomic(path, os.str());
}

}  // namespace pneumo
