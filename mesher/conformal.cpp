#include "mesher/conformal.hpp"

#include <algorithm>
#include <array>
#include <vector>

#include "mesher/mesh/conformity.hpp"
#include "mesher/mesh/element_topology.hpp"
#include "mesher/mesh/error.hpp"
#include "mesher/mesh/quality.hpp"

namespace hexfem {

namespace {

constexpr std::int32_t kNewNode = -2;  // stands for the node not placed yet in a NewCell

struct NewCell {
  CellKind kind;
  std::array<std::int32_t, 5> v;
};

// The mesh being changed: cells are only marked dead and appended until compact().
class EditableMesh {
 public:
  explicit EditableMesh(MixedMesh& m) : mesh(m), dead_(m.num_cells(), 0), at_(m.nodes.size()) {
    for (std::size_t c = 0; c < m.num_cells(); ++c) index_cell(static_cast<std::int32_t>(c));
  }

  MixedMesh& mesh;

  bool alive(std::int32_t c) const { return !dead_[c]; }
  CellKind kind(std::int32_t c) const { return mesh.cell_kind[c]; }
  const std::int32_t* nodes(std::int32_t c) const { return mesh.cell(c); }

  // Calls fn(c) for each live cell other than `skip` that holds both nodes a and b.
  template <class Fn>
  void for_cells_with(std::int32_t a, std::int32_t b, std::int32_t skip, Fn fn) const {
    for (std::int32_t c : at_[a]) {
      if (c == skip || dead_[c]) continue;
      const std::int32_t* v = nodes(c);
      if (std::find(v, v + num_nodes(kind(c)), b) != v + num_nodes(kind(c))) fn(c);
    }
  }

  // The live cell other than `skip` with the triangle face {a, b, c}, or -1.
  std::int32_t cell_with_triangle(std::int32_t a, std::int32_t b, std::int32_t c,
                                  std::int32_t skip) const {
    const FaceKey want = triangle_key(a, b, c);
    std::int32_t found = -1;
    for_cells_with(a, b, skip, [&](std::int32_t x) {
      const CellFaces& cf = faces_of(kind(x));
      for (int f = 0; f < cf.count; ++f)
        if (cf.face[f].n == 3 && face_key(nodes(x), cf.face[f]) == want) found = x;
    });
    return found;
  }

  // The diagonal d (0 or 1) of quad q whose halves (q[d], q[d+1], q[d+2]) and (q[d], q[d+2],
  // q[d+3]) each are the face of exactly one cell other than `cell`, or -1. "Exactly one": a
  // flat sliver on the quad has all four triangles, but two of them face other cells.
  int far_diagonal(const std::array<std::int32_t, 4>& q, std::int32_t cell) const {
    auto lone = [&](std::int32_t a, std::int32_t b, std::int32_t c) {
      return count_with_triangle(a, b, c, cell) == 1;
    };
    for (int d = 0; d < 2; ++d)
      if (lone(q[d], q[d + 1], q[d + 2]) && lone(q[d], q[d + 2], q[(d + 3) % 4])) return d;
    // Else any diagonal whose two halves have a cell (a sliver shared on every side).
    for (int d = 0; d < 2; ++d)
      if (count_with_triangle(q[d], q[d + 1], q[d + 2], cell) > 0 &&
          count_with_triangle(q[d], q[d + 2], q[(d + 3) % 4], cell) > 0)
        return d;
    return -1;
  }

  // How many live cells other than `skip` have the triangle face {a, b, c}.
  int count_with_triangle(std::int32_t a, std::int32_t b, std::int32_t c, std::int32_t skip) const {
    const FaceKey want = triangle_key(a, b, c);
    int n = 0;
    for_cells_with(a, b, skip, [&](std::int32_t x) {
      const CellFaces& cf = faces_of(kind(x));
      for (int f = 0; f < cf.count; ++f)
        if (cf.face[f].n == 3 && face_key(nodes(x), cf.face[f]) == want) ++n;
    });
    return n;
  }

  Vec3 position(std::int32_t v, const Vec3& new_node) const {
    return v == kNewNode ? new_node : mesh.nodes[v];
  }

  // The worst min scaled Jacobian of `cells` with the new node at `s`.
  double worst_quality(const std::vector<NewCell>& cells, const Vec3& s) const {
    double worst = 1e300;
    for (const NewCell& c : cells) {
      Vec3 x[5];
      for (int i = 0; i < num_nodes(c.kind); ++i) x[i] = position(c.v[i], s);
      worst = std::min(worst, min_scaled_jacobian(c.kind, x));
    }
    return worst;
  }

  // Replaces the cells `gone` by `cells` (solid and physical of `like`); a kNewNode in them
  // becomes a new node at `s` when `uses_new_node`.
  void replace(const std::vector<std::int32_t>& gone, std::vector<NewCell> cells,
               bool uses_new_node, const Vec3& s, std::int32_t like) {
    const std::int32_t solid = mesh.cell_solid[like], physical = mesh.cell_physical[like];
    for (std::int32_t c : gone) dead_[c] = 1;
    if (uses_new_node) {
      const auto id = static_cast<std::int32_t>(mesh.nodes.size());
      mesh.nodes.push_back(s);
      at_.emplace_back();
      for (NewCell& c : cells) std::replace(c.v.begin(), c.v.end(), kNewNode, id);
    }
    for (const NewCell& c : cells) {
      mesh.add_cell(c.kind, c.v.data(), solid, physical);
      dead_.push_back(0);
      index_cell(static_cast<std::int32_t>(mesh.num_cells() - 1));
    }
  }

  // Drops the dead cells, keeping the order of the others.
  void compact() {
    MixedMesh& m = mesh;
    std::size_t k = 0;
    for (std::size_t c = 0; c < m.num_cells(); ++c) {
      if (dead_[c]) continue;
      m.cell_kind[k] = m.cell_kind[c];
      std::copy_n(&m.cell_nodes[kMaxCellNodes * c], kMaxCellNodes,
                  &m.cell_nodes[kMaxCellNodes * k]);
      m.cell_solid[k] = m.cell_solid[c];
      m.cell_physical[k] = m.cell_physical[c];
      ++k;
    }
    m.cell_kind.resize(k);
    m.cell_nodes.resize(kMaxCellNodes * k);
    m.cell_solid.resize(k);
    m.cell_physical.resize(k);
  }

 private:
  void index_cell(std::int32_t c) {
    for (int i = 0; i < num_nodes(kind(c)); ++i) at_[nodes(c)[i]].push_back(c);
  }
  std::vector<char> dead_;
  std::vector<std::vector<std::int32_t>> at_;  // node -> cells (dead ones included)
};

std::array<std::int32_t, 4> quad_of(const EditableMesh& em, std::int32_t cell, int f) {
  const LocalFace& lf = faces_of(em.kind(cell)).face[f];
  const std::int32_t* v = em.nodes(cell);
  return {v[lf.v[0]], v[lf.v[1]], v[lf.v[2]], v[lf.v[3]]};
}

Vec3 centroid(const EditableMesh& em, const std::int32_t* ids, int n) {
  Vec3 g{0, 0, 0};
  for (int i = 0; i < n; ++i)
    for (int d = 0; d < 3; ++d) g[d] += em.mesh.nodes[ids[i]][d] / n;
  return g;
}

Vec3 lerp(const Vec3& a, const Vec3& b, double t) {
  return {a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]), a[2] + t * (b[2] - a[2])};
}

// The best of `candidates` for the new node of `cells`: its index, or -1 when none reaches
// `min_quality`.
int best_position(const EditableMesh& em, const std::vector<NewCell>& cells,
                  const std::vector<Vec3>& candidates, double min_quality) {
  int best = -1;
  double best_q = min_quality;
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    const double q = em.worst_quality(cells, candidates[i]);
    if (q >= best_q) {
      best_q = q;
      best = static_cast<int>(i);
    }
  }
  return best;
}

// The tets around edge (a, c) on the far side of quad (a, b, c, d), in order from the one on
// triangle (a, b, c) to the one on (a, c, d). Empty unless every other live cell holding a and c
// is one of them (a tet of the same solid), so that they fill the edge's half shell.
std::vector<std::int32_t> half_shell(const EditableMesh& em, std::int32_t cell,
                                     const std::array<std::int32_t, 4>& q, int d) {
  const std::int32_t a = q[d], b = q[d + 1], c = q[d + 2], e = q[(d + 3) % 4];
  std::size_t holding = 0;
  bool all_tets = true;
  em.for_cells_with(a, c, cell, [&](std::int32_t x) {
    ++holding;
    all_tets = all_tets && em.kind(x) == CellKind::Tet4;
  });
  std::vector<std::int32_t> shell;
  if (!all_tets) return shell;
  std::int32_t cur = em.cell_with_triangle(a, c, b, cell), prev_side = b;
  while (cur >= 0 && shell.size() < holding) {
    if (!shell.empty() && em.mesh.cell_solid[cur] != em.mesh.cell_solid[shell[0]]) break;
    shell.push_back(cur);
    const std::int32_t* v = em.nodes(cur);
    std::int32_t w = -1;
    for (int i = 0; i < 4; ++i)
      if (v[i] != a && v[i] != c && v[i] != prev_side) w = v[i];
    if (w == e) return shell.size() == holding ? shell : std::vector<std::int32_t>{};
    cur = em.cell_with_triangle(a, c, w, cur);
    prev_side = w;
  }
  return {};
}

bool split_cell(EditableMesh& em, std::int32_t cell, const ConformalOptions& o, ConformalReport& r);

// The pyramids holding edge (a, c) whose base does not hold both: once split about their centre
// (a pyramid on the base, tets on the sides) only tets hold the edge. Empty when another cell
// kind, or a pyramid with the edge in its base, holds it.
std::vector<std::int32_t> pyramids_in_the_way(const EditableMesh& em, std::int32_t cell,
                                              std::int32_t a, std::int32_t c) {
  std::vector<std::int32_t> found;
  bool other = false;
  em.for_cells_with(a, c, cell, [&](std::int32_t x) {
    if (em.kind(x) == CellKind::Tet4) return;
    const std::int32_t* v = em.nodes(x);
    const bool base_holds_both = em.kind(x) == CellKind::Pyramid5 &&
                                 std::find(v, v + 4, a) != v + 4 && std::find(v, v + 4, c) != v + 4;
    if (em.kind(x) != CellKind::Pyramid5 || base_holds_both) other = true;
    found.push_back(x);
  });
  return other ? std::vector<std::int32_t>{} : found;
}

// Fills the half shell of the NC quad (cell, f) with a pyramid on the quad and tets; true when
// done.
bool fill_half_shell(EditableMesh& em, std::int32_t cell, int f, const ConformalOptions& o,
                     ConformalReport& r) {
  const std::array<std::int32_t, 4> q = quad_of(em, cell, f);
  const int d = em.far_diagonal(q, cell);
  if (d < 0) return false;
  std::vector<std::int32_t> shell = half_shell(em, cell, q, d);
  if (shell.empty()) {  // pyramids in the way: split them (no hex volume), then try again
    const std::vector<std::int32_t> pyramids = pyramids_in_the_way(em, cell, q[d], q[d + 2]);
    if (pyramids.empty()) return false;
    for (std::int32_t p : pyramids)
      if (!split_cell(em, p, o, r)) return false;
    shell = half_shell(em, cell, q, d);
  }
  if (shell.size() < 2) return false;
  const std::int32_t a = q[d], c = q[d + 2];
  // The pyramid's base (0, 3, 2, 1) faces away from its apex: the quad as the cell sees it.
  const NewCell pyramid{CellKind::Pyramid5, {q[0], q[1], q[2], q[3], kNewNode}};
  if (shell.size() == 2) {  // the two tets share their fourth node: they are the pyramid
    const std::int32_t* v = em.nodes(shell[0]);
    std::int32_t apex = -1;
    for (int i = 0; i < 4; ++i)
      if (v[i] != a && v[i] != c && v[i] != q[d + 1]) apex = v[i];
    std::vector<NewCell> cells{pyramid};
    const Vec3 s = em.mesh.nodes[apex];
    if (em.worst_quality(cells, s) >= o.min_quality) {
      cells[0].v[4] = apex;
      em.replace(shell, cells, false, s, shell[0]);
      ++r.pyramids;
      ++r.shell_pyramids;
      return true;
    }
  }
  // Each shell tet (a, c, u, w) gives (s, u, w) with a, and with c: its own nodes with c, then a,
  // replaced by the new node keep its orientation.
  std::vector<NewCell> cells{pyramid};
  Vec3 far{0, 0, 0};  // the mean of the shell's nodes off the quad
  int n_far = 0;
  for (std::int32_t t : shell) {
    const std::int32_t* v = em.nodes(t);
    for (std::int32_t replaced : {a, c}) {
      NewCell nc{CellKind::Tet4, {v[0], v[1], v[2], v[3], -1}};
      std::replace(nc.v.begin(), nc.v.begin() + 4, replaced, kNewNode);
      cells.push_back(nc);
    }
    for (int i = 0; i < 4; ++i)
      if (v[i] != q[0] && v[i] != q[1] && v[i] != q[2] && v[i] != q[3]) {
        for (int k = 0; k < 3; ++k) far[k] += em.mesh.nodes[v[i]][k];
        ++n_far;
      }
  }
  for (double& x : far) x /= n_far;
  const Vec3 mid = lerp(em.mesh.nodes[a], em.mesh.nodes[c], 0.5);
  std::vector<Vec3> candidates;
  for (double t : {0.5, 0.4, 0.3, 0.2, 0.12, 0.06}) candidates.push_back(lerp(mid, far, t));
  const Vec3 qc = centroid(em, q.data(), 4);
  for (double t : {0.5, 0.35, 0.2, 0.1}) candidates.push_back(lerp(qc, far, t));
  const int best = best_position(em, cells, candidates, o.min_quality);
  if (best < 0) return false;
  em.replace(shell, cells, true, candidates[best], shell[0]);
  ++r.pyramids;
  ++r.steiner_points;
  return true;
}

// Splits the cell about a new node near its centre: a pyramid on each quad face that is matched
// or on the boundary, two tets on each NC quad (along the far side's diagonal), a tet on each
// triangle. True when done.
bool split_cell(EditableMesh& em, std::int32_t cell, const ConformalOptions& o,
                ConformalReport& r) {
  const CellKind kind = em.kind(cell);
  const std::int32_t* v = em.nodes(cell);
  const CellFaces& cf = faces_of(kind);
  std::vector<NewCell> cells;
  // A tet on an outward triangle (x, y, z): its face (0, 2, 1) is outward.
  auto tet_on = [&](std::int32_t x, std::int32_t y, std::int32_t z) {
    cells.push_back({CellKind::Tet4, {x, z, y, kNewNode, -1}});
  };
  std::vector<Vec3> candidates{centroid(em, v, num_nodes(kind))};
  for (int f = 0; f < cf.count; ++f) {
    const LocalFace& lf = cf.face[f];
    if (lf.n == 3) {
      tet_on(v[lf.v[0]], v[lf.v[1]], v[lf.v[2]]);
      continue;
    }
    const std::array<std::int32_t, 4> q = quad_of(em, cell, f);
    const int d = em.far_diagonal(q, cell);
    if (d < 0) {
      cells.push_back({CellKind::Pyramid5, {q[0], q[3], q[2], q[1], kNewNode}});
    } else {
      tet_on(q[d], q[d + 1], q[d + 2]);
      tet_on(q[d], q[d + 2], q[(d + 3) % 4]);
    }
  }
  // Off the centre towards each face, for cells too distorted for their centre.
  const Vec3 g = candidates[0];
  for (int f = 0; f < cf.count; ++f) {
    std::int32_t ids[4];
    for (int i = 0; i < cf.face[f].n; ++i) ids[i] = v[cf.face[f].v[i]];
    for (double t : {0.25, 0.5}) candidates.push_back(lerp(g, centroid(em, ids, cf.face[f].n), t));
  }
  const int best = best_position(em, cells, candidates, o.min_quality);
  if (best < 0) return false;
  em.replace({cell}, cells, true, candidates[best], cell);
  ++r.cells_split[static_cast<int>(kind)];
  ++r.steiner_points;
  return true;
}

// A flat tet on the four corners of quad (cell, f) (a sliver between its two diagonals): it
// goes, as the recombination absorbs such slivers into their quad, so that the quad faces the
// cells beyond it. True when one went.
bool drop_flat_sliver_on(EditableMesh& em, std::int32_t cell, int f) {
  const std::array<std::int32_t, 4> q = quad_of(em, cell, f);
  const std::int32_t t = em.cell_with_triangle(q[0], q[1], q[2], cell);
  if (t < 0 || em.kind(t) != CellKind::Tet4) return false;
  const std::int32_t* v = em.nodes(t);
  for (std::int32_t corner : q)
    if (std::find(v, v + 4, corner) == v + 4) return false;
  em.replace({t}, {}, false, {}, t);
  return true;
}

double hex_volume(const MixedMesh& mesh, double* total) {
  double hex = 0;
  *total = 0;
  for (std::size_t c = 0; c < mesh.num_cells(); ++c) {
    const double v = cell_volume(mesh, c);
    *total += v;
    if (mesh.cell_kind[c] == CellKind::Hex8) hex += v;
  }
  return hex;
}

}  // namespace

ConformalReport make_conformal(MixedMesh& mesh, const ConformalOptions& options) {
  if (mesh.order != 1) throw Error("the conformal pass runs on order-1 meshes");
  ConformalReport r;
  r.nc_before = mesh.nc_cell.size();
  r.hex_volume_before = hex_volume(mesh, &r.volume);
  if (mesh.nc_cell.empty()) {
    r.hex_volume_after = r.hex_volume_before;
    return r;
  }
  // In the order of the NC flags (deterministic); a face is looked at again, since an earlier
  // split of its cell may have made it conformal already. A few rounds: a split next to a flat
  // sliver can leave the sliver's other side to the next round.
  for (int round = 0; round < 4 && !mesh.nc_cell.empty(); ++round) {
    EditableMesh em(mesh);
    const std::vector<std::int32_t> nc_cell = mesh.nc_cell;
    const std::vector<std::int8_t> nc_face = mesh.nc_local_face;
    r.failed = 0;
    for (std::size_t i = 0; i < nc_cell.size(); ++i) {
      const std::int32_t cell = nc_cell[i];
      if (!em.alive(cell)) continue;
      if (em.far_diagonal(quad_of(em, cell, nc_face[i]), cell) < 0) continue;
      if (drop_flat_sliver_on(em, cell, nc_face[i])) ++r.absorbed_slivers;
      if (fill_half_shell(em, cell, nc_face[i], options, r)) continue;
      if (!split_cell(em, cell, options, r)) ++r.failed;
    }
    em.compact();
    flag_nonconformal_quads(mesh);
  }
  r.nc_after = mesh.nc_cell.size();
  double total = 0;
  r.hex_volume_after = hex_volume(mesh, &total);
  return r;
}

}  // namespace hexfem
