// SPDX-License-Identifier: MIT
// Accelerator hands each query to its Impl (accelerator_impl.h lists the files of its concerns).
#include "render/accelerator.h"

#include "render/accelerator_impl.h"

#include <algorithm>
#include <thread>

namespace whitted {

Accelerator::Accelerator(const Scene& scene, int threads)
    : Accelerator(scene, threads, embree_isa_from_environment()) {}
Accelerator::Accelerator(const Scene& scene, int threads, const std::string& isa, BvhChoice bvh)
    : m_impl(std::make_unique<Impl>(
          scene, threads > 0 ? threads : int(std::max(1u, std::thread::hardware_concurrency())), isa, bvh)) {}
bool Accelerator::has_bvh() const {
    return !m_impl->without_bvh;
}
int Accelerator::lane_width() const {
    return m_impl->lane_width;
}
const std::string& Accelerator::isa() const {
    return m_impl->isa;
}
Accelerator::~Accelerator() = default;
size_t Accelerator::peak_embree_bytes() const {
    return size_t(std::max<int64_t>(0, m_impl->memory.peak.load()));
}
size_t Accelerator::embree_bytes() const {
    return size_t(std::max<int64_t>(0, m_impl->memory.current.load()));
}
bool Accelerator::intersect(const Ray& ray, SurfaceHit& hit, HitParts parts) const {
    return m_impl->intersect(ray, hit, parts);
}
bool Accelerator::occluded(const Ray& ray) const {
    return m_impl->occluded(ray);
}

void Accelerator::intersect_packet(const Ray* rays, const bool* active, int count, SurfaceHit* hits, bool* found,
                                   HitParts parts) const {
    m_impl->intersect_packet(rays, active, count, hits, found, parts);
}
void Accelerator::occluded_packet(const Ray* rays, const bool* active, int count, bool* blocked) const {
    m_impl->occluded_packet(rays, active, count, blocked);
}

}  // namespace whitted
