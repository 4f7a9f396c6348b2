// make_conformal on hand-built meshes: a unit hex whose bottom face is NC against the cells
// below it. Expected counts and volumes are worked out by hand for each case.
#include <gtest/gtest.h>

#include <map>
#include <vector>

#include "mesher/conformal.hpp"
#include "mesher/mesh/conformity.hpp"
#include "mesher/mesh/face_keys.hpp"
#include "mesher/mesh/mesh_stats.hpp"
#include "mesher/mesh/quality.hpp"

namespace hexfem {
namespace {

constexpr int kHex = static_cast<int>(CellKind::Hex8), kPyr = static_cast<int>(CellKind::Pyramid5),
              kTet = static_cast<int>(CellKind::Tet4);

// The unit hex [0,1]^3: nodes 0..7 (bottom a=0 (0,0,0), b=1 (1,0,0), c=2 (1,1,0), e=3 (0,1,0)).
MixedMesh unit_hex() {
  MixedMesh m;
  for (double z : {0.0, 1.0}) {
    m.nodes.push_back({0, 0, z});
    m.nodes.push_back({1, 0, z});
    m.nodes.push_back({1, 1, z});
    m.nodes.push_back({0, 1, z});
  }
  m.add_cell(CellKind::Hex8, {0, 1, 2, 3, 4, 5, 6, 7});
  return m;
}

std::int32_t add_node(MixedMesh& m, const Vec3& x) {
  m.nodes.push_back(x);
  return static_cast<std::int32_t>(m.nodes.size() - 1);
}

// A tet given in either orientation, stored positive.
void add_tet(MixedMesh& m, std::int32_t p, std::int32_t q, std::int32_t r, std::int32_t s) {
  const Vec3 x[4] = {m.nodes[p], m.nodes[q], m.nodes[r], m.nodes[s]};
  if (min_scaled_jacobian(CellKind::Tet4, x) < 0) std::swap(q, r);
  m.add_cell(CellKind::Tet4, {p, q, r, s});
}

double total_volume(const MixedMesh& m) {
  double v = 0;
  for (std::size_t c = 0; c < m.num_cells(); ++c) v += cell_volume(m, c);
  return v;
}

// What every case checks after the pass: no NC quad left (counted from the faces, not the
// report), no cell inverted or flat, a closed boundary, the region's volume kept.
void expect_conformal_and_valid(const MixedMesh& m, double volume) {
  EXPECT_EQ(count_quad_faces(m).nonconformal, 0u);
  const MeshStats s = compute_stats(m);
  EXPECT_EQ(s.inverted, 0u);
  EXPECT_EQ(s.degenerate, 0u);
  EXPECT_TRUE(s.watertight) << s.open_boundary_edges << " open boundary edges";
  EXPECT_NEAR(total_volume(m), volume, 1e-12 * std::max(1.0, volume));
}

TEST(Conformal, TwoTetsSharingAnApexBecomeThePyramid) {
  // The lower cube's Kuhn tets on the hex's bottom diagonal (0,0,0)-(1,1,0): both contain
  // (0,0,-1), so with the quad they are the pyramid of height 1 (volume 1/3).
  MixedMesh m = unit_hex();
  const std::int32_t p = add_node(m, {0, 0, -1});
  add_tet(m, p, 0, 1, 2);
  add_tet(m, p, 0, 3, 2);
  flag_nonconformal_quads(m);
  ASSERT_EQ(m.nc_cell.size(), 1u);
  const ConformalReport r = make_conformal(m);
  EXPECT_EQ(r.nc_before, 1u);
  EXPECT_EQ(r.nc_after, 0u);
  EXPECT_EQ(r.pyramids, 1u);
  EXPECT_EQ(r.shell_pyramids, 1u);
  EXPECT_EQ(r.steiner_points, 0u);
  EXPECT_EQ(m.nodes.size(), 9u);
  const MeshStats s = compute_stats(m);
  EXPECT_EQ(s.cells_per_kind[kHex], 1u);
  EXPECT_EQ(s.cells_per_kind[kPyr], 1u);
  EXPECT_EQ(s.cells_per_kind[kTet], 0u);
  expect_conformal_and_valid(m, 1.0 + 1.0 / 3);
}

TEST(Conformal, ThreeTetShellGetsAPyramidAndSixTetsAroundANewNode) {
  // Tets (a,c,b,P), (a,c,P,R), (a,c,R,e) around the diagonal a-c below the hex: no apex is
  // shared, so a new node s fills the shell: the pyramid on the quad, (a,u,w,s) and (c,u,w,s)
  // for each tet. The hex stays.
  MixedMesh m = unit_hex();
  const std::int32_t p = add_node(m, {0.75, 0.25, -0.5});
  const std::int32_t q = add_node(m, {0.25, 0.75, -0.5});
  add_tet(m, 0, 2, 1, p);
  add_tet(m, 0, 2, p, q);
  add_tet(m, 0, 2, q, 3);
  flag_nonconformal_quads(m);
  ASSERT_EQ(m.nc_cell.size(), 1u);
  const double volume = total_volume(m);
  const ConformalReport r = make_conformal(m);
  EXPECT_EQ(r.pyramids, 1u);
  EXPECT_EQ(r.shell_pyramids, 0u);
  EXPECT_EQ(r.steiner_points, 1u);
  EXPECT_EQ(r.failed, 0u);
  EXPECT_EQ(m.nodes.size(), 11u);
  const MeshStats s = compute_stats(m);
  EXPECT_EQ(s.cells_per_kind[kHex], 1u);
  EXPECT_EQ(s.cells_per_kind[kPyr], 1u);
  EXPECT_EQ(s.cells_per_kind[kTet], 6u);
  EXPECT_DOUBLE_EQ(r.hex_volume_after, 1.0);
  expect_conformal_and_valid(m, volume);
}

TEST(Conformal, AHexWithAPyramidAcrossItsDiagonalIsSplitAboutItsCentre) {
  // Under the bottom face: the tet (a,b,c,P) and a pyramid whose side (c,a,e) holds the
  // diagonal a-c, so no tet shell can be filled there: the hex goes, split about a new node
  // into two tets on its bottom (the far side's triangles) and five pyramids on its other
  // faces. Volumes by hand: hex 1, tet 1/6, pyramid 1/3 (base sqrt(2) x 1, height 1/sqrt(2)).
  MixedMesh m = unit_hex();
  const std::int32_t p = add_node(m, {1, 0, -1});
  const std::int32_t x = add_node(m, {0, 0, -1});
  const std::int32_t y = add_node(m, {1, 1, -1});
  add_tet(m, 0, 1, 2, p);
  {
    std::int32_t pyr[5] = {0, x, y, 2, 3};
    const Vec3 c[5] = {m.nodes[0], m.nodes[x], m.nodes[y], m.nodes[2], m.nodes[3]};
    if (min_scaled_jacobian(CellKind::Pyramid5, c) < 0) std::swap(pyr[1], pyr[3]);
    m.add_cell(CellKind::Pyramid5, pyr);
  }
  flag_nonconformal_quads(m);
  ASSERT_EQ(m.nc_cell.size(), 1u);
  const ConformalReport r = make_conformal(m);
  EXPECT_EQ(r.cells_split[kHex], 1u);
  EXPECT_EQ(r.steiner_points, 1u);
  EXPECT_DOUBLE_EQ(r.hex_volume_before, 1.0);
  EXPECT_DOUBLE_EQ(r.hex_volume_after, 0.0);
  const MeshStats s = compute_stats(m);
  EXPECT_EQ(s.cells_per_kind[kHex], 0u);
  EXPECT_EQ(s.cells_per_kind[kPyr], 6u);
  EXPECT_EQ(s.cells_per_kind[kTet], 3u);
  expect_conformal_and_valid(m, 1.0 + 1.0 / 6 + 1.0 / 3);
}

// The volume inside the region's outer faces (the faces of one cell only, less the NC quads and
// their halves, which lie inside), by the divergence theorem: the cones over the faces from a
// point. What a refill of the cells about new nodes must give, whatever the cells.
double enclosed_volume(const MixedMesh& m) {
  std::map<FaceKey, int> uses;
  for (std::size_t c = 0; c < m.num_cells(); ++c) {
    const CellFaces& cf = faces_of(m.cell_kind[c]);
    for (int f = 0; f < cf.count; ++f) ++uses[face_key(m.cell(c), cf.face[f])];
  }
  std::vector<FaceKey> inside;  // the NC quads and the triangles on their corners
  for (std::size_t i = 0; i < m.nc_cell.size(); ++i)
    inside.push_back(face_key(m.cell(m.nc_cell[i]),
                              faces_of(m.cell_kind[m.nc_cell[i]]).face[m.nc_local_face[i]]));
  auto is_inside = [&](const FaceKey& k) {
    for (const FaceKey& q : inside) {
      int shared = 0;
      for (int i = 0; i < 4; ++i)
        if (k[i] >= 0 && std::find(q.begin(), q.end(), k[i]) != q.end()) ++shared;
      if (shared == (k[0] < 0 ? 3 : 4)) return true;
    }
    return false;
  };
  const Vec3 o = m.nodes[0];
  double v = 0;
  for (std::size_t c = 0; c < m.num_cells(); ++c) {
    const CellFaces& cf = faces_of(m.cell_kind[c]);
    for (int f = 0; f < cf.count; ++f) {
      const FaceKey k = face_key(m.cell(c), cf.face[f]);
      if (uses[k] != 1 || is_inside(k)) continue;
      const std::int32_t* n = m.cell(c);
      const LocalFace& lf = cf.face[f];
      if (lf.n == 3) {  // the tet with outward face (0, 2, 1) = the face
        const Vec3 x[4] = {m.nodes[n[lf.v[0]]], m.nodes[n[lf.v[2]]], m.nodes[n[lf.v[1]]], o};
        v += volume(CellKind::Tet4, x);
      } else {  // the pyramid with base (0, 3, 2, 1) outward
        const Vec3 x[5] = {m.nodes[n[lf.v[0]]], m.nodes[n[lf.v[3]]], m.nodes[n[lf.v[2]]],
                           m.nodes[n[lf.v[1]]], o};
        v += volume(CellKind::Pyramid5, x);
      }
    }
  }
  return v;
}

MixedMesh mesh_of(const std::vector<Vec3>& nodes,
                  const std::vector<std::pair<CellKind, std::vector<std::int32_t>>>& cells) {
  MixedMesh m;
  m.nodes = nodes;
  for (const auto& [kind, v] : cells) m.add_cell(kind, v.data());
  flag_nonconformal_quads(m);
  return m;
}

// True when quad {a, b, c, d} is still an NC face of `m`.
bool still_nc(const MixedMesh& m, FaceKey quad) {
  std::sort(quad.begin(), quad.end());
  for (std::size_t i = 0; i < m.nc_cell.size(); ++i)
    if (face_key(m.cell(m.nc_cell[i]),
                 faces_of(m.cell_kind[m.nc_cell[i]]).face[m.nc_local_face[i]]) == quad)
      return true;
  return false;
}

TEST(Conformal, AWedgeOnAFoldedQuadIsRefilledWithTheTwoTetsBehindIt) {
  // From 40mm_capot.stp at h = 3.66119 (translated), the NC face left before: a wedge whose
  // quad (1, 6, 5, 0) folds towards the two tets behind it (they share node 2). A pyramid on
  // the quad with apex 2 is inverted at a corner, no node inside the two tets makes one valid,
  // and the wedge cannot be split about a node of its own (a tet on the quad's half (1, 5, 0)
  // against the pyramid on its face (1, 0, 3, 4)). The wedge and the two tets go together about
  // one new node: the quad is gone.
  MixedMesh m = mesh_of({{0.058623, 0.901863, 1.326149},
                         {0.058623, 0.895954, 0.354546},
                         {0.058623, -0.085622, 0.360515},
                         {0.826094, 0.489539, -0.606988},
                         {0.826094, 1.844582, 1.316931},
                         {0.826094, 0.618730, 1.727466},
                         {0.826094, -0.575670, 0.568542}},
                        {{CellKind::Wedge6, {3, 1, 6, 4, 0, 5}},
                         {CellKind::Tet4, {1, 6, 5, 2}},
                         {CellKind::Tet4, {1, 5, 0, 2}}});
  ASSERT_EQ(m.nc_cell.size(), 1u);
  ASSERT_TRUE(still_nc(m, {1, 6, 5, 0}));
  {
    const Vec3 pyr[5] = {m.nodes[1], m.nodes[6], m.nodes[5], m.nodes[0], m.nodes[2]};
    EXPECT_LT(min_scaled_jacobian(CellKind::Pyramid5, pyr), 0);  // the fold
  }
  const double volume = enclosed_volume(m);
  const ConformalReport r = make_conformal(m);
  EXPECT_EQ(r.failed, 0u);
  EXPECT_EQ(r.nc_after, 0u);
  EXPECT_EQ(r.split_with_tets_behind, 1u);
  EXPECT_EQ(r.cells_split[static_cast<int>(CellKind::Wedge6)], 1u);
  EXPECT_FALSE(still_nc(m, {1, 6, 5, 0}));
  expect_conformal_and_valid(m, volume);
}

TEST(Conformal, AHexOnAFoldedQuadIsRefilledWithTheTetsBehindIt) {
  // From Block.stp at h = 1.39952, the NC face left before: hex face (11, 5, 8, 14), folded
  // (0.2 of its 1.9 side off its plane) towards the tets behind it; neither a pyramid on it
  // nor a split of the hex alone is valid. The hex and the tets behind go together.
  MixedMesh m = mesh_of({{8.065262, -11.393529, 4.5},
                         {7.372237, -10.343213, 6.563570},
                         {7, -8.662806, 5.820920},
                         {7.247908, -10.950740, 5.490336},
                         {7, -9.154845, 5.011600},
                         {8.078624, -8.662806, 5.820920},
                         {7, -8.010484, 5.107069},
                         {7.919138, -8.010484, 5.107069},
                         {8.657842, -10.337168, 6.573085},
                         {6.908251, -11.393529, 4.5},
                         {7, -9.571544, 4.160872},
                         {8.065262, -10.045728, 4.5},
                         {7.922931, -8.458787, 4.324225},
                         {9.25, -9.994009, 4.5},
                         {9.25, -10.806262, 5.769506}},
                        {{CellKind::Hex8, {4, 2, 1, 3, 11, 5, 8, 14}},
                         {CellKind::Pyramid5, {2, 6, 7, 5, 4}},
                         {CellKind::Pyramid5, {7, 12, 11, 5, 4}},
                         {CellKind::Pyramid5, {9, 10, 4, 3, 11}},
                         {CellKind::Tet4, {9, 0, 11, 3}},
                         {CellKind::Tet4, {11, 8, 14, 13}},
                         {CellKind::Tet4, {0, 11, 3, 14}},
                         {CellKind::Tet4, {11, 8, 13, 5}}});
  ASSERT_TRUE(still_nc(m, {11, 5, 8, 14}));
  const double volume = enclosed_volume(m);
  const ConformalReport r = make_conformal(m);
  EXPECT_EQ(r.failed, 0u);
  EXPECT_EQ(r.nc_after, 0u);
  EXPECT_EQ(r.split_with_tets_behind, 1u);
  EXPECT_FALSE(still_nc(m, {11, 5, 8, 14}));
  expect_conformal_and_valid(m, volume);
}

// How many stored boundary faces are not a face of exactly one cell.
std::size_t boundary_faces_off_the_cells(const MixedMesh& m) {
  std::map<FaceKey, int> uses;
  for (std::size_t c = 0; c < m.num_cells(); ++c) {
    const CellFaces& cf = faces_of(m.cell_kind[c]);
    for (int f = 0; f < cf.count; ++f) ++uses[face_key(m.cell(c), cf.face[f])];
  }
  std::size_t off = 0;
  for (std::size_t f = 0; f < m.num_bfaces(); ++f) {
    FaceKey k{m.bface(f)[0], m.bface(f)[1], m.bface(f)[2], m.bface(f)[3]};
    std::sort(k.begin(), k.end());
    off += uses[k] != 1;
  }
  return off;
}

TEST(Conformal, APyramidOnTwoBoundaryTrianglesBecomesTheirTwoTets) {
  // A pyramid whose base lies on two CAD faces: the boundary keeps the triangles (0,1,2) and
  // (0,2,3), each with its CAD face. Its two corner tets on them replace it; nothing is NC.
  MixedMesh m;
  m.nodes = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0.5, 0.5, 0.5}};
  m.add_cell(CellKind::Pyramid5, {0, 1, 2, 3, 4});  // counter-clockwise seen from the apex
  m.add_bface(0, 2, 1, -1, 1);
  m.add_bface(0, 3, 2, -1, 2);
  for (auto [a, b] : {std::pair{0, 1}, {1, 2}, {2, 3}, {3, 0}}) m.add_bface(a, b, 4, -1, 3);
  flag_nonconformal_quads(m);
  ASSERT_EQ(boundary_faces_off_the_cells(m), 2u);  // the two triangles
  const ConformalReport r = make_conformal(m);
  EXPECT_EQ(r.boundary_pyramids_split, 1u);
  EXPECT_EQ(boundary_faces_off_the_cells(m), 0u);
  const MeshStats s = compute_stats(m);
  EXPECT_EQ(s.cells_per_kind[kTet], 2u);
  EXPECT_EQ(s.cells_per_kind[kPyr], 0u);
  expect_conformal_and_valid(m, 1.0 / 6);
}

TEST(Conformal, AHexOnTwoBoundaryTrianglesIsSplitAboutItsCentre) {
  // The unit hex with its bottom kept as the triangles (0,2,1) and (0,3,2) of two CAD faces,
  // its other faces as quads: split about its centre, two tets on the bottom, five pyramids.
  MixedMesh m = unit_hex();
  m.add_bface(0, 2, 1, -1, 1);
  m.add_bface(0, 3, 2, -1, 2);
  const CellFaces& cf = faces_of(CellKind::Hex8);
  for (int f = 1; f < cf.count; ++f)
    m.add_bface(cf.face[f].v[0], cf.face[f].v[1], cf.face[f].v[2], cf.face[f].v[3], 3);
  flag_nonconformal_quads(m);
  ASSERT_EQ(boundary_faces_off_the_cells(m), 2u);
  const ConformalReport r = make_conformal(m);
  EXPECT_EQ(r.boundary_cells_split, 1u);
  EXPECT_EQ(r.cells_split[kHex], 1u);
  EXPECT_EQ(boundary_faces_off_the_cells(m), 0u);
  const MeshStats s = compute_stats(m);
  EXPECT_EQ(s.cells_per_kind[kHex], 0u);
  EXPECT_EQ(s.cells_per_kind[kPyr], 5u);
  EXPECT_EQ(s.cells_per_kind[kTet], 2u);
  expect_conformal_and_valid(m, 1.0);
}

TEST(Conformal, AConformalMeshIsLeftAlone) {
  MixedMesh m = unit_hex();
  const std::int32_t p = add_node(m, {0.5, 0.5, -0.5});
  m.add_cell(CellKind::Pyramid5, {0, 3, 2, 1, p});  // apex below: base seen from it
  flag_nonconformal_quads(m);
  const std::vector<std::int32_t> before = m.cell_nodes;
  const ConformalReport r = make_conformal(m);
  EXPECT_EQ(r.nc_before, 0u);
  EXPECT_EQ(m.cell_nodes, before);
}

}  // namespace
}  // namespace hexfem
