#include "mesher/surface_triangulation.hpp"

#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_face_base_with_info_2.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <set>
#include <string>
#include <vector>

#include "mesher/cdt_domain.hpp"
#include "mesher/mesh/error.hpp"
#include "mesher/vec3.hpp"

namespace hexfem {

namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
struct VInfo {
  int id = -1;  // local id (see FaceTriangles)
};
using Vb = CGAL::Triangulation_vertex_base_with_info_2<VInfo, K>;
using Fb =
    CGAL::Triangulation_face_base_with_info_2<int, K,
                                              CGAL::Constrained_triangulation_face_base_2<K>>;
using Tds = CGAL::Triangulation_data_structure_2<Vb, Fb>;
using CDT =
    CGAL::Constrained_Delaunay_triangulation_2<K, Tds, CGAL::No_constraint_intersection_tag>;

double angle(const Vec3& at, const Vec3& a, const Vec3& b) {
  const Vec3 u{a[0] - at[0], a[1] - at[1], a[2] - at[2]},
      v{b[0] - at[0], b[1] - at[1], b[2] - at[2]};
  const double nu = std::sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
  const double nv = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  if (!(nu > 0) || !(nv > 0)) return std::numbers::pi;
  return std::acos(std::clamp((u[0] * v[0] + u[1] * v[1] + u[2] * v[2]) / (nu * nv), -1.0, 1.0));
}

// The face's points by local id (boundary points first, then the packing's): their 3D position
// and the global node they stand for.
struct FacePointSet {
  const FaceBoundary& b;
  const FacePoints& in;
  const EdgePoints& points;
  int nb;
  const Vec3& xyz(int id) const {
    return id < nb ? points.xyz[static_cast<std::size_t>(b.node[static_cast<std::size_t>(id)])]
                   : in.xyz[static_cast<std::size_t>(id - nb)];
  }
  int node_key(int id) const { return id < nb ? b.node[static_cast<std::size_t>(id)] : -1 - id; }
};

bool in_domain(const CDT& cdt, CDT::Face_handle fh) {
  return !cdt.is_infinite(fh) && fh->info() % 2 == 1;
}

double min_angle(const FacePointSet& P, CDT::Face_handle fh) {
  double m = std::numbers::pi;
  for (int i = 0; i < 3; ++i)
    m = std::min(m,
                 angle(P.xyz(fh->vertex(i)->info().id), P.xyz(fh->vertex(CDT::ccw(i))->info().id),
                       P.xyz(fh->vertex(CDT::cw(i))->info().id)));
  return m;
}

// The constrained Delaunay triangulation of the boundary and the interior points in the scaled
// parameter plane; throws when the boundary does not survive it.
void insert_points(CDT& cdt, int f, const FacePointSet& P, Vec2 scale) {
  const FaceBoundary& b = P.b;
  const FacePoints& in = P.in;
  const int nb = P.nb;
  std::vector<CDT::Vertex_handle> handles(static_cast<std::size_t>(nb));
  for (int i = 0; i < nb; ++i) {
    const auto& p = b.uv[static_cast<std::size_t>(i)];
    auto v = cdt.insert(CDT::Point(p[0] * scale[0], p[1] * scale[1]));
    if (v->info().id >= 0 && P.node_key(v->info().id) != P.node_key(i))
      throw Error("face " + std::to_string(f) +
                  ": two boundary points coincide in the parameter plane");
    if (v->info().id < 0) v->info().id = i;
    handles[static_cast<std::size_t>(i)] = v;
  }
  try {
    for (const auto& s : b.segments) {
      auto va = handles[static_cast<std::size_t>(s[0])],
           vb = handles[static_cast<std::size_t>(s[1])];
      if (va != vb) cdt.insert_constraint(va, vb);
    }
  } catch (const std::exception&) {
    throw Error("face " + std::to_string(f) +
                ": its boundary segments cross in the parameter plane");
  }
  // Interior points; one falling on a vertex or a boundary segment would change the boundary
  // shared with the neighbouring face, so it is left out.
  CDT::Face_handle hint;
  for (std::size_t j = 0; j < in.uv.size(); ++j) {
    const CDT::Point p(in.uv[j][0] * scale[0], in.uv[j][1] * scale[1]);
    CDT::Locate_type lt;
    int li = 0;
    CDT::Face_handle fh = cdt.locate(p, lt, li, hint);
    if (lt == CDT::VERTEX || (lt == CDT::EDGE && cdt.is_constrained(CDT::Edge(fh, li)))) continue;
    auto v = cdt.insert(p, lt, fh, li);
    v->info().id = nb + static_cast<int>(j);
    hint = v->face();
  }
  for (const auto& s : b.segments) {
    auto va = handles[static_cast<std::size_t>(s[0])], vb = handles[static_cast<std::size_t>(s[1])];
    if (va != vb && !cdt.is_edge(va, vb))
      throw Error("face " + std::to_string(f) +
                  ": a boundary segment was lost in the triangulation");
  }
}

// Flips toward the Delaunay criterion on the 3D triangles, kept only where the flipped pair stays
// valid in the parameter plane. Returns how many.
std::size_t flip_toward_delaunay_3d(CDT& cdt, const FacePointSet& P) {
  std::size_t total = 0;
  const std::size_t max_flips = 20 * static_cast<std::size_t>(cdt.number_of_faces()) + 100;
  for (int pass = 0; pass < 50; ++pass) {
    std::size_t flips = 0;
    for (auto fh = cdt.finite_faces_begin(); fh != cdt.finite_faces_end(); ++fh) {
      if (!in_domain(cdt, fh)) continue;
      for (int i = 0; i < 3; ++i) {
        CDT::Face_handle g = fh->neighbor(i);
        if (cdt.is_constrained(CDT::Edge(fh, i)) || !in_domain(cdt, g)) continue;
        const auto vp = fh->vertex(i), ve1 = fh->vertex(CDT::ccw(i)), ve2 = fh->vertex(CDT::cw(i));
        const auto vq = g->vertex(g->index(fh));
        const Vec3 &p = P.xyz(vp->info().id), &q = P.xyz(vq->info().id);
        const Vec3 &e1 = P.xyz(ve1->info().id), &e2 = P.xyz(ve2->info().id);
        if (angle(p, e1, e2) + angle(q, e1, e2) <= std::numbers::pi + 1e-6) continue;
        // Valid in the plane: e1 and e2 strictly on opposite sides of the new edge p-q.
        if (CGAL::orientation(vp->point(), vq->point(), ve1->point()) != CGAL::RIGHT_TURN ||
            CGAL::orientation(vp->point(), vq->point(), ve2->point()) != CGAL::LEFT_TURN)
          continue;
        CDT::Face_handle h = fh;
        cdt.flip(h, i);
        ++flips;
        break;  // fh changed; move on
      }
    }
    total += flips;
    if (flips == 0 || total > max_flips) break;
  }

  return total;
}

// Unique, in the order of the points' ids: an order by handle (an address) would change from
// run to run wherever the removals interact.
void sort_by_id(std::vector<CDT::Vertex_handle>& v) {
  std::sort(v.begin(), v.end(), [](const CDT::Vertex_handle& a, const CDT::Vertex_handle& b) {
    return a->info().id < b->info().id;
  });
  v.erase(std::unique(v.begin(), v.end()), v.end());
}

// Whether every triangle around v turns counter-clockwise in the parameter plane. CGAL's
// remove() fills the hole left by v assuming so; around a folded triangle (a wild surface: the
// fuzz's sphere with one B-spline weight at 92) it looped for ever.
bool star_unfolded(const CDT& cdt, CDT::Vertex_handle v) {
  auto fc = cdt.incident_faces(v), end = fc;
  do {
    if (cdt.is_infinite(fc) || cdt.orientation(fc->vertex(0)->point(), fc->vertex(1)->point(),
                                               fc->vertex(2)->point()) != CGAL::LEFT_TURN)
      return false;
  } while (++fc != end);
  return true;
}

bool all_unfolded(const CDT& cdt) {
  for (auto fh = cdt.finite_faces_begin(); fh != cdt.finite_faces_end(); ++fh)
    if (cdt.orientation(fh->vertex(0)->point(), fh->vertex(1)->point(), fh->vertex(2)->point()) !=
        CGAL::LEFT_TURN)
      return false;
  return true;
}

// Whether CGAL's remove() can fill the hole v leaves. Its fill_hole_delaunay (Triangulation_2.h)
// cuts the hole, the ring around v, at the Delaunay vertex left of its first edge, again and
// again; where a part of the ring has no vertex strictly left of that edge (ring points exactly
// in line, as a wild face's packing can give) it loops for ever. The same choices are made here
// on the ring's points, and a removal that would not end is not made.
bool removal_fills_its_hole(const CDT& cdt, CDT::Vertex_handle v) {
  std::vector<CDT::Point> ring;
  auto fc = cdt.incident_faces(v), end = fc;
  do {
    if (cdt.is_infinite(fc)) return false;
    ring.push_back(fc->vertex(CDT::ccw(fc->index(v)))->point());
  } while (++fc != end);
  std::vector<std::vector<int>> holes(1);
  for (int i = 0; i < static_cast<int>(ring.size()); ++i) holes[0].push_back(i);
  while (!holes.empty()) {
    const std::vector<int> h = std::move(holes.back());
    holes.pop_back();
    const CDT::Point &p0 = ring[h[0]], &p1 = ring[h[1]];
    if (h.size() == 3) {
      if (cdt.orientation(p0, p1, ring[h[2]]) != CGAL::LEFT_TURN) return false;
      continue;
    }
    std::size_t cut = 0;  // the vertex h[cut] the first edge's triangle takes
    for (std::size_t k = 2; k < h.size(); ++k) {
      const CDT::Point& p = ring[h[k]];
      if (cdt.orientation(p0, p1, p) != CGAL::LEFT_TURN) continue;
      if (cut == 0 ||
          cdt.side_of_oriented_circle(p0, p1, ring[h[cut]], p, true) == CGAL::ON_POSITIVE_SIDE)
        cut = k;
    }
    if (cut == 0) return false;
    if (cut >= 3) holes.emplace_back(h.begin() + 1, h.begin() + cut + 1);
    std::vector<int> rest(h.begin() + cut, h.end());
    rest.push_back(h[0]);
    if (rest.size() >= 3) holes.push_back(std::move(rest));
  }
  return true;
}

void remove_flat_points(CDT& cdt, const FacePointSet& P) {
  const int nb = P.nb;
  // An interior point lying almost on the line between two of its neighbours (where the
  // packing grades steeply from a fine boundary) makes a flat triangle, with an angle near
  // 180 degrees at the point and a needle's angles at the others. The point is taken out when
  // the triangles that fill its star are better (smallest 3D angle) than the ones it had.
  constexpr double kFlat = 150 * std::numbers::pi / 180, kNeedle = 5 * std::numbers::pi / 180;
  std::vector<CDT::Vertex_handle> flat;
  for (auto fh = cdt.finite_faces_begin(); fh != cdt.finite_faces_end(); ++fh) {
    if (!in_domain(cdt, fh) || min_angle(P, fh) >= kNeedle) continue;
    for (int i = 0; i < 3; ++i) {
      const auto v = fh->vertex(i);
      if (v->info().id >= nb &&
          angle(P.xyz(v->info().id), P.xyz(fh->vertex(CDT::ccw(i))->info().id),
                P.xyz(fh->vertex(CDT::cw(i))->info().id)) > kFlat)
        flat.push_back(v);
    }
  }
  sort_by_id(flat);
  for (const auto& v : flat) {
    // The star of an interior point lies inside the face, on one nesting level.
    double before = std::numbers::pi;
    int level = -1;
    bool inside = true;
    std::vector<CDT::Vertex_handle> ring;
    std::set<CDT::Face_handle> kept;
    auto fc = cdt.incident_faces(v), fc_end = fc;
    do {
      inside = inside && in_domain(cdt, fc) && (level < 0 || fc->info() == level);
      if (!inside) break;
      level = fc->info();
      before = std::min(before, min_angle(P, fc));
      ring.push_back(fc->vertex(CDT::ccw(fc->index(v))));
    } while (++fc != fc_end);
    if (!inside || !star_unfolded(cdt, v) || !removal_fills_its_hole(cdt, v)) continue;
    for (const auto& w : ring) {
      auto g = cdt.incident_faces(w), g_end = g;
      do
        if (!g->has_vertex(v)) kept.insert(g);
      while (++g != g_end);
    }
    const CDT::Point at = v->point();
    const int id = v->info().id;
    cdt.remove(v);
    double after = std::numbers::pi;
    std::vector<CDT::Face_handle> fresh;
    for (const auto& w : ring) {
      auto g = cdt.incident_faces(w), g_end = g;
      do
        if (!cdt.is_infinite(g) && !kept.count(g) &&
            std::find(fresh.begin(), fresh.end(), g) == fresh.end()) {
          g->info() = level;
          fresh.push_back(g);
          after = std::min(after, min_angle(P, g));
        }
      while (++g != g_end);
    }
    if (after > before) continue;
    const auto back = cdt.insert(at);  // no better: as it was (Delaunay in the plane)
    back->info().id = id;
    auto g = cdt.incident_faces(back), g_end = g;
    do g->info() = level;
    while (++g != g_end);
  }
}

// Interior points of triangles whose normal points against the surface's (du x dv at the
// triangle's parametric centroid; the triangles are counter-clockwise in the parameter plane)
// are removed, a few rounds, and the domain marked again. Such a fold comes from a trimmed
// domain that reaches past the neighbouring face in space (freecad_hole_puzzle_counterbore at
// h = 0.216: a ball's pole 0.005 mm from the edge it shares with its rod, packed points 0.007 mm
// beyond that edge, triangles crossing the rod's).
void remove_folded_points(CDT& cdt, const FacePointSet& P, const CadModel& cad, int f, Vec2 scale) {
  for (int round = 0; round < 3; ++round) {
    std::vector<CDT::Vertex_handle> folded;
    for (auto fh = cdt.finite_faces_begin(); fh != cdt.finite_faces_end(); ++fh) {
      if (!in_domain(cdt, fh)) continue;
      const Vec3& a = P.xyz(fh->vertex(0)->info().id);
      const Vec3 n = v3::cross(v3::sub(P.xyz(fh->vertex(1)->info().id), a),
                               v3::sub(P.xyz(fh->vertex(2)->info().id), a));
      Vec2 uv{0, 0};
      for (int i = 0; i < 3; ++i) {
        uv[0] += fh->vertex(i)->point().x() / (3 * scale[0]);
        uv[1] += fh->vertex(i)->point().y() / (3 * scale[1]);
      }
      const SurfaceDerivs d = cad.eval(f, uv);
      if (!(v3::dot(n, v3::cross(d.du, d.dv)) < 0)) continue;
      for (int i = 0; i < 3; ++i)
        if (fh->vertex(i)->info().id >= P.nb) folded.push_back(fh->vertex(i));
    }
    if (folded.empty()) return;
    sort_by_id(folded);
    for (const auto& v : folded)
      if (star_unfolded(cdt, v) && removal_fills_its_hole(cdt, v)) cdt.remove(v);
    mark_nesting_levels(cdt);
  }
}

}  // namespace

FaceTriangles triangulate_face(int f, const FaceBoundary& b, const FacePoints& in,
                               const EdgePoints& points, Vec2 scale, const CadModel* cad) {
  const FacePointSet P{b, in, points, static_cast<int>(b.uv.size())};
  const int nb = P.nb;
  CDT cdt;
  insert_points(cdt, f, P, scale);
  FaceTriangles out;
  if (cdt.dimension() < 2) {
    out.interior_used.assign(in.uv.size(), false);
    return out;
  }
  mark_nesting_levels(cdt);
  out.flips = flip_toward_delaunay_3d(cdt, P);
  // CGAL's removal assumes a valid triangulation of the plane; where the flips above left a
  // triangle flat or folded there (none seen so far: a guard), the face keeps its points.
  if (all_unfolded(cdt)) {
    remove_flat_points(cdt, P);
    if (cad) remove_folded_points(cdt, P, *cad, f, scale);
  }
  out.interior_used.assign(in.uv.size(), false);
  for (auto fh = cdt.finite_faces_begin(); fh != cdt.finite_faces_end(); ++fh) {
    if (!in_domain(cdt, fh)) continue;
    std::array<int, 3> t{fh->vertex(0)->info().id, fh->vertex(1)->info().id,
                         fh->vertex(2)->info().id};
    const int k0 = P.node_key(t[0]), k1 = P.node_key(t[1]), k2 = P.node_key(t[2]);
    if (k0 == k1 || k1 == k2 || k0 == k2) continue;  // collapsed on a pole or apex
    for (int id : t)
      if (id >= nb) out.interior_used[static_cast<std::size_t>(id - nb)] = true;
    out.triangles.push_back(t);
  }
  return out;
}

}  // namespace hexfem
