// The fill test: whether the tets on a set of vertices form exactly one hex, prism or pyramid
// (paper section 4: "the tets that fill an element"), and the potential quad faces at a vertex
// the enumerations start from. Candidate is the element the recombination stages pass around:
// kind, corners in Gmsh order, the tets it is made of, its quality.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

#include "mesher/recombine_tets.hpp"

namespace hexfem {

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

// A hex as the enumeration finds it: corners and quality; its tets are found when it is placed.
// Half a Candidate's size: a million-vertex part has about 30 million hex candidates.
struct HexCorners {
  float quality = 0;
  std::array<std::int32_t, 8> nodes;
  // Candidate's order.
  bool operator<(const HexCorners& o) const {
    if (quality != o.quality) return quality > o.quality;
    return nodes < o.nodes;
  }
  Candidate candidate() const {
    Candidate c;
    c.kind = CellKind::Hex8;
    c.quality = quality;
    c.nodes = nodes;
    c.tets.fill(-1);
    return c;
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

using QuadKey = std::array<std::int32_t, 4>;
// The corners of quad face local_face of e, in the face's order; quad_key: the same, sorted.
QuadKey quad_corners(const Candidate& e, int local_face);
QuadKey quad_key(const Candidate& e, int local_face);

}  // namespace hexfem
