// Fixed-DOF selection: CAD faces, physical groups, coordinate conditions, components, errors.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "fem/boundary.hpp"
#include "mesher/mesh/error.hpp"
#include "mesher/mesh/structured_box.hpp"

namespace hexfem {
namespace {

MixedMesh beam() {
  return make_box_mesh({10, 2, 1}, 10, 2, 1, CellKind::Hex8);
}

TEST(Boundary, FaceSelectsItsNodes) {
  const MixedMesh m = beam();
  const NodeSelection s = select_fixed_nodes(m, "face:1");
  EXPECT_EQ(s.nodes.size(), 3u * 2u);  // (ny+1)(nz+1) nodes at x = 0
  for (std::int32_t v : s.nodes) EXPECT_EQ(m.nodes[v][0], 0.0);
  EXPECT_TRUE(s.component[0] && s.component[1] && s.component[2]);
  EXPECT_EQ(select_fixed_nodes(m, "face:1,2").nodes.size(), 12u);
}

TEST(Boundary, CoordinateConditionsAndComponents) {
  const MixedMesh m = beam();
  const NodeSelection s = select_fixed_nodes(m, "z<1e-9 & x>9.5 @xz");
  EXPECT_EQ(s.nodes.size(), 3u);  // bottom edge at x = 10
  EXPECT_TRUE(s.component[0]);
  EXPECT_FALSE(s.component[1]);
  EXPECT_TRUE(s.component[2]);
  const std::vector<std::uint8_t> mask = select_fixed_dofs(m, {"z<1e-9&x>9.5@xz", "face:1@y"});
  int fixed = 0;
  for (auto b : mask) fixed += b;
  EXPECT_EQ(fixed, 3 * 2 + 6 * 1);
  EXPECT_EQ(select_fixed_nodes(m, "x<=0").nodes.size(), 6u);
  EXPECT_EQ(select_fixed_nodes(m, "x>=10").nodes.size(), 6u);
}

TEST(Boundary, PhysicalGroupByNameOrTag) {
  MixedMesh m = beam();
  for (std::size_t f = 0; f < m.num_bfaces(); ++f)
    if (m.bface_cad_face[f] == 2) m.bface_physical[f] = 7;
  m.physical_names[{2, 7}] = "clamp";
  EXPECT_EQ(select_fixed_nodes(m, "group:clamp").nodes.size(), 6u);
  EXPECT_EQ(select_fixed_nodes(m, "group:7").nodes.size(), 6u);
  EXPECT_THROW(select_fixed_nodes(m, "group:nothere"), Error);
}

TEST(Boundary, EmptyOrBadSelectionIsAnError) {
  const MixedMesh m = beam();
  for (const char* spec : {"face:9", "x<-1", "x<0.5&x>0.6", "w<1", "x=<1", "x<abc", "face:a",
                           "face:1@q", "face:1@", "", "@x"}) {
    EXPECT_THROW(select_fixed_nodes(m, spec), Error) << spec;
  }
  try {
    select_fixed_nodes(m, "x<-1");
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("selects no node"), std::string::npos) << e.what();
  }
}

// One parser for the solver and the CLI (issue 17): it needs no mesh, and a face id is an
// integer written as one. Before, the solver read "face:3.0" as face 3 and the CLI refused it.
TEST(Boundary, OneParserWithoutAMesh) {
  const FixSpec f = parse_fix_spec(" face:3, 7 @xz ");
  EXPECT_EQ(f.kind, FixSpec::Kind::Faces);
  EXPECT_EQ(f.faces, (std::vector<int>{3, 7}));
  EXPECT_TRUE(f.component[0] && !f.component[1] && f.component[2]);
  const FixSpec c = parse_fix_spec("x<=1e-3&z>2");
  ASSERT_EQ(c.kind, FixSpec::Kind::Coordinates);
  ASSERT_EQ(c.conditions.size(), 2u);
  EXPECT_EQ(c.conditions[1].axis, 2);
  EXPECT_EQ(c.conditions[0].op, "<=");
  EXPECT_EQ(c.conditions[0].value, 1e-3);
  EXPECT_EQ(parse_fix_spec("group:clamp").group, "clamp");
  for (const char* spec : {"face:3.0", "face:+3", "face:0", "face:-1", "face:3e0",
                           "face:", "group:", "x<nan", "x<inf", "face:99999999999"})
    EXPECT_THROW(parse_fix_spec(spec), Error) << spec;
  const MixedMesh m = beam();
  EXPECT_THROW(select_fixed_nodes(m, "face:1.0"), Error);
}

TEST(Boundary, CountsTheRigidMotionsAFixedSetDoesNotHold) {
  // Counted by hand: what can still move rigidly when these DOFs are held.
  const MixedMesh m = beam();
  auto unheld = [&](std::vector<std::string> specs) {
    return count_unheld_rigid_motions(m, select_fixed_dofs(m, specs));
  };
  EXPECT_EQ(unheld({"face:1"}), 0);    // clamped end
  EXPECT_EQ(unheld({"face:1@x"}), 3);  // slides in y, z; turns about x
  // In-plane components only: slides along x, and tilts about y and z axes lying in the face.
  EXPECT_EQ(unheld({"face:1@yz"}), 3);
  EXPECT_EQ(unheld({"x<1e-9&y<1e-9&z<1e-9"}), 3);  // one pinned corner: three rotations
  EXPECT_EQ(unheld({"x<1e-9&z<1e-9"}), 1);         // pinned edge: the rotation about it
  EXPECT_EQ(unheld({"x<1e-9&z<1e-9", "x>9.99&y<1e-9&z<1e-9@z"}), 0);
  // FV52-like: u_z on the bottom edges leaves the in-plane motions (x, y, rotation about z).
  EXPECT_EQ(unheld({"z<1e-9&x<1e-9@z", "z<1e-9&x>9.99@z", "z<1e-9&y<1e-9@z", "z<1e-9&y>1.99@z"}),
            3);
}

TEST(Boundary, EliminationNumbersOnlyFreeDofsOfUsedNodes) {
  MixedMesh m = beam();
  m.nodes.push_back({50, 50, 50});  // a node no cell uses gets no DOF
  const std::vector<std::uint8_t> mask = select_fixed_dofs(m, {"face:1"});
  const DofMap map = number_free_dofs(m, mask);
  EXPECT_EQ(map.num_fixed, 18);
  EXPECT_EQ(map.num_free, 3 * 66 - 18);
  EXPECT_EQ(map.dof[3 * 66], -1);
  // A permuted node order numbers in that order.
  std::vector<std::int32_t> order(m.nodes.size());
  for (std::size_t i = 0; i < order.size(); ++i)
    order[i] = static_cast<std::int32_t>(order.size() - 1 - i);
  const DofMap rev = number_free_dofs(m, mask, order);
  EXPECT_EQ(rev.num_free, map.num_free);
  EXPECT_EQ(rev.dof[3 * 65 + 0], 0);  // node 65 is the first used node in reverse order
}

}  // namespace
}  // namespace hexfem
