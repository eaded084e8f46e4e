// SPDX-License-Identifier: MIT
// The Embree device: which instruction set runs (WHITTED_EMBREE_ISA), how wide its packets are,
// its errors and its memory.
#include "render/accelerator_device.h"

#include <algorithm>
#include <cstddef>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <vector>

namespace whitted {
namespace accel {

namespace {

std::string isa_list() {
    std::string list;
    for (const std::string& name : embree_isa_names()) list += (list.empty() ? "" : ", ") + name;
    return list;
}

}  // namespace

RTCDevice make_device(const std::string& config_start, const std::string& isa) {
    std::string config = config_start;
    if (!isa.empty()) config += ",isa=" + isa;
    RTCDevice device = rtcNewDevice(config.c_str());
    if (device) return device;
    const RTCError code = rtcGetDeviceError(nullptr);
    if (code == RTC_ERROR_UNSUPPORTED_CPU && !isa.empty())
        throw std::invalid_argument("WHITTED_EMBREE_ISA=" + isa + ": this CPU cannot run Embree's " + isa +
                                    " code (unset it to let Embree choose)");
    throw std::runtime_error("cannot create the Embree device (Embree error " + std::to_string(int(code)) + ")");
}

void record_embree_error(void* user, RTCError code, const char* message) {
    if (code == RTC_ERROR_NONE) return;
    auto* error = static_cast<EmbreeError*>(user);
    std::lock_guard lock(error->mutex);
    if (error->failed.load()) return;
    error->message = code == RTC_ERROR_OUT_OF_MEMORY ? std::string("Embree ran out of memory")
                                                     : std::string("Embree: ") + (message ? message : "unknown error");
    error->failed.store(true);
}

bool count_embree_memory(void* user, ssize_t bytes, bool /*post*/) {
    auto* count = static_cast<MemoryCount*>(user);
    const int64_t now = count->current.fetch_add(bytes) + bytes;
    int64_t peak = count->peak.load();
    while (now > peak && !count->peak.compare_exchange_weak(peak, now)) {
    }
    return true;  // never refuse: the limit is the machine's
}

int native_lane_width(RTCDevice device) {
    if (rtcGetDeviceProperty(device, RTC_DEVICE_PROPERTY_NATIVE_RAY16_SUPPORTED)) return 16;
    if (rtcGetDeviceProperty(device, RTC_DEVICE_PROPERTY_NATIVE_RAY8_SUPPORTED)) return 8;
    if (rtcGetDeviceProperty(device, RTC_DEVICE_PROPERTY_NATIVE_RAY4_SUPPORTED)) return 4;
    return 1;
}

}  // namespace accel

using accel::isa_list;
using accel::make_device;
using accel::native_lane_width;

namespace {
std::atomic<bool> g_huge_pages{false};
}  // namespace

void use_huge_pages(bool on) {
    g_huge_pages.store(on, std::memory_order_relaxed);
}

bool huge_pages_in_use() {
    return g_huge_pages.load(std::memory_order_relaxed);
}

const std::vector<std::string>& embree_isa_names() {
    static const std::vector<std::string> names = {"sse2", "sse4.2", "avx", "avx2", "avx512"};
    return names;
}

std::string embree_isa_from_environment() {
    const char* value = std::getenv("WHITTED_EMBREE_ISA");
    if (!value || !*value) return "";
    const std::vector<std::string>& names = embree_isa_names();
    if (std::find(names.begin(), names.end(), value) == names.end())
        throw std::invalid_argument(std::string("WHITTED_EMBREE_ISA=") + value +
                                    ": not one of Embree's instruction sets (" + isa_list() +
                                    "); unset it to let Embree choose");
    return value;
}

void require_embree_isa(const std::string& isa) {
    if (isa.empty()) return;  // Embree's own choice: every CPU it starts on can run it
    rtcReleaseDevice(make_device("verbose=0", isa));
}

bool embree_isa_supported(const std::string& isa) {
    try {
        require_embree_isa(isa);
        return true;
    } catch (const std::invalid_argument&) {
        return false;
    }
}

EmbreeInfo embree_info(const std::string& isa) {
    EmbreeInfo info;
    info.version = RTC_VERSION_STRING;
    // Each of Embree's instruction sets asks the CPU for all the features of the one before it
    // and more (SSE4.2 those of SSE2, AVX those of SSE4.2, ...), so the CPU runs a prefix of the
    // list: the widest it runs is found by trying from the widest down. A device made to try one
    // costs about 0.3 M instructions; on the widest CPUs, the common case, one is made here
    // instead of one per instruction set (docs/performance.md, "Start-up").
    const std::vector<std::string>& names = embree_isa_names();
    for (size_t n = names.size(); n > 0; --n)
        if (embree_isa_supported(names[n - 1])) {
            info.isas.assign(names.begin(), names.begin() + std::ptrdiff_t(n));
            break;
        }
    info.isa_in_use = !isa.empty() ? isa : info.isas.empty() ? std::string("?") : info.isas.back();
    RTCDevice device = make_device("verbose=0", isa);
    info.lane_width = native_lane_width(device);
    rtcReleaseDevice(device);
    return info;
}

}  // namespace whitted
