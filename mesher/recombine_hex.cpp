#include "mesher/recombine_hex.hpp"

#include <algorithm>

#include "mesher/mesh/quality.hpp"

namespace hexfem {

namespace {

// Hex corners (Gmsh order): corner 0 has edges to 1, 3, 4; the other corners' edges, in the
// right-handed order of element_topology.hpp's corner table:
//   1:(2,0,5) 2:(3,1,6) 3:(0,2,7) 4:(7,5,0) 5:(4,6,1) 6:(5,7,2) 7:(6,4,3).
// From lowest vertex v = p0 and p1 < p3, p1 < p4 (one of the three rotations about p0), each hex
// has exactly one labelling, so each is found once.
void hexes_from(const TetTopology& topo, std::int32_t v, double qmin, const FillRules& rules,
                FillScratch& scratch, std::vector<Candidate>& out) {
  const auto& X = topo.mesh().nodes;
  const std::int32_t* nb = topo.neighbours_begin(v);
  const std::int32_t* ne = topo.neighbours_end(v);
  // Neighbours above v only (v is the lowest vertex of the hexes found from it).
  const std::int32_t* gb = std::upper_bound(nb, ne, v);
  auto ok = [&](std::int32_t o, std::int32_t a, std::int32_t b, std::int32_t c) {
    return corner_jacobian(X[o], X[a], X[b], X[c]) >= qmin;
  };
  // x adjacent to a and b, above v, not in `taken`.
  auto common = [&](std::int32_t a, std::int32_t b, std::vector<std::int32_t>& res,
                    std::initializer_list<std::int32_t> taken) {
    res.clear();
    const std::int32_t* ab = std::upper_bound(topo.neighbours_begin(a), topo.neighbours_end(a), v);
    for (const std::int32_t* it = ab; it != topo.neighbours_end(a); ++it) {
      const std::int32_t x = *it;
      if (std::find(taken.begin(), taken.end(), x) != taken.end()) continue;
      if (topo.adjacent(b, x)) res.push_back(x);
    }
  };
  std::vector<std::int32_t> c2, c5, c7;
  for (const std::int32_t* i1 = gb; i1 != ne; ++i1) {
    const std::int32_t p1 = *i1;
    for (const std::int32_t* i3 = i1 + 1; i3 != ne; ++i3) {
      for (const std::int32_t* i4 = i1 + 1; i4 != ne; ++i4) {
        const std::int32_t p3 = *i3, p4 = *i4;
        if (p3 == p4 || !ok(v, p1, p3, p4)) continue;
        // p2 closes face (p0 p1 p2 p3), whose diagonal p0-p2 or p1-p3 is a tet edge.
        common(p1, p3, c2, {v, p1, p3, p4});
        if (c2.empty()) continue;
        common(p1, p4, c5, {v, p1, p3, p4});
        if (c5.empty()) continue;
        common(p3, p4, c7, {v, p1, p3, p4});
        if (c7.empty()) continue;
        const bool d13 = topo.adjacent(p1, p3), d14 = topo.adjacent(p1, p4),
                   d34 = topo.adjacent(p3, p4);
        for (std::int32_t p2 : c2) {
          if (!d13 && !topo.adjacent(v, p2)) continue;
          for (std::int32_t p5 : c5) {
            if (p5 == p2 || (!d14 && !topo.adjacent(v, p5)) || !ok(p1, p2, v, p5)) continue;
            for (std::int32_t p7 : c7) {
              if (p7 == p2 || p7 == p5 || (!d34 && !topo.adjacent(v, p7))) continue;
              if (!ok(p3, v, p2, p7) || !ok(p4, p7, p5, v)) continue;
              // p6: adjacent to p2, p5 and p7.
              for (auto it =
                       std::upper_bound(topo.neighbours_begin(p2), topo.neighbours_end(p2), v);
                   it != topo.neighbours_end(p2); ++it) {
                const std::int32_t p6 = *it;
                if (p6 == p1 || p6 == p3 || p6 == p4 || p6 == p5 || p6 == p7) continue;
                if (!topo.adjacent(p5, p6) || !topo.adjacent(p7, p6)) continue;
                if (!ok(p2, p3, p1, p6) || !ok(p5, p4, p6, p1) || !ok(p6, p5, p7, p2) ||
                    !ok(p7, p6, p4, p3))
                  continue;
                // The three faces at p6 need a diagonal among the tet edges too.
                if (!topo.adjacent(p1, p6) && !topo.adjacent(p2, p5)) continue;
                if (!topo.adjacent(p3, p6) && !topo.adjacent(p2, p7)) continue;
                if (!topo.adjacent(p4, p6) && !topo.adjacent(p5, p7)) continue;
                Candidate c;
                c.kind = CellKind::Hex8;
                c.nodes = {v, p1, p2, p3, p4, p5, p6, p7};
                if (!fills_element(topo, c, nullptr, rules, scratch)) continue;
                Vec3 x[8];
                for (int k = 0; k < 8; ++k) x[k] = X[c.nodes[k]];
                c.quality = static_cast<float>(min_scaled_jacobian(CellKind::Hex8, x));
                out.push_back(c);
              }
            }
          }
        }
      }
    }
  }
}

}  // namespace

std::vector<Candidate> enumerate_hexes(const TetTopology& topo, const HexOptions& options) {
  return collect_candidates(static_cast<std::int32_t>(topo.num_vertices()),
                            [&](std::int32_t v, FillScratch& scratch, std::vector<Candidate>& out) {
                              hexes_from(topo, v, options.min_quality, options.fill, scratch, out);
                            });
}

}  // namespace hexfem
