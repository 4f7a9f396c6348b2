#include "mesher/boundary_bulge.hpp"

#include <algorithm>
#include <cmath>

#include "mesher/mesh/element_topology.hpp"
#include "mesher/mesh/face_keys.hpp"
#include "mesher/mesh/quality.hpp"

namespace hexfem {

namespace {

// det(a, b, c) / 6: the signed volume of the cone from the origin over triangle (a, b, c).
double cone(const Vec3& a, const Vec3& b, const Vec3& c) {
  return (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
          a[2] * (b[0] * c[1] - b[1] * c[0])) /
         6;
}

// The cone volumes of quad q's two triangulations, along diagonal 0-2 and along 1-3.
std::array<double, 2> triangulations(const MixedMesh& m, const std::int32_t* q) {
  const Vec3 &a = m.nodes[q[0]], &b = m.nodes[q[1]], &c = m.nodes[q[2]], &d = m.nodes[q[3]];
  return {cone(a, b, c) + cone(a, c, d), cone(a, b, d) + cone(b, c, d)};
}

// Signed enclosed volume as the faces are stored (negative if they face inwards).
double stored_volume(const MixedMesh& m) {
  double v = 0;
  for (std::size_t f = 0; f < m.num_bfaces(); ++f) {
    const std::int32_t* q = m.bface(f);
    if (!m.bface_is_quad(f)) {
      v += cone(m.nodes[q[0]], m.nodes[q[1]], m.nodes[q[2]]);
      continue;
    }
    const auto t = triangulations(m, q);
    v += (t[0] + t[1]) / 2;
  }
  return v;
}

}  // namespace

double enclosed_volume(const MixedMesh& mesh) {
  return std::abs(stored_volume(mesh));
}

std::vector<BulgeSplit> triangulate_bulging_boundary_quads(MixedMesh& mesh, double target_volume,
                                                           double budget) {
  std::vector<BulgeSplit> out;
  const double stored = stored_volume(mesh);
  const double outward = stored < 0 ? -1.0 : 1.0;
  double gap = std::abs(stored) - target_volume;
  if (std::abs(gap) <= budget) return out;
  // Each quad's best change: the triangulation that moves the gap towards 0, by half the
  // difference of the two.
  // The cost of a split: the hex volume lost (a hex's split leaves pyramids and tets; another
  // cell's costs no hex volume). Cheapest per unit of change first.
  std::vector<std::pair<FaceKey, std::int32_t>> quad_cell;
  for (std::size_t c = 0; c < mesh.num_cells(); ++c) {
    const CellFaces& cf = faces_of(mesh.cell_kind[c]);
    for (int f = 0; f < cf.count; ++f)
      if (cf.face[f].n == 4)
        quad_cell.emplace_back(face_key(mesh.cell(c), cf.face[f]), static_cast<std::int32_t>(c));
  }
  std::sort(quad_cell.begin(), quad_cell.end());
  const auto hex_cost = [&](const std::int32_t* q) {
    FaceKey k{q[0], q[1], q[2], q[3]};
    std::sort(k.begin(), k.end());
    const auto it = std::lower_bound(quad_cell.begin(), quad_cell.end(), std::make_pair(k, -1));
    if (it == quad_cell.end() || it->first != k) return 0.0;
    const auto c = static_cast<std::size_t>(it->second);
    return mesh.cell_kind[c] == CellKind::Hex8 ? cell_volume(mesh, c) : 0.0;
  };
  struct Choice {
    double change, cost_per_change;
    std::size_t face;
    int diagonal;
  };
  std::vector<Choice> choices;
  for (std::size_t f = 0; f < mesh.num_bfaces(); ++f) {
    if (!mesh.bface_is_quad(f)) continue;
    const auto t = triangulations(mesh, mesh.bface(f));
    const double along02 = outward * (t[0] - t[1]) / 2;  // enclosed-volume change along 0-2
    const int d = (along02 > 0) == (gap < 0) ? 0 : 1;
    const double change = d == 0 ? along02 : -along02;
    if (change * gap < 0)
      choices.push_back({change, hex_cost(mesh.bface(f)) / std::abs(change), f, d});
  }
  std::sort(choices.begin(), choices.end(), [](const Choice& a, const Choice& b) {
    if (a.cost_per_change != b.cost_per_change) return a.cost_per_change < b.cost_per_change;
    if (a.change != b.change) return std::abs(a.change) > std::abs(b.change);
    return a.face < b.face;
  });
  for (const Choice& c : choices) {
    if (std::abs(gap) <= 0.8 * budget) break;
    std::array<std::int32_t, 4> q;
    std::copy_n(mesh.bface(c.face), 4, q.begin());
    const int d = c.diagonal;
    BulgeSplit s{q, static_cast<std::int32_t>(c.face),
                 static_cast<std::int32_t>(mesh.num_bfaces())};
    std::int32_t* stored_face = &mesh.bface_nodes[4 * c.face];
    stored_face[0] = q[d];
    stored_face[1] = q[d + 1];
    stored_face[2] = q[d + 2];
    stored_face[3] = -1;
    mesh.add_bface(q[d], q[d + 2], q[(d + 3) % 4], -1, mesh.bface_cad_face[c.face],
                   mesh.bface_physical[c.face]);
    out.push_back(s);
    gap += c.change;
  }
  return out;
}

std::size_t restore_unsplit_boundary_quads(MixedMesh& mesh, const std::vector<BulgeSplit>& splits) {
  if (splits.empty()) return 0;
  std::vector<FaceKey> triangles;
  for (std::size_t c = 0; c < mesh.num_cells(); ++c) {
    const CellFaces& cf = faces_of(mesh.cell_kind[c]);
    for (int f = 0; f < cf.count; ++f)
      if (cf.face[f].n == 3) triangles.push_back(face_key(mesh.cell(c), cf.face[f]));
  }
  std::sort(triangles.begin(), triangles.end());
  const auto is_face = [&](std::int32_t b) {
    const std::int32_t* t = mesh.bface(b);
    return std::binary_search(triangles.begin(), triangles.end(), triangle_key(t[0], t[1], t[2]));
  };
  std::vector<char> drop(mesh.num_bfaces(), 0);
  std::size_t restored = 0;
  for (const BulgeSplit& s : splits) {
    if (is_face(s.first) && is_face(s.second)) continue;
    std::copy(s.quad.begin(), s.quad.end(), &mesh.bface_nodes[4 * s.first]);
    drop[s.second] = 1;
    ++restored;
  }
  if (restored == 0) return 0;
  std::size_t k = 0;
  for (std::size_t f = 0; f < drop.size(); ++f) {
    if (drop[f]) continue;
    std::copy_n(&mesh.bface_nodes[4 * f], 4, &mesh.bface_nodes[4 * k]);
    mesh.bface_cad_face[k] = mesh.bface_cad_face[f];
    mesh.bface_physical[k] = mesh.bface_physical[f];
    ++k;
  }
  mesh.bface_nodes.resize(4 * k);
  mesh.bface_cad_face.resize(k);
  mesh.bface_physical.resize(k);
  return restored;
}

}  // namespace hexfem
