// End to end on the bundled steel part: CAD -> hex-dominant mesh -> frequencies, compared with
// the independent reference (Gmsh tet10 + CalculiX C3D10, Richardson; validation/reference/).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <vector>

#include "app/part_modal.hpp"
#include "fem/material.hpp"
#include "mesher/mesh/error.hpp"
#include "mesher/mesh/mesh_stats.hpp"

namespace hexfem {
namespace {

const std::string kSteelPart = std::string(HEXFEM_SOURCE_DIR) + "/models/steel_part.step";
const std::string kReference =
    std::string(HEXFEM_SOURCE_DIR) + "/validation/reference/steel_part.json";
constexpr int kClampedFace = 8;  // the face at x = 0 (models/README.md)

ModalOptions clamped_steel(int modes = 4) {
  ModalOptions o;
  o.material = material_by_name("steel");
  o.fix = {"face:" + std::to_string(kClampedFace)};
  o.num_modes = modes;
  return o;
}

TEST(PartPipeline, SteelPartMeshIsValidAndDeterministic) {
  const CadModel cad = CadModel::read(kSteelPart);
  MeshOptions options;
  options.surface.h = 2.0;
  MeshReport report;
  const MixedMesh a = mesh_part(cad, options, &report);
  const MeshStats s = compute_stats(a);
  EXPECT_EQ(s.inverted, 0u);
  EXPECT_EQ(s.degenerate, 0u);
  EXPECT_TRUE(s.watertight) << s.open_boundary_edges << " open boundary edges";
  EXPECT_GT(s.h_vol, 70.0);
  // Curved faces (holes, fillet) are polygons at h = 2: the volume is within 1 %.
  EXPECT_NEAR(s.volume, cad.volume(), 0.01 * cad.volume());
  const MixedMesh b = mesh_part(cad, options);
  EXPECT_EQ(a.nodes, b.nodes);
  EXPECT_EQ(a.cell_nodes, b.cell_nodes);
  EXPECT_EQ(a.bface_nodes, b.bface_nodes);
}

// The regression: meshed and solved here, the first four frequencies within 0.5 % of
// the independent reference (gmsh tet10 + CalculiX C3D10, Richardson extrapolated). At h = 0.7
// they come out at +0.20, +0.09, +0.21, +0.39 % (h = 1 leaves f4 at +0.74 %).
TEST(PartPipeline, SteelPartFrequenciesMatchTheIndependentReference) {
  std::ifstream in(kReference);
  ASSERT_TRUE(in) << kReference;
  const std::vector<double> reference =
      nlohmann::json::parse(in)["reference_hz"].get<std::vector<double>>();
  ASSERT_GE(reference.size(), 4u);
  const CadModel cad = CadModel::read(kSteelPart);
  MeshOptions options;
  options.surface.h = 0.7;
  ModalOptions modal = clamped_steel(4);
  modal.incompatible_hex = true;  // the CLI's default
  const PartModalResult r = run_part_modal(cad, options, modal);
  ASSERT_EQ(r.modal.frequencies.size(), 4u);
  for (int i = 0; i < 4; ++i) {
    const double error = r.modal.frequencies[i] / reference[i] - 1;
    std::printf("f%d = %.3f Hz, reference %.3f Hz, error %+.3f %%\n", i + 1, r.modal.frequencies[i],
                reference[i], 100 * error);
    EXPECT_LT(std::abs(error), 0.005) << "mode " << i + 1;
  }
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(PartPipeline, BadInputIsReported) {
  const CadModel cad = CadModel::read(kSteelPart);
  MeshOptions options;
  options.surface.h = 2.0;
  ModalOptions missing = clamped_steel();
  missing.fix = {"face:99"};
  EXPECT_NE(error_of([&] { run_part_modal(cad, options, missing); }).find("face 99 does not exist"),
            std::string::npos);
  ModalOptions sliding = clamped_steel();
  sliding.fix = {"face:8@x"};  // only the axial component: the part slides and turns
  EXPECT_NE(error_of([&] { run_part_modal(cad, options, sliding); }).find("free to move"),
            std::string::npos);
  MeshOptions zero = options;
  zero.surface.h = 0;
  EXPECT_NE(error_of([&] { mesh_part(cad, zero); }).find("must be > 0"), std::string::npos);
  MeshOptions huge = options;
  huge.surface.h = 1e-3;  // ~1e13 points
  EXPECT_NE(error_of([&] { mesh_part(cad, huge); }).find("--force"), std::string::npos);
}

// An h whose mesh needs more memory than the machine has is refused before any work, not killed
// by the system minutes later. The floor is 1.35 kB per estimated interior point V / h^3 (1.35 GB
// per million, below every part measured): worked out here from the CAD volume, and the limit
// set just above and just below it.
TEST(PartPipeline, AnHThatNeedsMoreMemoryThanThereIsIsRefused) {
  const CadModel cad = CadModel::read(kSteelPart);
  MeshOptions options;
  options.surface.h = 2.0;
  const double need = 1.35e3 * cad.volume() / 8.0;
  MeshOptions short_of = options;
  short_of.memory_limit_bytes = 0.9 * need;
  const std::string e = error_of([&] { mesh_part(cad, short_of); });
  char figures[200];
  std::snprintf(figures, sizeof figures, "would need at least %.1f GB of memory", need / 1e9);
  EXPECT_NE(e.find(figures), std::string::npos) << e;
  EXPECT_NE(e.find("--force"), std::string::npos) << e;
  MeshOptions enough = options;
  enough.memory_limit_bytes = 1.1 * need;
  EXPECT_GT(mesh_part(cad, enough).num_cells(), 0u);
  MeshOptions forced = short_of;
  forced.surface.force = true;
  EXPECT_GT(mesh_part(cad, forced).num_cells(), 0u);
}

// A coarse h cuts volume off a curved part (chords); the user is told by how much. The
// cylinder of tests/data: radius 6.7524 mm, length 42.5 mm (its bounding box), V = pi r^2 L.
TEST(PartPipeline, VolumeFarOffTheCadIsAWarning) {
  const CadModel cad = CadModel::read(std::string(HEXFEM_TEST_DATA) + "/cylinder.stp");
  const double exact = M_PI * 6.7524 * 6.7524 * 42.5;
  MeshOptions coarse;
  coarse.surface.h = 5.0;
  coarse.surface.repair = false;  // no second try with a curvature bound (tested on the tie rod)
  MeshReport r;
  mesh_part(cad, coarse, &r);
  const double error = (r.stats.volume - exact) / exact;
  ASSERT_GT(std::abs(error), 0.02);
  // (A second warning may say that hexes went back to tets on the chords.)
  const auto off = std::find_if(r.warnings.begin(), r.warnings.end(), [](const std::string& w) {
    return w.find("off the CAD volume") != std::string::npos;
  });
  ASSERT_NE(off, r.warnings.end());
  char pct[32];
  std::snprintf(pct, sizeof pct, "%+.1f %%", 100 * error);
  EXPECT_NE(off->find(pct), std::string::npos) << *off;
  MeshOptions fine;
  fine.surface.h = 1.0;
  MeshReport rf;
  mesh_part(cad, fine, &rf);
  EXPECT_LT(std::abs(rf.stats.volume - exact) / exact, 0.02);
  EXPECT_TRUE(rf.warnings.empty());
}

}  // namespace
}  // namespace hexfem
