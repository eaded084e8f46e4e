// SPDX-License-Identifier: MIT
#pragma once

#include <cstddef>

/// The program's operator new (large_blocks.cpp says why): what it does with a large block.
namespace whitted::large_blocks {

/// Blocks of populated_from() to populated_up_to() bytes have their pages mapped when they are
/// allocated (1 MiB, and 256 MiB or an eighth of the machine's memory if that is less).
size_t populated_from();
size_t populated_up_to();
/// False under AddressSanitizer or ThreadSanitizer, whose own operator new is kept.
bool replaces_operator_new();
/// Maps the pages wholly inside [block, block + size) if the size is in that range.
void populate(void* block, size_t size);

/// malloc's thresholds for the program (large_blocks.cpp, "Smaller blocks"): blocks under
/// mapped_from() (8 MiB) come from malloc's heaps, and up to kept_free() bytes freed at a
/// heap's top stay there for the next block instead of going back to the kernel. Called at the
/// start of main, before any thread; does nothing under a sanitizer, whose allocator is its own.
void keep_freed_memory();
size_t mapped_from();
size_t kept_free();

/// Transparent huge pages (large_blocks.cpp says where they pay). With use_huge_pages(true),
/// operator new gives each block of huge_from() (2 MiB) or more on 2 MiB boundaries, rounded
/// up to whole 2 MiB, asks for huge pages for it (MADV_HUGEPAGE) and leaves it unmapped;
/// otherwise, as by default, such a block is populated like any other in the range above.
size_t huge_from();
void use_huge_pages(bool on);
bool huge_pages();
/// Whether the system gives huge pages to memory that asks for them (its setting `always` or
/// `madvise`, not `never`).
bool system_offers_huge_pages();
/// What the first write to a 4 KiB page of fresh memory costs this process, in microseconds:
/// the page mapped by the kernel (MADV_POPULATE_WRITE), then written. About 5 under a
/// hypervisor with shadow page tables, well under 1 with hardware-assisted paging.
double first_write_microseconds();
/// From this cost of a 4 KiB page's first write, huge pages pay (main chooses them).
constexpr double huge_pages_from_microseconds = 2.0;

}  // namespace whitted::large_blocks
