// The structured box generator: positive cells, exact volume, tagged outward boundary faces,
// conformity.
#include <gtest/gtest.h>

#include <cmath>

#include "fem_test_util.hpp"
#include "mesher/mesh/conformity.hpp"
#include "mesher/mesh/error.hpp"
#include "mesher/mesh/quality.hpp"
#include "mesher/mesh/structured_box.hpp"

namespace hexfem {
namespace {

Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
Vec3 sub(const Vec3& a, const Vec3& b) {
  return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}

TEST(StructuredBox, EveryKind) {
  const Vec3 L{0.1, 0.02, 0.03};
  const int n[3] = {5, 2, 3};
  for (CellKind kind : test::kAllKinds) {
    MixedMesh m = make_box_mesh(L, n[0], n[1], n[2], kind);
    const int cubes = n[0] * n[1] * n[2];
    const std::size_t expected_cells =
        kind == CellKind::Hex8     ? cubes
        : kind == CellKind::Wedge6 ? 2 * cubes
                                   : 6 * cubes + (kind == CellKind::Pyramid5 ? 2 * cubes : 0);
    EXPECT_EQ(m.num_cells(), expected_cells) << kind_name(kind);
    double vol = 0;
    for (std::size_t c = 0; c < m.num_cells(); ++c) {
      EXPECT_FALSE(cell_is_inverted(m, c)) << kind_name(kind) << " cell " << c;
      vol += cell_volume(m, c);
    }
    EXPECT_NEAR(vol, L[0] * L[1] * L[2], 1e-15) << kind_name(kind);

    // Boundary: per CAD face, the vector area Σ ½(d1 x d2) must be the outward side area.
    Vec3 area[7] = {};
    for (std::size_t f = 0; f < m.num_bfaces(); ++f) {
      const std::int32_t* v = m.bface(f);
      const int id = m.bface_cad_face[f];
      ASSERT_GE(id, 1);
      ASSERT_LE(id, 6);
      const Vec3 a = m.nodes[v[0]], b = m.nodes[v[1]], c = m.nodes[v[2]];
      const Vec3 d = v[3] >= 0 ? m.nodes[v[3]] : a;
      const Vec3 s = cross(sub(c, a), sub(d, b));  // quad: ½ diagonals cross; triangle: d = a
      const Vec3 t = v[3] >= 0 ? s : cross(sub(b, a), sub(c, a));
      for (int k = 0; k < 3; ++k) area[id][k] += t[k] / 2;
    }
    for (int axis = 0; axis < 3; ++axis)
      for (int side = 0; side < 2; ++side) {
        const int id = 1 + 2 * axis + side;
        const double side_area = L[(axis + 1) % 3] * L[(axis + 2) % 3];
        for (int k = 0; k < 3; ++k)
          EXPECT_NEAR(area[id][k], k == axis ? (side ? side_area : -side_area) : 0.0, 1e-15)
              << kind_name(kind) << " face " << id;
      }
    flag_nonconformal_quads(m);
    EXPECT_TRUE(m.nc_cell.empty()) << kind_name(kind);
  }
}

TEST(StructuredBox, MixTriangulatesXFacesOnly) {
  const MixedMesh m = make_box_mesh({1, 1, 1}, 2, 2, 2, CellKind::Pyramid5);
  for (std::size_t f = 0; f < m.num_bfaces(); ++f)
    EXPECT_EQ(m.bface_is_quad(f), m.bface_cad_face[f] > 2) << f;
}

TEST(StructuredBox, RejectsBadInput) {
  EXPECT_THROW(make_box_mesh({1, 1, 1}, 0, 1, 1, CellKind::Hex8), Error);
  EXPECT_THROW(make_box_mesh({1, -1, 1}, 1, 1, 1, CellKind::Hex8), Error);
}

}  // namespace
}  // namespace hexfem
