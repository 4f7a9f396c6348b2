// Shared by the two CGAL triangulations of a face's parameter plane (background mesh and final
// mesh): which faces of a constrained triangulation lie inside the trimmed domain. Inside means
// an odd number of constraint crossings from the infinite face (outer wire, holes, islands).
#pragma once

#include <deque>
#include <vector>

namespace hexfem {

// CDT's face base must carry `info()` convertible from int (the nesting level).
template <class CDT>
void mark_nesting_levels(CDT& cdt) {
  using Face_handle = typename CDT::Face_handle;
  for (auto f = cdt.all_faces_begin(); f != cdt.all_faces_end(); ++f) f->info() = -1;
  std::deque<typename CDT::Edge> border;
  auto flood = [&](Face_handle start, int level) {
    if (start->info() != -1) return;
    std::vector<Face_handle> stack{start};
    start->info() = level;
    while (!stack.empty()) {
      Face_handle fh = stack.back();
      stack.pop_back();
      for (int i = 0; i < 3; ++i) {
        Face_handle n = fh->neighbor(i);
        if (n->info() != -1) continue;
        if (cdt.is_constrained(typename CDT::Edge(fh, i))) {
          border.emplace_back(fh, i);
        } else {
          n->info() = level;
          stack.push_back(n);
        }
      }
    }
  };
  flood(cdt.infinite_face(), 0);
  while (!border.empty()) {
    auto e = border.front();
    border.pop_front();
    Face_handle n = e.first->neighbor(e.second);
    if (n->info() == -1) flood(n, e.first->info() + 1);
  }
}

}  // namespace hexfem
