#include "mesher/volume_gap.hpp"

#include <algorithm>
#include <cmath>

#include "mesher/mesh/element_topology.hpp"
#include "mesher/mesh/parallel.hpp"
#include "mesher/mesh/quality.hpp"

namespace hexfem {

namespace {

double element_volume(const TetTopology& topo, const Candidate& e) {
  Vec3 x[8];
  for (int i = 0; i < num_nodes(e.kind); ++i) x[i] = topo.mesh().nodes[e.nodes[i]];
  return volume(e.kind, x);
}

struct Undo {
  double benefit_per_volume, gain;
  std::size_t element;
};

}  // namespace

double element_gap(const TetTopology& topo, const Candidate& e) {
  double d = element_volume(topo, e);
  for (std::int32_t t : e.tets)
    if (t >= 0) d -= topo.tet_volume(t);
  return d;
}

double volume_gap(const TetTopology& topo, const std::vector<Candidate>& elements,
                  const std::vector<std::int32_t>& absorbed) {
  // The elements' gaps on all threads, summed in element order.
  std::vector<double> gap(elements.size());
  const auto n = static_cast<std::ptrdiff_t>(elements.size());
#pragma omp parallel for schedule(static, 4096)
  for (std::ptrdiff_t i = 0; i < n; ++i) gap[i] = element_gap(topo, elements[i]);
  double g = 0;
  for (const double d : gap) g += d;
  for (std::int32_t t : absorbed) g -= topo.tet_volume(t);
  return g;
}

VolumeGap limit_volume_gap(RecombineState& s, double max_rel_gap) {
  const TetTopology& topo = s.topo;
  const std::vector<Candidate>& elements = s.elements;
  const double keep_sj = s.limits.keep_tet_quality;
  VolumeGap r;
  for (std::size_t t = 0; t < topo.mesh().tets.size(); ++t) r.tets += topo.tet_volume(t);
  double g = volume_gap(topo, elements, s.absorbed);
  r.gap_before = g;
  const double budget = max_rel_gap * r.tets;
  // A few rounds: freeing slivers makes the prediction of a round inexact.
  for (int round = 0; round < 8 && std::abs(g) > budget; ++round) {
    const QuadFaces quads(elements, topo.num_vertices());
    const TetsByCorners slivers(topo, s.absorbed);
    const double sign = g < 0 ? 1.0 : -1.0;  // undoing must move g towards 0
    // Each element's case on all threads, listed in element order.
    std::vector<Undo> undo =
        parallel_collect<Undo>(elements.size(), [&](std::size_t i, std::vector<Undo>& out) {
          const Candidate& e = elements[i];
          bool keeps_valid = true;
          for (std::int32_t t : e.tets)
            keeps_valid = keeps_valid && (t < 0 || tet_quality(topo, t) >= keep_sj);
          if (!keeps_valid) return;
          // Undoing changes the gap by -element_gap plus the slivers it frees: those on its faces
          // that no other element shares.
          double gain = -element_gap(topo, e);
          const CellFaces cf = faces_of(e.kind);
          for (int f = 0; f < cf.count && keeps_valid; ++f) {
            if (cf.face[f].n != 4) continue;
            // A sliver on a shared face is freed too when the neighbour goes in the same round.
            const QuadKey k = quad_key(e, f);
            const bool shared = quads.shared(6 * i + f);
            const std::int32_t t = slivers.find(k);
            if (t >= 0) {
              if (!shared) gain += topo.tet_volume(t);
              keeps_valid = keeps_valid && tet_quality(topo, t) >= keep_sj;
            }
          }
          if (!keeps_valid || sign * gain <= 0) return;
          out.push_back({sign * gain / element_volume(topo, e), gain, i});
        });
    if (undo.empty()) break;
    std::sort(undo.begin(), undo.end(), [](const Undo& a, const Undo& b) {
      return a.benefit_per_volume != b.benefit_per_volume
                 ? a.benefit_per_volume > b.benefit_per_volume
                 : a.element < b.element;
    });
    // Aim below the budget, so the freed slivers' surprises rarely need another round.
    std::vector<char> drop(elements.size(), 0);
    double predicted = g;
    for (const Undo& u : undo) {
      if (std::abs(predicted) <= 0.8 * budget) break;
      drop[u.element] = 1;
      predicted += u.gain;
    }
    s.remove(drop, r.undone);
    release_orphan_slivers(s);
    g = volume_gap(topo, elements, s.absorbed);
  }
  r.gap_after = g;
  s.debug_verify();
  return r;
}

}  // namespace hexfem
