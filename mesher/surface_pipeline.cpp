#include "mesher/surface_pipeline.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <map>
#include <optional>
#include <set>
#include <unordered_map>

#include "mesher/cross_field.hpp"
#include "mesher/edge_points.hpp"
#include "mesher/mesh/error.hpp"
#include "mesher/mesh/progress.hpp"
#include "mesher/size_field.hpp"
#include "mesher/stage_timer.hpp"
#include "mesher/surface_points.hpp"
#include "mesher/surface_triangulation.hpp"
#include "mesher/vec3.hpp"

namespace hexfem {

namespace {

using v3::cross;

// Runs body(i) for i in [0, n) on all threads; the first exception is rethrown afterwards.
template <class Body>
void parallel_for(int n, Body body) {
  // The error of the lowest failing index is the one reported, whatever the threads' timing:
  // same input, same message.
  std::exception_ptr error;
  int error_index = n;
#pragma omp parallel for schedule(dynamic, 1)
  for (int i = 0; i < n; ++i) {
    try {
      body(i);
    } catch (...) {
#pragma omp critical(hexfem_surface_error)
      if (i < error_index) {
        error = std::current_exception();
        error_index = i;
      }
    }
  }
  if (error) std::rethrow_exception(error);
}

SizeOptions size_options(const SurfaceOptions& o) {
  SizeOptions s;
  s.h = o.h;
  s.curvature = o.curvature;
  s.curvature_min_ratio = o.curvature_min_ratio;
  s.vertex_sizes = o.vertex_sizes;
  s.face_sizes = o.face_sizes;
  s.edge_sizes = o.edge_sizes;
  return s;
}

double face_estimate(const CadModel& cad, const SizeField& size, int f) {
  const auto b = cad.uv_bounds(f);
  const double h =
      std::min(size.global(), size.surface_bound(f, {0.5 * (b[0] + b[1]), 0.5 * (b[2] + b[3])}));
  return cad.face_area(f) / (h * h);
}

// Diagonals to split: triangle edges with an edge node at one end at least, not boundary
// segments of their face, where the node pair is used by more than two triangles over all faces
// (two half cylinders of a small hole drawing the same chord, or a full cylinder with three points
// per turn drawing one chord from both sides of its seam). Returns (face index, parametric
// midpoint) sorted by face.
std::vector<std::pair<std::size_t, Vec2>> shared_diagonals(
    const std::vector<FaceBoundary>& boundary, const std::vector<FacePoints>& pts,
    const std::vector<FaceTriangles>& tris) {
  struct Use {
    std::size_t face;
    Vec2 mid;
  };
  using Key = std::pair<std::int64_t, std::int64_t>;
  std::map<Key, std::vector<Use>> diagonals;  // one per (face, uv edge)
  std::map<Key, int> triangles;               // triangles using the node pair
  for (std::size_t k = 0; k < boundary.size(); ++k) {
    const auto& b = boundary[k];
    const int nb = static_cast<int>(b.uv.size());
    // Boundary segments by their local ids: a chord across a seam joins the same two nodes
    // as the seam segment but is a diagonal of the face.
    std::set<std::pair<int, int>> segs;
    for (const auto& sg : b.segments) segs.insert({std::min(sg[0], sg[1]), std::max(sg[0], sg[1])});
    // Edge nodes by node id; interior points are unique to their face.
    auto node_of = [&](int i) -> std::int64_t {
      return i < nb ? b.node[static_cast<std::size_t>(i)]
                    : -1 - static_cast<std::int64_t>((k << 32) | static_cast<std::size_t>(i));
    };
    std::set<std::pair<int, int>> seen;  // local uv edges already recorded
    for (const auto& t : tris[k].triangles) {
      for (int e = 0; e < 3; ++e) {
        const int i = t[static_cast<std::size_t>(e)], j = t[static_cast<std::size_t>((e + 1) % 3)];
        if (i >= nb && j >= nb) continue;  // two interior points: used by this face only
        const std::int64_t a = node_of(i), c = node_of(j);
        const Key key{std::min(a, c), std::max(a, c)};
        ++triangles[key];
        const std::pair<int, int> local{std::min(i, j), std::max(i, j)};
        if (segs.count(local) || !seen.insert(local).second) continue;
        const Vec2& p = i < nb ? b.uv[static_cast<std::size_t>(i)]
                               : pts[k].uv[static_cast<std::size_t>(i - nb)];
        const Vec2& q = j < nb ? b.uv[static_cast<std::size_t>(j)]
                               : pts[k].uv[static_cast<std::size_t>(j - nb)];
        diagonals[key].push_back({k, {0.5 * (p[0] + q[0]), 0.5 * (p[1] + q[1])}});
      }
    }
  }
  std::vector<std::pair<std::size_t, Vec2>> out;
  for (const auto& [key, list] : diagonals) {
    if (triangles[key] <= 2) continue;
    for (const Use& u : list) out.emplace_back(u.face, u.mid);
  }
  std::stable_sort(out.begin(), out.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  return out;
}

// Removes nodes no triangle uses (the second vertex of a collapsed micro edge), keeping the
// order of the others.
void drop_unused_nodes(SurfaceMesh& s) {
  MixedMesh& m = s.mesh;
  std::vector<int> index(m.nodes.size(), -1);
  for (int n : m.bface_nodes)
    if (n >= 0) index[static_cast<std::size_t>(n)] = 0;
  int next = 0;
  for (std::size_t i = 0; i < index.size(); ++i) {
    if (index[i] < 0) continue;
    index[i] = next;
    const auto j = static_cast<std::size_t>(next++);
    m.nodes[j] = m.nodes[i];
    s.frame[j] = s.frame[i];
    s.size[j] = s.size[i];
    s.on_edge[j] = s.on_edge[i];
  }
  const auto n = static_cast<std::size_t>(next);
  m.nodes.resize(n);
  s.frame.resize(n);
  s.size.resize(n);
  s.on_edge.resize(n);
  for (int& v : m.bface_nodes)
    if (v >= 0) v = index[static_cast<std::size_t>(v)];
}

// The face sides on each CAD edge of solid s (degenerate edges left out).
std::map<int, std::vector<int>> edge_uses(const CadModel& cad, int s) {
  std::map<int, std::vector<int>> uses;
  for (int f : cad.faces_of_solid(s))
    for (const auto& ce : cad.coedges(f))
      if (!cad.edge_degenerate(ce.edge)) uses[ce.edge].push_back(f);
  return uses;
}

std::string face_list(const std::vector<int>& fs) {
  std::string list;
  for (int f : fs) list += (list.empty() ? "" : ", ") + std::to_string(f);
  return list;
}

// Two lumps of a solid may touch along an edge: it then bounds four face sides (or another even
// number), and the surface mesh is closed and oriented though not manifold there; TetGen, the
// recombination and the solver take it as it is (the lumps share the edge's nodes). An odd
// number above two is a face inside the solid or hanging from it (no closed surface): refused
// with the edge and its faces named.
void require_closed_solids(const CadModel& cad) {
  for (int s = 1; s <= cad.num_solids(); ++s)
    for (const auto& [e, fs] : edge_uses(cad, s))
      if (fs.size() > 2 && fs.size() % 2 == 1)
        throw CadError("solid " + std::to_string(s) + " is not manifold: edge " +
                       std::to_string(e) + " bounds " + std::to_string(fs.size()) +
                       " face sides (faces " + face_list(fs) + ")");
}

}  // namespace

std::vector<std::string> touching_lumps(const CadModel& cad) {
  std::vector<std::string> out;
  for (int s = 1; s <= cad.num_solids(); ++s)
    for (const auto& [e, fs] : edge_uses(cad, s))
      if (fs.size() > 2 && fs.size() % 2 == 0)
        out.push_back("lumps of solid " + std::to_string(s) + " touch along CAD edge " +
                      std::to_string(e) + " (faces " + face_list(fs) +
                      "): the mesh joins them there by that edge's nodes only");
  return out;
}

double estimate_surface_points(const CadModel& cad, const SurfaceOptions& options) {
  const SizeField size(cad, size_options(options));
  double n = 0;
  for (int f = 1; f <= cad.num_faces(); ++f)
    if (!cad.solids_of_face(f).empty()) n += face_estimate(cad, size, f);
  return n;
}

namespace {

// What the surface stages hand on, per face of a solid (index k into `faces`).
struct FaceWork {
  std::vector<int> faces;  // faces of solids, in id order
  std::vector<FaceBoundary> boundary;
  std::vector<double> budget;   // the packing's point budget
  std::vector<bool> collapsed;  // boundary of fewer than three distinct nodes: not meshed
  std::vector<std::optional<FaceField>> field;
  std::vector<FacePoints> pts;
  std::vector<FaceTriangles> tris;
  std::size_t size() const { return faces.size(); }
};

void throw_if_too_many(double points, const char* what, const SurfaceOptions& o) {
  if (points <= o.max_points || o.force) return;
  char msg[240];
  std::snprintf(msg, sizeof msg,
                "h = %g%s gives about %.3g surface points (more than %.3g); use a larger h or "
                "--force",
                o.h, what, points, o.max_points);
  throw Error(msg);
}

// Stage 2: the edge points, each face's boundary, and its point budget. A second estimate from
// the sizes the edges actually got (curvature, narrow faces, vertex sizes): area over the mean
// boundary size squared per face. The packing budget of a face is a few times what its finest
// boundary size would give.
FaceWork face_boundaries(const CadModel& cad, const SizeField& size, const EdgePoints& edges,
                         const SurfaceOptions& options) {
  FaceWork w;
  for (int f = 1; f <= cad.num_faces(); ++f)
    if (!cad.solids_of_face(f).empty()) w.faces.push_back(f);
  const std::size_t nf = w.size();
  w.boundary.resize(nf);
  w.budget.resize(nf);
  w.collapsed.assign(nf, false);
  double refined = 0, worst = 0, worst_h = 0;
  int worst_face = 0;
  for (std::size_t k = 0; k < nf; ++k) {
    w.boundary[k] = face_boundary(cad, w.faces[k], edges);
    double hmin = size.global(), hsum = 0;
    for (int n : w.boundary[k].node) {
      const double h = edges.size[static_cast<std::size_t>(n)];
      hmin = std::min(hmin, h);
      hsum += h;
    }
    const double hmean = w.boundary[k].node.empty()
                             ? size.global()
                             : hsum / static_cast<double>(w.boundary[k].node.size());
    const double area = cad.face_area(w.faces[k]);
    refined += area / (hmean * hmean);
    if (area / (hmean * hmean) > worst) {
      worst = area / (hmean * hmean);
      worst_face = w.faces[k];
      worst_h = hmean;
    }
    w.budget[k] = std::min(4 * area / (hmin * hmin) + 1e4, 2.5e8);
    // A face whose boundary collapsed to fewer than three nodes (all its edges micro edges)
    // has no area to mesh; its neighbours close over it.
    const std::set<int> distinct(w.boundary[k].node.begin(), w.boundary[k].node.end());
    w.collapsed[k] = distinct.size() < 3;
  }
  char what[160];
  std::snprintf(what, sizeof what,
                " with the curvature and feature sizes (face %d: about %.3g points at a mean "
                "size of %.3g mm set by a thin wall or small feature next to it)",
                worst_face, worst, worst_h);
  throw_if_too_many(refined, what, options);
  return w;
}

// --align-opposite: faces in order of decreasing area (ties by id); each is packed again with
// the points of the faces before it that lie across a thin wall as seeds, so the wall's two
// sides carry the same lattice and the tets between them close into hexes. In sequence: a face
// seeds from faces already final. The final faces' points sit on a grid of cell `reach`; a face
// asks it around its own points (boundary and first packing), so only points within `reach` of
// the face are projected onto it.
void align_opposite_faces(const CadModel& cad, const EdgePoints& edges, FaceWork& w,
                          const SurfaceOptions& o) {
  std::vector<std::size_t> order(w.size());
  for (std::size_t k = 0; k < w.size(); ++k) order[k] = k;
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return cad.face_area(w.faces[a]) > cad.face_area(w.faces[b]);
  });
  const double reach = (o.align_opposite + 1) * o.h;
  auto cell = [&](const Vec3& p, int dx, int dy, int dz) {
    auto c = [&](double x, int d) {
      // A point off every range (NaN from a damaged surface) still gets a cell, without the
      // undefined conversion: the surface checks refuse such a mesh afterwards.
      const double q = std::floor(x / reach);
      const std::int64_t i = q > -1e15 && q < 1e15 ? static_cast<std::int64_t>(q) : 0;
      return static_cast<std::uint64_t>(i + d + (1 << 20)) & 0x1fffff;
    };
    return c(p[0], dx) << 42 | c(p[1], dy) << 21 | c(p[2], dz);
  };
  // (face index k, point index) of the final faces' interior points, by grid cell.
  std::unordered_map<std::uint64_t, std::vector<std::array<std::uint32_t, 2>>> grid;
  std::vector<std::vector<Vec3>> normals(w.size());  // outward, at the final faces' points
  auto share_solid = [&](std::size_t a, std::size_t b) {
    for (int s : cad.solids_of_face(w.faces[a]))
      for (int t : cad.solids_of_face(w.faces[b]))
        if (s == t) return true;
    return false;
  };
  std::vector<std::size_t> rank(w.size());
  for (std::size_t i = 0; i < order.size(); ++i) rank[order[i]] = i;
  for (std::size_t k : order) {
    if (w.collapsed[k]) continue;
    // Own points: xyz and parameters.
    std::vector<Vec3> own = w.pts[k].xyz;
    std::vector<Vec2> own_uv = w.pts[k].uv;
    for (std::size_t i = 0; i < w.boundary[k].node.size(); ++i) {
      own.push_back(edges.xyz[static_cast<std::size_t>(w.boundary[k].node[i])]);
      own_uv.push_back(w.boundary[k].uv[i]);
    }
    std::vector<Vec3> own_n(own.size());
    for (std::size_t i = 0; i < own.size(); ++i) own_n[i] = cad.normal(w.faces[k], own_uv[i]);
    // Each final point within reach of an own point, with the nearest own point's parameters.
    // Cheap tests first (opposite_seeds decides): normals roughly opposite, the point on the
    // solid's side of the own point's tangent plane and within T sizes of it.
    std::map<std::array<std::uint32_t, 2>, std::pair<double, std::size_t>> found;
    for (std::size_t i = 0; i < own.size(); ++i)
      for (int dx = -1; dx <= 1; ++dx)
        for (int dy = -1; dy <= 1; ++dy)
          for (int dz = -1; dz <= 1; ++dz) {
            const auto it = grid.find(cell(own[i], dx, dy, dz));
            if (it == grid.end()) continue;
            for (const auto& jp : it->second) {
              const Vec3 dp = v3::sub(w.pts[jp[0]].xyz[jp[1]], own[i]);
              const double d = v3::norm(dp), across = -v3::dot(dp, own_n[i]);
              if (d > reach || across <= 0 || across > o.align_opposite * o.h ||
                  v3::dot(normals[jp[0]][jp[1]], own_n[i]) > -0.8 || !share_solid(jp[0], k))
                continue;
              // Keyed by the source's rank: the candidates come in the order faces were final.
              const std::array<std::uint32_t, 2> key{static_cast<std::uint32_t>(rank[jp[0]]),
                                                     jp[1]};
              auto [pos, added] = found.try_emplace(key, d, i);
              if (!added && d < pos->second.first) pos->second = {d, i};
            }
          }
    if (!found.empty()) {
      std::vector<SeedCandidate> cands;
      for (const auto& [key, near] : found) {
        const std::size_t j = order[key[0]];
        cands.push_back(
            {w.faces[j], w.pts[j].xyz[key[1]], w.pts[j].uv[key[1]], own_uv[near.second]});
      }
      PackingOptions po;
      po.k = o.k;
      po.budget = static_cast<std::size_t>(w.budget[k]);
      po.seeds = opposite_seeds(cad, *w.field[k], cands, o.align_opposite);
      if (!po.seeds.empty()) w.pts[k] = pack_face(cad, *w.field[k], w.boundary[k], edges, po);
    }
    normals[k].resize(w.pts[k].xyz.size());
    for (std::size_t i = 0; i < w.pts[k].xyz.size(); ++i) {
      normals[k][i] = cad.normal(w.faces[k], w.pts[k].uv[i]);
      grid[cell(w.pts[k].xyz[i], 0, 0, 0)].push_back(
          {static_cast<std::uint32_t>(k), static_cast<std::uint32_t>(i)});
    }
  }
}

// Stage 5: each face triangulated from its points. A face with no interior point near two of
// its edges may join them by a diagonal that a neighbouring face sharing both edges draws too
// (two half cylinders of a small hole): the edge would be used four times. Such faces get a
// point in the middle of the diagonal.
void triangulate_faces(const CadModel& cad, const EdgePoints& edges, FaceWork& w) {
  w.tris.resize(w.size());
  parallel_for(static_cast<int>(w.size()), [&](int i) {
    const auto k = static_cast<std::size_t>(i);
    if (!w.collapsed[k])
      w.tris[k] =
          triangulate_face(w.faces[k], w.boundary[k], w.pts[k], edges, w.field[k]->scale(), &cad);
  });
  for (int round = 0; round < 4; ++round) {
    const auto split = shared_diagonals(w.boundary, w.pts, w.tris);
    if (split.empty()) break;
    std::vector<std::size_t> redo;
    for (const auto& [k, uv] : split) {
      if (!cad.contains(w.faces[k], uv)) continue;
      w.pts[k].uv.push_back(uv);
      w.pts[k].xyz.push_back(cad.point(w.faces[k], uv));
      if (redo.empty() || redo.back() != k) redo.push_back(k);
    }
    if (redo.empty()) break;
    for (std::size_t k : redo)
      w.tris[k] =
          triangulate_face(w.faces[k], w.boundary[k], w.pts[k], edges, w.field[k]->scale(), &cad);
  }
}

// Assembly: edge nodes first, then each face's used interior points in face order; the owning
// face (index into w.faces, or -1) and parameters of every node.
struct Owners {
  std::vector<int> face;
  std::vector<Vec2> uv;
};
Owners assemble_triangles(const CadModel& cad, const EdgePoints& edges, const FaceWork& w,
                          MixedMesh& m, SurfaceReport& rep) {
  m.nodes = edges.xyz;
  const std::size_t nedge = edges.xyz.size();
  Owners own{std::vector<int>(nedge, -1), std::vector<Vec2>(nedge)};
  for (std::size_t k = 0; k < w.size(); ++k) {
    const auto& b = w.boundary[k];
    for (std::size_t p = 0; p < b.uv.size(); ++p) {
      const auto n = static_cast<std::size_t>(b.node[p]);
      if (own.face[n] < 0 && !w.collapsed[k])
        own.face[n] = static_cast<int>(k), own.uv[n] = b.uv[p];
    }
  }
  for (std::size_t k = 0; k < w.size(); ++k) {
    const int f = w.faces[k];
    const auto& bnode = w.boundary[k].node;
    const int nb = static_cast<int>(w.boundary[k].uv.size());
    std::vector<int> global(w.pts[k].uv.size(), -1);
    for (std::size_t j = 0; j < w.pts[k].uv.size(); ++j) {
      if (!w.tris[k].interior_used[j]) continue;
      global[j] = static_cast<int>(m.nodes.size());
      m.nodes.push_back(w.pts[k].xyz[j]);
      own.face.push_back(static_cast<int>(k));
      own.uv.push_back(w.pts[k].uv[j]);
    }
    auto node_of = [&](int id) {
      return id < nb ? bnode[static_cast<std::size_t>(id)]
                     : global[static_cast<std::size_t>(id - nb)];
    };
    // Two triangles on the same three nodes (a fold where a ring around an apex or pole is
    // too small for the size, seen from both sides of the seam) cancel each other.
    std::map<std::array<int, 3>, int> count;
    auto key_of = [&](const std::array<int, 3>& t) {
      std::array<int, 3> g;
      for (int c = 0; c < 3; ++c) {
        const int id = t[static_cast<std::size_t>(c)];
        g[static_cast<std::size_t>(c)] = id < nb ? bnode[static_cast<std::size_t>(id)] : -1 - id;
      }
      std::sort(g.begin(), g.end());
      return g;
    };
    for (const auto& t : w.tris[k].triangles) ++count[key_of(t)];
    const bool rev = cad.face_reversed(f);
    for (const auto& t : w.tris[k].triangles) {
      if (count[key_of(t)] > 1) continue;
      std::array<int, 3> g{node_of(t[0]), node_of(t[1]), node_of(t[2])};
      if (rev) std::swap(g[1], g[2]);
      m.add_bface(g[0], g[1], g[2], -1, f);
    }
    rep.flips += w.tris[k].flips;
  }
  return own;
}

// Per node: the frame of its owning face there, n outward, and the size.
void node_frames(const CadModel& cad, const SizeField& size, const EdgePoints& edges,
                 const FaceWork& w, const Owners& own, SurfaceMesh& out) {
  const std::size_t nn = out.mesh.nodes.size(), nedge = edges.xyz.size();
  out.frame.resize(nn);
  out.size.resize(nn);
  out.on_edge.assign(nn, false);
  for (std::size_t n = 0; n < nn; ++n) {
    out.on_edge[n] = n < nedge;
    if (own.face[n] < 0) {  // a vertex of no meshed face (cannot happen for solids)
      out.frame[n] = {Vec3{1, 0, 0}, Vec3{0, 1, 0}, Vec3{0, 0, 1}};
      out.size[n] = size.global();
      continue;
    }
    const auto k = static_cast<std::size_t>(own.face[n]);
    const int f = w.faces[k];
    const Vec2 uv = own.uv[n];
    Frame fr = w.field[k]->frame(uv);
    // At a pole or apex the tangent plane is undefined: take the frame just inside the face.
    const auto bd = cad.uv_bounds(f);
    const Vec2 mid{0.5 * (bd[0] + bd[1]), 0.5 * (bd[2] + bd[3])};
    for (double step : {1e-6, 1e-4, 1e-2}) {
      if (fr.ok) break;
      fr = w.field[k]->frame({uv[0] + step * (mid[0] - uv[0]), uv[1] + step * (mid[1] - uv[1])});
    }
    Vec3 nrm = fr.ok ? fr.n : Vec3{0, 0, 1};
    Vec3 d1 = fr.ok ? fr.d1 : Vec3{1, 0, 0};
    if (cad.face_reversed(f)) nrm = {-nrm[0], -nrm[1], -nrm[2]};
    out.frame[n] = {d1, cross(nrm, d1), nrm};
    out.size[n] = n < nedge ? edges.size[n] : fr.h;
  }
}

SurfaceMesh mesh_surface_once(const CadModel& cad, const SurfaceOptions& options,
                              SurfaceReport& rep) {
  rep = SurfaceReport{};
  rep.curvature_used = options.curvature;
  if (!(options.k > 0 && options.k < 1)) throw Error("the packing factor k must be in (0, 1)");
  require_closed_solids(cad);
  StageTimer timer;
  auto lap = [&](const char* name) {
    rep.stage_seconds.emplace_back(name, timer.lap(name).seconds);
  };
  const SizeField size(cad, size_options(options));
  rep.estimated_points = estimate_surface_points(cad, options);
  throw_if_too_many(rep.estimated_points, "", options);
  lap("size field");

  show_progress("surface mesh: edge points");
  EdgePoints edges = discretise_edges(cad, size);
  if (options.sizes_from_edge_spacing) sizes_from_edge_spacing(cad, edges);
  FaceWork w = face_boundaries(cad, size, edges, options);
  rep.edge_points = edges.xyz.size();
  lap("edge points");

  show_progress("surface mesh: cross field");
  const int nf = static_cast<int>(w.size());
  w.field.resize(w.size());
  parallel_for(nf, [&](int i) {
    const auto k = static_cast<std::size_t>(i);
    if (!w.collapsed[k]) w.field[k].emplace(cad, w.faces[k], w.boundary[k], edges, size);
  });
  for (const auto& fl : w.field)
    if (fl) rep.background_triangles += fl->background_triangles();
  lap("cross field");

  show_progress("surface mesh: packing of parallelograms");
  w.pts.resize(w.size());
  parallel_for(nf, [&](int i) {
    const auto k = static_cast<std::size_t>(i);
    PackingOptions po;
    po.k = options.k;
    po.budget = static_cast<std::size_t>(w.budget[k]);
    if (!w.collapsed[k]) w.pts[k] = pack_face(cad, *w.field[k], w.boundary[k], edges, po);
  });
  if (options.align_opposite > 0) align_opposite_faces(cad, edges, w, options);
  for (const auto& p : w.pts) rep.candidates += p.candidates;
  lap("packing");

  show_progress("surface mesh: triangulation");
  triangulate_faces(cad, edges, w);
  lap("triangulation");

  SurfaceMesh out;
  const Owners own = assemble_triangles(cad, edges, w, out.mesh, rep);
  node_frames(cad, size, edges, w, own, out);
  out.faces_of_solid.resize(static_cast<std::size_t>(cad.num_solids()) + 1);
  for (int s = 1; s <= cad.num_solids(); ++s)
    out.faces_of_solid[static_cast<std::size_t>(s)] = cad.faces_of_solid(s);
  drop_unused_nodes(out);
  rep.points = out.mesh.nodes.size();
  rep.triangles = out.mesh.num_bfaces();
  rep.quality = triangle_quality(out.mesh, cad_corners(cad, out.mesh));
  lap("assembly");
  end_progress();
  return out;
}

bool all_valid(const std::vector<SolidCheck>& checks) {
  return std::all_of(checks.begin(), checks.end(), [](const SolidCheck& c) { return c.ok(); });
}

}  // namespace

SurfaceMesh mesh_surface(const CadModel& cad, const SurfaceOptions& options,
                         SurfaceReport* report) {
  SurfaceReport local;
  SurfaceReport& rep = report ? *report : local;
  SurfaceMesh out = mesh_surface_once(cad, options, rep);
  StageTimer timer;
  rep.checks = check_solids(out);
  rep.stage_seconds.emplace_back("checks", timer.lap("checks").seconds);
  // A size coarser than a thin wall's bend or a tight curved face lets chords of the two
  // sides cross (thin sheet parts at h much larger than the thickness). Meshing again with a
  // curvature bound (8, then 16 elements per turn, or twice the user's) follows such bends.
  if (!options.repair || all_valid(rep.checks)) return out;
  int curvature = options.curvature;
  for (int attempt = 0; attempt < 2; ++attempt) {
    curvature = curvature > 0 ? 2 * curvature : 8;
    SurfaceOptions retry = options;
    retry.curvature = curvature;
    SurfaceReport again;
    SurfaceMesh mesh;
    try {
      mesh = mesh_surface_once(cad, retry, again);
    } catch (const Error&) {
      break;  // the finer sizes exceed the point budget: keep the first mesh and its checks
    }
    timer.lap("retry");
    again.checks = check_solids(mesh);
    again.stage_seconds.emplace_back("checks", timer.lap("checks").seconds);
    for (const auto& [stage, sec] : rep.stage_seconds)
      again.stage_seconds.emplace_back("first attempt: " + stage, sec);
    again.curvature_used = curvature;
    rep = std::move(again);
    out = std::move(mesh);
    if (all_valid(rep.checks)) break;
  }
  return out;
}

}  // namespace hexfem
