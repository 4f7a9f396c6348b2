// flip_slivers: edge-removal flips of the free slivers left at the end of the recombination.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <map>
#include <vector>

#include "mesher/recombine_state.hpp"
#include "mesher/recombine_tets.hpp"
#include "mesher/volume_slivers.hpp"

namespace hexfem {
namespace {

// The four tets around edge (0, 1) that MVE_100-3_AP203 at h = 3.58 mm left as slivers (min
// scaled Jacobian 0.017, under the 0.02 bound), with the coordinates TetGen gave them: a 45-degree
// chamfer, so the ring of four is nearly planar and both of its diagonals give the same quality up
// to rounding. Flipping to the other diagonal "gained" 1.2e-16 and flipping back gained again:
// 16 million flips and 11 GB before the run was stopped.
TEST(SliverFlips, AShellWhoseTwoTriangulationsTieIsNotFlippedForEver) {
  TetMesh tets;
  // 822, 38684 (the edge), then the ring 13014, 829, 36645, 38459 of the run.
  tets.nodes = {{-47.000000000000014, 88.000000000000014, 48.000000000000007},
                {-47.000000000000007, 85.520309123308778, 44.000000000000007},
                {-47.70710678118656, 88.000000000000014, 47.707106781186553},
                {-48.000000000000014, 88.000000000000014, 47.000000000000007},
                {-44.561548917732352, 88.000000000000014, 45.345051720811405},
                {-44.000000000000007, 85.520309123308778, 47.000000000000007}};
  // As the run had them (positively oriented): 13014 822 38684 829, 38684 822 38459 36645,
  // 822 13014 38684 38459, 822 38684 829 36645.
  tets.tets = {{2, 0, 1, 3}, {1, 0, 5, 4}, {0, 2, 1, 5}, {0, 1, 3, 4}};
  tets.tet_solid.assign(4, 1);
  // The surface: the shell's eight outer faces (each face of a tet not shared with another).
  SurfaceMesh surface;
  surface.mesh.nodes = tets.nodes;
  // Each tet face by its sorted corners, with its outward corners and how many tets hold it.
  std::map<std::array<std::int32_t, 3>, std::pair<std::array<std::int32_t, 3>, int>> faces;
  const int outward[4][3] = {{1, 3, 2}, {0, 2, 3}, {0, 3, 1}, {0, 1, 2}};
  for (const auto& t : tets.tets)
    for (const auto& f : outward) {
      const std::array<std::int32_t, 3> face = {t[f[0]], t[f[1]], t[f[2]]};
      std::array<std::int32_t, 3> key = face;
      std::sort(key.begin(), key.end());
      auto& [corners, count] = faces[key];
      corners = face;
      ++count;
    }
  for (const auto& [key, face] : faces)
    if (face.second == 1)
      surface.mesh.add_bface(face.first[0], face.first[1], face.first[2], -1, 1);
  ASSERT_EQ(surface.mesh.num_bfaces(), 8u);
  const TetTopology topo(tets, surface);
  RecombineState state(topo, RecombineLimits{});
  ASSERT_EQ(state.limits.sliver_quality, 0.02);
  const SliverFlips flips = flip_slivers(state);
  // Neither triangulation of the ring is better than the other by more than rounding: no flip.
  EXPECT_EQ(flips.flips, 0u);
  EXPECT_TRUE(flips.added.empty());
  EXPECT_TRUE(flips.removed.empty());
  EXPECT_EQ(flips.slivers_left, 1u);  // the sliver of the four stays
}

}  // namespace
}  // namespace hexfem
