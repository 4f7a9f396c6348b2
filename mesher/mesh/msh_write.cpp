// Gmsh MSH 4.1 writer (ASCII and binary). Entities: one volume per CAD solid, one surface per
// CAD face, and one more for the NC quad faces (physical group "nonconformal"); element blocks
// follow the runs of the mesh's own order so reading back gives the same arrays.
#include <algorithm>
#include <charconv>
#include <limits>
#include <set>

#include "mesher/mesh/atomic_file.hpp"
#include "mesher/mesh/element_topology.hpp"
#include "mesher/mesh/mesh_io.hpp"

namespace hexfem {

namespace {

// Gmsh element types; at order 2 tet10 11, pyramid13 19, prism15 18, hex20 17 (the mesh's node
// order is Gmsh's).
int msh_type(CellKind k, int order) {
  if (order == 2) {
    constexpr int kOrder2[kNumCellKinds] = {11, 19, 18, 17};
    return kOrder2[static_cast<int>(k)];
  }
  switch (k) {
    case CellKind::Tet4:
      return 4;
    case CellKind::Hex8:
      return 5;
    case CellKind::Wedge6:
      return 6;
    case CellKind::Pyramid5:
      return 7;
  }
  return 0;
}

// Output that is either text or binary, so each section is written once.
class MshOut {
 public:
  MshOut(std::ostream& out, bool binary) : out_(out), binary_(binary) {}
  bool binary() const { return binary_; }
  void text(std::string_view s) { out_.write(s.data(), static_cast<std::streamsize>(s.size())); }
  void size(std::uint64_t v, char sep = ' ') {
    if (binary_) return raw(v);
    put_int(static_cast<long long>(v), sep);
  }
  void i32(std::int32_t v, char sep = ' ') {
    if (binary_) return raw(v);
    put_int(v, sep);
  }
  void real(double v, char sep = ' ') {
    if (binary_) return raw(v);
    char buf[32];
    auto res = std::to_chars(buf, buf + sizeof buf, v);  // shortest exact round trip
    *res.ptr++ = sep;
    out_.write(buf, res.ptr - buf);
  }
  // A line break between records in ASCII; nothing in binary.
  void end_record() {
    if (!binary_) out_.put('\n');
  }

 private:
  template <class T>
  void raw(T v) {
    out_.write(reinterpret_cast<const char*>(&v), sizeof v);
  }
  void put_int(long long v, char sep) {
    char buf[24];
    auto res = std::to_chars(buf, buf + sizeof buf, v);
    *res.ptr++ = sep;
    out_.write(buf, res.ptr - buf);
  }
  std::ostream& out_;
  bool binary_;
};

struct Entity {
  int dim, tag;
  std::set<int> physicals;
  double box[6] = {std::numeric_limits<double>::max(),  std::numeric_limits<double>::max(),
                   std::numeric_limits<double>::max(),  -std::numeric_limits<double>::max(),
                   -std::numeric_limits<double>::max(), -std::numeric_limits<double>::max()};
  void include(const Vec3& x) {
    for (int d = 0; d < 3; ++d) {
      box[d] = std::min(box[d], x[d]);
      box[3 + d] = std::max(box[3 + d], x[d]);
    }
  }
};

// A run of consecutive elements with the same entity and type.
struct Block {
  enum Source { kBoundaryFaces, kCells, kNcFaces };
  int dim, entity, type;
  std::size_t first, count;  // indices into bfaces, cells or the NC faces
  Source source;
};

// The nodes of NC face i as a quad4 / quad8 (order 2: the cell's mid-edge nodes of its edges).
int nc_face_nodes(const MixedMesh& mesh, std::size_t i, std::int32_t* out) {
  const std::int32_t c = mesh.nc_cell[i];
  const LocalFace& lf = faces_of(mesh.cell_kind[c]).face[mesh.nc_local_face[i]];
  for (int k = 0; k < 4; ++k) out[k] = mesh.cell(c)[lf.v[k]];
  if (mesh.order != 2) return 4;
  for (int k = 0; k < 4; ++k)
    out[4 + k] = mesh.cell_edges(c)[local_edge(mesh.cell_kind[c], lf.v[k], lf.v[(k + 1) % 4])];
  return 8;
}

void write_body(const MixedMesh& mesh, MshOut& o) {
  std::map<std::pair<int, int>, Entity> entities;
  auto entity = [&](int dim, int tag) -> Entity& {
    auto [it, fresh] = entities.try_emplace({dim, tag});
    if (fresh) {
      it->second.dim = dim;
      it->second.tag = tag;
    }
    return it->second;
  };
  std::vector<Block> blocks;
  for (std::size_t f = 0; f < mesh.num_bfaces(); ++f) {
    Entity& e = entity(2, mesh.bface_cad_face[f]);
    if (mesh.bface_physical[f]) e.physicals.insert(mesh.bface_physical[f]);
    for (int i = 0; i < (mesh.bface_is_quad(f) ? 4 : 3); ++i)
      e.include(mesh.nodes[mesh.bface(f)[i]]);
    if (mesh.order == 2)  // curved: the mid-edge nodes may stick out of the corners' box
      for (int i = 0; i < (mesh.bface_is_quad(f) ? 4 : 3); ++i)
        e.include(mesh.nodes[mesh.bface_edge_nodes[4 * f + i]]);
    const int type = mesh.order == 2 ? (mesh.bface_is_quad(f) ? 16 : 9)  // quad8, tri6
                                     : (mesh.bface_is_quad(f) ? 3 : 2);
    if (blocks.empty() || blocks.back().entity != e.tag || blocks.back().type != type)
      blocks.push_back({2, e.tag, type, f, 0, Block::kBoundaryFaces});
    ++blocks.back().count;
  }
  // The NC quad faces: one more surface entity, in the physical group kNonconformalGroup.
  std::map<std::pair<int, int>, std::string> names = mesh.physical_names;
  if (!mesh.nc_cell.empty()) {
    int tag = 0, physical = 0;
    for (const auto& [key, e] : entities) tag = std::max(tag, key.second);
    for (int p : mesh.bface_physical) physical = std::max(physical, p);
    for (const auto& [key, name] : names)
      if (key.first == 2) physical = std::max(physical, key.second);
    Entity& e = entity(2, tag + 1);
    e.physicals.insert(physical + 1);
    names[{2, physical + 1}] = kNonconformalGroup;
    std::int32_t ids[8];
    for (std::size_t i = 0; i < mesh.nc_cell.size(); ++i)
      for (int k = 0, n = nc_face_nodes(mesh, i, ids); k < n; ++k) e.include(mesh.nodes[ids[k]]);
    blocks.push_back({2, e.tag, mesh.order == 2 ? 16 : 3, 0, mesh.nc_cell.size(), Block::kNcFaces});
  }
  const std::size_t face_blocks = blocks.size();
  // With one physical group in the file, readers (meshio, gmsh's own SaveAll=0) look for every
  // element in a group: each surface and volume without one gets its own, "face_<tag>" and
  // "solid_<tag>". (Added once the cells' entities are known, below.)
  const bool every_entity_in_a_group = !mesh.nc_cell.empty();
  for (std::size_t c = 0; c < mesh.num_cells(); ++c) {
    Entity& e = entity(3, mesh.cell_solid[c]);
    if (mesh.cell_physical[c]) e.physicals.insert(mesh.cell_physical[c]);
    std::int32_t ids[kMaxElementNodes];
    for (int i = 0, n = mesh.element_nodes(c, ids); i < n; ++i) e.include(mesh.nodes[ids[i]]);
    const int type = msh_type(mesh.cell_kind[c], mesh.order);
    if (blocks.size() == face_blocks || blocks.back().entity != e.tag || blocks.back().type != type)
      blocks.push_back({3, e.tag, type, c, 0, Block::kCells});
    ++blocks.back().count;
  }
  if (every_entity_in_a_group) {
    int next[4] = {0, 0, 0, 0};
    for (const auto& [key, e] : entities)
      for (int p : e.physicals) next[key.first] = std::max(next[key.first], p);
    for (const auto& [key, name] : names) next[key.first] = std::max(next[key.first], key.second);
    for (auto& [key, e] : entities) {
      if (!e.physicals.empty()) continue;
      const int tag = ++next[key.first];
      e.physicals.insert(tag);
      names[{key.first, tag}] = (key.first == 3 ? "solid_" : "face_") + std::to_string(key.second);
    }
  }
  // Nodes live on one entity: the first volume, else the first surface, else a volume 1.
  if (entities.empty()) entity(3, 1).include({0, 0, 0});
  const Entity* home = nullptr;
  for (const auto& [key, e] : entities)
    if (!home || (e.dim == 3 && home->dim != 3)) home = &e;

  if (!names.empty()) {
    o.text("$PhysicalNames\n" + std::to_string(names.size()) + "\n");
    for (const auto& [key, name] : names)
      o.text(std::to_string(key.first) + " " + std::to_string(key.second) + " \"" + name + "\"\n");
    o.text("$EndPhysicalNames\n");
  }

  o.text("$Entities\n");
  std::size_t per_dim[4] = {0, 0, 0, 0};
  for (const auto& [key, e] : entities) ++per_dim[e.dim];
  for (std::size_t n : per_dim) o.size(n);
  o.end_record();
  for (const auto& [key, e] : entities) {
    o.i32(e.tag);
    for (double b : e.box) o.real(b);
    o.size(e.physicals.size());
    for (int p : e.physicals) o.i32(p);
    o.size(0);  // bounding entities are not recorded
    o.end_record();
  }
  if (o.binary()) o.text("\n");
  o.text("$EndEntities\n$Nodes\n");
  const std::size_t nn = mesh.nodes.size();
  o.size(1);
  o.size(nn);
  o.size(nn ? 1 : 0);
  o.size(nn);
  o.end_record();
  o.i32(home->dim);
  o.i32(home->tag);
  o.i32(0);
  o.size(nn);
  o.end_record();
  for (std::size_t i = 0; i < nn; ++i) {
    o.size(i + 1, '\n');
  }
  for (const Vec3& x : mesh.nodes) {
    o.real(x[0]);
    o.real(x[1]);
    o.real(x[2], '\n');
  }
  if (o.binary()) o.text("\n");
  o.text("$EndNodes\n$Elements\n");
  const std::size_t ne = mesh.num_bfaces() + mesh.nc_cell.size() + mesh.num_cells();
  o.size(blocks.size());
  o.size(ne);
  o.size(ne ? 1 : 0);
  o.size(ne);
  o.end_record();
  std::uint64_t tag = 1;
  for (const Block& b : blocks) {
    o.i32(b.dim);
    o.i32(b.entity);
    o.i32(b.type);
    o.size(b.count);
    o.end_record();
    for (std::size_t k = b.first; k < b.first + b.count; ++k) {
      o.size(tag++);
      std::int32_t ids[kMaxElementNodes];
      const int n = b.source == Block::kBoundaryFaces ? mesh.bface_element_nodes(k, ids)
                    : b.source == Block::kNcFaces     ? nc_face_nodes(mesh, k, ids)
                                                      : mesh.element_nodes(k, ids);
      for (int i = 0; i < n; ++i) o.size(ids[i] + 1, i + 1 == n ? '\n' : ' ');
    }
  }
  if (o.binary()) o.text("\n");
  o.text("$EndElements\n");
}

}  // namespace

void write_msh(const MixedMesh& mesh, const std::filesystem::path& path,
               const MeshWriteOptions& options) {
  write_atomically(path, options.binary, [&](std::ostream& out) {
    MshOut o(out, options.binary);
    o.text(options.binary ? "$MeshFormat\n4.1 1 8\n" : "$MeshFormat\n4.1 0 8\n");
    if (options.binary) {
      const std::int32_t one = 1;
      out.write(reinterpret_cast<const char*>(&one), sizeof one);
      o.text("\n");
    }
    o.text("$EndMeshFormat\n");
    // A section of hexfem's own (Gmsh and meshio skip sections they do not know).
    if (!mesh.length_unit.empty())
      o.text("$HexfemLengthUnit\n" + mesh.length_unit + "\n$EndHexfemLengthUnit\n");
    write_body(mesh, o);
  });
}

}  // namespace hexfem
