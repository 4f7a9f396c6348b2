// drop_flat_boundary_tets: a flat tet under two surface triangles of one CAD face goes, the
// surface taking its other diagonal, but never when that diagonal is already a surface edge.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <set>

#include "mesher/surface_mesh.hpp"
#include "mesher/tetrahedralize.hpp"
#include "mesher/volume_slivers.hpp"

namespace hexfem {
namespace {

// A flat quad p0-p2-p1-p3 on CAD face 1 (outward +z), split by the surface along p2-p3, and
// the flat tet under it whose other diagonal p0-p1 dips 0.01 below (positively oriented).
struct FlatQuad {
  TetMesh tets;
  SurfaceMesh surface;
  FlatQuad() {
    tets.nodes = {{0, 0, 0}, {1, 1, -0.01}, {1, 0, 0}, {0, 1, 0}, {0.5, 0.5, -1}, {0.5, 0.5, -2}};
    tets.tets = {{0, 1, 3, 2}};
    tets.tet_solid = {1};
    surface.mesh.nodes = tets.nodes;
    surface.mesh.add_bface(0, 2, 3, -1, 1);
    surface.mesh.add_bface(1, 3, 2, -1, 1);
  }
};

std::set<std::array<std::int32_t, 3>> sorted_triangles(const MixedMesh& m) {
  std::set<std::array<std::int32_t, 3>> out;
  for (std::size_t f = 0; f < m.num_bfaces(); ++f) {
    std::array<std::int32_t, 3> t{m.bface(f)[0], m.bface(f)[1], m.bface(f)[2]};
    std::sort(t.begin(), t.end());
    out.insert(t);
  }
  return out;
}

TEST(DropFlatBoundaryTets, FlatTetGoesAndTheSurfaceTakesTheOtherDiagonal) {
  FlatQuad q;
  EXPECT_EQ(drop_flat_boundary_tets(q.tets, q.surface, 0.02), 1u);
  EXPECT_TRUE(q.tets.tets.empty());
  const std::set<std::array<std::int32_t, 3>> want{{0, 1, 2}, {0, 1, 3}};
  EXPECT_EQ(sorted_triangles(q.surface.mesh), want);
  // Still outward (+z) and on CAD face 1.
  for (std::size_t f = 0; f < q.surface.mesh.num_bfaces(); ++f) {
    const std::int32_t* t = q.surface.mesh.bface(f);
    const Vec3 &a = q.tets.nodes[t[0]], &b = q.tets.nodes[t[1]], &c = q.tets.nodes[t[2]];
    const double nz = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
    EXPECT_GT(nz, 0);
    EXPECT_EQ(q.surface.mesh.bface_cad_face[f], 1);
  }
}

// As on a thin propeller blade at h = 45.29: p0-p1 is also the sharp edge of a fin (two more
// surface triangles). Taking it as the quad's diagonal would put it in four surface
// triangles, an open (non-manifold) boundary that the pipeline refused.
TEST(DropFlatBoundaryTets, NotWhenTheOtherDiagonalIsAlreadyASurfaceEdge) {
  FlatQuad q;
  q.surface.mesh.add_bface(0, 1, 4, -1, 2);
  q.surface.mesh.add_bface(1, 0, 5, -1, 3);
  const auto before = sorted_triangles(q.surface.mesh);
  EXPECT_EQ(drop_flat_boundary_tets(q.tets, q.surface, 0.02), 0u);
  EXPECT_EQ(q.tets.tets.size(), 1u);
  EXPECT_EQ(sorted_triangles(q.surface.mesh), before);
}

}  // namespace
}  // namespace hexfem
