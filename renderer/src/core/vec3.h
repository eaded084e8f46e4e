// SPDX-License-Identifier: MIT
#pragma once

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <type_traits>

namespace whitted {

/// `x` rounded to the nearest float, as a double. The float passes through an empty asm
/// statement (or, on other compilers and CPUs, a volatile) because GCC 12's SLP vectoriser (on
/// from -O2) drops a double → float → double round trip of neighbouring values:
/// Vec3{float(a.x), float(a.y), float(a.z)} came out with x and y unrounded (seen with g++ 12.2
/// at -O2 and -O3, not with the vectoriser off). The asm keeps the float in a register, where
/// a volatile went through memory: POV-Ray's mesh test (shapes.cpp) rounds a dozen values a hit.
inline double float_rounded(double x) {
    float f = static_cast<float>(x);
#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__))
    __asm__("" : "+x"(f));
#elif defined(__GNUC__) && defined(__aarch64__)
    __asm__("" : "+w"(f));
#else
    volatile float held = f;
    f = held;
#endif
    return f;
}

/// The next value above `x`: what std::nextafter(x, +infinity) returns, bit for bit, but inline.
/// The analytic callbacks ask for it on every candidate hit, where the library call was 2 % of
/// the spheres anchor's render time. For finite x the neighbour above is one step of the bit
/// pattern: up for positive x, down (toward zero) for negative x; 0 and -0 step to the smallest
/// subnormal; +infinity and NaN stay as they are.
template <class Real>
inline Real next_up(Real x) {
    using Bits = std::conditional_t<sizeof(Real) == 8, uint64_t, uint32_t>;
    static_assert(std::numeric_limits<Real>::is_iec559 && sizeof(Real) == sizeof(Bits));
    if (!(x < std::numeric_limits<Real>::infinity())) return x;
    if (x == 0) return std::numeric_limits<Real>::denorm_min();
    const Bits bits = std::bit_cast<Bits>(x);
    return std::bit_cast<Real>(x > 0 ? Bits(bits + 1) : Bits(bits - 1));
}

/// A 3-vector of doubles. Geometry and shading run in double precision because POV-Ray, the
/// renderer we are checked against, does its geometry in double; float would cost us whole
/// 16-bit codes on grazing hits.
struct Vec3 {
    double x = 0, y = 0, z = 0;

    constexpr Vec3() = default;
    constexpr Vec3(double x_, double y_, double z_) : x(x_), y(y_), z(z_) {}
    constexpr explicit Vec3(double c) : x(c), y(c), z(c) {}

    constexpr double operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
    double& operator[](int i) { return i == 0 ? x : (i == 1 ? y : z); }

    constexpr Vec3 operator-() const { return {-x, -y, -z}; }
    constexpr Vec3 operator+(const Vec3& o) const { return {x + o.x, y + o.y, z + o.z}; }
    constexpr Vec3 operator-(const Vec3& o) const { return {x - o.x, y - o.y, z - o.z}; }
    /// Component-wise product: colours multiply per channel.
    constexpr Vec3 operator*(const Vec3& o) const { return {x * o.x, y * o.y, z * o.z}; }
    constexpr Vec3 operator*(double s) const { return {x * s, y * s, z * s}; }
    constexpr Vec3 operator/(double s) const { return {x / s, y / s, z / s}; }
    Vec3& operator+=(const Vec3& o) {
        x += o.x;
        y += o.y;
        z += o.z;
        return *this;
    }
    Vec3& operator-=(const Vec3& o) {
        x -= o.x;
        y -= o.y;
        z -= o.z;
        return *this;
    }
    Vec3& operator*=(double s) {
        x *= s;
        y *= s;
        z *= s;
        return *this;
    }
    constexpr bool operator==(const Vec3& o) const = default;
};

constexpr Vec3 operator*(double s, const Vec3& v) {
    return v * s;
}
constexpr double dot(const Vec3& a, const Vec3& b) {
    return a.x * b.x + a.y * b.y + a.z * b.z;
}
constexpr Vec3 cross(const Vec3& a, const Vec3& b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline double length(const Vec3& v) {
    return std::sqrt(dot(v, v));
}
inline Vec3 normalize(const Vec3& v) {
    return v / length(v);
}
/// normalize(v), also for a direction whose squared length under- or overflows a double (any
/// non-zero length is a direction, [0, 4.9e-324, 0] too): such a v is first divided by its
/// largest component. Every other v gives normalize(v) bit for bit.
inline Vec3 unit_direction(const Vec3& v) {
    const double len = length(v);
    if (len > 1e-150 && len < 1e150) return v / len;
    const double largest = std::fmax(std::fabs(v.x), std::fmax(std::fabs(v.y), std::fabs(v.z)));
    const Vec3 scaled = v / largest;
    return scaled / length(scaled);
}
inline Vec3 min(const Vec3& a, const Vec3& b) {
    return {std::fmin(a.x, b.x), std::fmin(a.y, b.y), std::fmin(a.z, b.z)};
}
inline Vec3 max(const Vec3& a, const Vec3& b) {
    return {std::fmax(a.x, b.x), std::fmax(a.y, b.y), std::fmax(a.z, b.z)};
}
constexpr bool is_zero(const Vec3& v) {
    return v.x == 0 && v.y == 0 && v.z == 0;
}

/// Linear RGB, scene-referred (Rec.709 primaries). Same storage as a vector; the alias keeps
/// signatures readable in the lecture's terms.
using Color = Vec3;

}  // namespace whitted
