// The hexfem executable's operator new: large blocks are asked to sit on transparent huge pages.
//
// Why: the mesher's arrays are large and touched once or twice (tets, candidates, adjacency). At a
// million vertices a tenth of the run went to the kernel's page faults, one per 4 KiB page on
// first touch. With THP in "madvise" mode (as on the machine measured) a block the program marks
// with MADV_HUGEPAGE faults once per 2 MiB instead: ANC101 at h = 2 took 48-50 s instead of 55-61
// s, the same mesh (validation/volume.md). glibc can do this for every allocation, but only when
// GLIBC_TUNABLES names glibc.malloc.hugetlb at start, which a program cannot set for itself.
//
// Only this executable replaces operator new (the tests, the libraries and a HEXFEM_SANITIZE
// build keep the standard one); TetGen's child process inherits it. Blocks still come from malloc
// and go back with free: only the advice is added, on the whole 2 MiB pages inside a block of at
// least kHugeBlock bytes.
#include <sys/mman.h>

#include <cstdint>
#include <cstdlib>
#include <new>

namespace {

constexpr std::size_t kHugePage = std::size_t{2} << 20;
constexpr std::size_t kHugeBlock = std::size_t{4} << 20;

void* allocate(std::size_t n) {
  void* p = std::malloc(n ? n : 1);
  if (!p) throw std::bad_alloc();
  if (n >= kHugeBlock) {
    const auto begin = (reinterpret_cast<std::uintptr_t>(p) + kHugePage - 1) & ~(kHugePage - 1);
    const auto end = (reinterpret_cast<std::uintptr_t>(p) + n) & ~(kHugePage - 1);
    // Advice only: where the kernel has no huge pages (THP "never") the call fails, harmlessly.
    if (end > begin) ::madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
  }
  return p;
}

void* allocate_or_null(std::size_t n) noexcept {
  try {
    return allocate(n);
  } catch (...) {
    return nullptr;
  }
}

}  // namespace

void* operator new(std::size_t n) {
  return allocate(n);
}
void* operator new[](std::size_t n) {
  return allocate(n);
}
void* operator new(std::size_t n, const std::nothrow_t&) noexcept {
  return allocate_or_null(n);
}
void* operator new[](std::size_t n, const std::nothrow_t&) noexcept {
  return allocate_or_null(n);
}
void operator delete(void* p) noexcept {
  std::free(p);
}
void operator delete[](void* p) noexcept {
  std::free(p);
}
void operator delete(void* p, std::size_t) noexcept {
  std::free(p);
}
void operator delete[](void* p, std::size_t) noexcept {
  std::free(p);
}
void operator delete(void* p, const std::nothrow_t&) noexcept {
  std::free(p);
}
void operator delete[](void* p, const std::nothrow_t&) noexcept {
  std::free(p);
}
