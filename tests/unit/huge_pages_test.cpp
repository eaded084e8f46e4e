// SPDX-License-Identifier: MIT
// The program's operator new (renderer/app/huge_pages.cpp), linked into this test as into
// `whitted`: blocks of 2 MiB and more on huge-page boundaries, offered to the kernel for
// transparent huge pages; the standard's contract for failure kept.

#include "huge_pages.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <cstdio>
#include <fstream>
#include <limits>
#include <memory>
#include <new>
#include <string>
#include <vector>

namespace {

constexpr uintptr_t huge_page = whitted::huge_page_bytes;

#ifndef WHITTED_SANITIZED_NEW

TEST(HugePages, LargeBlocksStartOnAHugePageBoundary) {
    for (const size_t bytes : {size_t(2) << 20, (size_t(2) << 20) + 1, size_t(15) << 20, size_t(100) << 20}) {
        const std::unique_ptr<char[]> block(new char[bytes]);
        EXPECT_EQ(uintptr_t(block.get()) % huge_page, 0u) << bytes;
        block[bytes - 1] = 1;  // the whole length is there
    }
    std::vector<float> image(size_t(1280) * 960 * 3);
    EXPECT_EQ(uintptr_t(image.data()) % huge_page, 0u);
}

TEST(HugePages, SmallBlocksAreOrdinary) {
    // Below 2 MiB nothing is placed on a huge-page boundary: of 64 blocks of 1 MiB some must
    // lie off one (malloc's own alignment is 16 bytes).
    int on_boundary = 0;
    std::vector<std::unique_ptr<char[]>> blocks;
    for (int k = 0; k < 64; ++k) {
        blocks.emplace_back(new char[size_t(1) << 20]);
        on_boundary += uintptr_t(blocks.back().get()) % huge_page == 0;
    }
    EXPECT_LT(on_boundary, 64);
}

/// The kernel's transparent huge page mode: "always", "madvise" or "never" (the bracketed word).
std::string thp_mode() {
    std::ifstream file("/sys/kernel/mm/transparent_hugepage/enabled");
    std::string line;
    std::getline(file, line);
    const size_t open = line.find('['), close = line.find(']');
    return open == std::string::npos || close == std::string::npos ? "" : line.substr(open + 1, close - open - 1);
}

/// AnonHugePages of the mapping that holds `address`, in kB, from /proc/self/smaps.
long huge_kb_at(const void* address) {
    std::ifstream smaps("/proc/self/smaps");
    std::string line;
    bool inside = false;
    while (std::getline(smaps, line)) {
        unsigned long from = 0, to = 0;
        if (std::sscanf(line.c_str(), "%lx-%lx ", &from, &to) == 2 && line.find(':') > line.find(' ')) {
            inside = uintptr_t(address) >= from && uintptr_t(address) < to;
        } else if (inside && line.rfind("AnonHugePages:", 0) == 0) {
            return std::stol(line.substr(14));
        }
    }
    return -1;
}

TEST(HugePages, TheKernelGivesHugePagesWhereItCan) {
    const std::string mode = thp_mode();
    if (mode != "madvise" && mode != "always")
        GTEST_SKIP() << "transparent huge pages are '" << mode << "' on this kernel: nothing to ask for";
    const size_t bytes = size_t(16) << 20;
    const std::unique_ptr<char[]> block(new char[bytes]);
    for (size_t k = 0; k < bytes; k += 4096) block[k] = char(k);
    const long kb = huge_kb_at(block.get());
    // The kernel may refuse (memory too fragmented); it must not be asked in vain on an idle
    // machine, where the mapping holds at least one huge page.
    EXPECT_GE(kb, 2048) << "mode " << mode;
}

TEST(HugePages, ImpossibleSizesThrowOrGiveNull) {
    volatile size_t impossible = std::numeric_limits<size_t>::max() - 4096;
    EXPECT_THROW((void)::operator new(impossible), std::bad_alloc);
    EXPECT_EQ(::operator new(impossible, std::nothrow), nullptr);
    volatile size_t too_many = std::numeric_limits<size_t>::max() / 2;
    EXPECT_EQ(::operator new[](too_many, std::nothrow), nullptr);
}

int calls = 0;
void give_up() {
    ++calls;
    std::set_new_handler(nullptr);  // then the allocation throws
}

TEST(HugePages, TheNewHandlerIsAskedBeforeThrowing) {
    calls = 0;
    std::set_new_handler(give_up);
    volatile size_t impossible = std::numeric_limits<size_t>::max() - 4096;
    EXPECT_THROW((void)::operator new(impossible), std::bad_alloc);
    EXPECT_EQ(calls, 1);
    std::set_new_handler(nullptr);
}

#else

// Under AddressSanitizer or ThreadSanitizer huge_pages.cpp compiles to nothing, and the
// sanitizer's operator new is not ours to test: it ends the process on an impossible size
// instead of throwing std::bad_alloc. Said here, not left out silently.
TEST(HugePages, OurOperatorNewIsTestedWithoutSanitizers) {
    GTEST_SKIP() << "this build uses the sanitizer's operator new; huge_pages.cpp is not compiled in";
}

#endif

TEST(HugePages, ZeroBytesGiveDistinctBlocks) {
    void* a = ::operator new(0);
    void* b = ::operator new(0);
    EXPECT_NE(a, nullptr);
    EXPECT_NE(a, b);
    ::operator delete(a);
    ::operator delete(b);
}

}  // namespace
