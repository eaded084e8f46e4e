// SPDX-License-Identifier: MIT
// The `whitted` program's operator new: a block of 1 MiB or more has its pages mapped by the
// kernel in one call (MADV_POPULATE_WRITE) before the program first writes it.
//
// Why: a render writes most of its memory once, fresh from the kernel (the image, the mesh
// arrays, the display-referred rows), and with 4 KiB pages the first write of each page is a
// page fault. On the virtual machines Whitted is measured on each fault costs ~11 µs, a 15 MB
// image about 40 ms, a 1M-triangle mesh tens of thousands of faults. One madvise that maps the
// block's pages costs about half as much as faulting them one by one (docs/performance.md,
// "Design choices and what they cost").
//
// Huge pages, where they pay: under a hypervisor that keeps the guest's page tables in shadow
// (PVM, the AMD virtual machine of docs/performance.md), the first write to every 4 KiB page
// traps to the host even after the kernel has mapped it, about 5 µs each; a 2 MiB transparent
// huge page is one such trap for 512 pages. Under hardware-assisted paging the same write costs
// a fraction of a microsecond, and where the host takes back the guest's free memory in 2 MiB
// blocks a huge page's first touch costs the host 512 faults of its own (an Intel virtual
// machine under KVM: a million triangles' BVH built three times slower). Neither is known in
// advance, so main() measures it (first_write_microseconds) and the program uses huge pages,
// for its blocks of 2 MiB or more and for Embree's, only where a 4 KiB page's first write takes
// huge_pages_from_microseconds or more; elsewhere it turns them off for the process.
//
// Blocks larger than 256 MiB (or an eighth of the machine's memory, if less) are left to fault as
// they are written: a caller may reserve more than it fills (a buffer sized by a file's header,
// say, before the file is found short), and mapping it all at once would take memory, and time,
// the work may never need. The largest blocks of the bench scenes (the image, a mesh's arrays)
// are tens of megabytes. madvise is advice here: where the kernel predates
// MADV_POPULATE_WRITE (Linux 5.14) or refuses, the block is ordinary memory.
//
// Smaller blocks: malloc's own defaults let go of memory a render soon asks for again. Above
// 128 KiB (a threshold glibc then moves as blocks are freed) a block is mapped afresh, and
// when more than 128 KiB lies free at the top of a heap the heap is cut back (a TLB shootdown
// on every core) and the next block faults its pages in again. Writing a PNG,
// each band of rows goes through the display transform with a 64 KiB scratch buffer of its own: on some
// images (SPD `tetra -s 5`, 512x512) a thread's heap was cut back and regrown for every band,
// and the write took 24 ms instead of 7. So keep_freed_memory fixes both thresholds: blocks
// under 8 MiB always come from the heaps, and up to 64 MiB freed at a heap's top is kept.
// Larger blocks are mapped and given back as before. The heaps take blocks up to 8 MiB, not
// just up to the 1 MiB from which blocks are populated, because a block the heap gives again
// is written memory, which costs a fresh one's first writes nowhere: the arrays a reader grows
// by doubling and frees, a mesh's arrays made and let go while the scene is loaded. Measured in
// docs/performance.md ("Design choices and what they cost").
//
// Only the program replaces operator new: the library (libwhitted, the Python module) leaves
// its host's allocator alone. Memory from here is malloc's and operator delete frees it. Under
// AddressSanitizer or ThreadSanitizer nothing is replaced: their own operator new checks every
// new against its delete.
#include "large_blocks.h"

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define WHITTED_SANITIZED_NEW 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
#define WHITTED_SANITIZED_NEW 1
#endif
#endif

#include <malloc.h>
#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <new>

#ifndef MADV_POPULATE_WRITE
#define MADV_POPULATE_WRITE 23  // Linux 5.14; older headers lack it
#endif

namespace whitted::large_blocks {

namespace {
std::atomic<bool> g_huge_pages{false};
}  // namespace

size_t huge_from() {
    return size_t(2) << 20;
}

void use_huge_pages(bool on) {
    g_huge_pages.store(on, std::memory_order_relaxed);
}

bool huge_pages() {
    return g_huge_pages.load(std::memory_order_relaxed);
}

bool system_offers_huge_pages() {
    // "always [madvise] never": the bracketed word is the setting; "never" refuses MADV_HUGEPAGE.
    std::FILE* file = std::fopen("/sys/kernel/mm/transparent_hugepage/enabled", "r");
    if (!file) return false;
    char text[128] = {};
    const size_t read = std::fread(text, 1, sizeof text - 1, file);
    std::fclose(file);
    text[read] = '\0';
    return std::strstr(text, "[always]") != nullptr || std::strstr(text, "[madvise]") != nullptr;
}

double first_write_microseconds() {
    // Eight pages, each mapped and written once first so that what is timed is not the host's
    // own first touch of memory it had taken back, then given back to the kernel and mapped
    // and written again (MADV_POPULATE_WRITE as populate() does, then one byte a page), three
    // times; the least of the three, per page. Under shadow paging each page's write traps.
    constexpr size_t pages = 8;
    const size_t page = size_t(sysconf(_SC_PAGESIZE));
    const size_t bytes = pages * page;
    void* mapping = ::mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (mapping == MAP_FAILED) return 0;
    ::madvise(mapping, bytes, MADV_NOHUGEPAGE);  // 4 KiB pages whatever the system's setting
    volatile char* bytes_of = static_cast<volatile char*>(mapping);
    const auto touch = [&] {
        ::madvise(mapping, bytes, MADV_POPULATE_WRITE);
        for (size_t k = 0; k < pages; ++k) bytes_of[k * page] = char(k + 1);
    };
    touch();
    double least = std::numeric_limits<double>::infinity();
    for (int trial = 0; trial < 3; ++trial) {
        ::madvise(mapping, bytes, MADV_DONTNEED);
        const auto start = std::chrono::steady_clock::now();
        touch();
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        least = std::min(least, seconds);
    }
    ::munmap(mapping, bytes);
    return least * 1e6 / double(pages);
}

size_t populated_from() {
    return size_t(1) << 20;
}

size_t populated_up_to() {
    static const size_t limit = [] {
        const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
        const size_t most = size_t(256) << 20;
        return pages > 0 && page > 0 ? std::min(most, size_t(pages) / 8 * size_t(page)) : size_t(0);
    }();
    return limit;
}

bool replaces_operator_new() {
#ifdef WHITTED_SANITIZED_NEW
    return false;
#else
    return true;
#endif
}

void populate(void* block, size_t size) {
    if (!block || size < populated_from() || size > populated_up_to()) return;
    const uintptr_t page = uintptr_t(sysconf(_SC_PAGESIZE));
    // The pages wholly inside the block: the page it starts in holds malloc's header, already
    // written, and the one it ends in may be another block's.
    const uintptr_t first = (uintptr_t(block) + page - 1) / page * page;
    const uintptr_t end = (uintptr_t(block) + size) / page * page;
    if (end > first) ::madvise(reinterpret_cast<void*>(first), end - first, MADV_POPULATE_WRITE);
}

size_t mapped_from() {
    return size_t(8) << 20;
}
size_t kept_free() {
    return size_t(64) << 20;
}

void keep_freed_memory() {
#ifndef WHITTED_SANITIZED_NEW
    // Each call also stops glibc moving the other threshold (mallopt(3)): both are set.
    ::mallopt(M_MMAP_THRESHOLD, int(mapped_from()));
    ::mallopt(M_TRIM_THRESHOLD, int(kept_free()));
#endif
}

}  // namespace whitted::large_blocks

#ifndef WHITTED_SANITIZED_NEW

namespace {

/// The standard's loop: ask the new-handler for memory until it gives up by throwing.
void* allocate_or_throw(std::size_t size) {
    namespace blocks = whitted::large_blocks;
    if (size >= blocks::huge_from() && blocks::huge_pages()) {
        // On 2 MiB boundaries and in whole huge pages, left to fault as written: each of them is
        // then one fault (populating them would take as long as writing them).
        const size_t huge = blocks::huge_from(), rounded = (size + huge - 1) / huge * huge;
        void* block = nullptr;
        if (rounded >= size && posix_memalign(&block, huge, rounded) == 0) {
            ::madvise(block, rounded, MADV_HUGEPAGE);
            return block;
        }
    }
    for (;;) {
        if (void* block = std::malloc(size == 0 ? 1 : size)) {
            whitted::large_blocks::populate(block, size);
            return block;
        }
        const std::new_handler handler = std::get_new_handler();
        if (!handler) throw std::bad_alloc();
        handler();
    }
}

}  // namespace

void* operator new(std::size_t size) {
    return allocate_or_throw(size);
}
void* operator new[](std::size_t size) {
    return allocate_or_throw(size);
}
void* operator new(std::size_t size, const std::nothrow_t&) noexcept {
    try {
        return allocate_or_throw(size);
    } catch (...) {
        return nullptr;
    }
}
void* operator new[](std::size_t size, const std::nothrow_t& nothrow) noexcept {
    return ::operator new(size, nothrow);
}
void operator delete(void* block) noexcept {
    std::free(block);
}
void operator delete[](void* block) noexcept {
    std::free(block);
}
void operator delete(void* block, std::size_t) noexcept {
    std::free(block);
}
void operator delete[](void* block, std::size_t) noexcept {
    std::free(block);
}
void operator delete(void* block, const std::nothrow_t&) noexcept {
    std::free(block);
}
void operator delete[](void* block, const std::nothrow_t&) noexcept {
    std::free(block);
}

#endif
