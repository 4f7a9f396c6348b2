#include "mesher/recombine_conformity.hpp"

#include <algorithm>

#include "mesher/mesh/element_topology.hpp"
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
  const LocalFace lf = faces_of(e.kind).face[f];
  std::int32_t q[4];
  for (int k = 0; k < 4; ++k) q[k] = e.nodes[lf.v[k]];
  return (topo.surface_triangle(q[0], q[1], q[2]) >= 0 &&
          topo.surface_triangle(q[0], q[2], q[3]) >= 0) ||
         (topo.surface_triangle(q[0], q[1], q[3]) >= 0 &&
          topo.surface_triangle(q[1], q[2], q[3]) >= 0);
}

// across[6 * i + f] for every quad face f of every element i.
std::vector<Across> faces_across(const TetTopology& topo, const std::vector<Candidate>& elements) {
  struct Owner {
    QuadKey key;
    std::int32_t element;
    std::int8_t face;
    bool operator<(const Owner& o) const {
      for (int i = 0; i < 4; ++i)
        if (key[i] != o.key[i]) return key[i] < o.key[i];
      return element < o.element;
    }
  };
  std::vector<Owner> owners;
  for (std::size_t i = 0; i < elements.size(); ++i) {
    const CellFaces cf = faces_of(elements[i].kind);
    for (int f = 0; f < cf.count; ++f)
      if (cf.face[f].n == 4)
        owners.push_back(
            {quad_key(elements[i], f), static_cast<std::int32_t>(i), static_cast<std::int8_t>(f)});
  }
  std::sort(owners.begin(), owners.end());
  std::vector<Across> across(6 * elements.size());
  for (std::size_t a = 0; a < owners.size();) {
    std::size_t b = a + 1;
    while (b < owners.size() && owners[b].key == owners[a].key) ++b;
    if (b - a == 2) {
      across[6 * owners[a].element + owners[a].face] = {owners[a + 1].element, owners[a + 1].face};
      across[6 * owners[a + 1].element + owners[a + 1].face] = {owners[a].element, owners[a].face};
    } else if (b - a == 1 && quad_on_surface(topo, elements[owners[a].element], owners[a].face)) {
      across[6 * owners[a].element + owners[a].face].element = kSurface;
    }
    a = b;
  }
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

}  // namespace

std::size_t count_nc_faces(const TetTopology& topo, const std::vector<Candidate>& elements) {
  return count_nc(elements, faces_across(topo, elements), std::vector<char>(elements.size(), 0));
}

NcRepair undo_nonconformal_elements(const TetTopology& topo, std::vector<Candidate>& elements,
                                    std::vector<std::int32_t>& absorbed, std::vector<char>& used,
                                    double flat_sj, double keep_sj, double min_pyramid,
                                    int min_hex_gain, bool make_pyramids) {
  NcRepair r;
  std::vector<Across> across = faces_across(topo, elements);
  std::vector<char> gone(elements.size(), 0);
  r.nc_before = count_nc(elements, across, gone);
  // Absorbed slivers by their sorted corners: undoing an element frees those on its faces.
  std::vector<std::pair<QuadKey, std::int32_t>> slivers;
  for (std::int32_t t : absorbed) {
    QuadKey k = topo.mesh().tets[t];
    std::sort(k.begin(), k.end());
    slivers.push_back({k, t});
  }
  std::sort(slivers.begin(), slivers.end());
  // 1: every tet it gives back, slivers on its faces included, is good enough to stand alone;
  // 0: not; -1: not known yet.
  std::vector<signed char> good(elements.size(), -1);
  auto gives_back_good_tets = [&](std::int32_t i) {
    if (good[i] >= 0) return good[i] == 1;
    const Candidate& e = elements[i];
    bool ok = true;
    for (std::int32_t t : e.tets) ok = ok && (t < 0 || tet_quality(topo, t) >= keep_sj);
    const CellFaces cf = faces_of(e.kind);
    for (int f = 0; f < cf.count && ok; ++f) {
      if (cf.face[f].n != 4) continue;
      const QuadKey k = quad_key(e, f);
      auto it = std::lower_bound(slivers.begin(), slivers.end(), std::make_pair(k, -1));
      for (; it != slivers.end() && it->first == k && ok; ++it)
        ok = tet_quality(topo, it->second) >= keep_sj;
    }
    good[i] = ok ? 1 : 0;
    return ok;
  };
  // Undoing changes its neighbours' counts: rounds, no two neighbours in one.
  for (;;) {
    std::vector<Undo> undo;
    for (std::size_t i = 0; i < elements.size(); ++i) {
      if (gone[i]) continue;
      const CellFaces cf = faces_of(elements[i].kind);
      int gain = 0;
      bool ok = true;
      for (int f = 0; f < cf.count && ok; ++f) {
        if (cf.face[f].n != 4) continue;
        const Across& o = across[6 * i + f];
        if (o.element == kTets) {
          ++gain;  // an NC face goes
        } else if (o.element >= 0) {
          if (elements[o.element].kind == CellKind::Pyramid5)
            ok = gives_back_good_tets(o.element);  // it goes too, leaving no NC face
          else
            --gain;  // the partner's face becomes NC
        }
      }
      if (ok && gain >= (elements[i].kind == CellKind::Hex8 ? min_hex_gain : 1) &&
          gives_back_good_tets(static_cast<std::int32_t>(i)))
        undo.push_back({gain, elements[i].quality, static_cast<std::int32_t>(i)});
    }
    if (undo.empty()) break;
    std::sort(undo.begin(), undo.end());
    std::vector<char> touched(elements.size(), 0);
    for (const Undo& u : undo) {
      if (touched[u.element]) continue;
      std::vector<std::int32_t> drop{u.element};
      touched[u.element] = 1;
      const CellFaces cf = faces_of(elements[u.element].kind);
      for (int f = 0; f < cf.count; ++f) {
        const std::int32_t o = cf.face[f].n == 4 ? across[6 * u.element + f].element : kTets;
        if (o < 0) continue;
        touched[o] = 1;
        if (elements[o].kind == CellKind::Pyramid5) drop.push_back(o);
      }
      for (std::int32_t d : drop) {
        gone[d] = 1;
        ++r.undone[static_cast<int>(elements[d].kind)];
        for (std::int32_t t : elements[d].tets)
          if (t >= 0) used[t] = 0;
        const CellFaces df = faces_of(elements[d].kind);
        for (int f = 0; f < df.count; ++f) {
          const Across o = df.face[f].n == 4 ? across[6 * d + f] : Across{};
          if (o.element >= 0) across[6 * o.element + o.face] = Across{};  // now facing tets
        }
      }
    }
  }
  r.nc_after = count_nc(elements, across, gone);
  std::size_t k = 0;
  for (std::size_t i = 0; i < elements.size(); ++i)
    if (!gone[i]) elements[k++] = elements[i];
  elements.resize(k);
  release_orphan_slivers(topo, elements, absorbed, used, flat_sj);
  if (!make_pyramids) return r;
  // The partners' faces left facing tets: a pyramid on one matches it (each sits on an NC face).
  std::vector<Candidate> pyramids = enumerate_pyramids(topo, elements, used, min_pyramid);
  const std::vector<Candidate> kept = place_pyramids(pyramids, used);
  r.pyramids_added = kept.size();
  r.nc_after -= kept.size();
  elements.insert(elements.end(), kept.begin(), kept.end());
  return r;
}

}  // namespace hexfem
