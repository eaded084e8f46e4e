// SPDX-License-Identifier: MIT
// Embree's functions as Whitted calls them, each passing the call on to Debian's
// libembree3.so.3, which the first of them (rtcNewDevice: a device comes before anything else
// of Embree's) loads. Linked in the usual way, Embree is loaded before `main` by every run: its
// relocations and 168 static initialisers cost a process about 4 ms on the machines of
// docs/performance.md ("Start-up"), more than the rest of a tiny render. So only a run that
// makes a BVH, or asks what Embree can do (`whitted --version`, WHITTED_EMBREE_ISA), loads it;
// a scene that each ray traces without a BVH (Accelerator::has_bvh), and every command that
// traces nothing (convert, colour, a usage error), never does.

#include <embree3/rtcore.h>

#include <dlfcn.h>

#include <stdexcept>
#include <string>

namespace {

// Every Embree function Whitted calls (rtcInitIntersectContext is inline in Embree's header).
#define WHITTED_EMBREE_FUNCTIONS(X)          \
    X(rtcAttachGeometry)                     \
    X(rtcCommitGeometry)                     \
    X(rtcCommitScene)                        \
    X(rtcGetDeviceError)                     \
    X(rtcGetDeviceProperty)                  \
    X(rtcIntersect1)                         \
    X(rtcIntersect4)                         \
    X(rtcIntersect8)                         \
    X(rtcIntersect16)                        \
    X(rtcNewDevice)                          \
    X(rtcNewGeometry)                        \
    X(rtcNewScene)                           \
    X(rtcOccluded1)                          \
    X(rtcOccluded4)                          \
    X(rtcOccluded8)                          \
    X(rtcOccluded16)                         \
    X(rtcReleaseDevice)                      \
    X(rtcReleaseGeometry)                    \
    X(rtcReleaseScene)                       \
    X(rtcSetDeviceErrorFunction)             \
    X(rtcSetDeviceMemoryMonitorFunction)     \
    X(rtcSetGeometryBoundsFunction)          \
    X(rtcSetGeometryBuildQuality)            \
    X(rtcSetGeometryInstancedScene)          \
    X(rtcSetGeometryIntersectFilterFunction) \
    X(rtcSetGeometryIntersectFunction)       \
    X(rtcSetGeometryOccludedFilterFunction)  \
    X(rtcSetGeometryOccludedFunction)        \
    X(rtcSetGeometryTimeStepCount)           \
    X(rtcSetGeometryTransform)               \
    X(rtcSetGeometryUserData)                \
    X(rtcSetGeometryUserPrimitiveCount)      \
    X(rtcSetSceneBuildQuality)               \
    X(rtcSetSceneFlags)                      \
    X(rtcSetSharedGeometryBuffer)

/// What the dynamic loader is asked for: Embree 3's SONAME (Debian's package libembree3-3).
constexpr const char* embree_file = "libembree3.so.3";

struct EmbreeLibrary {
#define WHITTED_EMBREE_POINTER(name) decltype(&::name) name = nullptr;
    WHITTED_EMBREE_FUNCTIONS(WHITTED_EMBREE_POINTER)
#undef WHITTED_EMBREE_POINTER
};

/// Embree, loaded by the first call (thread-safe; a failure is thrown to that call, and the
/// next one tries again). Never unloaded: its threads and devices may outlive any one caller.
const EmbreeLibrary& embree() {
    static const EmbreeLibrary library = [] {
        void* handle = ::dlopen(embree_file, RTLD_LAZY | RTLD_LOCAL);
        if (!handle)
            throw std::runtime_error(std::string("cannot load Embree, which builds and traverses Whitted's BVH: ") +
                                     ::dlerror() + " (on Debian, Embree is the package libembree3-3)");
        EmbreeLibrary loaded;
#define WHITTED_EMBREE_LOOKUP(name)                                                                         \
    loaded.name = reinterpret_cast<decltype(&::name)>(::dlsym(handle, #name));                              \
    if (!loaded.name)                                                                                       \
        throw std::runtime_error(std::string("cannot use Embree: ") + embree_file + " has no " #name " (" + \
                                 "Whitted needs Embree 3.13, Debian's libembree3-3)");
        WHITTED_EMBREE_FUNCTIONS(WHITTED_EMBREE_LOOKUP)
#undef WHITTED_EMBREE_LOOKUP
        return loaded;
    }();
    return library;
}

}  // namespace

// Each function as rtcore.h declares it.
RTCDevice rtcNewDevice(const char* config) {
    return embree().rtcNewDevice(config);
}
void rtcReleaseDevice(RTCDevice device) {
    embree().rtcReleaseDevice(device);
}
RTCError rtcGetDeviceError(RTCDevice device) {
    return embree().rtcGetDeviceError(device);
}
ssize_t rtcGetDeviceProperty(RTCDevice device, RTCDeviceProperty prop) {
    return embree().rtcGetDeviceProperty(device, prop);
}
void rtcSetDeviceErrorFunction(RTCDevice device, RTCErrorFunction error, void* user) {
    embree().rtcSetDeviceErrorFunction(device, error, user);
}
void rtcSetDeviceMemoryMonitorFunction(RTCDevice device, RTCMemoryMonitorFunction monitor, void* user) {
    embree().rtcSetDeviceMemoryMonitorFunction(device, monitor, user);
}
RTCScene rtcNewScene(RTCDevice device) {
    return embree().rtcNewScene(device);
}
void rtcReleaseScene(RTCScene scene) {
    embree().rtcReleaseScene(scene);
}
void rtcCommitScene(RTCScene scene) {
    embree().rtcCommitScene(scene);
}
void rtcSetSceneBuildQuality(RTCScene scene, RTCBuildQuality quality) {
    embree().rtcSetSceneBuildQuality(scene, quality);
}
void rtcSetSceneFlags(RTCScene scene, RTCSceneFlags flags) {
    embree().rtcSetSceneFlags(scene, flags);
}
unsigned int rtcAttachGeometry(RTCScene scene, RTCGeometry geometry) {
    return embree().rtcAttachGeometry(scene, geometry);
}
RTCGeometry rtcNewGeometry(RTCDevice device, RTCGeometryType type) {
    return embree().rtcNewGeometry(device, type);
}
void rtcReleaseGeometry(RTCGeometry geometry) {
    embree().rtcReleaseGeometry(geometry);
}
void rtcCommitGeometry(RTCGeometry geometry) {
    embree().rtcCommitGeometry(geometry);
}
void rtcSetGeometryBoundsFunction(RTCGeometry geometry, RTCBoundsFunction bounds, void* user) {
    embree().rtcSetGeometryBoundsFunction(geometry, bounds, user);
}
void rtcSetGeometryBuildQuality(RTCGeometry geometry, RTCBuildQuality quality) {
    embree().rtcSetGeometryBuildQuality(geometry, quality);
}
void rtcSetGeometryInstancedScene(RTCGeometry geometry, RTCScene scene) {
    embree().rtcSetGeometryInstancedScene(geometry, scene);
}
void rtcSetGeometryIntersectFilterFunction(RTCGeometry geometry, RTCFilterFunctionN filter) {
    embree().rtcSetGeometryIntersectFilterFunction(geometry, filter);
}
void rtcSetGeometryIntersectFunction(RTCGeometry geometry, RTCIntersectFunctionN intersect) {
    embree().rtcSetGeometryIntersectFunction(geometry, intersect);
}
void rtcSetGeometryOccludedFilterFunction(RTCGeometry geometry, RTCFilterFunctionN filter) {
    embree().rtcSetGeometryOccludedFilterFunction(geometry, filter);
}
void rtcSetGeometryOccludedFunction(RTCGeometry geometry, RTCOccludedFunctionN occluded) {
    embree().rtcSetGeometryOccludedFunction(geometry, occluded);
}
void rtcSetGeometryTimeStepCount(RTCGeometry geometry, unsigned int count) {
    embree().rtcSetGeometryTimeStepCount(geometry, count);
}
void rtcSetGeometryTransform(RTCGeometry geometry, unsigned int time_step, RTCFormat format, const void* xfm) {
    embree().rtcSetGeometryTransform(geometry, time_step, format, xfm);
}
void rtcSetGeometryUserData(RTCGeometry geometry, void* ptr) {
    embree().rtcSetGeometryUserData(geometry, ptr);
}
void rtcSetGeometryUserPrimitiveCount(RTCGeometry geometry, unsigned int count) {
    embree().rtcSetGeometryUserPrimitiveCount(geometry, count);
}
void rtcSetSharedGeometryBuffer(RTCGeometry geometry, RTCBufferType type, unsigned int slot, RTCFormat format,
                                const void* ptr, size_t byte_offset, size_t byte_stride, size_t item_count) {
    embree().rtcSetSharedGeometryBuffer(geometry, type, slot, format, ptr, byte_offset, byte_stride, item_count);
}
void rtcIntersect1(RTCScene scene, RTCIntersectContext* context, RTCRayHit* rayhit) {
    embree().rtcIntersect1(scene, context, rayhit);
}
void rtcIntersect4(const int* valid, RTCScene scene, RTCIntersectContext* context, RTCRayHit4* rayhit) {
    embree().rtcIntersect4(valid, scene, context, rayhit);
}
void rtcIntersect8(const int* valid, RTCScene scene, RTCIntersectContext* context, RTCRayHit8* rayhit) {
    embree().rtcIntersect8(valid, scene, context, rayhit);
}
void rtcIntersect16(const int* valid, RTCScene scene, RTCIntersectContext* context, RTCRayHit16* rayhit) {
    embree().rtcIntersect16(valid, scene, context, rayhit);
}
void rtcOccluded1(RTCScene scene, RTCIntersectContext* context, RTCRay* ray) {
    embree().rtcOccluded1(scene, context, ray);
}
void rtcOccluded4(const int* valid, RTCScene scene, RTCIntersectContext* context, RTCRay4* ray) {
    embree().rtcOccluded4(valid, scene, context, ray);
}
void rtcOccluded8(const int* valid, RTCScene scene, RTCIntersectContext* context, RTCRay8* ray) {
    embree().rtcOccluded8(valid, scene, context, ray);
}
void rtcOccluded16(const int* valid, RTCScene scene, RTCIntersectContext* context, RTCRay16* ray) {
    embree().rtcOccluded16(valid, scene, context, ray);
}
