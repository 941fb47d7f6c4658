// Large blocks on huge pages: the global operator new, replaced (as C++ allows) to ask the
// kernel for transparent huge pages (2 MiB) under every block of at least 4 MiB, where the
// system's policy is to give them only where asked (Debian's default: "madvise").
//
// Why: a run's arrays are large (one per vessel or node, tens to hundreds of megabytes on a
// tree of millions of vessels) and on 4 KiB pages each first touch is a page fault and each
// sweep over them a stream of TLB misses. On this project's machines (virtual ones, where a
// fault costs several microseconds) the full tree's `--linear` ran 51 s with 4 KiB pages and
// 37 s with huge ones, the same bytes out (bench/README.md, "Huge pages"). glibc offers the
// same through its tunable glibc.malloc.hugetlb=1, which a program cannot set for itself: it
// is read from the environment before main.
//
// Only the advice is added: the block comes from malloc as before and operator delete, replaced
// with it, hands it to free, so the allocator's reuse, malloc_trim (core/free_memory.hpp) and
// every tool that watches malloc and free (valgrind) see one pair. The advice covers the
// 2 MiB-aligned interior of the block; the kernel may decline it (no huge page free, THP off),
// which leaves ordinary pages. Under AddressSanitizer (scripts/test --sanitize, scripts/fuzz)
// nothing is replaced: its own new and delete check that they are paired.
#include "core/huge_pages.hpp"

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <new>

#if defined(__linux__)
#include <sys/mman.h>
#endif

#if defined(__SANITIZE_ADDRESS__)
#define HEMOTREE_SANITIZED_ALLOCATION 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define HEMOTREE_SANITIZED_ALLOCATION 1
#endif
#endif

#if defined(HEMOTREE_SANITIZED_ALLOCATION)

bool hemotree::advises_huge_pages() { return false; }

#else

bool hemotree::advises_huge_pages() { return true; }

namespace {

constexpr std::size_t huge_page = std::size_t{2} << 20;
constexpr std::size_t advised_from = 2 * huge_page;

void advise_huge_pages([[maybe_unused]] void* block, [[maybe_unused]] std::size_t size) {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  const auto start = reinterpret_cast<std::uintptr_t>(block);
  const std::uintptr_t first = (start + huge_page - 1) & ~(huge_page - 1);
  const std::uintptr_t last = (start + size) & ~(huge_page - 1);
  if (last > first) madvise(reinterpret_cast<void*>(first), last - first, MADV_HUGEPAGE);
#endif
}

}  // namespace

void* operator new(std::size_t size) {
  if (size == 0) size = 1;
  for (;;) {
    if (void* block = std::malloc(size)) {
      if (size >= advised_from) advise_huge_pages(block, size);
      return block;
    }
    const std::new_handler handler = std::get_new_handler();
    if (!handler) throw std::bad_alloc();
    handler();
  }
}

void* operator new[](std::size_t size) { return ::operator new(size); }

void operator delete(void* block) noexcept { std::free(block); }
void operator delete[](void* block) noexcept { std::free(block); }
void operator delete(void* block, std::size_t) noexcept { std::free(block); }
void operator delete[](void* block, std::size_t) noexcept { std::free(block); }

#endif
