#include "fem/block_csr.hpp"

#include <algorithm>

#include "fem/nc_ties.hpp"
#include "fem/petsc_env.hpp"

namespace hexfem {

BlockCsr block_pattern(const NodeGraph& g, const DofLayout& L, bool upper, int width) {
  BlockCsr A;
  A.first = L.begin;
  A.width = width;
  const long nloc = L.end - L.begin;
  // Calls f(q) for each column of row p.
  const auto for_columns = [&](long p, auto&& f) {
    f(p);
    const std::int32_t v = L.order[p];
    for (long e = g.ptr[v]; e < g.ptr[v + 1]; ++e)
      if (const long q = L.pos[g.adj[e]]; q >= 0 && (!upper || q > p)) f(q);
  };
  A.ptr.assign(nloc + 1, 0);
  for (long r = 0; r < nloc; ++r) {
    long count = 0;
    for_columns(L.begin + r, [&](long) { ++count; });
    A.ptr[r + 1] = A.ptr[r] + count;
  }
  A.col.resize(A.ptr[nloc]);
  for (long r = 0; r < nloc; ++r) {
    long k = A.ptr[r];
    for_columns(L.begin + r, [&](long q) { A.col[k++] = static_cast<std::int32_t>(q); });
    std::sort(A.col.begin() + A.ptr[r], A.col.begin() + k);
  }
  A.val.assign(static_cast<std::size_t>(width) * A.col.size(), 0.0);
  return A;
}

void add_element(const PetscInt* pos, int n, const double* Ke, const double* Me, BlockCsr& K,
                 BlockCsr& M) {
  const int nd = 3 * n;
  // The element's nodes by ascending position: each row's columns are then found by searching
  // on from the previous one.
  int order[kMaxTiedElementNodes];
  int m = 0;
  for (int j = 0; j < n; ++j)
    if (pos[j] >= 0) order[m++] = j;
  std::sort(order, order + m, [&](int a, int b) { return pos[a] < pos[b]; });
  for (int i = 0; i < n; ++i) {
    const long r = static_cast<long>(pos[i]) - K.first;
    if (pos[i] < 0 || r < 0 || r >= K.rows()) continue;
    const std::int32_t* kc = K.col.data();
    const std::int32_t* mc = M.col.data();
    long k = K.ptr[r], km = M.ptr[r];
    for (int s = 0; s < m; ++s) {
      const int j = order[s];
      k = std::lower_bound(kc + k, kc + K.ptr[r + 1], pos[j]) - kc;
      double* b = &K.val[9 * k];
      for (int a = 0; a < 3; ++a)
        for (int c = 0; c < 3; ++c) b[3 * a + c] += Ke[(3 * i + a) * nd + 3 * j + c];
      if (pos[j] < pos[i]) continue;
      km = std::lower_bound(mc + km, mc + M.ptr[r + 1], pos[j]) - mc;
      for (int a = 0; a < 3; ++a) M.val[3 * km + a] += Me[(3 * i + a) * nd + 3 * j + a];
    }
  }
}

void count_blocks(const BlockCsr& A, const DofLayout& L, std::vector<PetscInt>& diag,
                  std::vector<PetscInt>& off) {
  diag.assign(A.rows(), 0);
  off.assign(A.rows(), 0);
  for (long r = 0; r < A.rows(); ++r)
    for (long k = A.ptr[r]; k < A.ptr[r + 1]; ++k)
      ++(A.col[k] >= L.begin && A.col[k] < L.end ? diag : off)[r];
}

void add_rows(const BlockCsr& A, Mat mat) {
  std::vector<PetscInt> cols;
  std::vector<double> v;
  for (long r = 0; r < A.rows(); ++r) {
    const long k0 = A.ptr[r];
    const int nb = static_cast<int>(A.ptr[r + 1] - k0);
    cols.assign(A.col.begin() + k0, A.col.begin() + k0 + nb);
    // PETSc's row-oriented block row: 3 rows of 3 nb values.
    v.assign(9 * static_cast<std::size_t>(nb), 0.0);
    for (int q = 0; q < nb; ++q)
      for (int a = 0; a < 3; ++a)
        for (int c = 0; c < 3; ++c) {
          const double x = A.width == 9 ? A.val[9 * (k0 + q) + 3 * a + c]
                           : a == c     ? A.val[3 * (k0 + q) + a]
                                        : 0.0;
          v[3 * nb * a + 3 * q + c] = x;
        }
    const PetscInt row = static_cast<PetscInt>(A.first + r);
    HEXFEM_PETSC(MatSetValuesBlocked(mat, 1, &row, nb, cols.data(), v.data(), ADD_VALUES));
  }
}

}  // namespace hexfem
