// The look-ahead hex selection (recombine_select.hpp): a tet mesh where greedy best-first makes
// one hex and a 1-for-2 swap makes two, and on a jittered lattice that every element the swaps
// leave passes the fill test and the conformity rules against all the others.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <random>
#include <set>

#include "mesher/mesh/error.hpp"
#include "mesher/mesh/structured_box.hpp"
#include "mesher/recombine_hex.hpp"
#include "mesher/recombine_select.hpp"
#include "mesher/volume_pipeline.hpp"
#include "tests/support/synthetic_surfaces.hpp"

namespace hexfem {
namespace {

struct Lattice {
  SurfaceMesh surface;
  TetMesh tets;
};
// A structured box split into six Kuhn tets per cube, nodes moved by `move`.
template <class Move>
Lattice lattice_of_tets(int nx, int ny, int nz, Move move) {
  const MixedMesh m = make_box_mesh({1.0 * nx, 1.0 * ny, 1.0 * nz}, nx, ny, nz, CellKind::Tet4);
  Lattice L;
  L.surface.mesh.nodes = m.nodes;
  for (auto& x : L.surface.mesh.nodes) x = move(x);
  for (std::size_t f = 0; f < m.num_bfaces(); ++f)
    L.surface.mesh.add_bface(m.bface(f)[0], m.bface(f)[1], m.bface(f)[2], -1, m.bface_cad_face[f]);
  L.tets.nodes = L.surface.mesh.nodes;
  for (std::size_t c = 0; c < m.num_cells(); ++c) {
    L.tets.tets.push_back({m.cell(c)[0], m.cell(c)[1], m.cell(c)[2], m.cell(c)[3]});
    L.tets.tet_solid.push_back(1);
  }
  return L;
}

// Greedy placement, then optionally the swaps; the state's elements are checked against the
// rules as a fresh greedy pass would check them: each fills its own tets, which no other element
// holds, and breaks no conformity rule with the elements before it.
struct Placed {
  std::size_t greedy = 0;
  std::vector<Candidate> elements;
  SwapReport report;
};
Placed place(const Lattice& L, bool swap, const SwapOptions& options = {}) {
  const TetTopology topo(L.tets, L.surface);
  std::vector<Candidate> cands = hex_candidate_list(topo, HexOptions{});
  RecombineState state(topo, RecombineLimits{});
  ConformityIndex index;
  Placed P;
  P.greedy = place_greedily(state, cands, index);
  if (swap) P.report = improve_by_swaps(state, swap_pool(topo, HexOptions{}, options), options);
  EXPECT_NO_THROW(state.verify());
  ConformityIndex fresh;
  std::vector<char> seen(state.used.size(), 0);
  for (const Candidate& e : state.elements) {
    Candidate again = e;
    again.tets.fill(-1);
    EXPECT_TRUE(fills_element(topo, again, nullptr, state.limits.fill));
    EXPECT_EQ(again.tets, e.tets);
    for (std::int32_t t : e.tets)
      if (t >= 0) {
        EXPECT_FALSE(seen[t]) << "tet " << t << " in two elements";
        seen[t] = 1;
      }
    EXPECT_FALSE(fresh.conflicts(e));
    fresh.add(e);
  }
  P.elements = state.elements;
  return P;
}

// The nodes of an element by their lattice (unsheared) x coordinates' range.
std::set<std::int32_t> nodes_of(const Candidate& c) {
  return {c.nodes.begin(), c.nodes.begin() + 8};
}

// The node sets of the n unit cubes of an n x 1 x 1 lattice (cube i: nodes with x in [i, i + 1]).
std::set<std::set<std::int32_t>> lattice_cubes(int n) {
  const MixedMesh box = make_box_mesh({1.0 * n, 1.0, 1.0}, n, 1, 1, CellKind::Tet4);
  std::set<std::set<std::int32_t>> cubes;
  for (int cube = 0; cube < n; ++cube) {
    std::set<std::int32_t> s;
    for (std::size_t v = 0; v < box.nodes.size(); ++v)
      if (box.nodes[v][0] >= cube - 1e-9 && box.nodes[v][0] <= cube + 1 + 1e-9)
        s.insert(static_cast<std::int32_t>(v));
    EXPECT_EQ(s.size(), 8u);
    cubes.insert(s);
  }
  return cubes;
}

TEST(HexSelection, OneForTwoSwapOnAShearedPairOfCubes) {
  // Two unit cubes side by side in x, six Kuhn tets each, sheared by x' = x - z: the lattice's
  // cubes become parallelepipeds (scaled Jacobian 1/sqrt 2) and the parallelepiped made of the
  // half of each cube with x >= z resp. x - 1 <= z becomes a unit cube (quality 1). Greedy takes
  // that cube and leaves two half cubes of three tets each: one hex. Taking it out lets the two
  // lattice cubes in: two hexes, every tet used.
  const Lattice L = lattice_of_tets(2, 1, 1, [](Vec3 x) { return Vec3{x[0] - x[2], x[1], x[2]}; });
  const Placed g = place(L, false);
  ASSERT_EQ(g.greedy, 1u);
  ASSERT_EQ(g.elements.size(), 1u);
  EXPECT_FLOAT_EQ(g.elements[0].quality, 1.0f);

  const Placed s = place(L, true);
  EXPECT_EQ(s.greedy, 1u);
  ASSERT_EQ(s.elements.size(), 2u);
  EXPECT_EQ(s.report.swaps, 1u);
  EXPECT_EQ(s.report.removed, 1u);
  EXPECT_EQ(s.report.inserted, 2u);
  // The two lattice cubes, by the unsheared x of their nodes: {0, 1} and {1, 2}.
  const auto expected = lattice_cubes(2);
  std::set<std::set<std::int32_t>> got;
  for (const Candidate& e : s.elements) {
    got.insert(nodes_of(e));
    EXPECT_NEAR(e.quality, 1 / std::sqrt(2.0), 1e-6);
    int ntets = 0;
    for (std::int32_t t : e.tets) ntets += t >= 0;
    EXPECT_EQ(ntets, 6);
  }
  EXPECT_EQ(got, expected);
  // The two lattice cubes share their whole x = 1 face: conformal, no rule broken.
  EXPECT_TRUE(compatible(s.elements[0], s.elements[1]));
}

TEST(HexSelection, TwoForThreeSwapOnAShearedRowOfThreeCubes) {
  // Three cubes sheared the same way: greedy makes the two unit cubes across cubes 1-2 and 2-3
  // (they share a whole face) and leaves a half cube at each end: two hexes. No single one of
  // them blocks two lattice cubes (cube 1 is blocked by the first alone, cube 3 by the second,
  // cube 2 by both), so only the 2-for-3 swap finds the three lattice cubes.
  const Lattice L = lattice_of_tets(3, 1, 1, [](Vec3 x) { return Vec3{x[0] - x[2], x[1], x[2]}; });
  const Placed g = place(L, false);
  ASSERT_EQ(g.elements.size(), 2u);
  for (const Candidate& e : g.elements) EXPECT_FLOAT_EQ(e.quality, 1.0f);
  const Placed s = place(L, true);
  ASSERT_EQ(s.elements.size(), 3u);
  EXPECT_EQ(s.report.swaps, 1u);
  EXPECT_EQ(s.report.removed, 2u);
  EXPECT_EQ(s.report.inserted, 3u);
  std::set<std::set<std::int32_t>> got;
  for (const Candidate& e : s.elements) got.insert(nodes_of(e));
  EXPECT_EQ(got, lattice_cubes(3));
  SwapOptions one_for_k;
  one_for_k.pair_swaps = false;
  EXPECT_EQ(place(L, true, one_for_k).elements.size(), 2u);
}

TEST(HexSelection, UnshearedCubesNeedNoSwap) {
  // The same two cubes unsheared: greedy already makes both; the swaps change nothing.
  const Lattice L = lattice_of_tets(2, 1, 1, [](Vec3 x) { return x; });
  const Placed s = place(L, true);
  EXPECT_EQ(s.greedy, 2u);
  EXPECT_EQ(s.elements.size(), 2u);
  EXPECT_EQ(s.report.swaps, 0u);
  EXPECT_EQ(s.report.inserted, 0u);
}

// Interior nodes of a 5x5x4 lattice moved at random by up to 0.3: many candidates of close
// quality, greedy blocks some pairs.
Lattice jittered_lattice() {
  std::mt19937 rng(16);
  std::uniform_real_distribution<double> d(-0.3, 0.3);
  const Lattice L = lattice_of_tets(5, 5, 4, [&](Vec3 x) {
    Vec3 y = x;
    const bool inner =
        x[0] > 0.5 && x[0] < 4.5 && x[1] > 0.5 && x[1] < 4.5 && x[2] > 0.5 && x[2] < 3.5;
    if (inner)
      for (int k = 0; k < 3; ++k) y[k] += d(rng);
    return y;
  });
  return L;
}

TEST(HexSelection, SwapsOnAJitteredLatticeKeepEveryRule) {
  // Every element left must pass place()'s checks, and there are at least as many as greedy
  // made.
  const Lattice L = jittered_lattice();
  const Placed g = place(L, false);
  const Placed s = place(L, true);
  EXPECT_EQ(s.greedy, g.elements.size());
  EXPECT_EQ(s.elements.size(), g.elements.size() + s.report.inserted - s.report.removed);
  EXPECT_GE(s.elements.size(), g.elements.size());
  EXPECT_GT(s.report.swaps, 0u);  // this seed: greedy blocks pairs
  std::printf("jittered lattice: greedy %zu hexes, with swaps %zu (%zu swaps, %zu fillable)\n",
              g.elements.size(), s.elements.size(), s.report.swaps, s.report.fillable);
}

// The jittered lattice after the greedy pass, and the wide search's mask.
class WideSearch : public ::testing::Test {
 protected:
  void SetUp() override {
    ConformityIndex index;
    place_greedily(state, cands, index);
    owner = state.element_of_tets();
    mask = wide_swap_search_mask(state);
  }
  // Every hex the enumeration finds under the mask.
  std::set<std::array<std::int32_t, 8>> found_under_mask() const {
    std::set<std::array<std::int32_t, 8>> found;
    for (const auto& run : enumerate_hexes(topo, HexOptions{}, QualityBand{}, &mask).runs)
      for (const HexCorners& h : run) found.insert(h.nodes);
    return found;
  }
  const Lattice L = jittered_lattice();
  const TetTopology topo{L.tets, L.surface};
  std::vector<Candidate> cands = hex_candidate_list(topo, HexOptions{});
  RecombineState state{topo, RecombineLimits{}};
  std::vector<std::int32_t> owner;
  std::vector<char> mask;
};

TEST_F(WideSearch, FindsEveryCandidateOfAOneForKSwap) {
  // wide_swap_search_mask's claim: a candidate holding a free tet whose other tets are all of one
  // element is found by the search it restricts. Checked against every candidate (swap_pool) on
  // the jittered lattice after the greedy pass.
  const auto found = found_under_mask();
  std::size_t checked = 0;
  for (const Candidate& c : swap_pool(topo, HexOptions{})) {
    bool has_free = false;
    std::set<std::int32_t> blockers;
    for (std::int32_t t : c.tets)
      if (t >= 0) {
        if (!state.used[t]) has_free = true;
        if (owner[t] >= 0) blockers.insert(owner[t]);
      }
    if (!has_free || blockers.size() != 1) continue;
    ++checked;
    EXPECT_TRUE(found.count(c.nodes)) << "a candidate of quality " << c.quality << " missed";
  }
  EXPECT_GT(checked, 10u);
  EXPECT_LT(found.size(), hex_candidate_list(topo, HexOptions{}).size());  // it does restrict
  std::printf("one-for-k candidates %zu, found by the wide search %zu of %zu candidates\n", checked,
              found.size(), cands.size());
}

TEST_F(WideSearch, KeepsTheFilledHexesThatHoldAFreeTet) {
  // hexes_holding_free_tets with a search mask tests each hex where it is found. Against the long
  // way round: every filled candidate (swap_pool, with its tets) that the masked enumeration
  // finds and one of whose own tets is free.
  const auto found = found_under_mask();
  std::vector<Candidate> expected;
  for (const Candidate& c : swap_pool(topo, HexOptions{})) {
    bool has_free = false;
    for (std::int32_t t : c.tets) has_free = has_free || (t >= 0 && !state.used[t]);
    if (has_free && found.count(c.nodes)) expected.push_back(c);
  }
  const std::vector<Candidate> got =
      hexes_holding_free_tets(topo, HexOptions{}, QualityBand{}, mask, state.used);
  ASSERT_EQ(got.size(), expected.size());
  EXPECT_GT(got.size(), 10u);
  for (std::size_t i = 0; i < got.size(); ++i) {
    EXPECT_EQ(got[i].nodes, expected[i].nodes) << i;  // the same hexes, best first
    auto a = got[i].tets, b = expected[i].tets;
    std::sort(a.begin(), a.end());
    std::sort(b.begin(), b.end());
    EXPECT_EQ(a, b) << i;
  }
  std::printf("wide search: %zu filled hexes hold a free tet, of %zu found\n", got.size(),
              found.size());
}

// Two unit cubes side by side in x, six Kuhn tets each; the second is mirrored in y, so the two
// split their shared face along different diagonals, and a flat tet on that face's four corners
// lies between them: a sliver free after the greedy pass, beside two hexes.
Lattice two_cubes_with_a_sliver() {
  Lattice L;
  auto id = [](int x, int y, int z) { return x + 3 * (y + 2 * z); };
  for (int z = 0; z < 2; ++z)
    for (int y = 0; y < 2; ++y)
      for (int x = 0; x < 3; ++x) L.tets.nodes.push_back({1.0 * x, 1.0 * y, 1.0 * z});
  auto positive = [&](std::array<std::int32_t, 4> t) {
    const auto& X = L.tets.nodes;
    Vec3 e[3];
    for (int k = 0; k < 3; ++k)
      for (int a = 0; a < 3; ++a) e[k][a] = X[t[k + 1]][a] - X[t[0]][a];
    const double det = e[0][0] * (e[1][1] * e[2][2] - e[1][2] * e[2][1]) -
                       e[0][1] * (e[1][0] * e[2][2] - e[1][2] * e[2][0]) +
                       e[0][2] * (e[1][0] * e[2][1] - e[1][1] * e[2][0]);
    if (det < 0) std::swap(t[2], t[3]);
    return t;
  };
  const int perms[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  for (int cube = 0; cube < 2; ++cube)
    for (const auto& p : perms) {
      std::array<std::int32_t, 4> t;
      int c[3] = {0, 0, 0};
      for (int k = 0; k < 4; ++k) {
        if (k > 0) c[p[k - 1]] = 1;
        t[k] = cube == 0 ? id(c[0], c[1], c[2]) : id(1 + c[0], 1 - c[1], c[2]);
      }
      L.tets.tets.push_back(positive(t));
    }
  L.tets.tets.push_back({id(1, 0, 0), id(1, 1, 0), id(1, 0, 1), id(1, 1, 1)});  // the sliver
  L.tets.tet_solid.assign(L.tets.tets.size(), 1);
  // The boundary: the tet faces that only one tet has, outward.
  std::map<std::array<std::int32_t, 3>, std::pair<int, std::array<std::int32_t, 3>>> faces;
  for (const auto& t : L.tets.tets)
    for (int f = 0; f < 4; ++f) {
      std::array<std::int32_t, 3> tri = {t[(f + 1) % 4], t[(f + 2) % 4], t[(f + 3) % 4]};
      if (f % 2 == 0) std::swap(tri[1], tri[2]);  // the face opposite corner f, outward
      auto key = tri;
      std::sort(key.begin(), key.end());
      auto& entry = faces[key];
      ++entry.first;
      entry.second = tri;
    }
  L.surface.mesh.nodes = L.tets.nodes;
  for (const auto& [key, entry] : faces)
    if (entry.first == 1)
      L.surface.mesh.add_bface(entry.second[0], entry.second[1], entry.second[2], -1, 1);
  return L;
}

TEST(HexSelection, SliversAloneOpenNothingForTheWideSearch) {
  // A free tet flat on the quad face two hexes share is in no hex a swap could put in: the wide
  // search's mask opens neither hex.
  const Lattice L = two_cubes_with_a_sliver();
  const TetTopology topo(L.tets, L.surface);
  std::vector<Candidate> cands = hex_candidate_list(topo, HexOptions{});
  RecombineState state(topo, RecombineLimits{});
  ConformityIndex index;
  ASSERT_EQ(place_greedily(state, cands, index), 2u);
  ASSERT_FALSE(state.used.back());  // the sliver (the last tet) is free
  const std::vector<char> mask = wide_swap_search_mask(state);
  EXPECT_EQ(mask, state.used);
}

TEST(HexSelection, NamesAndPipelineSwitch) {
  EXPECT_EQ(parse_hex_selection("greedy"), HexSelection::kGreedy);
  EXPECT_EQ(parse_hex_selection("swap"), HexSelection::kSwap);
  EXPECT_EQ(parse_hex_selection("swap-wide"), HexSelection::kSwapWide);
  EXPECT_THROW(parse_hex_selection("best"), Error);
  // The cylinder through the whole pipeline with swaps: a valid mesh, deterministic.
  const SurfaceMesh surf = synthetic::cylinder_surface(1.0, 1.0, 0.125);
  VolumeOptions o;
  o.hex_selection = HexSelection::kSwap;
  VolumeReport r1, r2, rg;
  const MixedMesh a = mesh_volume(surf, o, &r1);
  const MixedMesh b = mesh_volume(surf, o, &r2);
  VolumeOptions greedy;
  greedy.hex_selection = HexSelection::kGreedy;
  mesh_volume(surf, greedy, &rg);
  EXPECT_EQ(a.cell_nodes, b.cell_nodes);
  EXPECT_EQ(a.cell_kind, b.cell_kind);
  EXPECT_EQ(r1.stats.inverted, 0u);
  EXPECT_EQ(r1.stats.degenerate, 0u);
  EXPECT_GT(r1.hex_swaps.fillable, 0u);
  EXPECT_EQ(rg.hex_swaps.fillable, 0u);  // greedy: the swaps do not run
  std::printf("cylinder: H_nbr greedy %.2f swap %.2f, H_vol %.2f / %.2f (%zu swaps)\n",
              rg.stats.h_nbr, r1.stats.h_nbr, rg.stats.h_vol, r1.stats.h_vol, r1.hex_swaps.swaps);
}

}  // namespace
}  // namespace hexfem
