// What the recombination stages share: the tet mesh's adjacency, the test that a set of
// vertices is exactly filled by tets forming a hex or a prism, and the conformity rules of the
// paper (Figs 15-18) checked by hashing the faces, edges and diagonals of placed elements.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <utility>
#include <vector>

#include "mesher/open_hash.hpp"
#include "mesher/surface_mesh.hpp"
#include "mesher/tetrahedralize.hpp"

namespace hexfem {

// Sorted vertex triple, hashable.
struct TriKey {
  std::int32_t v[3];
  bool operator==(const TriKey& o) const {
    return v[0] == o.v[0] && v[1] == o.v[1] && v[2] == o.v[2];
  }
};
TriKey tri_key(std::int32_t a, std::int32_t b, std::int32_t c);
struct TriKeyHash {
  std::size_t operator()(const TriKey& k) const {
    std::uint64_t h = static_cast<std::uint32_t>(k.v[0]);
    h = h * 0x9E3779B97F4A7C15ull ^ static_cast<std::uint32_t>(k.v[1]);
    h = h * 0x9E3779B97F4A7C15ull ^ static_cast<std::uint32_t>(k.v[2]);
    return static_cast<std::size_t>(mix64(h));
  }
};
using TriKeyMap = OpenHashMap<TriKey, std::int32_t, TriKeyHash>;
inline std::uint64_t edge_key(std::int32_t a, std::int32_t b) {
  if (a > b) std::swap(a, b);
  return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(a)) << 32) |
         static_cast<std::uint32_t>(b);
}

// Adjacency of a tet mesh, plus where its faces lie on the surface.
class TetTopology {
 public:
  TetTopology(const TetMesh& tets, const SurfaceMesh& surface);

  const TetMesh& mesh() const { return mesh_; }
  std::size_t num_vertices() const { return adj_off_.size() - 1; }
  // Vertices 0 .. num_surface_nodes()-1 are the surface mesh's nodes.
  std::size_t num_surface_nodes() const { return num_surface_; }
  // Sorted neighbours of v (vertices sharing a tet edge) and the tets around v.
  const std::int32_t* neighbours_begin(std::int32_t v) const { return &adj_[adj_off_[v]]; }
  const std::int32_t* neighbours_end(std::int32_t v) const { return &adj_[adj_off_[v + 1]]; }
  const std::int32_t* star_begin(std::int32_t v) const { return &star_[star_off_[v]]; }
  const std::int32_t* star_end(std::int32_t v) const { return &star_[star_off_[v + 1]]; }
  // The tets whose lowest vertex is v, by increasing index, with their other three vertices
  // (each tet once over all vertices; read in one sweep, unlike the star).
  struct UpperTet {
    std::int32_t tet;
    std::int32_t v[3];
  };
  const UpperTet* upper_begin(std::int32_t v) const { return &upper_[upper_off_[v]]; }
  const UpperTet* upper_end(std::int32_t v) const { return &upper_[upper_off_[v + 1]]; }
  bool adjacent(std::int32_t a, std::int32_t b) const;
  // Surface triangle index of triangle (a,b,c), -1 when it is not on the surface.
  std::int32_t surface_triangle(std::int32_t a, std::int32_t b, std::int32_t c) const;
  // CAD face of surface triangle t.
  std::int32_t cad_face(std::int32_t t) const { return cad_face_[t]; }
  double tet_volume(std::int32_t t) const { return tet_volume_[t]; }

 private:
  const TetMesh& mesh_;
  std::size_t num_surface_ = 0;
  std::vector<std::int32_t> adj_off_, adj_, star_off_, star_, upper_off_;
  std::vector<UpperTet> upper_;
  std::vector<std::int32_t> cad_face_;
  TriKeyMap surface_tri_;
  std::vector<double> tet_volume_;
};

// A hex or prism made of tets (or a pyramid made of two).
struct Candidate {
  CellKind kind = CellKind::Hex8;
  float quality = 0;                  // min scaled Jacobian (quality.hpp)
  std::array<std::int32_t, 8> nodes;  // Gmsh order, unused slots -1
  std::array<std::int32_t, 7> tets;   // unused slots -1
  // Best first; ties by node ids, so the order never depends on how candidates were found.
  bool operator<(const Candidate& o) const {
    if (quality != o.quality) return quality > o.quality;
    return nodes < o.nodes;
  }
};

struct FillRules {
  double max_volume_gap = 0.02;  // |V(element) - V(its tets)| / V(its tets) allowed
  // Sum over quad faces of half the volume of the tet spanned by the face's corners (the most
  // a non-planar face can open or overlap against tets across it), relative to V(its tets).
  double max_face_twist = 0.2;
};

// True when the tets whose vertices all lie among `c.nodes` fill exactly the element c.kind
// (every face covered by its triangles: quads by two, triangles by one); they are all in one
// solid and (if `used` is given) all free; every quad face either lies inside the solid or has
// both triangles on the same CAD face; and the element's volume matches the tets'. Fills
// c.tets. c.nodes must be set and distinct.
// A potential quad face at vertex v: (v, a, x, b) with a < b, v's edges to a and b, x opposite;
// made of two mesh triangles split along v-x or along a-b.
struct CornerQuad {
  std::int32_t a, b, x;
  bool operator<(const CornerQuad& o) const {
    return a != o.a ? a < o.a : b != o.b ? b < o.b : x < o.x;
  }
  bool operator==(const CornerQuad& o) const { return a == o.a && b == o.b && x == o.x; }
};

struct FillScratch {  // per-thread work memory of the enumerations
  std::vector<CornerQuad> quads;
  std::vector<std::uint32_t> pairs;
  std::vector<std::uint64_t> keys;  // quads_at's packed quads (local a, local b, x), sorted
  // quads_at's numbering of v's neighbours above v: up[i], i < num_up; local[w] holds
  // (local_epoch << 32) | i for the current v.
  const std::int32_t* up = nullptr;
  std::size_t num_up = 0;
  std::vector<std::uint64_t> local;
  std::uint64_t local_epoch = 0;
  std::vector<std::uint32_t> near;  // epoch-stamped vertex marks of the enumerations
  std::uint32_t near_epoch = 0;
  std::vector<std::array<std::uint32_t, 2>> ranges;  // the hex enumeration's quad table
  std::vector<std::int32_t> sixth;                   // the hex enumeration's choices of p6
  std::vector<std::pair<std::int32_t, std::int32_t>> prism_partners, prism_bottoms;
};
// A fresh epoch for scratch.near (sized by the caller): marks of older epochs read as unmarked.
std::uint32_t next_near_epoch(FillScratch& scratch);

// Every potential quad face at v whose three other corners are above v (the enumerations find
// each element from its lowest vertex) and whose corner at v has |sin| >= min_sin: sorted,
// unique, in scratch.quads. Every face of a hex or prism made of tets is one (its two triangles
// are tet faces), so enumerating from these misses nothing. With `used`: only quads whose two
// triangles are faces of free tets. scratch.keys[i] holds quad i packed as (number of a among
// v's neighbours above v, scratch.up) << 48 | (number of b) << 32 | x.
void quads_at(const TetTopology& topo, std::int32_t v, double min_sin, FillScratch& scratch,
              const std::vector<char>* used = nullptr);
// The opposite corners x of the quads (v, a, x, b) in scratch.quads (a < b).
std::pair<const CornerQuad*, const CornerQuad*> quads_between(const FillScratch& scratch,
                                                              std::int32_t a, std::int32_t b);
bool fills_element(const TetTopology& topo, Candidate& c, const std::vector<char>* used,
                   const FillRules& rules);

// The quad face of an element (kind, nodes) whose four corners are the vertices of tet T (a
// flat "sliver" lying on that face), or -1.
int face_sliver_of(CellKind kind, const std::int32_t* nodes, const std::array<std::int32_t, 4>& T);
bool is_face_sliver(CellKind kind, const std::int32_t* nodes, const std::array<std::int32_t, 4>& T);

// Diagonal of quad face f (local face of kind) used by the tets of a filled element: the edge
// the two triangles share, as a local (i, j) of the face's vertex list (0-2 or 1-3).
// Returns 0 for the 0-2 diagonal, 1 for 1-3.
int quad_diagonal(const TetTopology& topo, const Candidate& c, int local_face);

// The conformity rules between hexes and prisms (paper Figs 15-18): no two elements share
// three vertices of a quad face unless they share the whole quad; no triangle face of a prism
// has three vertices of another element's quad; no edge of one is a diagonal of the other's quad.
// Every rule concerns two elements sharing two or more vertices: a candidate is checked against
// the placed elements at its corners (listed per vertex), not against tables of all faces.
class ConformityIndex {
 public:
  bool conflicts(const Candidate& c) const;
  void add(const Candidate& c);
  // Room for about n elements.
  void reserve(std::size_t n);

 private:
  struct Placed {
    CellKind kind;
    std::array<std::int32_t, 8> nodes;
  };
  // The placed elements at each vertex: up to 15 in place (one cache line), more in overflow_.
  struct alignas(64) AtVertex {
    std::int32_t count = 0;
    std::int32_t element[15];
  };
  template <class Visit>
  void for_each_at(std::int32_t v, Visit visit) const;

  std::vector<Placed> placed_;
  std::vector<AtVertex> at_;
  std::vector<std::pair<std::int32_t, std::int32_t>> overflow_;  // (vertex, element), sorted
  mutable std::vector<std::uint64_t> near_;  // conflicts' work list: element << 8 | corner
};

// The determinant of the edges from corner o to a, b, c and the product of their squared lengths.
struct CornerDet {
  double det, len2;
};
inline CornerDet corner_det(const Vec3& o, const Vec3& a, const Vec3& b, const Vec3& c) {
  const double e1[3] = {a[0] - o[0], a[1] - o[1], a[2] - o[2]};
  const double e2[3] = {b[0] - o[0], b[1] - o[1], b[2] - o[2]};
  const double e3[3] = {c[0] - o[0], c[1] - o[1], c[2] - o[2]};
  return {e1[0] * (e2[1] * e3[2] - e2[2] * e3[1]) - e1[1] * (e2[0] * e3[2] - e2[2] * e3[0]) +
              e1[2] * (e2[0] * e3[1] - e2[1] * e3[0]),
          (e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]) *
              (e2[0] * e2[0] + e2[1] * e2[1] + e2[2] * e2[2]) *
              (e3[0] * e3[0] + e3[1] * e3[1] + e3[2] * e3[2])};
}
// Min scaled Jacobian of corner o with edges to a, b, c (no kind scaling).
inline double corner_jacobian(const Vec3& o, const Vec3& a, const Vec3& b, const Vec3& c) {
  const CornerDet d = corner_det(o, a, b, c);
  const double len = std::sqrt(d.len2);
  return len > 0 ? d.det / len : 0.0;
}
// corner_jacobian(o, a, b, c) >= q, for q >= 0; an inverted corner (det < 0: the common case
// when the enumerations try both orientations) fails before the square root.
inline bool corner_at_least(const Vec3& o, const Vec3& a, const Vec3& b, const Vec3& c, double q) {
  const CornerDet d = corner_det(o, a, b, c);
  if (d.det < 0) return false;
  const double len = std::sqrt(d.len2);
  return (len > 0 ? d.det / len : 0.0) >= q;
}

// Free tets whose four vertices are the corners of a quad face of one of `elements`: slivers
// between the face's two diagonals, which fills_element leaves out. Such a sliver belongs to the
// element(s) whose bilinear face cuts through it:
//  - kSharedOrBoundary: the face is shared by two elements, or the sliver's other two faces are
//    surface triangles (the element's tets split the face along one diagonal, the surface along
//    the other): the element's quad face is then the boundary face.
//  - kFlat: any other sliver on a quad face whose min scaled Jacobian is below flat_sj (a flat
//    tet against tets: the bilinear face passes through it; left alone it is a zero-volume cell).
// Absorbed slivers are marked used and listed.
enum class SliverPolicy { kSharedOrBoundary, kFlat };
std::vector<std::int32_t> absorb_face_slivers(const TetTopology& topo,
                                              const std::vector<Candidate>& elements,
                                              std::vector<char>& used, SliverPolicy policy,
                                              double flat_sj = 0);

// After elements were removed: every absorbed sliver that no longer qualifies under
// absorb_face_slivers' rules (shared by two elements, under a boundary face, or below flat_sj
// on one element's face) is freed and dropped from `absorbed`. Returns how many.
std::size_t release_orphan_slivers(const TetTopology& topo, const std::vector<Candidate>& elements,
                                   std::vector<std::int32_t>& absorbed, std::vector<char>& used,
                                   double flat_sj);

// Min scaled Jacobian of tet t (quality.hpp's scaling: 1 for the regular tet).
double tet_quality(const TetTopology& topo, std::int32_t t);

// Sorted keys (sorted corners) of every quad face of `elements`; a key listed twice is a face
// two elements share.
using QuadKey = std::array<std::int32_t, 4>;
// The corners of quad face local_face of e, in the face's order; quad_key: the same, sorted.
QuadKey quad_corners(const Candidate& e, int local_face);
QuadKey quad_key(const Candidate& e, int local_face);
// Tets keyed by their sorted corners (a sliver on a quad face has that face's quad_key), sorted.
using KeyedTet = std::pair<QuadKey, std::int32_t>;
std::vector<KeyedTet> tets_by_corners(const TetTopology& topo,
                                      const std::vector<std::int32_t>& tets);
std::vector<QuadKey> sorted_quad_keys(const std::vector<Candidate>& elements);
bool quad_shared(const std::vector<QuadKey>& keys, const QuadKey& k);

// Runs find(v, scratch, out) for every vertex on all threads and returns the candidates
// sorted best first (the sort makes the result independent of the thread schedule).
using FindCandidates =
    std::function<void(std::int32_t v, FillScratch& scratch, std::vector<Candidate>& out)>;
std::vector<Candidate> collect_candidates(std::int32_t num_vertices, const FindCandidates& find);

// Greedy best-first placement: sorts `cands` (unless sorted) and keeps each one that tets fill
// (fills_element, for candidates whose tets are not known yet), whose tets are all free and
// that breaks no conformity rule. Marks the tets used; returns the kept candidates in order.
// The fill test of every candidate runs first, on all threads: only its last check (the tets
// are free) depends on the placement, and the serial pass makes that check itself.
std::vector<Candidate> place_greedily(const TetTopology& topo, std::vector<Candidate>& cands,
                                      std::vector<char>& used, ConformityIndex& index,
                                      const FillRules& rules);

}  // namespace hexfem
