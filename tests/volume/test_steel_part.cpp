// The whole mesher on the paper's steel part (models/steel_part.step, CAD volume 11394.6 mm^3):
// the defects a solver trips on. Flat tets on the R3 fillet (zero volume, scaled Jacobian 0)
// and boundary faces missing where a hex's quad face and the surface triangles under it split
// the quad along different diagonals (open boundary edges) were both found here.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "mesher/mesh/mesh_stats.hpp"
#include "mesher/mesh/quality.hpp"
#include "mesher/pipeline.hpp"

namespace hexfem {
namespace {

const std::string kSteelPart = std::string(HEXFEM_SOURCE_DIR) + "/models/steel_part.step";

void check_steel_part(double h) {
  MeshOptions o;
  o.surface.h = h;
  MeshReport r;
  const MixedMesh m = mesh_file(kSteelPart, o, &r);
  const MeshStats st = compute_stats(m);
  const VolumeReport& v = r.volume;
  SCOPED_TRACE("h = " + std::to_string(h));

  // Every cell clearly positive: no inverted, no flat cell, a sane min scaled Jacobian per kind.
  EXPECT_EQ(st.inverted, 0u);
  EXPECT_EQ(st.degenerate, 0u);
  for (int k = 0; k < kNumCellKinds; ++k) {
    if (!st.cells_per_kind[k]) continue;
    EXPECT_GT(st.min_sj_per_kind[k], 0.01) << kind_name(static_cast<CellKind>(k));
  }
  double min_cell = 1;
  for (std::size_t c = 0; c < m.num_cells(); ++c)
    min_cell = std::min(min_cell, cell_min_scaled_jacobian(m, c));
  EXPECT_GT(min_cell, 0.01);

  // A closed boundary: every boundary edge in exactly two boundary faces, and the stored
  // boundary faces are the cells' unmatched faces.
  EXPECT_TRUE(st.watertight);
  EXPECT_EQ(st.open_boundary_edges, 0u);
  EXPECT_EQ(st.num_boundary_faces, st.boundary_faces_derived);

  // Each TetGen tet used once: in an element, absorbed as a flat sliver, replaced by a flip,
  // dropped as a flat tet on the surface, or a tet of its own.
  const std::size_t tet_cells = st.cells_per_kind[static_cast<int>(CellKind::Tet4)];
  ASSERT_GE(tet_cells, v.tets_from_flips);
  EXPECT_EQ(v.tets_in_elements + v.absorbed_slivers + v.flipped_tets + v.flat_boundary_tets +
                tet_cells - v.tets_from_flips,
            v.tets);
  // The elements cover the tets: volume within 1e-3 (the non-planar quad faces' gap).
  EXPECT_LT(v.volume_rel_gap, 1e-3);
  EXPECT_NEAR(st.volume, v.volume_tets, 1e-3 * v.volume_tets);
  // And the CAD part: the chords of the fillets and holes cut a little off or on.
  EXPECT_NEAR(st.volume, 11394.6018, 0.01 * 11394.6018);
  EXPECT_GT(st.h_vol, 80.0);
}

TEST(SteelPart, H2HasNoFlatCellsAndAClosedBoundary) {
  check_steel_part(2.0);
}
TEST(SteelPart, H1HasNoFlatCellsAndAClosedBoundary) {
  check_steel_part(1.0);
}

}  // namespace
}  // namespace hexfem
