// SPDX-License-Identifier: MIT
// The `whitted` program's operator new: blocks of 2 MiB and more are placed on 2 MiB boundaries
// and offered to the kernel for transparent huge pages (MADV_HUGEPAGE).
//
// Why: a render touches most of its memory once, fresh from the kernel (the image, the mesh
// arrays, the widened triangles, Embree's BVH), and the first touch of each page is a page
// fault. With 4 KiB pages the 1M-triangle anchor takes ~45,000 of them; on a virtual machine
// each costs microseconds, and on the one Whitted is measured on huge pages took a third off
// that anchor's whole-process time (docs/performance.md, "Huge pages"). One 2 MiB page
// replaces 512 faults. Most Debian kernels set transparent huge pages to "madvise", so a
// program has to ask, and glibc's malloc asks only when GLIBC_TUNABLES says so before the
// program starts.
//
// Only the program replaces operator new: the library (libwhitted, the Python module) leaves
// its host's allocator alone. Memory from here is plain malloc memory (aligned_alloc), so the
// standard operator delete (free) releases it; delete is replaced too all the same, so that
// every new and delete of the program meet in one place. Under AddressSanitizer or
// ThreadSanitizer nothing is replaced: their own operator new checks every new against its
// delete.

#include "huge_pages.h"

#ifndef WHITTED_SANITIZED_NEW

#include <sys/mman.h>

#include <cstddef>
#include <cstdlib>
#include <new>

namespace {

constexpr std::size_t huge_page = whitted::huge_page_bytes;

/// `size` bytes, on a huge-page boundary with the huge pages asked for if there are 2 MiB or
/// more of them; nullptr when out of memory.
void* allocate(std::size_t size) noexcept {
    if (size >= huge_page) {
        const std::size_t whole = (size + huge_page - 1) / huge_page * huge_page;
        if (whole >= size) {  // no overflow
            void* block = std::aligned_alloc(huge_page, whole);
            if (block) {
                // Advice only: where the kernel has no huge pages, or THP is "never", the
                // block is ordinary memory.
                ::madvise(block, whole, MADV_HUGEPAGE);
                return block;
            }
            return nullptr;
        }
    }
    return std::malloc(size == 0 ? 1 : size);
}

/// The standard's loop: ask the new-handler for memory until it gives up by throwing.
void* allocate_or_throw(std::size_t size) {
    for (;;) {
        if (void* block = allocate(size)) return block;
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
void* operator new[](std::size_t size, const std::nothrow_t&) noexcept {
    try {
        return allocate_or_throw(size);
    } catch (...) {
        return nullptr;
    }
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
