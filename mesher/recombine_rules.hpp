// The paper's conformity rules between hexes and prisms (Figs 15-18), checked for a candidate
// against the elements placed so far.
#pragma once

#include <array>
#include <cstdint>
#include <utility>
#include <vector>

#include "mesher/recombine_fill.hpp"

namespace hexfem {

// The conformity rules between hexes and prisms (paper Figs 15-18): no two elements share
// three vertices of a quad face unless they share the whole quad; no triangle face of a prism
// has three vertices of another element's quad; no edge of one is a diagonal of the other's quad.
// Every rule concerns two elements sharing two or more vertices: a candidate is checked against
// the placed elements at its corners (listed per vertex), not against tables of all faces.
// The same rules between two elements alone: whether c breaks one against e.
bool rules_conflict(const Candidate& c, const Candidate& e);

class ConformityIndex {
 public:
  bool conflicts(const Candidate& c) const { return conflicts(c, 0, near_); }
  // Against the elements added from the `from`-th on only (added before: checked already), with
  // the caller's work list, so that threads can check at once while nothing is added.
  bool conflicts(const Candidate& c, std::size_t from, std::vector<std::uint64_t>& near) const;
  // Asks the memory for what conflicts(c) and add(c) will read (a hint, no effect otherwise).
  void prefetch(const Candidate& c) const {
    for (int i = 0; i < num_nodes(c.kind); ++i)
      if (static_cast<std::size_t>(c.nodes[i]) < at_.size()) __builtin_prefetch(&at_[c.nodes[i]]);
  }
  // How many elements were added.
  std::size_t size() const { return placed_.size(); }
  void add(const Candidate& c);
  // Room for about n elements.
  void reserve(std::size_t n);

 private:
  struct Placed {
    CellKind kind;
    std::array<std::int32_t, 8> nodes;
  };
  // The placed elements at each vertex: up to 15 in place (one cache line), more in overflow_.
  struct alignas(64) AtVertex {
    std::int32_t count = 0;
    std::int32_t element[15];
  };
  template <class Visit>
  void for_each_at(std::int32_t v, Visit visit) const;

  std::vector<Placed> placed_;
  std::vector<AtVertex> at_;
  std::vector<std::pair<std::int32_t, std::int32_t>> overflow_;  // (vertex, element), sorted
  mutable std::vector<std::uint64_t> near_;  // conflicts' work list: element << 8 | corner
};

}  // namespace hexfem
