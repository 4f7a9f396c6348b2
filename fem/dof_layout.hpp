// Where each node's three DOFs sit in the distributed matrices of the iterative path: the nodes
// that carry equations in one order, cut into one contiguous range per MPI rank.
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

namespace hexfem {

struct DofLayout {
  std::vector<std::int32_t> order;  // position -> node
  std::vector<std::int32_t> pos;    // node -> position, -1 when the node has no equation
  std::vector<long> starts;         // first position of each rank, plus the end
  long begin = 0, end = 0;          // this rank's positions
  int owner(long p) const {
    return static_cast<int>(std::upper_bound(starts.begin(), starts.end(), p) - starts.begin()) - 1;
  }
};

}  // namespace hexfem
