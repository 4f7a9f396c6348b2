// Point location against the closed surface of each solid of a SurfaceMesh (CGAL AABB trees):
// inside tests by ray parity, "is the boundary closer than r", segment crossings. Used by the
// volume point insertion and to classify the tets TetGen returns. Queries are thread-safe.
//
// Takes: the SurfaceMesh.
// Gives: inside tests, distances to the boundary, segment crossings per solid.
// Keeps: read-only after construction; thread-safe queries.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "mesher/surface_mesh.hpp"

namespace hexfem {

class SolidLocator {
 public:
  // Checks the surface (triangles only, indices in range, no degenerate triangle, every solid's
  // boundary closed: each edge used an even number of times) and builds one tree per solid.
  // A SurfaceMesh without faces_of_solid is one solid (id 1) bounded by all triangles.
  // Throws hexfem::Error naming the first problem found.
  explicit SolidLocator(const SurfaceMesh& surface);
  ~SolidLocator();
  SolidLocator(const SolidLocator&) = delete;
  SolidLocator& operator=(const SolidLocator&) = delete;

  int num_solids() const { return static_cast<int>(solid_triangles_.size()) - 1; }
  // Solids (1-based ids) whose boundary holds surface triangle t.
  const std::vector<int>& solids_of_triangle(std::size_t t) const { return solids_of_tri_[t]; }
  // Solids whose boundary holds a triangle incident to surface node v.
  const std::vector<int>& solids_of_node(std::size_t v) const { return solids_of_node_[v]; }

  // True when p is strictly inside solid s (ray parity; p must not lie on its boundary).
  bool inside(int s, const Vec3& p) const;
  // True when some boundary triangle of solid s is closer to p than r.
  bool near_boundary(int s, const Vec3& p, double r) const;
  // True when the segment [a, b] touches a boundary triangle of solid s.
  bool segment_hits_boundary(int s, const Vec3& a, const Vec3& b) const;
  // The lowest solid id strictly containing p, 0 if none.
  int locate(const Vec3& p) const;
  // Distance from p to the boundary of solid s; *triangle (if given) gets the surface triangle
  // holding the closest point.
  double distance(int s, const Vec3& p, std::int32_t* triangle = nullptr) const;
  // Distance along the ray from `origin` in unit direction `dir` to the first boundary triangle
  // of solid s that does not hold surface node `skip_node` (the ray's own start on the surface;
  // -1: none skipped); infinity when it meets none. *triangle (if given) gets the triangle hit.
  double ray_distance(int s, const Vec3& origin, const Vec3& dir, std::int32_t skip_node,
                      std::int32_t* triangle = nullptr) const;

  // Pairs of surface triangles that intersect other than along shared vertices/edges (at most
  // `max_pairs`), for naming the faces in an error message. Sorted, deterministic.
  std::vector<std::array<std::int32_t, 2>> intersecting_triangles(std::size_t max_pairs) const;

 private:
  struct Trees;
  const SurfaceMesh& surface_;
  std::vector<std::vector<std::int32_t>> solid_triangles_;  // per solid id (0 unused)
  std::vector<std::vector<int>> solids_of_tri_, solids_of_node_;
  std::unique_ptr<Trees> trees_;
};

// "triangle 12 (CAD face 3)" for messages.
std::string describe_surface_triangle(const SurfaceMesh& surface, std::size_t t);

}  // namespace hexfem
