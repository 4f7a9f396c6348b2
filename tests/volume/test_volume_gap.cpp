// The mixed mesh covers the tet mesh: its volume is within the 8e-4 budget of the volume the
// surface mesh encloses (which the tets fill exactly). Bilinear quad faces that no element shares
// lose volume against the tets; on a coarse cone the elements losing most must go back to tets for
// it to hold.
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <string>

#include "mesher/cad/cad_model.hpp"
#include "mesher/mesh/mesh_stats.hpp"
#include "mesher/surface_pipeline.hpp"
#include "mesher/volume_pipeline.hpp"
#include "tests/cad/cad_test_util.hpp"

namespace hexfem {
namespace {

// Volume enclosed by the outward surface triangles (divergence theorem), by hand.
double enclosed_volume(const MixedMesh& s) {
  double v = 0;
  for (std::size_t f = 0; f < s.num_bfaces(); ++f) {
    const auto* n = s.bface(f);
    const Vec3 &a = s.nodes[n[0]], &b = s.nodes[n[1]], &c = s.nodes[n[2]];
    v += (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
          a[2] * (b[0] * c[1] - b[1] * c[0])) /
         6.0;
  }
  return v;
}

struct GapRun {
  double rel_gap;  // |V(mixed) - V(enclosed by the surface)| / V(enclosed)
  MeshStats stats;
  VolumeReport report;
};

GapRun mesh_cone(double max_total_gap) {
  const CadModel cad = CadModel::read(std::string(HEXFEM_TEST_DATA) + "/Cone_1.brep");
  SurfaceOptions so;
  so.h = 13.7;  // bbox diagonal / 30: coarse, so quad faces on the cone are twisted
  const SurfaceMesh surface = mesh_surface(cad, so);
  VolumeOptions vo;
  vo.max_total_gap = max_total_gap;
  // The point and element rules this case was chosen with: unlimited, it opens a gap > 1e-3
  // (the defaults since then leave it at 6e-4, which would not exercise the limit).
  vo.inherit_frame = false;
  vo.max_volume_gap = 0.02;
  GapRun r;
  const MixedMesh m = mesh_volume(surface, vo, &r.report);
  r.stats = compute_stats(m);
  const double enclosed = enclosed_volume(surface.mesh);
  r.rel_gap = std::abs(r.stats.volume - enclosed) / enclosed;
  return r;
}

TEST(VolumeGap, CoarseConeCoversItsTetsWithinTheBudget) {
  const GapRun limited = mesh_cone(8e-4);
  EXPECT_LE(limited.rel_gap, 8e-4);
  EXPECT_EQ(limited.stats.inverted, 0u);
  EXPECT_EQ(limited.stats.degenerate, 0u);
  EXPECT_TRUE(limited.stats.watertight);
  // Without the limit the same cone misses it: the undone elements are what makes it hold.
  const GapRun unlimited = mesh_cone(1.0);
  EXPECT_GT(unlimited.rel_gap, 1e-3);
  std::size_t undone = 0;
  for (std::size_t n : limited.report.gap_undone) undone += n;
  EXPECT_GT(undone, 0u);
  // Only what is needed goes: most hexes stay.
  EXPECT_GT(limited.stats.h_vol, 0.8 * unlimited.stats.h_vol);
}

}  // namespace
}  // namespace hexfem

namespace hexfem {
namespace {

// `hexfem mesh` of the cylinder at h = 1.55 with the given --max-gap: the --json report.
nlohmann::json mesh_cylinder(const std::string& max_gap) {
  std::string out;
  EXPECT_EQ(cadtest::run_cli("mesh " + cadtest::data("cylinder.stp") + " --h 1.55 --json -o " +
                                 cadtest::work("gap_cylinder.msh").string() +
                                 (max_gap.empty() ? "" : " --max-gap " + max_gap),
                             &out),
            0)
      << out;
  const auto brace = out.find('{');
  return brace == std::string::npos ? nlohmann::json{} : nlohmann::json::parse(out.substr(brace));
}

// When the volume-gap stage sends back more than a tenth of the hexes (here forced by a budget
// of 1e-6; on 1385_Laufrad at h = 8 the default 8e-4 sends back 38,619 of 81,576 and H_vol falls
// from 78 to 41 %), the report says how many and which --max-gap keeps them; that budget does.
TEST(VolumeGap, HexesSentBackForTheGapAreReported) {
  const nlohmann::json tight = mesh_cylinder("1e-6");
  ASSERT_TRUE(tight.contains("warnings"));
  const std::size_t undone = tight["undone_for_volume_gap"]["hex8"];
  ASSERT_GT(undone, 0u);
  std::string warning;
  for (const auto& w : tight["warnings"])
    if (w.get<std::string>().find("hexes went back to tets") != std::string::npos) warning = w;
  ASSERT_FALSE(warning.empty()) << tight["warnings"].dump();
  EXPECT_EQ(warning.rfind(std::to_string(undone) + " of ", 0), 0u) << warning;
  const auto at = warning.find("--max-gap ");
  ASSERT_NE(at, std::string::npos) << warning;
  const std::size_t from = at + 10;
  const std::string keep =
      warning.substr(from, warning.find_first_not_of("0123456789.e+-", from) - from);
  const nlohmann::json kept = mesh_cylinder(keep);
  EXPECT_EQ(kept["undone_for_volume_gap"].value("hex8", 0), 0) << keep;
  EXPECT_GT(kept["h_vol_percent"].get<double>(), tight["h_vol_percent"].get<double>());
  for (const auto& w : kept["warnings"])
    EXPECT_EQ(w.get<std::string>().find("hexes went back"), std::string::npos) << w;
  // The default budget sends none of this mesh's hexes back: no such warning.
  for (const auto& w : mesh_cylinder("")["warnings"])
    EXPECT_EQ(w.get<std::string>().find("hexes went back"), std::string::npos) << w;
}

}  // namespace
}  // namespace hexfem
