// The whole mesher on the paper's steel part (models/steel_part.step, CAD volume 11394.6 mm^3):
// the defects a solver trips on. Flat tets on the R3 fillet (zero volume, scaled Jacobian 0)
// and boundary faces missing where a hex's quad face and the surface triangles under it split
// the quad along different diagonals (open boundary edges) were both found here.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "mesher/mesh/error.hpp"
#include "mesher/mesh/mesh_stats.hpp"
#include "mesher/mesh/quality.hpp"
#include "mesher/mesh_reports.hpp"
#include "mesher/pipeline.hpp"

namespace hexfem {
namespace {

const std::string kSteelPart = std::string(HEXFEM_SOURCE_DIR) + "/models/steel_part.step";

// Checks every validity property on the mesh of `path` at size h, every cell with a min scaled
// Jacobian above min_sj; returns the stats.
MeshStats check_part(const std::string& path, double h, double min_sj) {
  MeshOptions o;
  o.surface.h = h;
  MeshReport r;
  const MixedMesh m = mesh_file(path, o, &r);
  const MeshStats st = compute_stats(m);
  const VolumeReport& v = r.volume;
  SCOPED_TRACE(path + ", h = " + std::to_string(h));

  // Every cell clearly positive: no inverted, no flat cell, a sane min scaled Jacobian per kind.
  EXPECT_EQ(st.inverted, 0u);
  EXPECT_EQ(st.degenerate, 0u);
  for (int k = 0; k < kNumCellKinds; ++k) {
    if (!st.cells_per_kind[k]) continue;
    EXPECT_GT(st.min_sj_per_kind[k], min_sj) << kind_name(static_cast<CellKind>(k));
  }
  double min_cell = 1;
  for (std::size_t c = 0; c < m.num_cells(); ++c)
    min_cell = std::min(min_cell, cell_min_scaled_jacobian(m, c));
  EXPECT_GT(min_cell, min_sj);

  // A closed boundary: every boundary edge in exactly two boundary faces, and the stored
  // boundary faces are the cells' unmatched faces.
  EXPECT_TRUE(st.watertight);
  EXPECT_EQ(st.open_boundary_edges, 0u);
  EXPECT_EQ(st.num_boundary_faces, st.boundary_faces_derived);

  // Each TetGen tet used once: in an element, absorbed as a flat sliver, replaced by a flip,
  // dropped as a flat tet on the surface, or a tet of its own.
  const std::size_t tet_cells = st.cells_per_kind[static_cast<int>(CellKind::Tet4)];
  EXPECT_GE(tet_cells, v.tets_from_flips);
  EXPECT_EQ(v.tets_in_elements + v.absorbed_slivers + v.flipped_tets + v.flat_boundary_tets +
                tet_cells - v.tets_from_flips,
            v.tets);
  // The cells (their exact volumes, from the statistics) cover TetGen's tets (summed in the
  // pipeline before recombination): within the gap budget of twisted quad faces against tets
  // (VolumeOptions::max_total_gap, 8e-4, README "volume gap").
  EXPECT_NEAR(st.volume, v.volume_tets, VolumeOptions{}.max_total_gap * v.volume_tets);
  return st;
}

void check_steel_part(double h) {
  const MeshStats st = check_part(kSteelPart, h, 0.01);
  // And the CAD part: the chords of the fillets and holes cut a little off or on.
  EXPECT_LT(std::abs(st.volume - 11394.6018) / 11394.6018, 0.005);
  EXPECT_GT(st.h_vol, 80.0);
}

TEST(SteelPart, H2HasNoFlatCellsAndAClosedBoundary) {
  check_steel_part(2.0);
}
TEST(SteelPart, H1HasNoFlatCellsAndAClosedBoundary) {
  check_steel_part(1.0);
}

// Thin webs and blends: at h = bbox diagonal / 30 an interior hex face had a surface triangle
// on three corners (open edges), at / 60 a flat tet was boxed in by pyramids.
TEST(ControlArm, CoarseAndFineHaveNoFlatCellsAndAClosedBoundary) {
  const std::string arm = std::string(HEXFEM_TEST_DATA) + "/0049_control_arm.step";
  // Slivers the flips cannot improve remain there (min 0.005 / 0.008 measured).
  check_part(arm, 10.1, 0.002);
  check_part(arm, 5.04862, 0.002);
}

// The NC repair once undid a prism with a flat sliver absorbed on its face: the freed sliver
// stayed a flat cell (cone at h = bbox diagonal / 60).
TEST(Cone, NcRepairFreesNoFlatSliver) {
  check_part(std::string(HEXFEM_TEST_DATA) + "/Cone_1.brep", 6.87184, 1e-3);
}

}  // namespace
}  // namespace hexfem

namespace hexfem {
namespace {

// The tie rod (inch) at h = bounding-box diagonal / 30: a flat tet of four coplanar surface
// vertices stayed boxed in by pyramids the NC repair made, so no flip or lift could remove it and
// the mesh was refused for a flat cell (issue 14). The fallback undoes the elements at its
// edges and flips again.
TEST(TieRod, FlatCellFallbackLeavesNoFlatCell) {
  MeshOptions o;
  o.surface.h = 4.27121;
  o.surface.repair = false;  // the mesh at this h, not the one meshed again for its volume
  // The flat tet comes with the surface packed face by face (the default until session 28);
  // with the thin-wall alignment this h needs no fallback.
  o.surface.align_opposite = 0;
  MeshReport r;
  const MixedMesh m = mesh_file(std::string(HEXFEM_TEST_DATA) + "/tie_rod.step", o, &r);
  const MeshStats st = compute_stats(m);
  EXPECT_EQ(st.inverted, 0u);
  EXPECT_EQ(st.degenerate, 0u);
  EXPECT_TRUE(st.watertight);
  EXPECT_GT(r.volume.flat_fallback_undone, 0u);  // the fallback is what made it valid
  EXPECT_NEAR(st.volume, r.volume.volume_tets, 1e-3 * r.volume.volume_tets);
}

}  // namespace
}  // namespace hexfem

namespace hexfem {
namespace {

// The same rod at h = diagonal / 30 loses 18.7 % of its volume to the chords of its 11 mm
// shank; the mesher meshes it again with a curvature bound and says so.
TEST(TieRod, CoarseSizeIsMeshedAgainWithACurvatureBound) {
  MeshOptions o;
  o.surface.h = 4.27121;
  MeshReport r;
  const MixedMesh m = mesh_file(std::string(HEXFEM_TEST_DATA) + "/tie_rod.step", o, &r);
  const CadModel cad = CadModel::read(std::string(HEXFEM_TEST_DATA) + "/tie_rod.step");
  const MeshStats st = compute_stats(m);
  EXPECT_EQ(st.degenerate + st.inverted, 0u);
  EXPECT_LT(std::abs(st.volume - cad.volume()) / cad.volume(), 0.05);
  EXPECT_EQ(r.surface.curvature_used, 16);
  ASSERT_FALSE(r.warnings.empty());
  EXPECT_NE(r.warnings[0].find("curvature bound of 16"), std::string::npos) << r.warnings[0];
  // The --json stages add up to the total, the first mesh's time listed on its own: the report
  // of the mesh kept has only its own stages.
  nlohmann::json j;
  to_json(j, r);
  double sum = 0;
  for (const auto& stage : j["pipeline_stages"]) sum += stage["seconds"].get<double>();
  EXPECT_NEAR(sum, r.total_seconds, 1e-9);
  EXPECT_EQ(j["pipeline_stages"].back()["name"], "earlier attempts (meshed again)");
  EXPECT_GT(j["pipeline_stages"].back()["seconds"].get<double>(), 0.05);
}

}  // namespace
}  // namespace hexfem

namespace hexfem {
namespace {

// Propeller.rle meshed with `o`: valid, watertight, within 5 % of the CAD volume; the report.
MeshReport expect_propeller_is_the_part(const MeshOptions& o) {
  const std::string path = std::string(HEXFEM_TEST_DATA) + "/Propeller.rle";
  MeshReport r;
  const MeshStats st = compute_stats(mesh_file(path, o, &r));
  const double cad_volume = CadModel::read(path).volume();
  EXPECT_EQ(st.degenerate + st.inverted, 0u);
  EXPECT_TRUE(st.watertight);
  EXPECT_LT(std::abs(st.volume - cad_volume) / cad_volume, 0.05);
  return r;
}

// Propeller at h = diagonal / 30: its thin twisted blades lose 18 % of the volume to chords,
// still 11.3 % at a curvature bound of 16 (refused by `hexfem mesh` past 10 % before); the bound
// is doubled while the mesh stays past 5 % and gets closer, here to 32: -2.9 %.
TEST(Propeller, CurvatureBoundIsDoubledUntilTheMeshIsThePart) {
  MeshOptions o;
  o.surface.h = 45.3;
  const MeshReport r = expect_propeller_is_the_part(o);
  EXPECT_EQ(r.surface.curvature_used, 32);
  ASSERT_FALSE(r.warnings.empty());
  // The first try's figure, as the warning gives it: the chords' loss, give or take what the
  // elements' bilinear faces add (-18.0 % with the greedy selection, -18.1 % with the swaps).
  const std::string& w = r.warnings[0];
  const auto at = w.find(" was ");
  ASSERT_NE(at, std::string::npos) << w;
  const double off = std::stod(w.substr(at + 5));
  EXPECT_LT(off, -17.5) << w;
  EXPECT_GT(off, -18.5) << w;
}

// The same part at h = diagonal / 20 with modal's order-2 curvature default (12 per turn, never
// finer than h/2): -17.5 % at every bound, since the floor keeps the blades' edges coarse, while
// no bound at all gives -3.7 %; `modal --order 2` refused it. The bound now goes on without the
// floor before the part is refused (48 per turn: -1.8 %).
TEST(Propeller, TheOrder2CurvatureFloorIsDroppedWhenItKeepsTheMeshOff) {
  MeshOptions o;
  o.surface.h = 67.9339;
  o.surface.curvature = 12;
  o.surface.curvature_min_ratio = 0.5;
  const MeshReport r = expect_propeller_is_the_part(o);
  ASSERT_FALSE(r.warnings.empty());
  EXPECT_NE(r.warnings[0].find("no floor at h/2"), std::string::npos) << r.warnings[0];
}

// The AS1 assembly's bodies touch (a nut on its rod): one conforming mesh cannot hold them, and
// the refusal says so in the CAD's terms instead of reporting a TetGen failure.
TEST(Assembly, TouchingSolidsAreRefusedByName) {
  MeshOptions o;
  o.surface.h = 8.79;
  try {
    mesh_file(std::string(HEXFEM_TEST_DATA) + "/as1-oc-214.stp", o);
    FAIL() << "the assembly's touching solids were meshed";
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("solids 1 and 3 of the CAD model touch or overlap"), std::string::npos)
        << what;
    EXPECT_EQ(what.find("TetGen"), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
}

}  // namespace
}  // namespace hexfem

namespace hexfem {
namespace {

// A part meshed at h with `o` after the local refinement of the faces in `faces`: valid,
// watertight, within `tol` of the CAD volume; those faces among the refined ones, and the
// warning naming the defect.
void expect_refined_and_valid(const std::string& path, const MeshOptions& o,
                              const std::vector<int>& faces, const std::string& defect,
                              double tol) {
  MeshReport r;
  const MeshStats st = compute_stats(mesh_file(path, o, &r));
  EXPECT_EQ(st.inverted + st.degenerate, 0u);
  EXPECT_TRUE(st.watertight);
  for (int f : faces)
    EXPECT_TRUE(std::binary_search(r.refined_faces.begin(), r.refined_faces.end(), f)) << f;
  EXPECT_LE(r.refined_faces.size(), 12u);  // local: a few of the part's faces
  ASSERT_FALSE(r.warnings.empty());
  EXPECT_NE(r.warnings[0].find("meshed again at h/"), std::string::npos) << r.warnings[0];
  EXPECT_NE(r.warnings[0].find(defect), std::string::npos) << r.warnings[0];
  const double cad_volume = CadModel::read(path).volume();
  EXPECT_LT(std::abs(st.volume - cad_volume) / cad_volume, tol);
}

// 917_fusee (a cast steering knuckle, units metre) at h = 28.7295 mm (its diagonal / 15): a
// B-spline face meets its planar neighbour at a knife edge, and at this h one of its triangles
// lies on two of the neighbour's, facing the other way: a pocket of zero thickness that TetGen
// fills with two flat tets, which no flip, lift or interior point removes. The faces under the
// flat cells (the knife edge's two among them) are meshed again at h/2, and the mesh is valid.
TEST(Fusee, FlatCellsOnAKnifeEdgeGoWhenTheirFacesAreMeshedFiner) {
  const std::string path = std::string(HEXFEM_TEST_DATA) + "/917_fusee.stp";
  MeshOptions o;
  o.surface.h = 28.7295;
  o.surface.repair = false;  // the mesh at h alone
  EXPECT_THROW(mesh_file(path, o), LocalMeshError);
  o.surface.repair = true;
  expect_refined_and_valid(path, o, {105, 122}, "flat or inverted cells", 0.05);
}

// 40mm_capot at h = 14.644 mm (its diagonal / 15) with the curvature bound `modal` uses at order
// 2 (12 per turn, never finer than h/2): triangles of CAD face 6 cross faces 99 and 120, and
// TetGen refuses the surface. The faces of the crossing triangles are meshed again finer (h/2
// still crosses, with more faces; h/4 does not), and the mesh is valid.
// What this process and its children write to file descriptor 2 while it lives.
class StderrCapture {
 public:
  explicit StderrCapture(std::string path) : path_(std::move(path)) {
    std::fflush(stderr);
    saved_ = ::dup(2);
    const int fd = ::open(path_.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    ::dup2(fd, 2);
    ::close(fd);
  }
  ~StderrCapture() { restore(); }
  std::string text() {
    restore();
    std::ifstream in(path_);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  }

 private:
  void restore() {
    if (saved_ < 0) return;
    std::fflush(stderr);
    ::dup2(saved_, 2);
    ::close(saved_);
    saved_ = -1;
  }
  std::string path_;
  int saved_ = -1;
};

TEST(Capot, FacesWhoseTrianglesCrossAreMeshedFiner) {
  const std::string path = std::string(HEXFEM_TEST_DATA) + "/40mm_capot.stp";
  MeshOptions o;
  o.surface.h = 14.644;
  o.surface.curvature = 12;
  o.surface.curvature_min_ratio = 0.5;
  o.surface.repair = false;  // the mesh at h alone
  // TetGen (in a child process) crashes on its own error; glibc's report of it ("free():
  // invalid pointer") must not reach the user's terminal.
  StderrCapture capture(std::string(HEXFEM_WORK_DIR) + "/capot_stderr.txt");
  try {
    mesh_file(path, o);
    ADD_FAILURE() << "the surface at h was expected to cross itself";
  } catch (const LocalMeshError& e) {
    EXPECT_NE(std::string(e.what()).find("intersects itself"), std::string::npos) << e.what();
    EXPECT_TRUE(std::binary_search(e.cad_faces.begin(), e.cad_faces.end(), 6));
  }
  EXPECT_EQ(capture.text(), "");
  o.surface.repair = true;
  expect_refined_and_valid(path, o, {6}, "crossed itself", 0.02);
}

}  // namespace
}  // namespace hexfem
