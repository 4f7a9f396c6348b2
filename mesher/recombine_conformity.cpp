#include "mesher/recombine_conformity.hpp"

#include <algorithm>

#include "mesher/mesh/element_topology.hpp"
#include "mesher/mesh/quality.hpp"
#include "mesher/recombine_prism_pyramid.hpp"

namespace hexfem {

namespace {

// What lies across quad face f of an element: another element's quad (and which of its faces),
// the surface, or tets (NC).
constexpr std::int32_t kSurface = -2, kTets = -1;
struct Across {
  std::int32_t element = kTets;
  std::int8_t face = -1;
};

// Quad face f of e lies on the surface: its two triangles, split along either diagonal, are
// surface triangles.
bool quad_on_surface(const TetTopology& topo, const Candidate& e, int f) {
  const QuadKey q = quad_corners(e, f);
  return (topo.surface_triangle(q[0], q[1], q[2]) >= 0 &&
          topo.surface_triangle(q[0], q[2], q[3]) >= 0) ||
         (topo.surface_triangle(q[0], q[1], q[3]) >= 0 &&
          topo.surface_triangle(q[1], q[2], q[3]) >= 0);
}

// across[6 * i + f] for every quad face f of every element i (on all threads: each slot is
// written by its own element).
std::vector<Across> faces_across(const TetTopology& topo, const std::vector<Candidate>& elements) {
  const QuadFaces quads(elements, topo.num_vertices());
  std::vector<Across> across(6 * elements.size());
  parallel_for_quad_faces(elements, [&](std::size_t i, int f) {
    const std::size_t own = 6 * i + f;
    const std::int32_t other = quads.match(own);
    if (other >= 0)
      across[own] = {other / 6, static_cast<std::int8_t>(other % 6)};
    else if (other == QuadFaces::kAlone && quad_on_surface(topo, elements[i], f))
      across[own].element = kSurface;
  });
  return across;
}

std::size_t count_nc(const std::vector<Candidate>& elements, const std::vector<Across>& across,
                     const std::vector<char>& gone) {
  std::size_t nc = 0;
  for (std::size_t i = 0; i < elements.size(); ++i) {
    if (gone[i]) continue;
    const CellFaces cf = faces_of(elements[i].kind);
    for (int f = 0; f < cf.count; ++f)
      nc += cf.face[f].n == 4 && across[6 * i + f].element == kTets;
  }
  return nc;
}

bool has_vertex(const std::array<std::int32_t, 4>& T, std::int32_t v) {
  return T[0] == v || T[1] == v || T[2] == v || T[3] == v;
}

// The pyramid on quad q (in the outward order of the element it rests on) made of the two tets
// on its triangles split along diagonal d (0: q0-q2, 1: q1-q3), found by tet_on(triangle)
// (a tet with that face, or -1): they must share their fourth vertex, which is no corner of q
// (a flat tet on the face), lie in one solid, and make a pyramid of at least min_quality.
template <class TetOn>
bool pyramid_on(const TetTopology& topo, const std::int32_t* q, int d, TetOn tet_on,
                double min_quality, Candidate& out) {
  const std::int32_t tri[2][3] = {{q[d], q[d + 1], q[d + 2]}, {q[d + 2], q[(d + 3) % 4], q[d]}};
  std::int32_t tet[2], apex[2] = {-1, -1};
  for (int s = 0; s < 2; ++s) {
    tet[s] = tet_on(tri[s]);
    if (tet[s] < 0) return false;
    for (std::int32_t w : topo.mesh().tets[tet[s]])
      if (w != tri[s][0] && w != tri[s][1] && w != tri[s][2]) apex[s] = w;
  }
  if (tet[0] == tet[1] || apex[0] != apex[1] ||
      topo.mesh().tet_solid[tet[0]] != topo.mesh().tet_solid[tet[1]])
    return false;
  for (int k = 0; k < 4; ++k)
    if (q[k] == apex[0]) return false;
  out.kind = CellKind::Pyramid5;
  out.nodes = {q[0], q[1], q[2], q[3], apex[0], -1, -1, -1};
  out.tets = {std::min(tet[0], tet[1]), std::max(tet[0], tet[1]), -1, -1, -1, -1, -1};
  Vec3 x[5];
  for (int i = 0; i < 5; ++i) x[i] = topo.mesh().nodes[out.nodes[i]];
  const double qual = min_scaled_jacobian(CellKind::Pyramid5, x);
  out.quality = static_cast<float>(qual);
  return qual > 0 && qual >= min_quality;
}

bool has_triangle(const std::array<std::int32_t, 4>& T, const std::int32_t* tri) {
  return has_vertex(T, tri[0]) && has_vertex(T, tri[1]) && has_vertex(T, tri[2]);
}

// The pyramid that e's own tets on its quad face f make on the matching face pf of partner p
// once e is undone (base in p's outward order, apex inside e). Tets of e already taken by
// another such pyramid (taken[0..n)) are not reused. A face with a sliver between the two
// elements' diagonals gets none here (the final pyramid pass handles it).
bool pyramid_behind(const TetTopology& topo, const Candidate& e, int f, const Candidate& p, int pf,
                    double min_quality, const std::int32_t* taken, int n, Candidate& out) {
  const QuadKey q = quad_corners(p, pf);
  const int d = quad_diagonal(topo, p, pf);
  const LocalFace ef = faces_of(e.kind).face[f];
  const int de = quad_diagonal(topo, e, f);
  const std::int32_t pd[2] = {q[d], q[d + 2]}, ed[2] = {e.nodes[ef.v[de]], e.nodes[ef.v[de + 2]]};
  if (!((pd[0] == ed[0] && pd[1] == ed[1]) || (pd[0] == ed[1] && pd[1] == ed[0]))) return false;
  auto own_tet = [&](const std::int32_t* tri) {
    for (std::int32_t t : e.tets)
      if (t >= 0 && std::find(taken, taken + n, t) == taken + n &&
          has_triangle(topo.mesh().tets[t], tri))
        return t;
    return std::int32_t{-1};
  };
  return pyramid_on(topo, q.data(), d, own_tet, min_quality, out);
}

struct Undo {
  int gain;
  float quality;
  std::int32_t element;
  bool operator<(const Undo& o) const {
    if (gain != o.gain) return gain > o.gain;
    if (quality != o.quality) return quality < o.quality;
    return element < o.element;
  }
};

// True when the two free tets across quad face f of c (split along c's diagonal) make a
// pyramid of at least min_quality on it: the final pyramid pass can then match the face.
bool pyramid_possible(const TetTopology& topo, const Candidate& c, int f,
                      const std::vector<char>& used, double min_quality) {
  const QuadKey q = quad_corners(c, f);
  auto free_tet = [&](const std::int32_t* tri) {
    for (auto it = topo.star_begin(tri[0]); it != topo.star_end(tri[0]); ++it)
      if (has_triangle(topo.mesh().tets[*it], tri) &&
          std::find(c.tets.begin(), c.tets.end(), *it) == c.tets.end())
        return used[*it] ? std::int32_t{-1} : *it;
    return std::int32_t{-1};
  };
  Candidate unused;
  return pyramid_on(topo, q.data(), quad_diagonal(topo, c, f), free_tet, min_quality, unused);
}

// Prisms in the gaps between elements, made of free tets and of the tets of whole two-tet
// pyramids: a prism whose quad faces match NC faces of hexes or prisms replaces the pyramid on
// one of them and matches the others (where two hexes meet at an edge with a wedge of tets
// between them, the pyramid on one face leaves the other NC). Kept, best gain first then best
// quality, when it lowers the NC count: +1 for each NC face of an element it matches, -1 for
// each of its own quad faces left facing tets and for each pyramid it takes whose base it does
// not match. The elements (gone ones skipped) and what lies across their quad faces are kept up
// to date.
class GapPrisms {
 public:
  GapPrisms(RecombineState& s, std::vector<Across>& across, std::vector<char>& gone);
  // Places the prisms; r.undone counts the pyramids taken. `around` receives the new prisms and
  // the elements they match (whose faces may now hold a sliver to absorb). Returns how many.
  std::size_t run(NcRepair& r, std::vector<Candidate>& around);

 private:
  struct Scored {
    int gain;
    std::size_t cand;
    bool operator<(const Scored& o) const { return gain != o.gain ? gain > o.gain : cand < o.cand; }
  };
  // Owner (6 * element + face) of the quad face with sorted corners k, or -1.
  std::int32_t owner_of(const QuadKey& k) const;
  QuadKey corners(std::int32_t o) const { return quad_corners(s_.elements[o / 6], o % 6); }
  // Prisms with two owned faces, one of them NC, meeting at an edge (u, v) (the wedge of tets
  // between two elements); their lateral edge u-v is the prism's edge 0-3. Sorted, unique.
  std::vector<Candidate> candidates() const;
  // The NC count's drop if c is placed now (0 or less: not worth it); fills c.tets and taken_.
  int score(Candidate& c);
  // Puts the elements near a kept candidate into the conformity index (a conflict needs two
  // shared vertices).
  void index_elements_near(const std::vector<Candidate>& cands, const std::vector<Scored>& order);
  // Places c (scored just before, so taken_ holds its pyramids); returns its element index.
  std::int32_t place(const Candidate& c, NcRepair& r);

  RecombineState& s_;
  std::vector<Across>& across_;
  std::vector<char>& gone_;
  std::vector<char> soft_;                // used, but pyramid tets count as free
  std::vector<std::int32_t> pyramid_of_;  // tet -> the two-tet pyramid holding it, or -1
  std::vector<std::pair<QuadKey, std::int32_t>> owner_;  // hex/prism faces facing tets or a pyramid
  std::vector<std::pair<QuadKey, std::int32_t>> added_;  // quad faces of the new prisms, sorted
  std::vector<std::int32_t> taken_;                      // pyramids the scored candidate takes
  ConformityIndex index_;
};

GapPrisms::GapPrisms(RecombineState& s, std::vector<Across>& across, std::vector<char>& gone)
    : s_(s), across_(across), gone_(gone), soft_(s.used), pyramid_of_(s.used.size(), -1) {
  const std::vector<Candidate>& elements = s.elements;
  for (std::size_t i = 0; i < elements.size(); ++i) {
    const Candidate& e = elements[i];
    if (gone[i]) continue;
    if (e.kind == CellKind::Pyramid5) {
      if (e.tets[2] >= 0) continue;  // it holds a sliver: left alone
      for (int k = 0; k < 2; ++k) {
        soft_[e.tets[k]] = 0;
        pyramid_of_[e.tets[k]] = static_cast<std::int32_t>(i);
      }
      continue;
    }
    // Only faces facing tets or a pyramid: a candidate cannot have a face matched by two
    // elements already (the tets on both sides are taken).
    const CellFaces cf = faces_of(e.kind);
    for (int f = 0; f < cf.count; ++f) {
      const std::int32_t o = cf.face[f].n == 4 ? across[6 * i + f].element : kSurface;
      if (o == kTets || (o >= 0 && elements[o].kind == CellKind::Pyramid5))
        owner_.push_back({quad_key(e, f), static_cast<std::int32_t>(6 * i + f)});
    }
  }
  std::sort(owner_.begin(), owner_.end());
}

std::int32_t GapPrisms::owner_of(const QuadKey& k) const {
  for (const auto* v : {&owner_, &added_}) {
    auto it = std::lower_bound(v->begin(), v->end(), std::make_pair(k, -1));
    if (it != v->end() && it->first == k) return it->second;
  }
  return -1;
}

std::vector<Candidate> GapPrisms::candidates() const {
  std::vector<std::pair<std::uint64_t, std::int32_t>> by_edge;  // (edge, owner face)
  for (const auto& [key, o] : owner_) {
    const QuadKey q = corners(o);
    for (int k = 0; k < 4; ++k) by_edge.push_back({edge_key(q[k], q[(k + 1) % 4]), o});
  }
  std::sort(by_edge.begin(), by_edge.end());
  std::vector<Candidate> cands;
  const auto& X = s_.topo.mesh().nodes;
  for (const auto& [key, o] : owner_) {
    if (across_[o].element != kTets) continue;
    const QuadKey q = corners(o);
    for (int k = 0; k < 4; ++k) {
      std::int32_t u = q[k], v = q[(k + 1) % 4], x = q[(k + 3) % 4], y = q[(k + 2) % 4];
      if (u > v) {
        std::swap(u, v);
        std::swap(x, y);
      }
      auto it =
          std::lower_bound(by_edge.begin(), by_edge.end(), std::make_pair(edge_key(u, v), -1));
      for (; it != by_edge.end() && it->first == edge_key(u, v); ++it) {
        if (it->second == o) continue;
        const QuadKey p = corners(it->second);
        const int iu = static_cast<int>(std::find(p.begin(), p.end(), u) - p.begin());
        const int iv = static_cast<int>(std::find(p.begin(), p.end(), v) - p.begin());
        // The corners next to u and v in the other face, away from the shared edge.
        const std::int32_t x2 = p[(iu + 1) % 4] == v ? p[(iu + 3) % 4] : p[(iu + 1) % 4];
        const std::int32_t y2 = p[(iv + 1) % 4] == u ? p[(iv + 3) % 4] : p[(iv + 1) % 4];
        if (x2 == x || y2 == y || x2 == y || y2 == x) continue;
        for (int flip = 0; flip < 2; ++flip) {
          Candidate c;
          c.kind = CellKind::Wedge6;
          c.nodes = flip ? std::array<std::int32_t, 8>{u, x2, x, v, y2, y, -1, -1}
                         : std::array<std::int32_t, 8>{u, x, x2, v, y, y2, -1, -1};
          c.tets.fill(-1);
          Vec3 w[6];
          for (int i = 0; i < 6; ++i) w[i] = X[c.nodes[i]];
          const double qual = min_scaled_jacobian(CellKind::Wedge6, w);
          if (!(qual > 0 && qual >= s_.limits.min_quality)) continue;
          c.quality = static_cast<float>(qual);
          cands.push_back(c);
        }
      }
    }
  }
  std::sort(cands.begin(), cands.end());
  cands.erase(
      std::unique(cands.begin(), cands.end(),
                  [](const Candidate& a, const Candidate& b) { return a.nodes == b.nodes; }),
      cands.end());
  return cands;
}

int GapPrisms::score(Candidate& c) {
  const std::vector<Candidate>& elements = s_.elements;
  bool matches_nc = false;  // cheap test first: most candidates match no NC face
  const CellFaces cf = faces_of(c.kind);
  for (int f = 0; f < cf.count && !matches_nc; ++f) {
    if (cf.face[f].n != 4) continue;
    const std::int32_t o = owner_of(quad_key(c, f));
    matches_nc = o >= 0 && across_[o].element == kTets;
  }
  if (!matches_nc) return 0;
  c.tets.fill(-1);
  if (!fills_element(s_.topo, c, &soft_, s_.limits.fill)) return 0;
  taken_.clear();
  for (std::int32_t t : c.tets)
    if (t >= 0 && pyramid_of_[t] >= 0 &&
        std::find(taken_.begin(), taken_.end(), pyramid_of_[t]) == taken_.end())
      taken_.push_back(pyramid_of_[t]);
  for (std::int32_t y : taken_)  // both of its tets, or none
    for (int k = 0; k < 2; ++k)
      if (std::find(c.tets.begin(), c.tets.end(), elements[y].tets[k]) == c.tets.end()) return 0;
  int gain = 0, base_matched = 0;
  for (int f = 0; f < cf.count; ++f) {
    if (cf.face[f].n != 4) continue;
    const std::int32_t o = owner_of(quad_key(c, f));
    if (o >= 0) {
      const Across a = across_[o];
      if (a.element == kTets) {
        ++gain;
      } else if (a.element < 0 || elements[a.element].kind != CellKind::Pyramid5 ||
                 std::find(taken_.begin(), taken_.end(), a.element) == taken_.end()) {
        return 0;  // matched by something it does not replace
      } else {
        ++base_matched;  // it replaces the pyramid there
      }
    } else if (!quad_on_surface(s_.topo, c, f) &&
               !pyramid_possible(s_.topo, c, f, s_.used, s_.limits.min_pyramid_quality)) {
      --gain;
    }
  }
  return gain - (static_cast<int>(taken_.size()) - base_matched);
}

void GapPrisms::index_elements_near(const std::vector<Candidate>& cands,
                                    const std::vector<Scored>& order) {
  std::vector<char> near(s_.topo.num_vertices(), 0);
  for (const Scored& o : order)
    for (int k = 0; k < 6; ++k) near[cands[o.cand].nodes[k]] = 1;
  for (std::size_t i = 0; i < s_.elements.size(); ++i) {
    const Candidate& e = s_.elements[i];
    if (gone_[i] || e.kind == CellKind::Pyramid5) continue;
    bool is_near = false;
    for (int k = 0; k < num_nodes(e.kind) && !is_near; ++k) is_near = near[e.nodes[k]];
    if (is_near) index_.add(e);
  }
}

std::int32_t GapPrisms::place(const Candidate& c, NcRepair& r) {
  for (std::int32_t y : taken_) {
    gone_[y] = 1;
    s_.release(y);  // its tets go to the prism
    ++r.undone[static_cast<int>(CellKind::Pyramid5)];
    const Across a = across_[6 * y];  // the face the pyramid rested on: now facing tets
    if (a.element >= 0) across_[6 * a.element + a.face] = Across{};
  }
  const auto ci = static_cast<std::int32_t>(s_.elements.size());
  s_.place(c);
  gone_.push_back(0);
  across_.resize(6 * s_.elements.size());
  const CellFaces cf = faces_of(c.kind);
  for (int f = 0; f < cf.count; ++f) {
    if (cf.face[f].n != 4) continue;
    const QuadKey k = quad_key(c, f);
    const std::int32_t o = owner_of(k);
    if (o >= 0) {
      across_[o] = {ci, static_cast<std::int8_t>(f)};
      across_[6 * ci + f] = {o / 6, static_cast<std::int8_t>(o % 6)};
    } else if (quad_on_surface(s_.topo, c, f)) {
      across_[6 * ci + f].element = kSurface;
    }
    added_.insert(std::lower_bound(added_.begin(), added_.end(), std::make_pair(k, -1)),
                  {k, 6 * ci + f});
  }
  for (std::int32_t t : c.tets)
    if (t >= 0) {
      soft_[t] = 1;
      pyramid_of_[t] = -1;
    }
  index_.add(c);
  return ci;
}

std::size_t GapPrisms::run(NcRepair& r, std::vector<Candidate>& around) {
  std::vector<Candidate> cands = candidates();
  std::vector<Scored> order;
  for (std::size_t i = 0; i < cands.size(); ++i) {
    const int g = score(cands[i]);
    if (g > 0) order.push_back({g, i});
  }
  std::stable_sort(order.begin(), order.end());
  index_elements_near(cands, order);
  std::size_t made = 0;
  std::vector<std::int32_t> fresh;  // new prisms and the elements they match
  for (const Scored& o : order) {
    Candidate c = cands[o.cand];
    if (score(c) < o.gain || index_.conflicts(c)) continue;  // its neighbourhood changed
    const std::int32_t ci = place(c, r);
    ++made;
    fresh.push_back(ci);
    const CellFaces cf = faces_of(c.kind);
    for (int f = 0; f < cf.count; ++f)
      if (across_[6 * ci + f].element >= 0) fresh.push_back(across_[6 * ci + f].element);
  }
  std::sort(fresh.begin(), fresh.end());
  fresh.erase(std::unique(fresh.begin(), fresh.end()), fresh.end());
  for (std::int32_t i : fresh)
    if (!gone_[i]) around.push_back(s_.elements[i]);
  return made;
}

}  // namespace

std::size_t count_nc_faces(const TetTopology& topo, const std::vector<Candidate>& elements) {
  return count_nc(elements, faces_across(topo, elements), std::vector<char>(elements.size(), 0));
}

namespace {

// The rounds of undoing: what lies across every quad face, which elements are gone (erased at
// the end), and per element whether the tets it would give back may stand alone.
class Undoer {
 public:
  Undoer(RecombineState& s, const NcRepairOptions& o, NcRepair& r)
      : s_(s),
        o_(o),
        r_(r),
        across_(faces_across(s.topo, s.elements)),
        gone_(s.elements.size(), 0),
        slivers_(s.topo, s.absorbed),
        good_(s.elements.size(), -1),
        gain_(s.elements.size(), kUnknown) {}

  std::size_t count() const { return count_nc(s_.elements, across_, gone_); }
  // Undoes the elements worth it, round after round (undoing changes its neighbours' gains).
  void run() {
    for (;;) {
      const std::vector<Undo> undo = worth_undoing();
      if (undo.empty()) break;
      std::vector<char> touched(s_.elements.size(), 0);
      for (const Undo& u : undo)
        if (!touched[u.element]) undo_element(u.element, touched);
    }
  }
  std::vector<Across>& across() { return across_; }
  std::vector<char>& gone() { return gone_; }

 private:
  // 1: every tet element i gives back, slivers on its faces included, is good enough to stand
  // alone (s.limits.keep_tet_quality); 0: not.
  bool gives_back_good_tets(std::int32_t i);
  // The pyramids e's tets make on its partners' faces once e is undone (pyramid_behind), by
  // partner face: (e's face, the pyramid), in behind_.
  void find_pyramids_behind(std::int32_t i);
  // How much undoing element i lowers the NC count, or kNotWorth when less than its kind's
  // minimum gain (or it cannot be undone). It depends only on what lies across i's faces.
  static constexpr int kUnknown = -1000, kNotWorth = -1001;
  int gain_of(std::size_t i);
  // The elements whose undoing lowers the NC count by their kind's minimum gain, best first.
  std::vector<Undo> worth_undoing();
  // Undoes element i and the pyramids on it, and makes the pyramids behind it at once (so later
  // rounds see those faces matched); no neighbour of a touched element goes in the same round.
  void undo_element(std::int32_t i, std::vector<char>& touched);

  RecombineState& s_;
  const NcRepairOptions& o_;
  NcRepair& r_;
  std::vector<Across> across_;
  std::vector<char> gone_;
  const TetsByCorners slivers_;    // the absorbed slivers
  std::vector<signed char> good_;  // gives_back_good_tets, -1: not known yet
  // gain_of, kUnknown until asked and again whenever what lies across a face changes: a round
  // asks only the elements next to the last round's changes (most rounds undo a handful).
  std::vector<int> gain_;
  std::vector<std::pair<int, Candidate>> behind_;
};

bool Undoer::gives_back_good_tets(std::int32_t i) {
  if (good_[i] >= 0) return good_[i] == 1;
  const Candidate& e = s_.elements[i];
  const double keep_sj = s_.limits.keep_tet_quality;
  bool ok = true;
  for (std::int32_t t : e.tets) ok = ok && (t < 0 || tet_quality(s_.topo, t) >= keep_sj);
  const CellFaces cf = faces_of(e.kind);
  for (int f = 0; f < cf.count && ok; ++f) {
    if (cf.face[f].n != 4) continue;
    const QuadKey k = quad_key(e, f);
    const std::int32_t t = slivers_.find(k);
    if (t >= 0) ok = tet_quality(s_.topo, t) >= keep_sj;
  }
  good_[i] = ok ? 1 : 0;
  return ok;
}

void Undoer::find_pyramids_behind(std::int32_t i) {
  behind_.clear();
  if (!o_.make_pyramids) return;
  std::int32_t taken[8];
  int n = 0;
  const Candidate& e = s_.elements[i];
  const CellFaces cf = faces_of(e.kind);
  for (int f = 0; f < cf.count; ++f) {
    const Across o = cf.face[f].n == 4 ? across_[6 * i + f] : Across{};
    if (o.element < 0 || s_.elements[o.element].kind == CellKind::Pyramid5) continue;
    Candidate c;
    if (!pyramid_behind(s_.topo, e, f, s_.elements[o.element], o.face,
                        s_.limits.min_pyramid_quality, taken, n, c))
      continue;
    taken[n++] = c.tets[0];
    taken[n++] = c.tets[1];
    behind_.push_back({f, c});
  }
}

int Undoer::gain_of(std::size_t i) {
  const CellFaces cf = faces_of(s_.elements[i].kind);
  int gain = 0, nc = 0;
  bool ok = true;
  for (int f = 0; f < cf.count && ok; ++f) {
    if (cf.face[f].n != 4) continue;
    const Across& o = across_[6 * i + f];
    if (o.element == kTets) {
      ++gain;  // an NC face goes
      ++nc;
    } else if (o.element >= 0) {
      if (s_.elements[o.element].kind == CellKind::Pyramid5)
        ok = gives_back_good_tets(o.element);  // it goes too, leaving no NC face
      else
        --gain;  // the partner's face becomes NC, unless a pyramid of e's tets covers it
    }
  }
  const int need = s_.elements[i].kind == CellKind::Hex8 ? o_.min_hex_gain : 1;
  if (!ok || nc < need) return kNotWorth;
  if (gain < need) {
    find_pyramids_behind(static_cast<std::int32_t>(i));
    gain += static_cast<int>(behind_.size());
  }
  if (gain >= need && gives_back_good_tets(static_cast<std::int32_t>(i))) return gain;
  return kNotWorth;
}

std::vector<Undo> Undoer::worth_undoing() {
  std::vector<Undo> undo;
  for (std::size_t i = 0; i < s_.elements.size(); ++i) {
    if (gone_[i]) continue;
    if (gain_[i] == kUnknown) gain_[i] = gain_of(i);
    if (gain_[i] != kNotWorth)
      undo.push_back({gain_[i], s_.elements[i].quality, static_cast<std::int32_t>(i)});
  }
  std::sort(undo.begin(), undo.end());
  return undo;
}

void Undoer::undo_element(std::int32_t i, std::vector<char>& touched) {
  std::vector<Candidate>& elements = s_.elements;
  find_pyramids_behind(i);  // before across_ changes
  std::vector<std::int32_t> drop{i};
  touched[i] = 1;
  const CellFaces cf = faces_of(elements[i].kind);
  for (int f = 0; f < cf.count; ++f) {
    const std::int32_t o = cf.face[f].n == 4 ? across_[6 * i + f].element : kTets;
    if (o < 0) continue;
    touched[o] = 1;
    if (elements[o].kind == CellKind::Pyramid5) drop.push_back(o);
  }
  // Partners' faces as they were, for the pyramids made on them below.
  std::vector<Across> partner;
  for (const auto& [f, c] : behind_) partner.push_back(across_[6 * i + f]);
  for (std::int32_t d : drop) {
    gone_[d] = 1;
    ++r_.undone[static_cast<int>(elements[d].kind)];
    s_.release(d);
    const CellFaces df = faces_of(elements[d].kind);
    for (int f = 0; f < df.count; ++f) {
      const Across o = df.face[f].n == 4 ? across_[6 * d + f] : Across{};
      if (o.element < 0) continue;
      across_[6 * o.element + o.face] = Across{};  // now facing tets
      gain_[o.element] = kUnknown;
    }
  }
  for (std::size_t k = 0; k < behind_.size(); ++k) {
    const auto y = static_cast<std::int32_t>(elements.size());
    s_.place(behind_[k].second);
    gone_.push_back(0);
    good_.push_back(-1);
    gain_.push_back(kUnknown);
    touched.push_back(1);
    across_.resize(6 * elements.size());
    across_[6 * y] = partner[k];  // the pyramid's base is its face 0
    across_[6 * partner[k].element + partner[k].face] = {y, 0};
    gain_[partner[k].element] = kUnknown;
    ++r_.pyramids_added;
  }
}

}  // namespace

NcRepair undo_nonconformal_elements(RecombineState& s, const NcRepairOptions& o) {
  NcRepair r;
  Undoer undoer(s, o, r);
  r.nc_before = undoer.count();
  undoer.run();
  std::vector<Candidate> around;
  if (o.make_prisms && o.make_pyramids)
    r.prisms_added = GapPrisms(s, undoer.across(), undoer.gone()).run(r, around);
  r.nc_after = undoer.count();
  s.erase(undoer.gone());  // their tets were freed when they went
  release_orphan_slivers(s);
  // Slivers between a new prism's face and the surface or a matched face belong to it, as after
  // the prism stage; flat ones on its faces against tets too, as after the pyramids.
  for (SliverPolicy p : {SliverPolicy::kSharedOrBoundary, SliverPolicy::kFlat})
    absorb_face_slivers(s, around, p);
  if (o.make_pyramids) {
    // The partners' faces left facing tets: a pyramid on one matches it (each sits on an NC face).
    std::vector<Candidate> pyramids = enumerate_pyramids(s);
    const std::size_t kept = place_pyramids(s, pyramids);
    r.pyramids_added += kept;
    r.nc_after -= kept;
  }
  s.debug_verify();
  return r;
}

}  // namespace hexfem
