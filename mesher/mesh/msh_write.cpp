// Gmsh MSH 4.1 writer (ASCII and binary). Entities: one volume per CAD solid, one surface per
// CAD face; element blocks follow the runs of the mesh's own order so reading back gives the
// same arrays.
#include <algorithm>
#include <charconv>
#include <limits>
#include <set>

#include "mesher/mesh/atomic_file.hpp"
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
  int dim, entity, type;
  std::size_t first, count;  // indices into bfaces (dim 2) or cells (dim 3)
};

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
      blocks.push_back({2, e.tag, type, f, 0});
    ++blocks.back().count;
  }
  const std::size_t face_blocks = blocks.size();
  for (std::size_t c = 0; c < mesh.num_cells(); ++c) {
    Entity& e = entity(3, mesh.cell_solid[c]);
    if (mesh.cell_physical[c]) e.physicals.insert(mesh.cell_physical[c]);
    std::int32_t ids[kMaxElementNodes];
    for (int i = 0, n = mesh.element_nodes(c, ids); i < n; ++i) e.include(mesh.nodes[ids[i]]);
    const int type = msh_type(mesh.cell_kind[c], mesh.order);
    if (blocks.size() == face_blocks || blocks.back().entity != e.tag || blocks.back().type != type)
      blocks.push_back({3, e.tag, type, c, 0});
    ++blocks.back().count;
  }
  // Nodes live on one entity: the first volume, else the first surface, else a volume 1.
  if (entities.empty()) entity(3, 1).include({0, 0, 0});
  const Entity* home = nullptr;
  for (const auto& [key, e] : entities)
    if (!home || (e.dim == 3 && home->dim != 3)) home = &e;

  if (!mesh.physical_names.empty()) {
    o.text("$PhysicalNames\n" + std::to_string(mesh.physical_names.size()) + "\n");
    for (const auto& [key, name] : mesh.physical_names)
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
  const std::size_t ne = mesh.num_bfaces() + mesh.num_cells();
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
      const int n = b.dim == 2 ? mesh.bface_element_nodes(k, ids) : mesh.element_nodes(k, ids);
      for (int i = 0; i < n; ++i) o.size(ids[i] + 1, i + 1 == n ? '\n' : ' ');
    }
  }
  if (o.binary()) o.text("\n");
  o.text("$EndElements\n");
}

}  // namespace

void write_msh(const MixedMesh& mesh, const std::filesystem::path& path,
               const MshWriteOptions& options) {
  write_atomically(path, options.binary, [&](std::ostream& out) {
    MshOut o(out, options.binary);
    o.text(options.binary ? "$MeshFormat\n4.1 1 8\n" : "$MeshFormat\n4.1 0 8\n");
    if (options.binary) {
      const std::int32_t one = 1;
      out.write(reinterpret_cast<const char*>(&one), sizeof one);
      o.text("\n");
    }
    o.text("$EndMeshFormat\n");
    write_body(mesh, o);
  });
}

}  // namespace hexfem
