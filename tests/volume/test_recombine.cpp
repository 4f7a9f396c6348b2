// Recombination (hexes, prisms, pyramids, conformity rules) and the whole volume pipeline, on
// tet meshes whose answer is known: structured lattices split into tets, boxes, a cylinder.
#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "mesher/mesh/conformity.hpp"
#include "mesher/mesh/error.hpp"
#include "mesher/mesh/quality.hpp"
#include "mesher/mesh/structured_box.hpp"
#include "mesher/recombine_conformity.hpp"
#include "mesher/recombine_hex.hpp"
#include "mesher/recombine_prism_pyramid.hpp"
#include "mesher/volume_pipeline.hpp"
#include "tests/support/synthetic_surfaces.hpp"

namespace hexfem {
namespace {

// A structured box split into tets, as a TetMesh + the SurfaceMesh of its boundary triangles.
struct Lattice {
  SurfaceMesh surface;
  TetMesh tets;
};
Lattice lattice_of_tets(int nx, int ny, int nz, CellKind kind) {
  const MixedMesh m = make_box_mesh({1.0 * nx, 1.0 * ny, 1.0 * nz}, nx, ny, nz, kind);
  Lattice L;
  L.surface.mesh.nodes = m.nodes;  // every node counts as a surface node here (harmless)
  for (std::size_t f = 0; f < m.num_bfaces(); ++f)
    L.surface.mesh.add_bface(m.bface(f)[0], m.bface(f)[1], m.bface(f)[2], -1, m.bface_cad_face[f]);
  L.tets.nodes = m.nodes;
  for (std::size_t c = 0; c < m.num_cells(); ++c) {
    EXPECT_EQ(m.cell_kind[c], CellKind::Tet4);
    L.tets.tets.push_back({m.cell(c)[0], m.cell(c)[1], m.cell(c)[2], m.cell(c)[3]});
    L.tets.tet_solid.push_back(1);
  }
  return L;
}

TEST(RecombineHex, FindsEveryCubeOfAKuhnLattice) {
  const Lattice L = lattice_of_tets(4, 3, 2, CellKind::Tet4);
  const TetTopology topo(L.tets, L.surface);
  const auto cands = enumerate_hexes(topo, HexOptions{});
  RecombineState state(topo, RecombineLimits{});
  ConformityIndex index;
  ASSERT_EQ(place_greedily(state, cands, index), 24u);
  const std::vector<Candidate>& hexes = state.elements;
  for (const Candidate& h : hexes) {
    EXPECT_FLOAT_EQ(h.quality, 1.0f);
    int ntets = 0;
    for (auto t : h.tets) ntets += t >= 0;
    EXPECT_EQ(ntets, 6);  // Kuhn: six tets per cube
  }
  for (char u : state.used) EXPECT_TRUE(u);
  // The sheared parallelepipeds the lattice also contains score below the cubes.
  EXPECT_GT(cands.size(), hexes.size());
  std::vector<HexCorners> merged;
  RunMerger<HexCorners> merger(cands);
  while (const HexCorners* h = merger.next()) merged.push_back(*h);
  ASSERT_EQ(merged.size(), cands.size());
  for (std::size_t i = 1; i < merged.size(); ++i) EXPECT_TRUE(merged[i - 1] < merged[i]);
}

// Runs of unequal length (one empty) merge into the one sorted order, each candidate once.
TEST(RecombineHex, RunMergerGivesTheSortedUnionOfTheRuns) {
  SortedRuns<HexCorners> r;
  std::vector<HexCorners> all;
  for (int run = 0; run < 5; ++run) {
    std::vector<HexCorners> v;
    for (int i = 0; i < 7 * run; ++i) {
      HexCorners h;
      h.quality = static_cast<float>((i * 37 + run * 11) % 23) / 23.0f;  // ties in quality
      h.nodes = {run, i, 0, 0, 0, 0, 0, 0};
      v.push_back(h);
      all.push_back(h);
    }
    std::sort(v.begin(), v.end());
    r.runs.push_back(v);
  }
  std::sort(all.begin(), all.end());
  std::vector<HexCorners> merged;
  RunMerger<HexCorners> merger(r);
  while (const HexCorners* h = merger.next()) merged.push_back(*h);
  ASSERT_EQ(merged.size(), all.size());
  for (std::size_t i = 0; i < all.size(); ++i) {
    EXPECT_EQ(merged[i].nodes, all[i].nodes);
    EXPECT_EQ(merged[i].quality, all[i].quality);
  }
}

TEST(RecombineHex, QuadAcrossTwoCadFacesIsNotMade) {
  // One cube; split the x=0 face's two triangles between CAD faces 1 and 7.
  Lattice L = lattice_of_tets(1, 1, 1, CellKind::Tet4);
  int changed = 0;
  for (std::size_t f = 0; f < L.surface.mesh.num_bfaces() && !changed; ++f)
    if (L.surface.mesh.bface_cad_face[f] == 1) {
      L.surface.mesh.bface_cad_face[f] = 7;
      ++changed;
    }
  auto hexes_made = [](const Lattice& l) {
    const TetTopology topo(l.tets, l.surface);
    const auto cands = enumerate_hexes(topo, HexOptions{});
    RecombineState state(topo, RecombineLimits{});
    ConformityIndex index;
    return place_greedily(state, cands, index);
  };
  EXPECT_EQ(hexes_made(L), 0u);
  EXPECT_EQ(hexes_made(lattice_of_tets(1, 1, 1, CellKind::Tet4)), 1u);
}

TEST(RecombinePrism, FindsPrismsWhenHexesAreNotMade) {
  const Lattice L = lattice_of_tets(2, 2, 1, CellKind::Tet4);
  const TetTopology topo(L.tets, L.surface);
  RecombineState state(topo, RecombineLimits{});
  std::vector<Candidate> pc = enumerate_prisms(state);
  ConformityIndex index;
  place_greedily(state, pc, index);
  const std::vector<Candidate>& prisms = state.elements;
  // 24 tets: at most 8 prisms of three tets; each kept prism is valid and made of 3 tets.
  EXPECT_GE(prisms.size(), 4u);
  for (const Candidate& p : prisms) {
    EXPECT_EQ(p.kind, CellKind::Wedge6);
    Vec3 x[6];
    for (int i = 0; i < 6; ++i) x[i] = L.tets.nodes[p.nodes[i]];
    EXPECT_GT(min_scaled_jacobian(CellKind::Wedge6, x), 0.3);
    EXPECT_NEAR(volume(CellKind::Wedge6, x), 0.5, 1e-12);  // half a unit cube
    EXPECT_EQ(p.tets[2] >= 0 && p.tets[3] < 0, true);
  }
}

Candidate hex(std::array<std::int32_t, 8> n) {
  Candidate c;
  c.kind = CellKind::Hex8;
  c.nodes = n;
  return c;
}

TEST(ConformityIndex, RulesOfFigures15To18) {
  // Hex A on lattice nodes 0..7; B shares A's face (1,2,6,5) fully; C shares three of its
  // corners; D has as an edge the diagonal 1-6 of A's face.
  ConformityIndex index;
  index.add(hex({0, 1, 2, 3, 4, 5, 6, 7}));
  EXPECT_FALSE(index.conflicts(hex({1, 8, 9, 2, 5, 10, 11, 6})));       // same quad: conformal
  EXPECT_TRUE(index.conflicts(hex({1, 8, 9, 2, 5, 10, 11, 12})));       // 1,2,5 of quad (1,2,6,5)
  EXPECT_TRUE(index.conflicts(hex({1, 6, 13, 14, 15, 16, 17, 18})));    // edge 1-6 = A's diagonal
  EXPECT_FALSE(index.conflicts(hex({7, 19, 20, 21, 22, 23, 24, 25})));  // one shared vertex
  // A prism whose triangle face holds three corners of A's quad (0,1,5,4).
  Candidate prism;
  prism.kind = CellKind::Wedge6;
  prism.nodes = {0, 1, 5, 30, 31, 32, -1, -1};
  EXPECT_TRUE(index.conflicts(prism));
  // And A's diagonals against a placed prism's edges.
  ConformityIndex j;
  Candidate p2;
  p2.kind = CellKind::Wedge6;
  p2.nodes = {0, 2, 40, 41, 42, 43, -1, -1};  // edge 0-2 = diagonal of A's face (0,3,2,1)
  j.add(p2);
  EXPECT_TRUE(j.conflicts(hex({0, 1, 2, 3, 4, 5, 6, 7})));
}

// The cubes of a 3x3x3 Kuhn lattice as hexes made of their tets; keep(i, j, k) picks the cubes
// that stay hexes, the others stay tets.
struct Recombined {
  Lattice lattice;
  std::vector<Candidate> hexes;
  std::vector<char> used;
};
template <class Keep>
Recombined lattice_with_hexes(Keep keep, int nz = 3) {
  Recombined R{lattice_of_tets(3, 3, nz, CellKind::Tet4), {}, {}};
  const TetTopology topo(R.lattice.tets, R.lattice.surface);
  const auto cands = enumerate_hexes(topo, HexOptions{});
  RecombineState state(topo, RecombineLimits{});
  ConformityIndex index;
  R.used.assign(state.used.size(), 0);
  place_greedily(state, cands, index);
  for (const Candidate& h : state.elements) {
    Vec3 c{0, 0, 0};  // the cube's centre
    for (int i = 0; i < 8; ++i)
      for (int d = 0; d < 3; ++d) c[d] += R.lattice.tets.nodes[h.nodes[i]][d] / 8;
    if (!keep(static_cast<int>(c[0]), static_cast<int>(c[1]), static_cast<int>(c[2]))) continue;
    R.hexes.push_back(h);
    for (auto t : h.tets)
      if (t >= 0) R.used[t] = 1;
  }
  return R;
}

// The NC repair on R's hexes, with the given pyramid quality and hex gain; the state it leaves
// must keep each tet in one place.
struct Repaired {
  NcRepair nr;
  std::vector<Candidate> elements;
  std::vector<char> used;
  std::size_t nc_left;  // counted again on the elements left
};
Repaired repair(const Recombined& R, double min_pyramid, int min_hex_gain, bool pyramids = true,
                bool prisms = false) {
  const TetTopology topo(R.lattice.tets, R.lattice.surface);
  RecombineLimits limits;
  limits.min_pyramid_quality = min_pyramid;
  RecombineState state(topo, limits);
  state.elements = R.hexes;
  state.used = R.used;
  NcRepairOptions o;
  o.min_hex_gain = min_hex_gain;
  o.make_pyramids = pyramids;
  o.make_prisms = prisms;
  const NcRepair nr = undo_nonconformal_elements(state, o);
  EXPECT_NO_THROW(state.verify());
  return {nr, state.elements, state.used, count_nc_faces(topo, state.elements)};
}

TEST(RecombineState, VerifyFindsATetInTwoPlacesOrInNone) {
  const Lattice L = lattice_of_tets(1, 1, 1, CellKind::Tet4);
  const TetTopology topo(L.tets, L.surface);
  RecombineState state(topo, RecombineLimits{});
  const auto cands = enumerate_hexes(topo, HexOptions{});
  ConformityIndex index;
  ASSERT_EQ(place_greedily(state, cands, index), 1u);
  EXPECT_NO_THROW(state.verify());
  state.absorbed.push_back(state.elements[0].tets[0]);  // also in the hex
  EXPECT_THROW(state.verify(), Error);
  state.absorbed.clear();
  state.used[state.elements[0].tets[1]] = 0;  // in the hex, yet marked free
  EXPECT_THROW(state.verify(), Error);
  state.remove(std::vector<char>{1});
  EXPECT_NO_THROW(state.verify());
  for (char u : state.used) EXPECT_FALSE(u);
}

TEST(NcRepair, LoneHexAmongTetsGoesBack) {
  // The middle cube alone: six quad faces against tets (NC); undoing it leaves none.
  Recombined R = lattice_with_hexes([](int i, int j, int k) { return i == 1 && j == 1 && k == 1; });
  ASSERT_EQ(R.hexes.size(), 1u);
  const Repaired out = repair(R, 0.05, 1);
  const NcRepair& nr = out.nr;
  EXPECT_EQ(nr.nc_before, 6u);
  EXPECT_EQ(nr.undone[static_cast<int>(CellKind::Hex8)], 1u);
  EXPECT_EQ(nr.nc_after, 0u);
  EXPECT_EQ(out.nc_left, nr.nc_after);
  EXPECT_TRUE(out.elements.empty());
  for (char u : out.used) EXPECT_FALSE(u);  // its six tets are free again
}

TEST(NcRepair, HexLayerOnTheSurfaceStays) {
  // The bottom layer of nine cubes: each has one face against tets above and at least two
  // matched faces beside it, so undoing any would make more NC faces than it removes.
  Recombined R = lattice_with_hexes([](int, int, int k) { return k == 0; });
  ASSERT_EQ(R.hexes.size(), 9u);
  const Repaired out = repair(R, 0.05, 1, false);
  const NcRepair& nr = out.nr;
  EXPECT_EQ(nr.nc_before, 9u);
  EXPECT_EQ(nr.undone[static_cast<int>(CellKind::Hex8)], 0u);
  EXPECT_EQ(nr.nc_after, 9u);
  EXPECT_EQ(out.nc_left, nr.nc_after);
  EXPECT_EQ(out.elements.size(), 9u);
}

TEST(NcRepair, HexStickingOutOfALayerGoesBack) {
  // The bottom layer plus the cube on top of its middle: that one has five faces against tets
  // and one matched (undoing it: 5 - 1 = 4 NC faces fewer); the layer stays.
  Recombined R = lattice_with_hexes(
      [](int i, int j, int k) { return k == 0 || (i == 1 && j == 1 && k == 1); });
  ASSERT_EQ(R.hexes.size(), 10u);
  const Repaired out = repair(R, 0.05, 1, false);
  const NcRepair& nr = out.nr;
  EXPECT_EQ(nr.nc_before, 8u + 5u);  // the middle of the layer is matched by the cube on top
  EXPECT_EQ(nr.undone[static_cast<int>(CellKind::Hex8)], 1u);
  EXPECT_EQ(nr.nc_after, 9u);
  EXPECT_EQ(out.nc_left, nr.nc_after);
  EXPECT_EQ(out.elements.size(), 9u);
}

// A row of three cubes across a one-cube-thick slab (their z faces on the surface), the other
// cubes tets: each cube has two NC faces (y = 1 and y = 2), the middle one two matched faces.
// In a Kuhn cube the two tets on each face share the far end of the main diagonal, and the
// tets on the middle cube's x = 1 and x = 2 faces are four distinct tets: undone, the middle
// cube leaves pyramids (min scaled Jacobian sqrt(2/3) = 0.816) on both neighbours' faces.
Recombined slab_row() {
  return lattice_with_hexes([](int, int j, int) { return j == 1; }, 1);
}

TEST(NcRepair, HexWhosePartnersGetPyramidsGoesBack) {
  // Counting only NC faces, the middle cube gains 2 - 2 = 0 and the end ones 2 - 1 = 1 (below
  // the hex gain 2): nothing would go. Counting the pyramids its own tets make on the two
  // partner faces, undoing the middle gains 2; then each end cube has two NC faces and a pyramid
  // (which goes with it) and gains 2. Every NC face goes: 6 -> 0.
  Recombined R = slab_row();
  ASSERT_EQ(R.hexes.size(), 3u);
  {
    const TetTopology topo(R.lattice.tets, R.lattice.surface);
    EXPECT_EQ(count_nc_faces(topo, R.hexes), 6u);
  }
  const Repaired out = repair(R, 0.05, 2);
  const NcRepair& nr = out.nr;
  EXPECT_EQ(nr.nc_before, 6u);
  EXPECT_EQ(nr.undone[static_cast<int>(CellKind::Hex8)], 3u);
  EXPECT_EQ(nr.undone[static_cast<int>(CellKind::Pyramid5)], 2u);  // made, then gone with the ends
  EXPECT_EQ(nr.pyramids_added, 2u);
  EXPECT_EQ(nr.nc_after, 0u);
  EXPECT_TRUE(out.elements.empty());
  for (char u : out.used) EXPECT_FALSE(u);
}

TEST(NcRepair, HexWhosePartnersGetNoPyramidStays) {
  // Same row, but pyramids must reach a min scaled Jacobian of 0.9 (theirs is 0.816): undoing
  // the middle cube would turn both partner faces NC (gain 0), the end cubes gain 1 < 2.
  Recombined R = slab_row();
  ASSERT_EQ(R.hexes.size(), 3u);
  const Repaired out = repair(R, 0.9, 2);
  const NcRepair& nr = out.nr;
  EXPECT_EQ(nr.nc_before, 6u);
  EXPECT_EQ(nr.undone[static_cast<int>(CellKind::Hex8)], 0u);
  EXPECT_EQ(nr.pyramids_added, 0u);
  EXPECT_EQ(nr.nc_after, 6u);
  EXPECT_EQ(out.nc_left, 6u);
  EXPECT_EQ(out.elements.size(), 3u);
}

// A one-cube-thick slab of 3x3 cubes, all hexes but the middle one (tets): its four side faces
// are NC. Its Kuhn tets (around the diagonal from (1,1) to (2,2)) split it into two prisms
// along the plane x = y, each matching two of the hexes' faces. The two tets on each face share
// an apex, but the pyramids on the faces at y = 1 and x = 2 (and at y = 2 and x = 1) need a
// common tet: pyramids alone leave two NC faces.
Recombined slab_around_a_hole() {
  return lattice_with_hexes([](int i, int j, int) { return !(i == 1 && j == 1); }, 1);
}

// Quad faces of `elements` that no other element's quad matches, off the box's surface: counted
// from the vertex sets alone.
std::size_t unmatched_interior_quads(const Lattice& L, const std::vector<Candidate>& elements) {
  const QuadFaces quads(elements, L.tets.nodes.size());
  std::size_t n = 0;
  for (std::size_t i = 0; i < elements.size(); ++i)
    for (int f = 0; f < faces_of(elements[i].kind).count; ++f) {
      if (faces_of(elements[i].kind).face[f].n != 4 || quads.shared(6 * i + f)) continue;
      const QuadKey key = quad_key(elements[i], f);
      bool on_surface = false;  // all four corners on one side of the 3x3x1 box
      for (int d = 0; d < 3 && !on_surface; ++d)
        for (double side : {0.0, d == 2 ? 1.0 : 3.0}) {
          bool all = true;
          for (std::int32_t v : key) all = all && L.tets.nodes[v][d] == side;
          on_surface = on_surface || all;
        }
      n += !on_surface;
    }
  return n;
}

TEST(NcRepair, PrismsFillTheGapBetweenHexFaces) {
  Recombined R = slab_around_a_hole();
  ASSERT_EQ(R.hexes.size(), 8u);
  const Repaired out = repair(R, 0.05, 2, true, true);
  const NcRepair& nr = out.nr;
  EXPECT_EQ(nr.nc_before, 4u);
  EXPECT_EQ(nr.prisms_added, 2u);
  EXPECT_EQ(nr.nc_after, 0u);
  EXPECT_EQ(unmatched_interior_quads(R.lattice, out.elements), 0u);
  int hexes = 0, wedges = 0;
  for (const Candidate& e : out.elements) {
    hexes += e.kind == CellKind::Hex8;
    wedges += e.kind == CellKind::Wedge6;
    EXPECT_GT(e.quality, 0.8f);  // right-angled prisms: sqrt(2)/2 * 2/sqrt(3) = 0.816
  }
  EXPECT_EQ(hexes, 8);
  EXPECT_EQ(wedges, 2);
  for (char u : out.used) EXPECT_TRUE(u);
}

TEST(NcRepair, WithoutPrismsPyramidsLeaveTwoNcFaces) {
  Recombined R = slab_around_a_hole();
  const Repaired out = repair(R, 0.05, 2, true);
  const NcRepair& nr = out.nr;
  EXPECT_EQ(nr.nc_before, 4u);
  EXPECT_EQ(nr.prisms_added, 0u);
  EXPECT_EQ(nr.pyramids_added, 2u);
  EXPECT_EQ(nr.nc_after, 2u);
  EXPECT_EQ(unmatched_interior_quads(R.lattice, out.elements), 2u);
}

// Checks every property the pipeline promises on one mesh.
void check_mesh(const MixedMesh& m, const VolumeReport& r) {
  EXPECT_EQ(r.stats.inverted, 0u);
  for (std::size_t c = 0; c < m.num_cells(); ++c) ASSERT_FALSE(cell_is_inverted(m, c)) << c;
  EXPECT_LT(r.volume_rel_gap, 1e-3);
  EXPECT_NEAR(r.stats.volume, r.volume_tets, 1e-3 * r.volume_tets);
  // Each tet used once: TetGen's tets are those merged into elements, the absorbed slivers,
  // the tets left and those the sliver flips replaced (the tets left include the flips' new
  // tets).
  EXPECT_EQ(r.tets_in_elements + r.absorbed_slivers + r.stats.cells_per_kind[0] + r.flipped_tets,
            r.tets + r.tets_from_flips);
  // NC flags are those of the lead's definition.
  MixedMesh copy = m;
  flag_nonconformal_quads(copy);
  EXPECT_EQ(copy.nc_cell, m.nc_cell);
  EXPECT_EQ(m.nc_cell.size(), r.stats.nonconformal_quads);
}

TEST(VolumePipeline, BoxLatticeBecomesAllHexes) {
  const SurfaceMesh s = synthetic::box_surface({2.0, 1.0, 1.0}, {10, 5, 5});
  VolumeReport r;
  const MixedMesh m = mesh_volume(s, VolumeOptions{}, &r);
  check_mesh(m, r);
  EXPECT_EQ(r.stats.cells_per_kind[static_cast<int>(CellKind::Hex8)], 250u);
  EXPECT_EQ(m.num_cells(), 250u);
  EXPECT_DOUBLE_EQ(r.stats.h_nbr, 100.0);
  EXPECT_NEAR(r.stats.q_mean, 1.0, 1e-9);
  EXPECT_EQ(r.stats.nonconformal_quads, 0u);
  // Every boundary face became a quad: 2 * (10*5 + 10*5 + 5*5) squares.
  EXPECT_EQ(r.boundary_quads, 250u);
  EXPECT_EQ(r.boundary_triangles, 0u);
  EXPECT_NEAR(r.stats.volume, 2.0, 1e-12);
  // Boundary quads keep the CAD faces: 50 on each y/z side, 25 on each x side.
  std::vector<int> per_face(7, 0);
  for (std::size_t f = 0; f < m.num_bfaces(); ++f) ++per_face[m.bface_cad_face[f]];
  EXPECT_EQ(per_face, (std::vector<int>{0, 25, 25, 50, 50, 50, 50}));
}

TEST(VolumePipeline, CylinderIsValidDeterministicAndMostlyHexes) {
  const SurfaceMesh s = synthetic::cylinder_surface(1.0, 1.0, 0.125);
  VolumeReport r1, r2;
  const MixedMesh a = mesh_volume(s, VolumeOptions{}, &r1);
  const MixedMesh b = mesh_volume(s, VolumeOptions{}, &r2);
  check_mesh(a, r1);
  EXPECT_EQ(a.nodes, b.nodes);
  EXPECT_EQ(a.cell_kind, b.cell_kind);
  EXPECT_EQ(a.cell_nodes, b.cell_nodes);
  EXPECT_EQ(a.bface_nodes, b.bface_nodes);
  EXPECT_EQ(a.nc_cell, b.nc_cell);
  EXPECT_GT(r1.stats.h_vol, 70.0);
  EXPECT_GT(r1.stats.cells_per_kind[static_cast<int>(CellKind::Wedge6)], 0u);
  EXPECT_GT(r1.stats.cells_per_kind[static_cast<int>(CellKind::Pyramid5)], 0u);
  // Without prisms and pyramids there are none, and no fewer hexes placed.
  VolumeOptions o;
  o.no_prisms = o.no_pyramids = true;
  VolumeReport r3;
  const MixedMesh c = mesh_volume(s, o, &r3);
  check_mesh(c, r3);
  EXPECT_EQ(r3.stats.cells_per_kind[static_cast<int>(CellKind::Wedge6)], 0u);
  EXPECT_EQ(r3.stats.cells_per_kind[static_cast<int>(CellKind::Pyramid5)], 0u);
  // Counted before the volume-gap pass, which undoes more hexes when their unshared faces meet
  // tets rather than prisms and pyramids.
  const int hex = static_cast<int>(CellKind::Hex8);
  EXPECT_EQ(r3.stats.cells_per_kind[hex] + r3.gap_undone[hex] + r3.nc_undone[hex],
            r1.stats.cells_per_kind[hex] + r1.gap_undone[hex] + r1.nc_undone[hex]);
}

TEST(VolumePipeline, BadOptionsAreErrors) {
  const SurfaceMesh s = synthetic::box_surface({1, 1, 1}, {2, 2, 2});
  VolumeOptions o;
  o.k = 1.2;
  EXPECT_THROW(mesh_volume(s, o), Error);
  o = {};
  o.min_quality = 2;
  EXPECT_THROW(mesh_volume(s, o), Error);
  o = {};
  o.nc_hex_gain = 0;
  EXPECT_THROW(mesh_volume(s, o), Error);
}

}  // namespace
}  // namespace hexfem
