// The tet mesh as the recombination stages see it: each vertex's neighbours and star, the tets
// above each vertex, the surface triangles among its faces, tet volumes and qualities. Built once
// after TetGen (and the flat boundary tets' removal); read-only afterwards.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
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
  // The tet other than `skip` with face (a, b, c), or -1 (none: a surface triangle).
  std::int32_t tet_across(std::int32_t skip, std::int32_t a, std::int32_t b, std::int32_t c) const;
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

// Min scaled Jacobian of tet t (quality.hpp's scaling: 1 for the regular tet).
double tet_quality(const TetTopology& topo, std::int32_t t);

}  // namespace hexfem
