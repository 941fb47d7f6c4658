// core/huge_pages.cpp: a large block from operator new is advised to transparent huge pages,
// a small one is left as malloc gives it. Read back from the kernel's own account of the
// process's mappings (/proc/self/smaps: "THPeligible: 1" where a mapping may take them).
#include <gtest/gtest.h>
#include <malloc.h>

#include <cstdint>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "core/huge_pages.hpp"

namespace {

// The system's policy, "always", "madvise" or "never" (the bracketed word), or "" where the
// kernel has no transparent huge pages.
std::string huge_page_policy() {
  std::ifstream in("/sys/kernel/mm/transparent_hugepage/enabled");
  std::string text;
  std::getline(in, text);
  const auto open = text.find('['), close = text.find(']');
  return open == std::string::npos || close == std::string::npos ? "" : text.substr(open + 1, close - open - 1);
}

// THPeligible of the mapping that holds `address`: 1, 0, or -1 where none was found.
int huge_page_eligible(const void* address) {
  const auto at = reinterpret_cast<std::uintptr_t>(address);
  std::ifstream smaps("/proc/self/smaps");
  std::string line;
  bool inside = false;
  while (std::getline(smaps, line)) {
    std::uintptr_t low = 0, high = 0;
    char dash = 0;
    std::istringstream head(line);
    if (head >> std::hex >> low >> dash >> high && dash == '-') {
      inside = low <= at && at < high;
      continue;
    }
    if (inside && line.rfind("THPeligible:", 0) == 0) return std::stoi(line.substr(12));
  }
  return -1;
}

}  // namespace

TEST(HugePages, ALargeBlockIsAdvisedWhereThePolicyAsksForAdvice) {
  if (!hemotree::advises_huge_pages()) GTEST_SKIP() << "built with AddressSanitizer, whose new and delete are kept";
  if (huge_page_policy() != "madvise")
    GTEST_SKIP() << "transparent huge pages are '" << huge_page_policy() << "' here, not 'madvise'";
  // 64 MiB: several whole 2 MiB pages inside it wherever malloc places it.
  std::vector<double> block(std::size_t{8} << 20, 1.0);
  const int eligible = huge_page_eligible(block.data() + block.size() / 2);
  if (eligible < 0) GTEST_SKIP() << "this kernel's smaps has no THPeligible (Linux before 5.0)";
  EXPECT_EQ(eligible, 1);
}

TEST(HugePages, ASmallBlockIsLeftAsMallocGivesIt) {
  if (!hemotree::advises_huge_pages())
    GTEST_SKIP() << "built with AddressSanitizer, whose allocator places blocks its own way";
  if (huge_page_policy() != "madvise")
    GTEST_SKIP() << "transparent huge pages are '" << huge_page_policy() << "' here, not 'madvise'";
  // 1 MiB: below the 4 MiB from which blocks are advised. A fixed mmap threshold below it
  // makes malloc map the block on its own, a mapping nothing else shares (the threshold
  // otherwise rises after a large block is freed, and the block would come from the heap).
  ASSERT_EQ(mallopt(M_MMAP_THRESHOLD, 512 << 10), 1);
  const auto block = std::make_unique<char[]>(std::size_t{1} << 20);
  const int eligible = huge_page_eligible(block.get() + (std::size_t{1} << 19));
  if (eligible < 0) GTEST_SKIP() << "this kernel's smaps has no THPeligible (Linux before 5.0)";
  EXPECT_EQ(eligible, 0);
}
