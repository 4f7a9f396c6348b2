#include "mesher/recombine_rules.hpp"

#include <algorithm>
#include <bit>

#include "mesher/mesh/element_topology.hpp"

namespace hexfem {

namespace {

// Per kind, as bit sets over local corners: each face's corners, and the pairs of corners
// joined by an edge or by a quad's diagonal (bit 8 i + j, both ways round).
struct KindSets {
  int num_faces = 0;
  std::array<unsigned, 6> face{};
  std::array<bool, 6> quad{};
  std::uint64_t edge = 0, diagonal = 0;
};
KindSets kind_sets(CellKind kind) {
  KindSets k;
  const CellFaces cf = faces_of(kind);
  k.num_faces = cf.count;
  auto pair = [](int a, int b) {
    return (std::uint64_t{1} << (8 * a + b)) | (std::uint64_t{1} << (8 * b + a));
  };
  for (int f = 0; f < cf.count; ++f) {
    const LocalFace& lf = cf.face[f];
    for (int i = 0; i < lf.n; ++i) {
      k.face[f] |= 1u << lf.v[i];
      k.edge |= pair(lf.v[i], lf.v[(i + 1) % lf.n]);
    }
    k.quad[f] = lf.n == 4;
    if (k.quad[f]) k.diagonal |= pair(lf.v[0], lf.v[2]) | pair(lf.v[1], lf.v[3]);
  }
  return k;
}
const KindSets& sets_of(CellKind kind) {
  static const std::array<KindSets, kNumCellKinds> table = [] {
    std::array<KindSets, kNumCellKinds> t;
    for (int k = 0; k < kNumCellKinds; ++k) t[k] = kind_sets(static_cast<CellKind>(k));
    return t;
  }();
  return table[static_cast<int>(kind)];
}

// The rules between candidate c and an element of kind ek, given at[k]: c's corner at the
// element's corner k, or -1 (at least two shared).
bool rules_broken(const Candidate& c, CellKind ek, const int* at) {
  const KindSets& cs = sets_of(c.kind);
  const KindSets& es = sets_of(ek);
  const int ne = num_nodes(ek);
  // An edge of one on a diagonal of the other.
  for (int a = 0; a < ne; ++a) {
    if (at[a] < 0) continue;
    for (int b = a + 1; b < ne; ++b) {
      if (at[b] < 0) continue;
      const std::uint64_t ab = std::uint64_t{1} << (8 * a + b);
      const std::uint64_t cab = std::uint64_t{1} << (8 * at[a] + at[b]);
      if (((es.edge & ab) && (cs.diagonal & cab)) || ((es.diagonal & ab) && (cs.edge & cab)))
        return true;
    }
  }
  // A face of one holding three corners of a face of the other, one of the two a quad (two
  // quads holding all four corners are the same face: conformal).
  for (int f = 0; f < es.num_faces; ++f) {
    unsigned fc = 0;  // the element's face f, in the candidate's corners
    for (int k = 0; k < ne; ++k)
      if ((es.face[f] >> k & 1u) && at[k] >= 0) fc |= 1u << at[k];
    if (std::popcount(fc) < 3) continue;
    for (int g = 0; g < cs.num_faces; ++g)
      if ((es.quad[f] || cs.quad[g]) && std::popcount(fc & cs.face[g]) == 3) return true;
  }
  return false;
}

}  // namespace

bool rules_conflict(const Candidate& c, const Candidate& e) {
  int at[8];
  int shared = 0;
  const int nc = num_nodes(c.kind), ne = num_nodes(e.kind);
  for (int k = 0; k < ne; ++k) {
    at[k] = -1;
    for (int i = 0; i < nc; ++i)
      if (c.nodes[i] == e.nodes[k]) at[k] = i;
    shared += at[k] >= 0;
  }
  return shared >= 2 && rules_broken(c, e.kind, at);  // every rule needs two shared vertices
}

template <class Visit>
void ConformityIndex::for_each_at(std::int32_t v, Visit visit) const {
  if (static_cast<std::size_t>(v) >= at_.size()) return;
  const AtVertex& a = at_[v];
  for (int i = 0; i < std::min(a.count, 15); ++i) visit(a.element[i]);
  if (a.count <= 15) return;
  auto it = std::lower_bound(overflow_.begin(), overflow_.end(), std::pair{v, -1});
  for (; it != overflow_.end() && it->first == v; ++it) visit(it->second);
}

bool ConformityIndex::conflicts(const Candidate& c, std::size_t from,
                                std::vector<std::uint64_t>& near) const {
  const int nc = num_nodes(c.kind);
  near.clear();
  for (int i = 0; i < nc; ++i)
    for_each_at(c.nodes[i], [&](std::int32_t e) {
      if (static_cast<std::size_t>(e) >= from)
        near.push_back(static_cast<std::uint64_t>(e) << 8 | static_cast<unsigned>(i));
    });
  std::sort(near.begin(), near.end());
  for (std::size_t i = 0; i < near.size();) {
    std::size_t j = i + 1;
    while (j < near.size() && near[j] >> 8 == near[i] >> 8) ++j;
    // Every rule needs two shared vertices.
    if (j - i < 2) {
      i = j;
      continue;
    }
    const Placed& e = placed_[near[i] >> 8];
    // The candidate's corner at each of e's corners, or -1.
    int at[8];
    const int ne = num_nodes(e.kind);
    for (int k = 0; k < ne; ++k) {
      at[k] = -1;
      for (std::size_t s = i; s < j; ++s) {
        const int ci = static_cast<int>(near[s] & 0xff);
        if (c.nodes[ci] == e.nodes[k]) at[k] = ci;
      }
    }
    i = j;
    if (rules_broken(c, e.kind, at)) return true;
  }
  return false;
}

void ConformityIndex::reserve(std::size_t n) {
  placed_.reserve(n);
}

void ConformityIndex::add(const Candidate& c) {
  const auto id = static_cast<std::int32_t>(placed_.size());
  placed_.push_back({c.kind, c.nodes});
  for (int i = 0; i < num_nodes(c.kind); ++i) {
    const std::int32_t v = c.nodes[i];
    if (static_cast<std::size_t>(v) >= at_.size())
      at_.resize(std::max<std::size_t>(v + 1, 2 * at_.size()));
    AtVertex& a = at_[v];
    if (a.count < 15) {
      a.element[a.count] = id;
    } else {
      const std::pair<std::int32_t, std::int32_t> entry{v, id};
      overflow_.insert(std::upper_bound(overflow_.begin(), overflow_.end(), entry), entry);
    }
    ++a.count;
  }
}

}  // namespace hexfem
