// SPDX-License-Identifier: MIT
#pragma once

// The Embree device under the accelerator: its instruction set, chosen by the user or by
// Embree; its errors, reported from C code and thrown afterwards; and its memory.

#include <embree3/rtcore.h>

#include <atomic>
#include <cstdint>
#include <mutex>
#include <stdexcept>
#include <string>
#include <vector>

#include <sys/types.h>

namespace whitted {

/// Embree's instruction sets, narrowest first, by the names of Embree's `isa=` setting. Embree
/// picks the widest the CPU has; forcing a narrower one (WHITTED_EMBREE_ISA) lets the tests run,
/// on one machine, the code paths that users' CPUs take (docs/building.md).
const std::vector<std::string>& embree_isa_names();
/// $WHITTED_EMBREE_ISA: "" when unset or empty (Embree chooses). Throws std::invalid_argument,
/// naming the choices, when it is none of embree_isa_names().
std::string embree_isa_from_environment();
/// Throws std::invalid_argument, saying so, when Embree cannot run `isa` on this CPU ("" always
/// can): an Embree device is made with it and released, so a bad setting is found before any work.
void require_embree_isa(const std::string& isa);
bool embree_isa_supported(const std::string& isa);

/// Whether the arrays the accelerator maps for Embree (the widened corners, their indices,
/// MappedArray) ask for transparent huge pages instead of being mapped in whole as they are
/// made. Off unless the caller turns it on (api::use_huge_pages): the `whitted` program does
/// where a 4 KiB page's first write is dear (renderer/app/large_blocks.cpp says where).
void use_huge_pages(bool on);
bool huge_pages_in_use();

/// What `whitted --version` reports of Embree.
struct EmbreeInfo {
    std::string version;            ///< e.g. "3.13.5"
    std::vector<std::string> isas;  ///< of embree_isa_names(), those this CPU can run
    std::string isa_in_use;         ///< the one asked for, else the widest of `isas`
    int lane_width = 1;             ///< Accelerator::lane_width() with it
};
EmbreeInfo embree_info(const std::string& isa);

namespace accel {

/// An Embree device with the render's thread count and, unless `isa` is empty, that instruction
/// set. Throws std::invalid_argument when the CPU cannot run `isa`.
RTCDevice make_device(const std::string& config_start, const std::string& isa);

/// The widest packet Embree traverses natively with the device's instruction set. A wider call
/// than that goes through Embree's ray stream filter, which ignores the `valid` mask (hence
/// set_empty_lane) and regroups the rays into packets of the native width itself; calling at
/// the native width keeps Embree on the code that honours the mask. Measured against 16-wide
/// calls through the filter on the same CPU, the two were within a few percent of each other
/// (docs/performance.md). The width changes only the grouping: each ray's answer is
/// recomputed in double, so the pixels are the same for every width.
int native_lane_width(RTCDevice device);

/// The first error Embree reported. Embree calls record_embree_error from C code, where an
/// exception must not pass, and from any render thread: it keeps the message, and the caller
/// throws it once the Embree call has returned (throw_if_failed).
struct EmbreeError {
    std::atomic<bool> failed{false};
    mutable std::mutex mutex;
    std::string message;

    void throw_if_failed(const char* during) const {
        if (!failed.load(std::memory_order_relaxed)) return;
        std::lock_guard lock(mutex);
        throw std::runtime_error(message + " (" + during + ")");
    }
};

/// Embree's error callback; `user` is the device's EmbreeError.
void record_embree_error(void* user, RTCError code, const char* message);

/// Embree's own allocations, counted as they happen (--stats reports the peak: the BVH and
/// its build's scratch memory).
struct MemoryCount {
    std::atomic<int64_t> current{0}, peak{0};
};

/// Embree's memory monitor; `user` is the device's MemoryCount. Never refuses: the limit is
/// the machine's.
bool count_embree_memory(void* user, ssize_t bytes, bool post);

}  // namespace accel
}  // namespace whitted
