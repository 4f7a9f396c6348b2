#include "mesher/surface_check.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Surface_mesh.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <map>
#include <numbers>
#include <optional>
#include <unordered_map>

#include "mesher/edge_points.hpp"

namespace hexfem {

namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using PmpMesh = CGAL::Surface_mesh<K::Point_3>;

// A boundary triangle of a solid: its bface index and its corners, outward from that solid.
struct SolidTri {
  std::size_t f;
  std::array<int, 3> t;
};

// The triangles `tris` of m as a CGAL surface mesh; false when some triangle cannot be added
// (a non-manifold vertex or edge). face_of[i] = the bface index of CGAL face i. A node marked in
// `private_nodes` gets a copy of its own in each triangle, which keeps the CGAL mesh manifold
// where two sheets of a solid touch along an edge.
bool build_pmp_mesh(const MixedMesh& m, const std::vector<SolidTri>& tris, PmpMesh& mesh,
                    std::vector<std::size_t>* face_of,
                    const std::vector<char>* private_nodes = nullptr) {
  std::unordered_map<int, PmpMesh::Vertex_index> vmap;
  auto point = [&](int n) {
    const Vec3& p = m.nodes[static_cast<std::size_t>(n)];
    return K::Point_3(p[0], p[1], p[2]);
  };
  auto vertex = [&](int n) {
    if (private_nodes && (*private_nodes)[static_cast<std::size_t>(n)])
      return mesh.add_vertex(point(n));
    auto it = vmap.find(n);
    if (it != vmap.end()) return it->second;
    auto v = mesh.add_vertex(point(n));
    vmap.emplace(n, v);
    return v;
  };
  bool built = true;
  for (const auto& [f, t] : tris) {
    if (mesh.add_face(vertex(t[0]), vertex(t[1]), vertex(t[2])) == PmpMesh::null_face())
      built = false;
    else if (face_of)
      face_of->push_back(f);
  }
  return built;
}

std::vector<SolidTri> triangles_of_solid(const SurfaceMesh& s, std::size_t solid) {
  // A face between two glued solids is oriented outward from the lower id (the CAD face's
  // orientation in its first solid): for the other solid its triangles turn over.
  std::vector<std::size_t> first;  // per CAD face: the lowest solid that holds it
  for (std::size_t t = s.faces_of_solid.size(); t-- > 1;)
    for (int f : s.faces_of_solid[t]) {
      if (static_cast<std::size_t>(f) >= first.size()) first.resize(f + 1, 0);
      first[f] = t;
    }
  const auto& faces = s.faces_of_solid[solid];
  std::vector<SolidTri> tris;
  for (std::size_t f = 0; f < s.mesh.num_bfaces(); ++f) {
    const int cad_face = s.mesh.bface_cad_face[f];
    if (std::find(faces.begin(), faces.end(), cad_face) == faces.end()) continue;
    const auto* b = s.mesh.bface(f);
    if (first[cad_face] == solid)
      tris.push_back({f, {b[0], b[1], b[2]}});
    else
      tris.push_back({f, {b[0], b[2], b[1]}});
  }
  return tris;
}

enum class EdgeUse { ok, open, nonmanifold, misoriented, touching };

// How one solid's triangles use an undirected edge, from the counts in each direction. Where two
// lumps of a solid touch along a CAD edge (the edge bounds four face sides, as on
// gehause_rohteil) each of their sheets uses the edge once each way: the surface is closed and
// oriented there, though not manifold ("touching").
EdgeUse edge_use(const std::array<int, 2>& n, bool on_cad_edge) {
  const int total = n[0] + n[1];
  if (total == 1) return EdgeUse::open;
  if (total == 2) return n[0] == 1 ? EdgeUse::ok : EdgeUse::misoriented;
  if (total % 2 == 0 && n[0] == n[1] && on_cad_edge) return EdgeUse::touching;
  return EdgeUse::nonmanifold;
}

bool on_cad_edge(const SurfaceMesh& s, int a, int b) {
  const auto& e = s.on_edge;
  return e.size() == s.mesh.nodes.size() && e[static_cast<std::size_t>(a)] &&
         e[static_cast<std::size_t>(b)];
}

// Marks the two nodes of a touching edge in `touching` (sized to the mesh's nodes on first use).
void mark_touching(std::vector<char>& touching, std::size_t num_nodes,
                   const std::pair<int, int>& edge) {
  touching.resize(num_nodes, 0);
  touching[static_cast<std::size_t>(edge.first)] = 1;
  touching[static_cast<std::size_t>(edge.second)] = 1;
}

// The intersecting pairs of triangles among `tris` (bface indices, sorted pairs). `touching`:
// nodes of touching edges (or empty). Triangles that share such a node meet there by
// construction and are not counted; each triangle gets its own copy of those nodes so that CGAL
// can build a manifold mesh. nullopt when no CGAL mesh can be built (a non-manifold vertex
// elsewhere).
std::optional<std::vector<std::pair<std::size_t, std::size_t>>> intersecting_triangles(
    const MixedMesh& m, const std::vector<SolidTri>& tris, const std::vector<char>& touching) {
  PmpMesh mesh;
  std::vector<std::size_t> face_of;
  if (!build_pmp_mesh(m, tris, mesh, &face_of, touching.empty() ? nullptr : &touching))
    return std::nullopt;
  std::vector<std::pair<PmpMesh::Face_index, PmpMesh::Face_index>> pairs;
  CGAL::Polygon_mesh_processing::self_intersections<CGAL::Parallel_if_available_tag>(
      mesh, std::back_inserter(pairs));
  std::vector<std::pair<std::size_t, std::size_t>> out;
  for (const auto& [fa, fb] : pairs) {
    const std::size_t a = face_of[static_cast<std::size_t>(fa)],
                      b = face_of[static_cast<std::size_t>(fb)];
    bool meet_at_touching = false;
    if (!touching.empty())
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
          meet_at_touching |=
              m.bface(a)[i] == m.bface(b)[j] && touching[static_cast<std::size_t>(m.bface(a)[i])];
    if (!meet_at_touching) out.emplace_back(std::min(a, b), std::max(a, b));
  }
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace

std::array<double, 3> triangle_angles(const Vec3& a, const Vec3& b, const Vec3& c) {
  auto ang = [](const Vec3& at, const Vec3& p, const Vec3& q) {
    const double ux = p[0] - at[0], uy = p[1] - at[1], uz = p[2] - at[2];
    const double vx = q[0] - at[0], vy = q[1] - at[1], vz = q[2] - at[2];
    const double cx = uy * vz - uz * vy, cy = uz * vx - ux * vz, cz = ux * vy - uy * vx;
    // atan2 of |u x v| and u.v: accurate for tiny and near-straight angles alike.
    return std::atan2(std::sqrt(cx * cx + cy * cy + cz * cz), ux * vx + uy * vy + uz * vz) * 180 /
           std::numbers::pi;
  };
  return {ang(a, b, c), ang(b, c, a), ang(c, a, b)};
}

bool is_right_isosceles(const Vec3& a, const Vec3& b, const Vec3& c) {
  auto t = triangle_angles(a, b, c);
  std::sort(t.begin(), t.end());
  return std::abs(t[2] - 90) <= 10 && std::abs(t[1] - 45) <= 10 && std::abs(t[0] - 45) <= 10;
}

std::vector<CadCorner> cad_corners(const CadModel& cad, const MixedMesh& m) {
  std::map<Vec3, int> node_at;
  for (std::size_t n = 0; n < m.nodes.size(); ++n) node_at.emplace(m.nodes[n], static_cast<int>(n));
  // The node of each CAD vertex: the one at its point, or for the second vertex of a micro edge
  // (collapsed onto the first by the mesher) the nearest vertex node within a thousandth of
  // the part's size.
  const int nv = cad.num_vertices();
  std::vector<int> node_of(static_cast<std::size_t>(nv) + 1, -1);
  for (int v = 1; v <= nv; ++v) {
    const auto it = node_at.find(cad.vertex_point(v));
    if (it != node_at.end()) node_of[static_cast<std::size_t>(v)] = it->second;
  }
  const BBox3 box = cad.bbox();
  const double tol =
      1e-3 * std::hypot(box.max[0] - box.min[0], box.max[1] - box.min[1], box.max[2] - box.min[2]);
  for (int v = 1; v <= nv; ++v) {
    if (node_of[static_cast<std::size_t>(v)] >= 0) continue;
    const Vec3 x = cad.vertex_point(v);
    double best = tol;
    for (int w = 1; w <= nv; ++w) {
      const int n = node_of[static_cast<std::size_t>(w)];
      if (w == v || n < 0) continue;
      const Vec3& y = m.nodes[static_cast<std::size_t>(n)];
      const double d = std::hypot(x[0] - y[0], x[1] - y[1], x[2] - y[2]);
      if (d < best) best = d, node_of[static_cast<std::size_t>(v)] = n;
    }
  }
  std::vector<CadCorner> out;
  for (int f = 1; f <= cad.num_faces(); ++f) {
    for (const FaceCorner& c : face_corners(cad, f)) {
      const int n = node_of[static_cast<std::size_t>(c.vertex)];
      if (!std::isnan(c.angle) && n >= 0) out.push_back({n, f, c.vertex, c.angle});
    }
  }
  return out;
}

TriangleQuality triangle_quality(const MixedMesh& m, const std::vector<CadCorner>& corners) {
  TriangleQuality q;
  std::size_t ri = 0;
  // (node, face) -> the sharpest corner of the face at that node
  std::map<std::pair<int, int>, double> corner_at;
  for (const CadCorner& c : corners) {
    const auto [it, fresh] = corner_at.emplace(std::pair{c.node, c.face}, c.angle);
    if (!fresh) it->second = std::min(it->second, c.angle);
  }
  for (std::size_t f = 0; f < m.num_bfaces(); ++f) {
    if (m.bface_is_quad(f)) continue;
    const auto* t = m.bface(f);
    const Vec3 &a = m.nodes[static_cast<std::size_t>(t[0])],
               &b = m.nodes[static_cast<std::size_t>(t[1])],
               &c = m.nodes[static_cast<std::size_t>(t[2])];
    const auto ang = triangle_angles(a, b, c);
    const double lo = std::min({ang[0], ang[1], ang[2]}), hi = std::max({ang[0], ang[1], ang[2]});
    q.min_angle = std::min(q.min_angle, lo);
    q.max_angle = std::max(q.max_angle, hi);
    if (lo < 5) {
      ++q.below_5;
      const int k = ang[0] == lo ? 0 : ang[1] == lo ? 1 : 2;
      const auto it = corner_at.find({t[k], m.bface_cad_face[f]});
      if (it != corner_at.end() && it->second < 5) {
        q.forcing_corner_min =
            q.below_5_at_cad_corners ? std::min(q.forcing_corner_min, it->second) : it->second;
        q.forcing_corner_max = std::max(q.forcing_corner_max, it->second);
        ++q.below_5_at_cad_corners;
      }
    }
    if (is_right_isosceles(a, b, c)) ++ri;
    ++q.triangles;
  }
  q.right_isosceles_share =
      q.triangles ? static_cast<double>(ri) / static_cast<double>(q.triangles) : 0;
  return q;
}

std::vector<SolidCheck> check_solids(const SurfaceMesh& s, bool self_intersection) {
  const MixedMesh& m = s.mesh;
  std::vector<SolidCheck> out;
  for (std::size_t solid = 1; solid < s.faces_of_solid.size(); ++solid) {
    SolidCheck c;
    c.solid = static_cast<int>(solid);
    const std::vector<SolidTri> tris = triangles_of_solid(s, solid);
    c.triangles = tris.size();
    // Directed edge counts: a closed, consistently oriented manifold uses each undirected edge
    // once in each direction.
    std::map<std::pair<int, int>, std::array<int, 2>> edges;
    for (const auto& [f, t] : tris) {
      for (int k = 0; k < 3; ++k) {
        const int a = t[k], b = t[(k + 1) % 3];
        auto& e = edges[{std::min(a, b), std::max(a, b)}];
        ++e[a < b ? 0 : 1];
      }
      const Vec3 &p = m.nodes[static_cast<std::size_t>(t[0])],
                 &q = m.nodes[static_cast<std::size_t>(t[1])],
                 &r = m.nodes[static_cast<std::size_t>(t[2])];
      c.volume += (p[0] * (q[1] * r[2] - q[2] * r[1]) - p[1] * (q[0] * r[2] - q[2] * r[0]) +
                   p[2] * (q[0] * r[1] - q[1] * r[0])) /
                  6.0;
    }
    std::vector<char> touching;
    for (const auto& [key, n] : edges) {
      switch (edge_use(n, on_cad_edge(s, key.first, key.second))) {
        case EdgeUse::open:
          ++c.open_edges;
          break;
        case EdgeUse::nonmanifold:
          ++c.nonmanifold_edges;
          break;
        case EdgeUse::misoriented:
          ++c.misoriented_edges;
          break;
        case EdgeUse::touching:
          ++c.touching_edges;
          mark_touching(touching, m.nodes.size(), key);
          break;
        case EdgeUse::ok:
          break;
      }
    }
    if (self_intersection && c.open_edges == 0 && c.nonmanifold_edges == 0 &&
        c.misoriented_edges == 0) {
      // A vertex where two sheets touch (non-manifold vertex) cannot be built; CGAL would
      // not test such a mesh, so it counts as failing.
      c.self_intersection_tested = true;
      if (touching.empty()) {
        PmpMesh mesh;
        const bool built = build_pmp_mesh(m, tris, mesh, nullptr);
        c.self_intersects =
            !built ||
            CGAL::Polygon_mesh_processing::does_self_intersect<CGAL::Parallel_if_available_tag>(
                mesh);
      } else {
        const auto pairs = intersecting_triangles(m, tris, touching);
        c.self_intersects = !pairs || !pairs->empty();
      }
    }
    out.push_back(c);
  }
  return out;
}

std::vector<std::string> surface_defects(const SurfaceMesh& s, std::size_t max_lines) {
  const MixedMesh& m = s.mesh;
  std::vector<std::string> out;
  char line[300];
  auto faces_of = [&](const std::vector<std::size_t>& fs) {
    std::string list;
    for (std::size_t f : fs) {
      if (!list.empty()) list += ',';
      list += std::to_string(m.bface_cad_face[f]);
    }
    return list;
  };
  auto xyz = [&](int n) { return m.nodes[static_cast<std::size_t>(n)]; };
  for (std::size_t solid = 1; solid < s.faces_of_solid.size(); ++solid) {
    const std::vector<SolidTri> tris = triangles_of_solid(s, solid);
    std::map<std::pair<int, int>, std::vector<std::size_t>> edges;
    std::map<std::pair<int, int>, std::array<int, 2>> dir;
    for (const auto& [f, t] : tris) {
      for (int k = 0; k < 3; ++k) {
        const int a = t[k], b = t[(k + 1) % 3];
        edges[{std::min(a, b), std::max(a, b)}].push_back(f);
        ++dir[{std::min(a, b), std::max(a, b)}][a < b ? 0 : 1];
      }
    }
    std::size_t n_bad = 0;
    std::vector<char> touching;
    for (const auto& [key, fs] : edges) {
      const EdgeUse use = edge_use(dir[key], on_cad_edge(s, key.first, key.second));
      if (use == EdgeUse::touching) mark_touching(touching, m.nodes.size(), key);
      const char* what = use == EdgeUse::open          ? "open"
                         : use == EdgeUse::nonmanifold ? "non-manifold"
                         : use == EdgeUse::misoriented ? "misoriented"
                                                       : nullptr;
      if (!what || n_bad++ >= max_lines) continue;
      const Vec3 p = xyz(key.first), q = xyz(key.second);
      std::snprintf(line, sizeof line,
                    "solid %zu: %s edge (%.6g, %.6g, %.6g)-(%.6g, %.6g, %.6g), CAD faces %s", solid,
                    what, p[0], p[1], p[2], q[0], q[1], q[2], faces_of(fs).c_str());
      out.emplace_back(line);
    }
    if (n_bad != 0) continue;  // CGAL needs a manifold to look for intersections
    const auto found = intersecting_triangles(m, tris, touching);
    if (!found) {
      out.push_back("solid " + std::to_string(solid) + ": a non-manifold vertex");
      continue;
    }
    const auto& pairs = *found;
    for (std::size_t i = 0; i < pairs.size() && i < max_lines; ++i) {
      const auto [a, b] = pairs[i];
      const Vec3 p = xyz(m.bface(a)[0]);
      std::snprintf(line, sizeof line,
                    "solid %zu: triangles of CAD faces %d and %d intersect near (%.6g, %.6g, %.6g)",
                    solid, m.bface_cad_face[a], m.bface_cad_face[b], p[0], p[1], p[2]);
      out.emplace_back(line);
    }
    if (pairs.size() > max_lines)
      out.push_back("solid " + std::to_string(solid) + ": " + std::to_string(pairs.size()) +
                    " intersecting triangle pairs in all");
  }
  std::size_t n_small = 0;
  for (std::size_t f = 0; f < m.num_bfaces(); ++f) {
    if (m.bface_is_quad(f)) continue;
    const auto* t = m.bface(f);
    const auto ang = triangle_angles(xyz(t[0]), xyz(t[1]), xyz(t[2]));
    const double lo = std::min({ang[0], ang[1], ang[2]});
    if (lo >= 5 || n_small++ >= max_lines) continue;
    const Vec3 p = xyz(t[0]);
    int on_edges = 0;
    double len[3];
    for (int k = 0; k < 3; ++k) {
      on_edges += s.on_edge.size() == m.nodes.size() && s.on_edge[static_cast<std::size_t>(t[k])];
      const Vec3 a = xyz(t[k]), b = xyz(t[(k + 1) % 3]);
      len[k] = std::hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]);
    }
    std::snprintf(line, sizeof line,
                  "CAD face %d: triangle with a %.3g deg angle at (%.6g, %.6g, %.6g), sides %.3g "
                  "%.3g %.3g, %d of 3 corners on CAD edges",
                  m.bface_cad_face[f], lo, p[0], p[1], p[2], len[0], len[1], len[2], on_edges);
    out.emplace_back(line);
  }
  return out;
}

}  // namespace hexfem
