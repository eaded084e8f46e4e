// SPDX-License-Identifier: MIT
#pragma once
// What huge_pages.cpp and its test share: the block size from which the program's operator new
// asks for huge pages, and whether it replaces operator new at all (not under AddressSanitizer
// or ThreadSanitizer, whose own operator new checks every new against its delete).

#include <cstddef>

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define WHITTED_SANITIZED_NEW 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
#define WHITTED_SANITIZED_NEW 1
#endif
#endif

namespace whitted {

/// A transparent huge page on x86-64 and most aarch64 kernels: 2 MiB.
constexpr std::size_t huge_page_bytes = std::size_t(2) << 20;

}  // namespace whitted
