// GeometryProjector keeps its OCCT projectors from one point to the next; its answers must be
// those of closest_point_on_geometry, which makes a fresh projector for every point.
#include <gtest/gtest.h>

#include <cstdint>
#include <optional>

#include "cad_test_util.hpp"
#include "mesher/cad/cad_model.hpp"
#include "mesher/cad/cad_project.hpp"

namespace hexfem {
namespace {

using cadtest::data;

// The Propeller's B-spline blades and the curved edges between its faces: points scattered
// around every face's centroid (faces in a shuffled order, so that each projector is used again
// after others), and around points of every edge shared by two faces.
TEST(GeometryProjector, GivesWhatAFreshProjectorGives) {
  const CadModel cad = CadModel::read(data("Propeller.rle"));
  GeometryProjector projector(cad);
  std::uint64_t x = 7;
  auto jitter = [&](double scale) {
    x = x * 6364136223846793005ull + 1442695040888963407ull;
    return scale * (static_cast<double>(x >> 11) / 9007199254740992.0 - 0.5);
  };
  int compared = 0, on_edges = 0;
  for (int round = 0; round < 3; ++round) {
    for (int k = 0; k < cad.num_faces(); ++k) {
      const int f = 1 + (k * 37 + round * 11) % cad.num_faces();
      const Vec3 c = cad.face_centroid(f);
      const Vec3 p{c[0] + jitter(20), c[1] + jitter(20), c[2] + jitter(20)};
      const std::optional<Vec3> fresh = closest_point_on_geometry(cad, p, f, f);
      const std::optional<Vec3> kept = projector.closest(p, f, f);
      ASSERT_EQ(fresh.has_value(), kept.has_value()) << "face " << f;
      if (fresh) {
        EXPECT_EQ(*fresh, *kept) << "face " << f;
      }
      ++compared;
    }
    for (int e = 1; e <= cad.num_edges(); ++e) {
      const std::vector<int>& faces = cad.faces_of_edge(e);
      if (cad.edge_degenerate(e) || faces.size() < 2 || faces[0] == faces[1]) continue;
      const Vec2 r = cad.edge_range(e);
      const Vec3 q = cad.edge_point(e, r[0] + (0.25 + 0.25 * round) * (r[1] - r[0]));
      const Vec3 p{q[0] + jitter(5), q[1] + jitter(5), q[2] + jitter(5)};
      const std::optional<Vec3> fresh = closest_point_on_geometry(cad, p, faces[0], faces[1]);
      const std::optional<Vec3> kept = projector.closest(p, faces[1], faces[0]);
      ASSERT_EQ(fresh.has_value(), kept.has_value()) << "edge " << e;
      if (fresh) {
        EXPECT_EQ(*fresh, *kept) << "edge " << e;
      }
      ++on_edges;
    }
  }
  EXPECT_GT(compared, 100);
  EXPECT_GT(on_edges, 100);
  // A face id that does not exist: nothing, as for the fresh projector.
  EXPECT_FALSE(projector.closest({0, 0, 0}, cad.num_faces() + 1, cad.num_faces() + 1));
}

}  // namespace
}  // namespace hexfem
