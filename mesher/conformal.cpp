#include "mesher/conformal.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "mesher/boundary_bulge.hpp"
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
    for (std::size_t f = 0; f < m.num_bfaces(); ++f)
      if (!m.bface_is_quad(f))
        boundary_triangles_.push_back(triangle_key(m.bface(f)[0], m.bface(f)[1], m.bface(f)[2]));
    std::sort(boundary_triangles_.begin(), boundary_triangles_.end());
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

  // The diagonal d (0 or 1) of quad q whose halves are both stored boundary triangles (a cell's
  // quad over two CAD faces keeps them, each with its CAD face), or -1.
  int boundary_diagonal(const std::array<std::int32_t, 4>& q) const {
    auto stored = [&](std::int32_t a, std::int32_t b, std::int32_t c) {
      return std::binary_search(boundary_triangles_.begin(), boundary_triangles_.end(),
                                triangle_key(a, b, c));
    };
    for (int d = 0; d < 2; ++d)
      if (stored(q[d], q[d + 1], q[d + 2]) && stored(q[d], q[d + 2], q[(d + 3) % 4])) return d;
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
  std::vector<FaceKey> boundary_triangles_;    // the stored boundary triangles, sorted
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

// Moves `x` to raise the worst quality of `cells` about it: a compass search over the 3 axes and
// the 8 cube diagonals, from a step of a tenth of the cells' size down to 1e-4 of it.
double compass_search(const EditableMesh& em, const std::vector<NewCell>& cells, Vec3& x) {
  Vec3 lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
  for (const NewCell& c : cells)
    for (int i = 0; i < num_nodes(c.kind); ++i)
      if (c.v[i] != kNewNode)
        for (int k = 0; k < 3; ++k) {
          lo[k] = std::min(lo[k], em.mesh.nodes[c.v[i]][k]);
          hi[k] = std::max(hi[k], em.mesh.nodes[c.v[i]][k]);
        }
  const double size =
      std::sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                (hi[2] - lo[2]) * (hi[2] - lo[2]));
  std::vector<Vec3> dirs;
  for (int k = 0; k < 3; ++k)
    for (double sign : {1.0, -1.0}) {
      Vec3 e{0, 0, 0};
      e[k] = sign;
      dirs.push_back(e);
    }
  const double r = 1 / std::sqrt(3.0);
  for (double sx : {r, -r})
    for (double sy : {r, -r})
      for (double sz : {r, -r}) dirs.push_back({sx, sy, sz});
  double best = em.worst_quality(cells, x);
  for (double step = 0.1 * size; step > 1e-4 * size; step /= 2) {
    for (bool moved = true; moved;) {
      moved = false;
      for (const Vec3& e : dirs) {
        const Vec3 y{x[0] + step * e[0], x[1] + step * e[1], x[2] + step * e[2]};
        const double q = em.worst_quality(cells, y);
        if (q > best) {
          best = q;
          x = y;
          moved = true;
        }
      }
    }
  }
  return best;
}

// The best of `candidates` for the new node of `cells`: its index, or -1 when none reaches
// `min_quality`. When none does, a compass search from the best one may find a position that
// does: it is appended to `candidates`.
int best_position(const EditableMesh& em, const std::vector<NewCell>& cells,
                  std::vector<Vec3>& candidates, double min_quality) {
  int best = -1, best_any = 0;
  double best_q = min_quality, best_any_q = -1e300;
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    const double q = em.worst_quality(cells, candidates[i]);
    if (q >= best_q) {
      best_q = q;
      best = static_cast<int>(i);
    }
    if (q > best_any_q) {
      best_any_q = q;
      best_any = static_cast<int>(i);
    }
  }
  if (best >= 0 || candidates.empty()) return best;
  Vec3 x = candidates[best_any];
  if (compass_search(em, cells, x) < min_quality) return -1;
  candidates.push_back(x);
  return static_cast<int>(candidates.size() - 1);
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

// The shell's fill `cells` (a pyramid on the quad, two tets per shell tet, about kNewNode) with
// the shell node w in place of the new node: the tets that hold w already go flat and are left
// out. For shell tets (a, c, w_j, w_j+1) around the edge, w = w_k gives the pyramid and the
// tets (a, w_j, w_j+1, w_k), (c, w_j, w_j+1, w_k) for j + 1 < k and j > k: a fan about w_k,
// the shell refilled without a new node (for two tets, the pyramid alone).
std::vector<NewCell> fill_about(const std::vector<NewCell>& cells, std::int32_t w) {
  std::vector<NewCell> out;
  for (NewCell c : cells) {
    const auto end = c.v.begin() + num_nodes(c.kind);
    if (std::find(c.v.begin(), end, w) != end) continue;
    std::replace(c.v.begin(), end, kNewNode, w);
    out.push_back(c);
  }
  return out;
}

// The fill `cells` about the node of the tets `shell` (off the quad q) that makes the worst new
// cell best, or empty when none reaches options.min_quality.
std::vector<NewCell> fill_about_shell_node(const EditableMesh& em,
                                           const std::vector<std::int32_t>& shell,
                                           const std::vector<NewCell>& cells,
                                           const std::array<std::int32_t, 4>& q,
                                           const ConformalOptions& o) {
  std::vector<NewCell> best;
  double best_q = o.min_quality;
  for (std::int32_t t : shell)
    for (int i = 0; i < 4; ++i) {
      const std::int32_t w = em.nodes(t)[i];
      if (std::find(q.begin(), q.end(), w) != q.end()) continue;
      std::vector<NewCell> fill = fill_about(cells, w);
      const double quality = em.worst_quality(fill, {});
      if (quality >= best_q) {
        best_q = quality;
        best = std::move(fill);
      }
    }
  return best;
}

// Refills the shell about a node of its own (see above); true when done.
bool refill_about_shell_node(EditableMesh& em, const std::vector<std::int32_t>& shell,
                             const std::vector<NewCell>& cells,
                             const std::array<std::int32_t, 4>& q, const ConformalOptions& o,
                             ConformalReport& r) {
  const std::vector<NewCell> fill = fill_about_shell_node(em, shell, cells, q, o);
  if (fill.empty()) return false;
  em.replace(shell, fill, false, {}, shell[0]);
  ++r.pyramids;
  ++(shell.size() == 2 ? r.shell_pyramids : r.flip_pyramids);
  return true;
}

// Adds to `cavity` the tets across its faces (not `cell`'s, of the same solid); false when none.
bool grow_cavity(const EditableMesh& em, std::int32_t cell, std::vector<std::int32_t>& cavity) {
  const std::size_t n = cavity.size();
  for (std::size_t i = 0; i < n; ++i) {
    const std::int32_t* v = em.nodes(cavity[i]);
    for (const LocalFace& lf : faces_of(CellKind::Tet4).face) {
      if (lf.n != 3) continue;
      const std::int32_t x = em.cell_with_triangle(v[lf.v[0]], v[lf.v[1]], v[lf.v[2]], cavity[i]);
      if (x < 0 || x == cell || em.kind(x) != CellKind::Tet4 ||
          em.mesh.cell_solid[x] != em.mesh.cell_solid[cavity[0]] ||
          std::find(cavity.begin(), cavity.end(), x) != cavity.end())
        continue;
      cavity.push_back(x);
    }
  }
  return cavity.size() > n;
}

// Appends the cones about kNewNode over the faces of `cell` but face `skip` (-1: none): a pyramid
// on each quad face that is matched or on the boundary, two tets on each NC quad (along the far
// side's diagonal) and on each boundary quad stored as two triangles (along theirs), a tet on
// each triangle.
void cell_cones(const EditableMesh& em, std::int32_t cell, int skip, std::vector<NewCell>& cells) {
  const std::int32_t* v = em.nodes(cell);
  const CellFaces& cf = faces_of(em.kind(cell));
  // A tet on an outward triangle (x, y, z): its face (0, 2, 1) is outward.
  auto tet_on = [&](std::int32_t x, std::int32_t y, std::int32_t z) {
    cells.push_back({CellKind::Tet4, {x, z, y, kNewNode, -1}});
  };
  for (int f = 0; f < cf.count; ++f) {
    const LocalFace& lf = cf.face[f];
    if (f == skip) continue;
    if (lf.n == 3) {
      tet_on(v[lf.v[0]], v[lf.v[1]], v[lf.v[2]]);
      continue;
    }
    const std::array<std::int32_t, 4> q = quad_of(em, cell, f);
    int d = em.far_diagonal(q, cell);
    if (d < 0) d = em.boundary_diagonal(q);
    if (d < 0) {
      cells.push_back({CellKind::Pyramid5, {q[0], q[3], q[2], q[1], kNewNode}});
    } else {
      tet_on(q[d], q[d + 1], q[d + 2]);
      tet_on(q[d], q[d + 2], q[(d + 3) % 4]);
    }
  }
}

// The fill about a new node of the tets `cavity` behind the NC quad (cell, f), whose halves
// meet on the diagonal (a, c) = (q[d], q[d + 2]): a tet on each face of the cavity but the two
// halves, and either a pyramid on the quad (`with_cell` false) or the cones over `cell`'s other
// faces (`cell` goes too, and the quad with it). Empty when the faces do not close up: each
// edge in exactly two of them, no face but the halves holding a and c (with the pyramid), and
// every node of the cavity on one of its faces (none left out of the mesh).
std::vector<NewCell> cavity_fill(const EditableMesh& em, const std::vector<std::int32_t>& cavity,
                                 std::int32_t cell, int f, int d, bool with_cell) {
  const std::array<std::int32_t, 4> q = quad_of(em, cell, f);
  const std::int32_t a = q[d], c = q[d + 2];
  const FaceKey half1 = triangle_key(a, q[d + 1], c), half2 = triangle_key(a, c, q[(d + 3) % 4]);
  std::vector<NewCell> cells;
  if (with_cell)
    cell_cones(em, cell, f, cells);
  else
    cells.push_back({CellKind::Pyramid5, {q[0], q[1], q[2], q[3], kNewNode}});
  int halves = 0;
  std::vector<std::int32_t> nodes;
  for (std::int32_t t : cavity) {
    const std::int32_t* v = em.nodes(t);
    nodes.insert(nodes.end(), v, v + 4);
    for (const LocalFace& lf : faces_of(CellKind::Tet4).face) {
      if (lf.n != 3) continue;
      const std::int32_t x = v[lf.v[0]], y = v[lf.v[1]], z = v[lf.v[2]];
      const std::int32_t across = em.cell_with_triangle(x, y, z, t);
      if (across >= 0 && std::find(cavity.begin(), cavity.end(), across) != cavity.end()) continue;
      const FaceKey key = triangle_key(x, y, z);
      if (key == half1 || key == half2) {
        ++halves;
        continue;
      }
      const bool holds_a = x == a || y == a || z == a, holds_c = x == c || y == c || z == c;
      if (!with_cell && holds_a && holds_c) return {};
      cells.push_back({CellKind::Tet4, {x, z, y, kNewNode, -1}});  // (x, y, z) outward
    }
  }
  if (halves != 2) return {};
  // The faces' edges (each cell's nodes but the new one, in order, are its face's polygon).
  std::vector<std::pair<std::int32_t, std::int32_t>> edges;
  std::vector<std::int32_t> on_faces;
  for (const NewCell& nc : cells) {
    const int n = num_nodes(nc.kind) - 1;
    for (int i = 0; i < n; ++i) {
      const std::int32_t x = nc.v[i], y = nc.v[(i + 1) % n];
      edges.emplace_back(std::min(x, y), std::max(x, y));
      on_faces.push_back(x);
    }
  }
  std::sort(edges.begin(), edges.end());
  for (std::size_t i = 0; i < edges.size(); i += 2)
    if (i + 1 >= edges.size() || edges[i] != edges[i + 1] ||
        (i + 2 < edges.size() && edges[i + 2] == edges[i]))
      return {};
  std::sort(on_faces.begin(), on_faces.end());
  for (std::int32_t x : nodes)
    if (!std::binary_search(on_faces.begin(), on_faces.end(), x)) return {};
  return cells;
}

// Refills the tets `cavity` behind the NC quad (cell, f) (far diagonal d), and `cell` too when
// `with_cell`, about a new node (candidates about the cavity's centre, then a compass search) or
// else about a node of the cavity; true when done.
bool fill_cavity(EditableMesh& em, std::int32_t cell, int f, int d,
                 const std::vector<std::int32_t>& cavity, bool with_cell, const ConformalOptions& o,
                 ConformalReport& r) {
  const std::vector<NewCell> cells = cavity_fill(em, cavity, cell, f, d, with_cell);
  if (cells.empty()) return false;
  const std::array<std::int32_t, 4> q = quad_of(em, cell, f);
  Vec3 far{0, 0, 0};
  int n_far = 0;
  std::vector<Vec3> candidates;
  if (with_cell) candidates.push_back(centroid(em, em.nodes(cell), num_nodes(em.kind(cell))));
  for (std::int32_t t : cavity) {
    candidates.push_back(centroid(em, em.nodes(t), 4));
    for (int i = 0; i < 4; ++i)
      if (std::find(q.begin(), q.end(), em.nodes(t)[i]) == q.end()) {
        for (int k = 0; k < 3; ++k) far[k] += em.mesh.nodes[em.nodes(t)[i]][k];
        ++n_far;
      }
  }
  if (n_far == 0) return false;
  for (double& x : far) x /= n_far;
  const Vec3 qc = centroid(em, q.data(), 4);
  for (double t : {0.9, 0.7, 0.5, 0.3}) candidates.push_back(lerp(qc, far, t));
  if (with_cell)
    for (double t : {0.3, 0.5}) candidates.push_back(lerp(candidates[0], qc, t));
  std::vector<std::int32_t> gone = cavity;
  if (with_cell) gone.push_back(cell);
  const CellKind kind = em.kind(cell);
  const int best = best_position(em, cells, candidates, o.min_quality);
  if (best >= 0) {
    em.replace(gone, cells, true, candidates[best], cavity[0]);
    ++r.steiner_points;
  } else {
    const std::vector<NewCell> fill = fill_about_shell_node(em, cavity, cells, q, o);
    if (fill.empty()) return false;
    em.replace(gone, fill, false, {}, cavity[0]);
  }
  if (with_cell) {
    ++r.cells_split[static_cast<int>(kind)];
    ++r.split_with_tets_behind;
  } else {
    ++r.pyramids;
    ++r.grown_cavities;
  }
  return true;
}

// Splits the NC quad's cell together with the tets behind the quad (those on its halves, then
// one or two layers more) about one node: the quad goes. True when done.
bool split_with_tets_behind(EditableMesh& em, std::int32_t cell, int f, const ConformalOptions& o,
                            ConformalReport& r) {
  const std::array<std::int32_t, 4> q = quad_of(em, cell, f);
  const int d = em.far_diagonal(q, cell);
  if (d < 0) return false;
  std::vector<std::int32_t> cavity;
  for (const std::int32_t t : {em.cell_with_triangle(q[d], q[d + 1], q[d + 2], cell),
                               em.cell_with_triangle(q[d], q[d + 2], q[(d + 3) % 4], cell)}) {
    if (t < 0 || em.kind(t) != CellKind::Tet4 || em.mesh.cell_solid[t] != em.mesh.cell_solid[cell])
      return false;
    if (std::find(cavity.begin(), cavity.end(), t) == cavity.end()) cavity.push_back(t);
  }
  for (int layer = 0; layer < 3; ++layer) {
    if (fill_cavity(em, cell, f, d, cavity, true, o, r)) return true;
    if (layer < 2 && !grow_cavity(em, cell, cavity)) return false;
  }
  return false;
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
  // Two tets share their fourth node: with the quad they are the pyramid (no new node).
  if (shell.size() == 2 && refill_about_shell_node(em, shell, cells, q, o, r)) return true;
  const Vec3 mid = lerp(em.mesh.nodes[a], em.mesh.nodes[c], 0.5);
  std::vector<Vec3> candidates;
  for (double t : {0.5, 0.4, 0.3, 0.2, 0.12, 0.06}) candidates.push_back(lerp(mid, far, t));
  const Vec3 qc = centroid(em, q.data(), 4);
  for (double t : {0.5, 0.35, 0.2, 0.1}) candidates.push_back(lerp(qc, far, t));
  const int best = best_position(em, cells, candidates, o.min_quality);
  if (best >= 0) {
    em.replace(shell, cells, true, candidates[best], shell[0]);
    ++r.pyramids;
    ++r.steiner_points;
    return true;
  }
  // No position inside the shell: a node of the shell itself may still be the apex.
  if (shell.size() > 2 && refill_about_shell_node(em, shell, cells, q, o, r)) return true;
  // Else the shell grown by a layer of tets, twice at most (a fold of the quad towards the far
  // side can leave no room for an apex in the shell alone).
  std::vector<std::int32_t> cavity = shell;
  for (int layer = 0; layer < 2; ++layer) {
    if (!grow_cavity(em, cell, cavity)) return false;
    if (fill_cavity(em, cell, f, d, cavity, false, o, r)) return true;
  }
  return false;
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
  cell_cones(em, cell, -1, cells);
  // The centre, and off it towards each face for cells too distorted for their centre.
  std::vector<Vec3> candidates{centroid(em, v, num_nodes(kind))};
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

// A cell's boundary quad that the boundary faces keep as two triangles (over two CAD faces): a
// pyramid becomes the two tets on those triangles (they are corner tets of the pyramid, so
// positive), another cell is split about a node (two tets on the quad). Then every boundary face
// is a face of a cell. Returns the cells changed.
std::size_t split_on_boundary_triangles(MixedMesh& mesh, const ConformalOptions& o,
                                        ConformalReport& r) {
  EditableMesh em(mesh);
  std::size_t changed = 0;
  const auto n = static_cast<std::int32_t>(mesh.num_cells());
  for (std::int32_t cell = 0; cell < n; ++cell) {
    if (em.kind(cell) == CellKind::Tet4) continue;
    const CellFaces& cf = faces_of(em.kind(cell));
    for (int f = 0; f < cf.count; ++f) {
      if (cf.face[f].n != 4) continue;
      const std::array<std::int32_t, 4> q = quad_of(em, cell, f);
      const int d = em.boundary_diagonal(q);
      if (d < 0) continue;
      if (em.kind(cell) == CellKind::Pyramid5) {
        // q is the base (0, 1, 2, 3) as (0, 3, 2, 1): diagonal d of q is the base's d.
        const std::int32_t* v = em.nodes(cell);
        const int e = d;
        const std::vector<NewCell> tets{
            {CellKind::Tet4, {v[e], v[e + 1], v[e + 2], v[4], -1}},
            {CellKind::Tet4, {v[e], v[e + 2], v[(e + 3) % 4], v[4], -1}}};
        if (em.worst_quality(tets, {}) >= o.min_quality) {
          em.replace({cell}, tets, false, {}, cell);
          ++r.boundary_pyramids_split;
          ++changed;
          break;
        }
      }
      if (split_cell(em, cell, o, r)) {
        ++r.boundary_cells_split;
        ++changed;
      }
      break;
    }
  }
  em.compact();
  return changed;
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
  const bool some = !options.only_quads.empty();
  std::vector<std::array<std::int32_t, 4>> only = options.only_quads;
  for (auto& q : only) std::sort(q.begin(), q.end());
  std::sort(only.begin(), only.end());
  auto wanted = [&only, some](std::array<std::int32_t, 4> q) {
    if (!some) return true;
    std::sort(q.begin(), q.end());
    return std::binary_search(only.begin(), only.end(), q);
  };
  if (!some && split_on_boundary_triangles(mesh, options, r) > 0) flag_nonconformal_quads(mesh);
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
      if (!em.alive(cell) || !wanted(quad_of(em, cell, nc_face[i]))) continue;
      if (em.far_diagonal(quad_of(em, cell, nc_face[i]), cell) < 0) continue;
      if (drop_flat_sliver_on(em, cell, nc_face[i])) ++r.absorbed_slivers;
      if (fill_half_shell(em, cell, nc_face[i], options, r)) continue;
      if (split_cell(em, cell, options, r)) continue;
      if (!split_with_tets_behind(em, cell, nc_face[i], options, r)) ++r.failed;
    }
    em.compact();
    flag_nonconformal_quads(mesh);
  }
  if (options.target_volume > 0 && !some) {
    const double t = options.target_volume;
    r.gap_before_bulge = r.gap_after_bulge = (enclosed_volume(mesh) - t) / t;
    const std::vector<BulgeSplit> splits =
        triangulate_bulging_boundary_quads(mesh, t, options.max_gap * t);
    if (!splits.empty()) {
      ConformalReport scratch;  // the boundary splits' counts stay apart from the ones above
      split_on_boundary_triangles(mesh, options, scratch);
      r.steiner_points += scratch.steiner_points;
      r.bulge_quads_restored = restore_unsplit_boundary_quads(mesh, splits);
      r.bulge_quads_split = splits.size() - r.bulge_quads_restored;
      flag_nonconformal_quads(mesh);
      r.gap_after_bulge = (enclosed_volume(mesh) - t) / t;
    }
  }
  r.nc_after = mesh.nc_cell.size();
  double total = 0;
  r.hex_volume_after = hex_volume(mesh, &total);
  return r;
}

}  // namespace hexfem
