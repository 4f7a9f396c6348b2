#include "mesher/solid_locator.hpp"

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/box_intersection_d.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <set>

#include "mesher/mesh/error.hpp"

namespace hexfem {

namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = K::Point_3;
using Triangle = K::Triangle_3;
using TriIt = std::vector<Triangle>::const_iterator;
using Primitive = CGAL::AABB_triangle_primitive<K, TriIt>;
using Tree = CGAL::AABB_tree<CGAL::AABB_traits<K, Primitive>>;

Point P(const Vec3& v) {
  return Point(v[0], v[1], v[2]);
}

// Directions for parity rays, tried in order until one misses every edge and vertex.
constexpr double kRayDirs[][3] = {{0.5773, 0.6318, 0.5175},   {-0.3461, 0.8254, -0.4461},
                                  {0.7071, -0.1737, -0.6854}, {-0.2931, -0.5119, 0.8074},
                                  {0.9113, 0.2917, -0.2906},  {-0.6242, -0.7013, -0.3443}};

// Counts the triangles a ray crosses; flags a crossing through an edge, a vertex or in the
// triangle's plane (the parity would be wrong) so that the caller tries another ray.
struct ParityTraits {
  Point origin, ahead;
  int count = 0;
  bool degenerate = false;
  bool go_further() const { return !degenerate; }
  void intersection(const K::Ray_3& ray, const Primitive& prim) {
    const Triangle& t = *prim.id();
    if (!CGAL::do_intersect(ray, t)) return;
    for (int i = 0; i < 3; ++i) {
      if (CGAL::orientation(origin, ahead, t[i], t[(i + 1) % 3]) == CGAL::COPLANAR) {
        degenerate = true;
        return;
      }
    }
    if (CGAL::orientation(t[0], t[1], t[2], origin) == CGAL::COPLANAR) {
      degenerate = true;
      return;
    }
    ++count;
  }
  template <class Node>
  bool do_intersect(const K::Ray_3& ray, const Node& node) const {
    return CGAL::do_intersect(ray, node.bbox());
  }
};

// Stops at the first triangle closer than sqrt(r2).
struct NearTraits {
  double r2;
  bool found = false;
  bool go_further() const { return !found; }
  void intersection(const Point& p, const Primitive& prim) {
    if (CGAL::squared_distance(p, *prim.id()) < r2) found = true;
  }
  template <class Node>
  bool do_intersect(const Point& p, const Node& node) const {
    const CGAL::Bbox_3& b = node.bbox();
    double d2 = 0;
    for (int i = 0; i < 3; ++i) {
      const double lo = b.min(i) - p[i], hi = p[i] - b.max(i);
      const double d = std::max({lo, hi, 0.0});
      d2 += d * d;
    }
    return d2 < r2;
  }
};

}  // namespace

struct SolidLocator::Trees {
  std::vector<std::vector<Triangle>> tris;  // per solid
  std::vector<std::unique_ptr<Tree>> tree;
};

std::string describe_surface_triangle(const SurfaceMesh& surface, std::size_t t) {
  return "triangle " + std::to_string(t) + " (CAD face " +
         std::to_string(surface.mesh.bface_cad_face[t]) + ")";
}

SolidLocator::SolidLocator(const SurfaceMesh& surface)
    : surface_(surface), trees_(std::make_unique<Trees>()) {
  const MixedMesh& m = surface.mesh;
  const std::size_t nt = m.num_bfaces(), nn = m.nodes.size();
  if (nt == 0) throw Error("surface mesh has no triangles");
  if (m.bface_nodes.size() != 4 * nt) throw Error("surface mesh: bface arrays do not match");
  for (std::size_t t = 0; t < nt; ++t) {
    const std::int32_t* f = m.bface(t);
    if (f[3] >= 0) throw Error("surface mesh: boundary face " + std::to_string(t) + " is a quad");
    for (int i = 0; i < 3; ++i)
      if (f[i] < 0 || static_cast<std::size_t>(f[i]) >= nn)
        throw Error("surface mesh: " + describe_surface_triangle(surface, t) +
                    " has a node index out of range");
    if (f[0] == f[1] || f[1] == f[2] || f[0] == f[2] ||
        CGAL::collinear(P(m.nodes[f[0]]), P(m.nodes[f[1]]), P(m.nodes[f[2]])))
      throw Error("surface mesh: " + describe_surface_triangle(surface, t) + " is degenerate");
  }
  // Solids and their triangles.
  std::map<int, std::vector<int>> solids_of_cad_face;
  int ns = static_cast<int>(surface.faces_of_solid.size()) - 1;
  if (ns < 1) {
    ns = 1;
    for (std::size_t t = 0; t < nt; ++t) solids_of_cad_face[m.bface_cad_face[t]] = {1};
  } else {
    for (int s = 1; s <= ns; ++s)
      for (int f : surface.faces_of_solid[s]) solids_of_cad_face[f].push_back(s);
  }
  solid_triangles_.assign(ns + 1, {});
  solids_of_tri_.assign(nt, {});
  solids_of_node_.assign(nn, {});
  for (std::size_t t = 0; t < nt; ++t) {
    auto it = solids_of_cad_face.find(m.bface_cad_face[t]);
    if (it == solids_of_cad_face.end())
      throw Error("surface mesh: " + describe_surface_triangle(surface, t) +
                  " lies on a CAD face that bounds no solid");
    solids_of_tri_[t] = it->second;
    for (int s : it->second) {
      solid_triangles_[s].push_back(static_cast<std::int32_t>(t));
      for (int i = 0; i < 3; ++i) {
        auto& v = solids_of_node_[m.bface(t)[i]];
        if (std::find(v.begin(), v.end(), s) == v.end()) v.push_back(s);
      }
    }
  }
  for (auto& v : solids_of_node_) std::sort(v.begin(), v.end());
  trees_->tris.resize(ns + 1);
  trees_->tree.resize(ns + 1);
  for (int s = 1; s <= ns; ++s) {
    if (solid_triangles_[s].empty())
      throw Error("surface mesh: solid " + std::to_string(s) + " has no triangles");
    // Closed boundary: every edge of the solid's triangles is used an even number of times.
    std::vector<std::array<std::int32_t, 3>> edges;  // (lo, hi, triangle)
    for (std::int32_t t : solid_triangles_[s]) {
      const std::int32_t* f = m.bface(t);
      for (int i = 0; i < 3; ++i)
        edges.push_back({std::min(f[i], f[(i + 1) % 3]), std::max(f[i], f[(i + 1) % 3]), t});
    }
    std::sort(edges.begin(), edges.end());
    for (std::size_t i = 0; i < edges.size();) {
      std::size_t j = i;
      while (j < edges.size() && edges[j][0] == edges[i][0] && edges[j][1] == edges[i][1]) ++j;
      if ((j - i) % 2)
        throw Error("surface mesh: the boundary of solid " + std::to_string(s) +
                    " is not closed: edge (" + std::to_string(edges[i][0]) + ", " +
                    std::to_string(edges[i][1]) + ") of " +
                    describe_surface_triangle(surface, edges[i][2]) + " is used " +
                    std::to_string(j - i) + " time(s)");
      i = j;
    }
    auto& tris = trees_->tris[s];
    for (std::int32_t t : solid_triangles_[s]) {
      const std::int32_t* f = m.bface(t);
      tris.emplace_back(P(m.nodes[f[0]]), P(m.nodes[f[1]]), P(m.nodes[f[2]]));
    }
    trees_->tree[s] = std::make_unique<Tree>(tris.begin(), tris.end());
    trees_->tree[s]->build();
  }
}

SolidLocator::~SolidLocator() = default;

bool SolidLocator::inside(int s, const Vec3& p) const {
  const Point o = P(p);
  for (const auto& d : kRayDirs) {
    ParityTraits traits;
    traits.origin = o;
    traits.ahead = Point(p[0] + d[0], p[1] + d[1], p[2] + d[2]);
    const K::Ray_3 ray(o, traits.ahead);
    trees_->tree[s]->traversal(ray, traits);
    if (!traits.degenerate) return traits.count % 2 == 1;
  }
  throw Error("point location failed: every test ray from (" + std::to_string(p[0]) + ", " +
              std::to_string(p[1]) + ", " + std::to_string(p[2]) +
              ") grazes a surface edge or vertex");
}

bool SolidLocator::near_boundary(int s, const Vec3& p, double r) const {
  NearTraits traits{r * r};
  trees_->tree[s]->traversal(P(p), traits);
  return traits.found;
}

bool SolidLocator::segment_hits_boundary(int s, const Vec3& a, const Vec3& b) const {
  return trees_->tree[s]->do_intersect(K::Segment_3(P(a), P(b)));
}

int SolidLocator::locate(const Vec3& p) const {
  for (int s = 1; s <= num_solids(); ++s) {
    const CGAL::Bbox_3 b = trees_->tree[s]->bbox();
    if (p[0] < b.xmin() || p[0] > b.xmax() || p[1] < b.ymin() || p[1] > b.ymax() ||
        p[2] < b.zmin() || p[2] > b.zmax())
      continue;
    if (inside(s, p)) return s;
  }
  return 0;
}

double SolidLocator::distance(int s, const Vec3& p, std::int32_t* triangle) const {
  const auto& tris = trees_->tris[s];
  const auto hit = trees_->tree[s]->closest_point_and_primitive(P(p));
  if (triangle) *triangle = solid_triangles_[s][hit.second - tris.begin()];
  return std::sqrt(CGAL::squared_distance(P(p), hit.first));
}

double SolidLocator::ray_distance(int s, const Vec3& origin, const Vec3& dir,
                                  std::int32_t skip_node, std::int32_t* triangle) const {
  const auto& tris = trees_->tris[s];
  const MixedMesh& m = surface_.mesh;
  const auto skip = [&](TriIt it) {
    if (skip_node < 0) return false;
    const std::int32_t* f = m.bface(solid_triangles_[s][it - tris.begin()]);
    return f[0] == skip_node || f[1] == skip_node || f[2] == skip_node;
  };
  const Point o = P(origin);
  const K::Ray_3 ray(o, Point(origin[0] + dir[0], origin[1] + dir[1], origin[2] + dir[2]));
  const auto hit = trees_->tree[s]->first_intersection(ray, skip);
  if (triangle) *triangle = hit ? solid_triangles_[s][hit->second - tris.begin()] : -1;
  if (!hit) return std::numeric_limits<double>::infinity();
  double best = std::numeric_limits<double>::infinity();
  if (const Point* q = boost::get<Point>(&hit->first)) {
    best = std::sqrt(CGAL::squared_distance(o, *q));
  } else if (const K::Segment_3* sg = boost::get<K::Segment_3>(&hit->first)) {
    // The ray runs in the triangle's plane: its nearer end.
    best = std::sqrt(
        std::min(CGAL::squared_distance(o, sg->source()), CGAL::squared_distance(o, sg->target())));
  }
  return best;
}

std::vector<std::array<std::int32_t, 2>> SolidLocator::intersecting_triangles(
    std::size_t max_pairs) const {
  const MixedMesh& m = surface_.mesh;
  const std::size_t nt = m.num_bfaces();
  using Box = CGAL::Box_intersection_d::Box_with_info_d<double, 3, std::size_t>;
  std::vector<Box> boxes;
  boxes.reserve(nt);
  std::vector<Triangle> tri(nt);
  for (std::size_t t = 0; t < nt; ++t) {
    const std::int32_t* f = m.bface(t);
    tri[t] = Triangle(P(m.nodes[f[0]]), P(m.nodes[f[1]]), P(m.nodes[f[2]]));
    boxes.emplace_back(tri[t].bbox(), t);
  }
  std::set<std::array<std::int32_t, 2>> found;
  auto callback = [&](const Box& ba, const Box& bb) {
    const std::size_t a = ba.info(), b = bb.info();
    const std::int32_t *fa = m.bface(a), *fb = m.bface(b);
    int shared = 0, sa = -1, sb = -1;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        if (fa[i] == fb[j]) {
          ++shared;
          sa = i;
          sb = j;
        }
    bool hit = false;
    if (shared == 0) {
      hit = CGAL::do_intersect(tri[a], tri[b]);
    } else if (shared == 1) {
      // Sharing one vertex: they intersect elsewhere iff the opposite edge of one meets the other.
      const K::Segment_3 ea(tri[a][(sa + 1) % 3], tri[a][(sa + 2) % 3]);
      const K::Segment_3 eb(tri[b][(sb + 1) % 3], tri[b][(sb + 2) % 3]);
      hit = CGAL::do_intersect(ea, tri[b]) || CGAL::do_intersect(eb, tri[a]);
    } else if (shared == 2) {
      // Sharing an edge: they overlap iff coplanar with both apexes on the same side.
      int apex_a = 0, apex_b = 0;
      for (int i = 0; i < 3; ++i) {
        if (fa[i] != fb[0] && fa[i] != fb[1] && fa[i] != fb[2]) apex_a = i;
        if (fb[i] != fa[0] && fb[i] != fa[1] && fb[i] != fa[2]) apex_b = i;
      }
      const Point& pa = tri[a][apex_a];
      const Point& pb = tri[b][apex_b];
      const Point& e0 = tri[a][(apex_a + 1) % 3];
      const Point& e1 = tri[a][(apex_a + 2) % 3];
      hit = CGAL::coplanar(e0, e1, pa, pb) &&
            CGAL::coplanar_orientation(e0, e1, pa, pb) == CGAL::POSITIVE;
    } else {
      hit = true;  // duplicate triangle
    }
    if (hit)
      found.insert(
          {static_cast<std::int32_t>(std::min(a, b)), static_cast<std::int32_t>(std::max(a, b))});
  };
  CGAL::box_self_intersection_d(boxes.begin(), boxes.end(), callback);
  std::vector<std::array<std::int32_t, 2>> pairs(found.begin(), found.end());
  if (pairs.size() > max_pairs) pairs.resize(max_pairs);
  return pairs;
}

}  // namespace hexfem
