#include "mesh/deformation_file.h"

#include <cerrno>
#include <cmath>
#include <cstring>
#include <cstdio>
#include <fstream>
#include <memory>
#include <stdexcept>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/input_file.h"

namespace pneumo {

static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "deformation.bin is written in host byte order");

namespace {

constexpr char kMagic[8] = {'P', 'N', 'E', 'U', 'M', 'O', 'D', 'F'};
constexpr uint32_t kHeaderBytes = 64;

struct Header {
  char magic[8];
  uint32_t version, header_bytes;
  uint64_t nodes, tets, fingerprint, checksum;
  double pressure_pa;
  uint32_t flags, zero;
};
static_assert(sizeof(Header) == kHeaderBytes, "header layout");

struct Fnv1a {
  uint64_t h = 1469598103934665603ull;
  void add(const void* p, std::size_t n) {
    const auto* b = static_cast<const unsigned char*>(p);
    for (std::size_t i = 0; i < n; ++i) h = (h ^ b[i]) * 1099511628211ull;
  }
  template <class T> void add(const T& v) { add(&v, sizeof v); }
};

uint64_t payload_checksum(const std::vector<Vec3>& u) {
  Fnv1a f;
  for (const Vec3& v : u) f.add(v.data(), 3 * sizeof(double));
  return f.h;
}

}  // namespace

uint64_t mesh_fingerprint(const Mesh& mesh, uint32_t version) {
  Fnv1a f;
  if (version == 1) {
    if (!mesh.cube_voxels.uniform()) return 0;
    f.add(int32_t(mesh.cube_voxels[0]));
  } else {
    for (int a = 0; a < 3; ++a) f.add(int32_t(mesh.cube_voxels[a]));
  }
  f.add(uint64_t(mesh.node_count()));
  for (const Vec3& x : mesh.rest_m) f.add(x.data(), 3 * sizeof(double));
  f.add(mesh.node_part.data(), mesh.node_part.size() * sizeof(Part));
  f.add(uint64_t(mesh.tets.size()));
  f.add(mesh.tets.data(), mesh.tets.size() * sizeof(mesh.tets[0]));
  f.add(mesh.tet_part.data(), mesh.tet_part.size() * sizeof(Part));
  return f.h;
}

void write_deformation(const std::string& path, const Mesh& mesh, const Deformation& d) {
  if (int64_t(d.displacement_m.size()) != mesh.node_count())
    throw std::invalid_argument("write_deformation: " + std::to_string(d.displacement_m.size()) +
                                " displacements for " + std::to_string(mesh.node_count()) + " nodes");
  check_writable_target(path);
  Header h{};
  std::memcpy(h.magic, kMagic, sizeof kMagic);
  h.version = kDeformationFileVersion;
  h.header_bytes = kHeaderBytes;
  h.nodes = uint64_t(mesh.node_count());
  h.tets = uint64_t(mesh.tets.size());
  h.fingerprint = mesh_fingerprint(mesh);
  h.checksum = payload_checksum(d.displacement_m);
  h.pressure_pa = d.pressure_pa;
  h.flags = d.converged ? 1u : 0u;
  AtomicFile f(path);
  {
    std::ofstream os(f.temp_path(), std::ios::binary);
    os.write(reinterpret_cast<const char*>(&h), sizeof h);
    for (const Vec3& v : d.displacement_m) os.write(reinterpret_cast<const char*>(v.data()), 3 * sizeof(double));
    os.flush();
    if (!os) throw std::runtime_error("cannot write " + f.temp_path() + ": " + std::strerror(errno));
  }
  f.commit();
}

Deformation read_deformation(const std::string& path, const Mesh& mesh) {
  if (probe_file(path).kind == FileKind::Missing)
    throw file_error(path, "cannot open the deformation (run pneumo simulate with this --out first)");
  // A regular file (core/input_file.h): a FIFO or a device under the name is refused, not read.
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> file(InputFile(path, "the deformation").release_to_stdio(),
                                                      &std::fclose);
  std::FILE* is = file.get();
  Header h{};
  if (std::fread(&h, 1, sizeof h, is) != sizeof h || std::memcmp(h.magic, kMagic, sizeof kMagic) != 0)
    throw file_error(path, "not a pneumo deformation file");
  // Version 1 differs only in its fingerprint (one L for all axes): still read.
  if ((h.version != 1 && h.version != kDeformationFileVersion) || h.header_bytes != kHeaderBytes)
    throw file_error(path, "deformation file version " + std::to_string(h.version) + ", this pneumo reads versions 1 and " +
                               std::to_string(kDeformationFileVersion));
  // A version 1 file was written for a mesh of one L: never for one whose axes differ.
  const bool same_mesh = h.version == 1 ? mesh.cube_voxels.uniform() && h.fingerprint == mesh_fingerprint(mesh, 1)
                                        : h.fingerprint == mesh_fingerprint(mesh);
  if (h.nodes != uint64_t(mesh.node_count()) || h.tets != uint64_t(mesh.tets.size()) || !same_mesh)
    throw file_error(path, "written for another mesh (" + std::to_string(h.nodes) + " nodes, " +
                               std::to_string(h.tets) + " tetrahedra; the scene now gives " +
                               std::to_string(mesh.node_count()) + " nodes, " + std::to_string(mesh.tets.size()) +
                               " tetrahedra" + (h.nodes == uint64_t(mesh.node_count()) ? ", other positions" : "") +
                               "): the scene or its inputs changed since the simulation; run pneumo simulate again");
  Deformation d;
  d.pressure_pa = h.pressure_pa;
  d.converged = (h.flags & 1u) != 0;
  d.displacement_m.resize(std::size_t(h.nodes));
  bool whole = true;
  for (Vec3& v : d.displacement_m) whole = whole && std::fread(v.data(), sizeof(double), 3, is) == 3;
  if (!whole) throw file_error(path, "truncated: fewer displacements than its " + std::to_string(h.nodes) + " nodes");
  if (std::fgetc(is) != EOF) throw file_error(path, "trailing bytes after the displacements");
  if (payload_checksum(d.displacement_m) != h.checksum) throw file_error(path, "corrupt: the checksum does not match");
  for (const Vec3& v : d.displacement_m)
    if (!v.allFinite()) throw file_error(path, "holds a non-finite displacement");
  return d;
}

}  // namespace pneumo
