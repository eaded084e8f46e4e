// SPDX-License-Identifier: MIT
// The program's operator new (renderer/app/large_blocks.cpp), linked into this test as into
// `whitted`: a block of 1 MiB up to 256 MiB (an eighth of the memory if less) has its pages mapped
// before it is written; the standard's contract for failure kept.

#include "large_blocks.h"

#include <gtest/gtest.h>
#include <malloc.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <memory>
#include <new>
#include <string>
#include <thread>
#include <vector>

namespace {

namespace blocks = whitted::large_blocks;

/// How many of the pages wholly inside [block, block + size) are mapped (mincore).
size_t mapped_pages(const void* block, size_t size, size_t& pages) {
    const uintptr_t page = uintptr_t(sysconf(_SC_PAGESIZE));
    const uintptr_t first = (uintptr_t(block) + page - 1) / page * page;
    const uintptr_t end = (uintptr_t(block) + size) / page * page;
    pages = end > first ? (end - first) / page : 0;
    std::vector<unsigned char> resident(pages);
    if (pages == 0 || mincore(reinterpret_cast<void*>(first), end - first, resident.data()) != 0) return 0;
    size_t mapped = 0;
    for (const unsigned char r : resident) mapped += r & 1;
    return mapped;
}

/// Whether this kernel maps pages on request (MADV_POPULATE_WRITE, Linux 5.14).
bool kernel_populates() {
    const size_t page = size_t(sysconf(_SC_PAGESIZE));
    void* mapping = mmap(nullptr, page, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (mapping == MAP_FAILED) return false;
    const bool populates = madvise(mapping, page, 23 /* MADV_POPULATE_WRITE */) == 0;
    munmap(mapping, page);
    return populates;
}

TEST(LargeBlocks, TheRangeIsOneMebibyteTo256MebibytesOrAnEighthOfMemory) {
    EXPECT_EQ(blocks::populated_from(), size_t(1) << 20);
    const size_t memory = size_t(sysconf(_SC_PHYS_PAGES)) * size_t(sysconf(_SC_PAGESIZE));
    EXPECT_EQ(blocks::populated_up_to(), std::min(size_t(256) << 20, memory / 8));
}

TEST(LargeBlocks, BlocksInTheRangeAreMappedBeforeTheyAreWritten) {
    if (!blocks::replaces_operator_new()) GTEST_SKIP() << "the sanitizer's operator new is kept";
    if (!kernel_populates()) GTEST_SKIP() << "this kernel predates MADV_POPULATE_WRITE";
    // Sizes at both ends of the range, odd sizes, and the image of the anchors (1280×960 RGB).
    for (const size_t bytes : {blocks::populated_from(), blocks::populated_from() + 1, size_t(15) << 20,
                               size_t(1280) * 960 * 3 * sizeof(float) + 12}) {
        const std::unique_ptr<char[]> block(new char[bytes]);  // not written: no first touch
        size_t pages = 0;
        const size_t mapped = mapped_pages(block.get(), bytes, pages);
        ASSERT_GT(pages, 0u);
        EXPECT_EQ(mapped, pages) << bytes << " bytes";
    }
    std::vector<float> image;
    image.reserve(size_t(1280) * 960 * 3);
    size_t pages = 0;
    const size_t mapped = mapped_pages(image.data(), image.capacity() * sizeof(float), pages);
    EXPECT_EQ(mapped, pages);
}

TEST(LargeBlocks, BlocksBeyondTheRangeAreLeftToFault) {
    if (!blocks::replaces_operator_new()) GTEST_SKIP() << "the sanitizer's operator new is kept";
    // Only addresses: the pages are not mapped unless something writes them.
    const size_t bytes = blocks::populated_up_to() + (size_t(1) << 20);
    const std::unique_ptr<char[]> block(new (std::nothrow) char[bytes]);
    if (!block) GTEST_SKIP() << "no " << bytes << " bytes of addresses to give";
    size_t pages = 0;
    const size_t mapped = mapped_pages(block.get(), bytes, pages);
    EXPECT_GT(pages, 0u);
    EXPECT_LT(mapped, pages / 100);
}

TEST(LargeBlocks, PopulateMapsOnlyThePagesInsideTheBlock) {
    if (!kernel_populates()) GTEST_SKIP() << "this kernel predates MADV_POPULATE_WRITE";
    // A private mapping of 4 MiB, populated from its second page's middle to its last page's
    // middle: only the pages wholly inside are mapped.
    const size_t page = size_t(sysconf(_SC_PAGESIZE)), size = size_t(4) << 20;
    void* mapping = mmap(nullptr, size, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    ASSERT_NE(mapping, MAP_FAILED);
    char* base = static_cast<char*>(mapping);
    blocks::populate(base + page + page / 2, size - 2 * page);
    std::vector<unsigned char> resident(size / page);
    ASSERT_EQ(mincore(mapping, size, resident.data()), 0);
    const size_t last = size / page - 1;
    EXPECT_EQ(resident[0] & 1, 0);
    EXPECT_EQ(resident[1] & 1, 0);  // the block starts inside it
    for (size_t k = 2; k < last; ++k) EXPECT_EQ(resident[k] & 1, 1) << k;
    EXPECT_EQ(resident[last] & 1, 0);  // the block ends inside it
    munmap(mapping, size);
}

TEST(LargeBlocks, SizesOutsideTheRangeAreNotPopulated) {
    const size_t page = size_t(sysconf(_SC_PAGESIZE)), size = size_t(4) << 20;
    void* mapping = mmap(nullptr, size, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    ASSERT_NE(mapping, MAP_FAILED);
    blocks::populate(mapping, blocks::populated_from() - 1);
    blocks::populate(nullptr, size);
    std::vector<unsigned char> resident(size / page);
    ASSERT_EQ(mincore(mapping, size, resident.data()), 0);
    for (const unsigned char r : resident) EXPECT_EQ(r & 1, 0);
    munmap(mapping, size);
}

TEST(LargeBlocks, ImpossibleSizesThrowOrGiveNull) {
    // The sanitizer's allocator aborts on such sizes unless told otherwise: not ours to test.
    if (!blocks::replaces_operator_new()) GTEST_SKIP() << "the sanitizer's operator new is kept";
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

TEST(LargeBlocks, TheNewHandlerIsAskedBeforeThrowing) {
    if (!blocks::replaces_operator_new()) GTEST_SKIP() << "the sanitizer's operator new is kept";
    calls = 0;
    std::set_new_handler(give_up);
    volatile size_t impossible = std::numeric_limits<size_t>::max() - 4096;
    EXPECT_THROW((void)::operator new(impossible), std::bad_alloc);
    EXPECT_EQ(calls, 1);
    std::set_new_handler(nullptr);
}

/// The calling thread's minor page faults so far.
long thread_page_faults() {
    rusage usage{};
    getrusage(RUSAGE_THREAD, &usage);
    return usage.ru_minflt;
}

TEST(LargeBlocks, SmallBlocksFreedAndAskedForAgainCostNoPageFaults) {
    if (!blocks::replaces_operator_new()) GTEST_SKIP() << "the sanitizer's allocator is its own";
    blocks::keep_freed_memory();
    long first = 0, after = 0;
    volatile char sink = 0;
    // On a thread of its own, so on a heap of its own (a render's worker threads). Two blocks of
    // 100 KiB, written and freed: with glibc's defaults the heap was cut back every round and
    // the next round faulted again (100 page faults in the 100 rounds, without the call).
    std::thread([&] {
        const auto round = [&] {
            const size_t bytes = size_t(100) << 10;
            char* a = static_cast<char*>(std::malloc(bytes));
            char* b = static_cast<char*>(std::malloc(bytes));
            ASSERT_TRUE(a && b);
            std::memset(a, 1, bytes);
            std::memset(b, 2, bytes);
            sink = char(a[bytes - 1] + b[bytes / 2]);
            std::free(b);
            std::free(a);
        };
        round();
        first = thread_page_faults();
        for (int i = 0; i < 100; ++i) round();
        after = thread_page_faults();
    }).join();
    EXPECT_EQ(sink, 3);
    EXPECT_LE(after - first, 10) << "page faults in 100 rounds after the first";
    EXPECT_EQ(blocks::kept_free(), size_t(64) << 20);
}

TEST(LargeBlocks, BlocksUnderEightMebibytesComeFromTheHeaps) {
    if (!blocks::replaces_operator_new()) GTEST_SKIP() << "the sanitizer's allocator is its own";
    blocks::keep_freed_memory();
    EXPECT_EQ(blocks::mapped_from(), size_t(8) << 20);
    // mallinfo2's hblks: the blocks malloc has mapped on their own (and will give back).
    const size_t before = mallinfo2().hblks;
    void* heap = std::malloc(blocks::mapped_from() - 4096);
    const size_t after_heap = mallinfo2().hblks;
    void* mapped = std::malloc(blocks::mapped_from());
    const size_t after_mapped = mallinfo2().hblks;
    ASSERT_TRUE(heap && mapped);
    std::free(mapped);
    std::free(heap);
    EXPECT_EQ(after_heap, before) << "a block just under the threshold was mapped on its own";
    EXPECT_EQ(after_mapped, before + 1) << "a block of the threshold came from a heap";
}

/// The VmFlags of the mapping holding `address` (/proc/self/smaps): "hg" where it asked for
/// huge pages (MADV_HUGEPAGE), "nh" where it refused them.
std::string mapping_flags(const void* address) {
    std::FILE* smaps = std::fopen("/proc/self/smaps", "r");
    if (!smaps) return "";
    char line[512];
    bool inside = false;
    std::string flags;
    const auto at = uintptr_t(address);
    while (std::fgets(line, sizeof line, smaps)) {
        unsigned long start = 0, end = 0;
        if (std::sscanf(line, "%lx-%lx ", &start, &end) == 2 && std::strchr(line, '-') < std::strchr(line, ' ')) {
            inside = at >= start && at < end;
        } else if (inside && std::strncmp(line, "VmFlags:", 8) == 0) {
            flags = line + 8;
            break;
        }
    }
    std::fclose(smaps);
    return flags;
}

/// Restores use_huge_pages(false) however a test ends.
struct HugePagesForThisTest {
    HugePagesForThisTest() { blocks::use_huge_pages(true); }
    ~HugePagesForThisTest() { blocks::use_huge_pages(false); }
};

TEST(LargeBlocks, WithHugePagesBlocksFromTwoMebibytesAreAlignedAndAskForThem) {
    if (!blocks::replaces_operator_new()) GTEST_SKIP() << "the sanitizer's operator new is kept";
    // A kernel built without transparent huge pages refuses MADV_HUGEPAGE (and has no such file).
    if (access("/sys/kernel/mm/transparent_hugepage/enabled", F_OK) != 0)
        GTEST_SKIP() << "this kernel has no transparent huge pages";
    EXPECT_EQ(blocks::huge_from(), size_t(2) << 20);
    EXPECT_FALSE(blocks::huge_pages());
    const HugePagesForThisTest huge;
    EXPECT_TRUE(blocks::huge_pages());
    const size_t two = blocks::huge_from();
    // At the threshold, odd sizes past it, a heap-sized block and one malloc maps on its own.
    for (const size_t bytes : {two, two + 1, size_t(3) << 20 | 5, blocks::mapped_from() + 12345}) {
        const std::unique_ptr<char[]> block(new char[bytes]);
        EXPECT_EQ(uintptr_t(block.get()) % two, 0u) << bytes << " bytes";
        EXPECT_NE(mapping_flags(block.get()).find(" hg"), std::string::npos) << bytes << " bytes";
        std::memset(block.get(), 7, bytes);  // the whole block is the caller's
        EXPECT_EQ(block[bytes - 1], 7);
    }
    // Under the threshold, as without huge pages: populated.
    if (kernel_populates()) {
        const size_t bytes = two - 4096;
        const std::unique_ptr<char[]> block(new char[bytes]);
        size_t pages = 0;
        const size_t mapped = mapped_pages(block.get(), bytes, pages);
        EXPECT_EQ(mapped, pages);
    }
}

TEST(LargeBlocks, WithHugePagesTheStandardContractHolds) {
    if (!blocks::replaces_operator_new()) GTEST_SKIP() << "the sanitizer's operator new is kept";
    const HugePagesForThisTest huge;
    volatile size_t impossible = std::numeric_limits<size_t>::max() - 4096;  // rounding would wrap
    EXPECT_THROW((void)::operator new(impossible), std::bad_alloc);
    EXPECT_EQ(::operator new(impossible, std::nothrow), nullptr);
    std::vector<float> image(size_t(1280) * 960 * 3, 0.5f);  // grown, copied and freed by the vector
    image.resize(image.size() * 2, 0.25f);
    EXPECT_EQ(image.front(), 0.5f);
    EXPECT_EQ(image.back(), 0.25f);
}

TEST(LargeBlocks, TheSystemsHugePageSettingIsRead) {
    std::FILE* file = std::fopen("/sys/kernel/mm/transparent_hugepage/enabled", "r");
    if (!file) {
        EXPECT_FALSE(blocks::system_offers_huge_pages());
        return;
    }
    char text[128] = {};
    text[std::fread(text, 1, sizeof text - 1, file)] = '\0';
    std::fclose(file);
    EXPECT_EQ(blocks::system_offers_huge_pages(), std::strstr(text, "[never]") == nullptr) << text;
}

TEST(LargeBlocks, AFirstWriteIsTimed) {
    const double microseconds = blocks::first_write_microseconds();
    EXPECT_GT(microseconds, 0.0);
    EXPECT_LT(microseconds, 1e5);  // 0.1 s a page: no machine, only a broken clock
    EXPECT_EQ(blocks::huge_pages_from_microseconds, 2.0);
}

TEST(LargeBlocks, ZeroBytesGiveDistinctBlocks) {
    void* a = ::operator new(0);
    void* b = ::operator new(0);
    EXPECT_NE(a, nullptr);
    EXPECT_NE(a, b);
    ::operator delete(a);
    ::operator delete(b);
}

}  // namespace
