#include "mesher/tets_from_mesh.hpp"

#include <algorithm>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "mesher/mesh/element_topology.hpp"
#include "mesher/mesh/error.hpp"
#include "mesher/mesh/quality.hpp"

namespace hexfem {

namespace {

using Tri = std::array<std::int32_t, 3>;

Tri sorted(Tri t) {
  std::sort(t.begin(), t.end());
  return t;
}

std::string tri_name(const Tri& t) {
  return "(" + std::to_string(t[0] + 1) + ", " + std::to_string(t[1] + 1) + ", " +
         std::to_string(t[2] + 1) + ")";
}

// A face of a tet: its sorted corners, the tet, and the corner opposite it.
struct TetFace {
  Tri key;
  std::int32_t tet, opposite;
  bool operator<(const TetFace& o) const { return key != o.key ? key < o.key : tet < o.tet; }
};

// Entity tags index arrays: a bound keeps a wild tag from asking for gigabytes.
constexpr std::int32_t kMaxEntityTag = 1000000;

void check_cells(const MixedMesh& mesh) {
  if (mesh.num_cells() == 0) throw Error("the mesh has no volume cells (recombine reads tets)");
  if (mesh.order != 1)
    throw Error("the mesh is of order 2: recombine reads first-order tets (tet4)");
  for (std::size_t c = 0; c < mesh.num_cells(); ++c) {
    if (mesh.cell_kind[c] != CellKind::Tet4)
      throw Error("cell " + std::to_string(c + 1) + " is a " + kind_name(mesh.cell_kind[c]) +
                  ": recombine reads a mesh of tets only");
    if (mesh.cell_solid[c] < 1)
      throw Error("tet " + std::to_string(c + 1) +
                  " has no volume entity (tag >= 1): the volumes must be tagged");
    if (mesh.cell_solid[c] > kMaxEntityTag)
      throw Error("tet " + std::to_string(c + 1) + " has volume tag " +
                  std::to_string(mesh.cell_solid[c]) + ", above " + std::to_string(kMaxEntityTag));
  }
  // The stages after TetGen index arrays by surface and volume ids (a tag of -1 crashed them,
  // the fuzz, seed 67).
  for (std::size_t f = 0; f < mesh.num_bfaces(); ++f) {
    const std::int32_t tag = mesh.bface_cad_face[f];
    const std::int32_t* b = mesh.bface(f);
    if (tag < 1 || tag > kMaxEntityTag)
      throw Error("boundary face " + tri_name({b[0], b[1], b[2]}) + " has surface tag " +
                  std::to_string(tag) + ": the surfaces must be tagged 1 to " +
                  std::to_string(kMaxEntityTag));
  }
}

}  // namespace

TetsFromMesh tets_from_mesh(const MixedMesh& mesh) {
  check_cells(mesh);
  TetsFromMesh out;
  const std::size_t nt = mesh.num_cells();
  // Tets positive (Gmsh Tet4), as TetGen's are given to the recombination.
  std::vector<std::array<std::int32_t, 4>> tets(nt);
  for (std::size_t c = 0; c < nt; ++c) {
    const std::int32_t* v = mesh.cell(c);
    tets[c] = {v[0], v[1], v[2], v[3]};
    const Vec3 x[4] = {mesh.nodes[v[0]], mesh.nodes[v[1]], mesh.nodes[v[2]], mesh.nodes[v[3]]};
    const double vol = volume(CellKind::Tet4, x);  // signed
    if (!(vol != 0)) throw Error("tet " + std::to_string(c + 1) + " has no volume (flat)");
    if (vol < 0) {
      std::swap(tets[c][2], tets[c][3]);
      ++out.turned_tets;
    }
  }
  // The tets' faces, grouped: one tet (the boundary), two (inside, or between two volumes).
  std::vector<TetFace> faces;
  faces.reserve(4 * nt);
  static constexpr int kFace[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
  for (std::size_t t = 0; t < nt; ++t)
    for (int f = 0; f < 4; ++f)
      faces.push_back({sorted({tets[t][kFace[f][0]], tets[t][kFace[f][1]], tets[t][kFace[f][2]]}),
                       static_cast<std::int32_t>(t), tets[t][f]});
  std::sort(faces.begin(), faces.end());
  // The file's triangles, sorted by corners.
  struct FileTri {
    Tri key;
    std::int32_t face;
    bool operator<(const FileTri& o) const { return key != o.key ? key < o.key : face < o.face; }
  };
  std::vector<FileTri> file;
  for (std::size_t f = 0; f < mesh.num_bfaces(); ++f) {
    const std::int32_t* b = mesh.bface(f);
    if (mesh.bface_is_quad(f))
      throw Error("boundary face " + std::to_string(f + 1) +
                  " is a quad: the tets' boundary is "
                  "triangles");
    file.push_back({sorted({b[0], b[1], b[2]}), static_cast<std::int32_t>(f)});
  }
  if (file.empty())
    throw Error(
        "the mesh has no boundary triangles: recombine needs the tets' boundary, tagged "
        "by surface (Gmsh: save every element, e.g. -save_all)");
  std::sort(file.begin(), file.end());
  for (std::size_t i = 1; i < file.size(); ++i)
    if (file[i].key == file[i - 1].key)
      throw Error("boundary triangle " + tri_name(file[i].key) + " is given twice");

  // Boundary triangles: outward from their tet; between two volumes, outward from the lower
  // volume id. Kept in the file's order.
  std::vector<Tri> oriented(mesh.num_bfaces());
  std::vector<char> matched(mesh.num_bfaces(), 0);
  const auto num_solids =
      static_cast<std::size_t>(*std::max_element(mesh.cell_solid.begin(), mesh.cell_solid.end()));
  std::vector<std::vector<int>> faces_of_solid(num_solids + 1);
  for (std::size_t i = 0; i < faces.size();) {
    std::size_t e = i + 1;
    while (e < faces.size() && faces[e].key == faces[i].key) ++e;
    if (e - i > 2)
      throw Error("triangle " + tri_name(faces[i].key) + " is a face of " + std::to_string(e - i) +
                  " tets: the tets overlap");
    const std::int32_t ta = faces[i].tet;
    const std::int32_t sa = mesh.cell_solid[ta];
    const std::int32_t sb = e - i == 2 ? mesh.cell_solid[faces[i + 1].tet] : -1;
    if (sa == sb) {  // inside one volume
      i = e;
      continue;
    }
    const auto it = std::lower_bound(file.begin(), file.end(), FileTri{faces[i].key, -1});
    if (it == file.end() || it->key != faces[i].key)
      throw Error("the tets' boundary triangle " + tri_name(faces[i].key) +
                  " is not among the mesh's boundary triangles: the boundary must be given whole");
    // The face as its outward tet sees it (for two volumes: the lower id's).
    const TetFace& own = e - i == 2 && sb < sa ? faces[i + 1] : faces[i];
    const auto& T = tets[own.tet];
    int f = 0;
    while (T[f] != own.opposite) ++f;
    oriented[it->face] = {T[kFace[f][0]], T[kFace[f][1]], T[kFace[f][2]]};
    matched[it->face] = 1;
    const int cad_face = mesh.bface_cad_face[it->face];
    for (std::int32_t s : {sa, sb})
      if (s >= 1) faces_of_solid[s].push_back(cad_face);
    i = e;
  }
  for (std::size_t f = 0; f < matched.size(); ++f)
    if (!matched[f]) {
      const std::int32_t* b = mesh.bface(f);
      throw Error("boundary triangle " + tri_name({b[0], b[1], b[2]}) +
                  " is not on the boundary of the tets (inside a volume, or no tet's face)");
    }
  for (auto& list : faces_of_solid) {
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end()), list.end());
  }

  // Surface nodes first (in the file's order), then the others the tets hold.
  const std::size_t nn = mesh.nodes.size();
  std::vector<std::int32_t> renum(nn, -1);
  std::vector<char> on_surface(nn, 0), in_tet(nn, 0);
  for (const Tri& t : oriented)
    for (std::int32_t v : t) on_surface[v] = 1;
  for (const auto& T : tets)
    for (std::int32_t v : T) in_tet[v] = 1;
  std::int32_t next = 0;
  for (std::size_t v = 0; v < nn; ++v)
    if (on_surface[v]) renum[v] = next++;
  const auto ns = static_cast<std::size_t>(next);
  for (std::size_t v = 0; v < nn; ++v)
    if (in_tet[v] && !on_surface[v]) renum[v] = next++;
  out.unused_nodes = nn - static_cast<std::size_t>(next);

  TetMesh& tm = out.tets;
  tm.nodes.resize(static_cast<std::size_t>(next));
  for (std::size_t v = 0; v < nn; ++v)
    if (renum[v] >= 0) tm.nodes[renum[v]] = mesh.nodes[v];
  tm.tets.resize(nt);
  for (std::size_t t = 0; t < nt; ++t)
    for (int k = 0; k < 4; ++k) tm.tets[t][k] = renum[tets[t][k]];
  tm.tet_solid = mesh.cell_solid;

  SurfaceMesh& sm = out.surface;
  sm.mesh.nodes.assign(tm.nodes.begin(), tm.nodes.begin() + static_cast<std::ptrdiff_t>(ns));
  sm.mesh.physical_names = mesh.physical_names;
  sm.mesh.length_unit = mesh.length_unit;
  for (std::size_t f = 0; f < oriented.size(); ++f) {
    for (std::int32_t v : oriented[f]) sm.mesh.bface_nodes.push_back(renum[v]);
    sm.mesh.bface_nodes.push_back(-1);
    sm.mesh.bface_cad_face.push_back(mesh.bface_cad_face[f]);
    sm.mesh.bface_physical.push_back(0);
  }
  sm.faces_of_solid = std::move(faces_of_solid);
  return out;
}

}  // namespace hexfem
