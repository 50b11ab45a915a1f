// Buffer<T>: a std::vector whose large storage is aligned to and advised for
// transparent huge pages (buffer.hpp, src/huge_pages.cpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "tessera/buffer.hpp"

namespace {

using tessera::Buffer;
using tessera::detail::huge_page_bytes;

constexpr std::size_t large = 3 * huge_page_bytes / sizeof(double);  // 3 huge pages of doubles

bool aligned(const void* p) { return reinterpret_cast<std::uintptr_t>(p) % huge_page_bytes == 0; }

TEST(Buffer, LargeStorageIsAlignedToHugePages) {
  Buffer<double> b(large);
  EXPECT_TRUE(aligned(b.data()));
  Buffer<std::int32_t> small(1000);
  EXPECT_LT(small.capacity() * sizeof(std::int32_t), huge_page_bytes);  // the ordinary allocator's
}

// Growth across the threshold (small -> large storage), copies, swaps and a
// shrink back (large -> small) keep the values: every allocation is freed by
// the path that made it (a mismatch would crash or corrupt the heap).
TEST(Buffer, GrowsAndShrinksAcrossTheThreshold) {
  Buffer<double> b;
  std::vector<double> ref;
  for (std::size_t k = 0; k < large; ++k) {
    b.push_back(0.5 * static_cast<double>(k));
    ref.push_back(0.5 * static_cast<double>(k));
  }
  ASSERT_TRUE(std::equal(b.begin(), b.end(), ref.begin(), ref.end()));
  EXPECT_TRUE(aligned(b.data()));
  Buffer<double> copy = b;
  EXPECT_TRUE(aligned(copy.data()));
  EXPECT_EQ(copy, b);
  Buffer<double> other(10, 1.0);
  other.swap(copy);
  EXPECT_EQ(other, b);
  EXPECT_EQ(copy, Buffer<double>(10, 1.0));
  b.resize(100);
  b.shrink_to_fit();
  EXPECT_TRUE(std::equal(b.begin(), b.end(), ref.begin()));
  // Explicit values still initialize, uninitialized growth aside.
  Buffer<int> z(2 * huge_page_bytes / sizeof(int), 7);
  EXPECT_EQ(z.front(), 7);
  EXPECT_EQ(z.back(), 7);
}

// The advice took: the mapping holding a large Buffer is eligible for
// transparent huge pages. Only where the kernel offers them in madvise or
// always mode and TESSERA_HUGE_PAGES does not turn the advice off.
TEST(Buffer, LargeStorageIsEligibleForHugePages) {
  std::ifstream mode("/sys/kernel/mm/transparent_hugepage/enabled");
  std::string modes;
  if (!mode || !std::getline(mode, modes) || modes.find("[never]") != std::string::npos)
    GTEST_SKIP() << "no transparent huge pages on this system";
  if (const char* env = std::getenv("TESSERA_HUGE_PAGES"); env != nullptr && std::strcmp(env, "0") == 0)
    GTEST_SKIP() << "TESSERA_HUGE_PAGES=0";
  Buffer<double> b(large);
  const auto at = reinterpret_cast<std::uintptr_t>(b.data());
  std::ifstream smaps("/proc/self/smaps");
  ASSERT_TRUE(smaps) << "no /proc/self/smaps";
  std::string line;
  bool inside = false, found = false;
  while (std::getline(smaps, line)) {
    std::uintptr_t lo = 0, hi = 0;
    char dash = 0;
    std::istringstream head(line);
    // A mapping's first line: "lo-hi perms ...", addresses in hex.
    if (head >> std::hex >> lo >> dash >> hi && dash == '-') {
      inside = lo <= at && at < hi;
      continue;
    }
    if (inside && line.rfind("THPeligible:", 0) == 0) {
      EXPECT_NE(line.find('1'), std::string::npos) << line;
      found = true;
      break;
    }
  }
  EXPECT_TRUE(found) << "no THPeligible line for the buffer's mapping";
}

}  // namespace
