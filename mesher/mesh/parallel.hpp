// Loops, sorts and merges on all OpenMP threads for the mesher's big lists (millions of faces),
// whose results never depend on the number of threads. A sort's result is std::sort's whenever
// elements that compare equal are identical, which holds for every list sorted with it (keys
// with the owner in the order, or plain keys). Without OpenMP: the serial loop, std::sort and
// std::merge.
#pragma once

#include <algorithm>
#include <cstddef>
#include <functional>
#include <vector>

#ifdef _OPENMP
#include <omp.h>
#endif

namespace hexfem {

// std::merge of [a, a + na) and [b, b + nb) into out, cut into `pieces` merges of equal output
// length run on all threads. Each cut is placed on the merge path (the first k outputs take i
// elements of a and k - i of b, ties from a first, as std::merge does).
template <class T, class Less = std::less<>>
void parallel_merge(const T* a, std::size_t na, const T* b, std::size_t nb, T* out, int pieces,
                    Less less = {}) {
  auto split = [&](std::size_t k) {
    std::size_t lo = k > nb ? k - nb : 0, hi = std::min(k, na);
    while (lo < hi) {
      const std::size_t mid = (lo + hi) / 2;
      if (!less(b[k - mid - 1], a[mid]))
        lo = mid + 1;
      else
        hi = mid;
    }
    return lo;
  };
  const std::size_t n = na + nb;
#pragma omp parallel for schedule(static, 1) if (pieces > 1)
  for (int p = 0; p < pieces; ++p) {
    const std::size_t k0 = n * p / pieces, k1 = n * (p + 1) / pieces;
    const std::size_t i0 = split(k0), i1 = split(k1);
    std::merge(a + i0, a + i1, b + (k0 - i0), b + (k1 - i1), out + k0, less);
  }
}

// std::sort of v: one part per thread sorted, then merged in pairs, each merge on all threads.
template <class T, class Less = std::less<>>
void parallel_sort(std::vector<T>& v, Less less = {}) {
  int threads = 1;
#ifdef _OPENMP
  threads = omp_get_max_threads();
#endif
  if (threads < 2 || v.size() < (std::size_t{1} << 15)) {
    std::sort(v.begin(), v.end(), less);
    return;
  }
  std::vector<std::size_t> cut(threads + 1);
  for (int p = 0; p <= threads; ++p) cut[p] = v.size() * p / threads;
#pragma omp parallel for schedule(static, 1)
  for (int p = 0; p < threads; ++p) std::sort(v.begin() + cut[p], v.begin() + cut[p + 1], less);
  std::vector<T> buffer(v.size());
  while (cut.size() > 2) {
    std::vector<std::size_t> next{0};
    const std::size_t pairs = (cut.size() - 1) / 2;
    const int pieces = std::max(1, threads / static_cast<int>(pairs));
    for (std::size_t q = 0; q + 2 < cut.size(); q += 2) {
      parallel_merge(v.data() + cut[q], cut[q + 1] - cut[q], v.data() + cut[q + 1],
                     cut[q + 2] - cut[q + 1], buffer.data() + cut[q], pieces, less);
      next.push_back(cut[q + 2]);
    }
    if ((cut.size() - 1) % 2) {  // an odd part out: copied as it is
      std::copy(v.begin() + cut[cut.size() - 2], v.end(), buffer.begin() + cut[cut.size() - 2]);
      next.push_back(cut.back());
    }
    v.swap(buffer);
    cut.swap(next);
  }
}

// Calls add(i, out) for every i in [0, n) on all threads and returns what the calls appended to
// `out`, in the order of i: each thread takes one block of indices (OpenMP's static schedule
// hands them out in thread order) and the blocks are joined in order. `expected`: about how
// many items all calls append (reserved, as address space only, so the lists need not grow).
template <class T, class Add>
std::vector<T> parallel_collect(std::size_t n, Add add, std::size_t expected = 0) {
  int threads = 1;
#ifdef _OPENMP
  threads = omp_get_max_threads();
#endif
  std::vector<std::vector<T>> parts(threads);
  const auto count = static_cast<std::ptrdiff_t>(n);
#pragma omp parallel num_threads(threads)
  {
    int me = 0;
#ifdef _OPENMP
    me = omp_get_thread_num();
#endif
    parts[me].reserve(expected / threads + expected / 8);
#pragma omp for schedule(static)
    for (std::ptrdiff_t i = 0; i < count; ++i) add(static_cast<std::size_t>(i), parts[me]);
  }
  std::size_t total = 0;
  for (const std::vector<T>& p : parts) total += p.size();
  std::vector<T> all;
  all.reserve(total);
  for (const std::vector<T>& p : parts) all.insert(all.end(), p.begin(), p.end());
  return all;
}

}  // namespace hexfem
