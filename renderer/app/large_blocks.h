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

}  // namespace whitted::large_blocks
