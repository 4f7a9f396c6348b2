#include "mesher/recombine_state.hpp"

#include <string>

#include "mesher/mesh/error.hpp"

namespace hexfem {

void RecombineState::place(const Candidate& e) {
  for (std::int32_t t : e.tets)
    if (t >= 0) used[t] = 1;
  elements.push_back(e);
}

void RecombineState::release(std::size_t i) {
  for (std::int32_t t : elements[i].tets)
    if (t >= 0) used[t] = 0;
}

void RecombineState::erase(const std::vector<char>& drop) {
  std::size_t k = 0;
  for (std::size_t i = 0; i < elements.size(); ++i)
    if (!drop[i]) elements[k++] = elements[i];
  elements.resize(k);
}

std::vector<std::int32_t> RecombineState::element_of_tets() const {
  std::vector<std::int32_t> owner(used.size(), -1);
  for (std::size_t e = 0; e < elements.size(); ++e)
    for (std::int32_t t : elements[e].tets)
      if (t >= 0) owner[t] = static_cast<std::int32_t>(e);
  return owner;
}

void RecombineState::remove(const std::vector<char>& drop, std::size_t* undone) {
  for (std::size_t i = 0; i < elements.size(); ++i) {
    if (!drop[i]) continue;
    if (undone) ++undone[static_cast<int>(elements[i].kind)];
    release(i);
  }
  erase(drop);
}

void RecombineState::verify(const std::vector<std::int32_t>& replaced) const {
  std::vector<std::uint8_t> count(used.size(), 0);
  for (const Candidate& e : elements)
    for (std::int32_t t : e.tets)
      if (t >= 0) ++count[t];
  for (std::int32_t t : absorbed) ++count[t];
  for (std::int32_t t : replaced) ++count[t];
  for (std::size_t t = 0; t < used.size(); ++t) {
    if (!used[t]) ++count[t];
    if (count[t] != 1)
      throw Error("volume mesher: tet " + std::to_string(t) + " is used " +
                  std::to_string(count[t]) + " times (internal error)");
  }
}

}  // namespace hexfem
