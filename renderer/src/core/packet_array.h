// SPDX-License-Identifier: MIT
#pragma once

#include <new>
#include <type_traits>

namespace whitted {

/// Room for the N values of a ray packet (rays, hits, colours) that the code fills before it
/// reads them. Unlike T[N] it is not zeroed when made: Vec3, Ray and SurfaceHit zero their
/// members by default, and zeroing the scratch arrays of every packet, about 8 KB per packet and
/// bounce, cost several percent of a render (docs/performance.md).
template <class T, int N>
class PacketArray {
    static_assert(std::is_trivially_copyable_v<T> && std::is_trivially_destructible_v<T>,
                  "values live in raw storage: they must be plain data");

public:
    PacketArray() {}  // NOLINT(modernize-use-equals-default): `= default` would zero the values

    T& operator[](int i) { return data()[i]; }
    const T& operator[](int i) const { return data()[i]; }
    T* data() { return std::launder(reinterpret_cast<T*>(m_storage)); }
    const T* data() const { return std::launder(reinterpret_cast<const T*>(m_storage)); }

private:
    alignas(T) unsigned char m_storage[sizeof(T) * N];
};

}  // namespace whitted
