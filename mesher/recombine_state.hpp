// What the recombination stages pass along (hexes -> prisms -> pyramids -> NC repair -> volume
// gap -> sliver flips): the tet topology (read-only), the elements placed so far, the slivers
// absorbed into their quad faces, which tets are used, and the limits every stage reads.
// Invariant: each tet is in exactly one place: one element, the absorbed list, or free
// (used[t] == 0). Every stage that changes the state keeps it; debug_verify() checks it at the
// end of each such stage in debug builds, and the pipeline calls verify() once at the end.
#pragma once

#include <cstdint>
#include <vector>

#include "mesher/recombine_fill.hpp"

namespace hexfem {

struct RecombineLimits {
  double min_quality = 0.3;           // hexes and prisms below this min scaled Jacobian: not made
  double min_pyramid_quality = 0.05;  // pyramids below it stay two tets
  // A free tet on an element's quad face with a lower min scaled Jacobian is absorbed into that
  // element (a sliver between the face's two diagonals); free tets below it are flipped away.
  double sliver_quality = 0.02;
  // An element is undone (NC repair, volume gap, pyramids next to slivers) only when every tet it
  // gives back reaches this: a flatter tet would be a flat cell of its own.
  double keep_tet_quality = 1e-3;
  FillRules fill;  // the fill test's volume and twist tolerances
};

struct RecombineState {
  RecombineState(const TetTopology& t, const RecombineLimits& l)
      : topo(t), limits(l), used(t.mesh().tets.size(), 0) {}

  const TetTopology& topo;
  RecombineLimits limits;
  std::vector<Candidate> elements;     // hexes, prisms, pyramids
  std::vector<std::int32_t> absorbed;  // slivers merged into elements' quad faces
  std::vector<char> used;              // 1: in an element, absorbed, or (after flips) replaced

  // Appends an element whose tets are free, marking them used.
  void place(const Candidate& e);
  // Frees the tets of elements[i] (it stays listed until erased).
  void release(std::size_t i);
  // Erases the elements with drop[i] set (order kept), without touching the tets.
  void erase(const std::vector<char>& drop);
  // For each tet, the index of the element that holds it, or -1.
  std::vector<std::int32_t> element_of_tets() const;
  // release + erase of the elements with drop[i] set; adds how many of each kind went to
  // undone[kind] when given.
  void remove(const std::vector<char>& drop, std::size_t* undone = nullptr);
  // Throws hexfem::Error naming the first tet that is not in exactly one place; `replaced`: tets
  // the sliver flips took out (used, in no element).
  void verify(const std::vector<std::int32_t>& replaced = {}) const;
  void debug_verify() const {
#ifndef NDEBUG
    verify();
#endif
  }
};

}  // namespace hexfem
