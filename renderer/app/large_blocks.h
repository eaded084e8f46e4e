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

}  // namespace whitted::large_blocks
