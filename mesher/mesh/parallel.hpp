// Loops, sorts and merges on all OpenMP threads for the mesher's big lists (millions of faces),
// whose results never depend on the number of threads. A sort's result is std::sort's whenever
// elements that compare equal are identical, which holds for every list sorted with it (keys
// with the owner in the order, or plain keys). Without OpenMP: the serial loop, std::sort and
// std::merge.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

#ifdef _OPENMP
#include <omp.h>
#endif

namespace hexfem {

// The threads a parallel region gets, and the calling thread's number in its region (1 and 0
// without OpenMP).
inline int max_threads() {
#ifdef _OPENMP
  return omp_get_max_threads();
#else
  return 1;
#endif
}
inline int thread_index() {
#ifdef _OPENMP
  return omp_get_thread_num();
#else
  return 0;
#endif
}

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
  const int threads = max_threads();
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
  const int threads = max_threads();
  std::vector<std::vector<T>> parts(threads);
  const auto count = static_cast<std::ptrdiff_t>(n);
#pragma omp parallel num_threads(threads)
  {
    const int me = thread_index();
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

// A counting sort of items 0..n-1 into buckets 0..m-1 on all threads: keys(t, f) calls f(b)
// for each bucket b of item t; off gets the buckets' offsets (m + 1) and put(i, t, b) is called
// with each slot i of bucket b. Each thread takes one block of items and counts, then fills,
// its own; bucket b's slots go to the blocks in order, so every bucket holds its items in
// increasing order, as one thread would put them.
template <class Keys, class Put>
void parallel_bucket_items(std::size_t n, std::size_t m, Keys keys, std::vector<std::int32_t>& off,
                           Put put) {
  const int threads = max_threads();
  std::vector<std::vector<std::int32_t>> at(threads);
  const auto count = static_cast<std::ptrdiff_t>(n);
#pragma omp parallel num_threads(threads)
  {
    const int me = thread_index();
    at[me].assign(m, 0);
#pragma omp for schedule(static)
    for (std::ptrdiff_t t = 0; t < count; ++t)
      keys(static_cast<std::size_t>(t), [&](std::int32_t b) { ++at[me][b]; });
#pragma omp single
    {
      off.assign(m + 1, 0);
      std::int32_t next = 0;
      for (std::size_t b = 0; b < m; ++b) {
        off[b] = next;
        for (int q = 0; q < threads; ++q) {
          if (at[q].empty()) continue;  // a thread the team did not get
          const std::int32_t c = at[q][b];
          at[q][b] = next;
          next += c;
        }
      }
      off[m] = next;
    }  // the single's barrier: every block's slots are known before any is filled
#pragma omp for schedule(static)
    for (std::ptrdiff_t t = 0; t < count; ++t)
      keys(static_cast<std::size_t>(t), [&](std::int32_t b) {
        put(static_cast<std::size_t>(at[me][b]++), static_cast<std::size_t>(t), b);
      });
  }
}

}  // namespace hexfem
