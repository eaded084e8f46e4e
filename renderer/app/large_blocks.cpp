// SPDX-License-Identifier: MIT
// The `whitted` program's operator new: a block of 1 MiB or more has its pages mapped by the
// kernel in one call (MADV_POPULATE_WRITE) before the program first writes it.
//
// Why: a render writes most of its memory once, fresh from the kernel (the image, the mesh
// arrays, the display-referred rows), and with 4 KiB pages the first write of each page is a
// page fault. On the virtual machines Whitted is measured on each fault costs ~11 µs, a 15 MB
// image about 40 ms, a 1M-triangle mesh tens of thousands of faults. One madvise that maps the
// block's pages costs about half as much as faulting them one by one (docs/performance.md,
// "Design choices and what they cost"). Huge pages would spare more but cost more on hosts that
// reclaim a guest's free memory in 2 MiB blocks: main() turns them off.
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
#include <cstdint>
#include <cstdlib>
#include <new>

#ifndef MADV_POPULATE_WRITE
#define MADV_POPULATE_WRITE 23  // Linux 5.14; older headers lack it
#endif

namespace whitted::large_blocks {

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
