// The parallel helpers give what one thread gives, whatever the number of threads.
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "mesher/mesh/parallel.hpp"

namespace hexfem {
namespace {

// Items with one to three buckets each from a fixed linear congruential sequence; the reference
// is the plain serial counting sort: each bucket gets its items in increasing order.
TEST(Parallel, BucketItemsAreTheSerialCountingSort) {
  const std::size_t n = 100000, m = 997;
  std::vector<std::vector<std::int32_t>> keys(n);
  std::uint64_t x = 12345;
  for (auto& k : keys) {
    x = x * 6364136223846793005ull + 1442695040888963407ull;
    const int count = 1 + static_cast<int>((x >> 60) % 3);
    for (int i = 0; i < count; ++i) {
      x = x * 6364136223846793005ull + 1442695040888963407ull;
      k.push_back(static_cast<std::int32_t>((x >> 33) % m));
    }
  }
  std::vector<std::vector<std::size_t>> bucket(m);
  for (std::size_t t = 0; t < n; ++t)
    for (std::int32_t b : keys[t]) bucket[b].push_back(t);
  std::vector<std::int32_t> want_off{0};
  std::vector<std::size_t> want;
  for (const auto& b : bucket) {
    want.insert(want.end(), b.begin(), b.end());
    want_off.push_back(static_cast<std::int32_t>(want.size()));
  }
  for (int threads : {1, 2, 3}) {
#ifdef _OPENMP
    omp_set_num_threads(threads);
#endif
    std::vector<std::int32_t> off;
    std::vector<std::size_t> got(want.size(), n);
    std::vector<std::int32_t> got_bucket(want.size(), -1);
    parallel_bucket_items(
        n, m,
        [&](std::size_t t, auto&& f) {
          for (std::int32_t b : keys[t]) f(b);
        },
        off,
        [&](std::size_t i, std::size_t t, std::int32_t b) {
          got[i] = t;
          got_bucket[i] = b;
        });
    EXPECT_EQ(off, want_off) << threads << " threads";
    EXPECT_EQ(got, want) << threads << " threads";
    for (std::size_t b = 0; b < m; ++b)
      for (std::int32_t i = off[b]; i < off[b + 1]; ++i)
        ASSERT_EQ(got_bucket[i], static_cast<std::int32_t>(b));
  }
#ifdef _OPENMP
  omp_set_num_threads(max_threads());
#endif
}

}  // namespace
}  // namespace hexfem
