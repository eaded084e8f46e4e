// SPDX-License-Identifier: MIT
#pragma once

#include "core/vec3.h"

#include <array>

namespace whitted {

/// An affine transform held as a 4x4 row-major matrix whose last row is (0, 0, 0, 1), with its
/// inverse kept alongside so that rays can go into object space and normals back out.
class Transform {
public:
    Transform() = default;
    /// `m` is row-major, 12 numbers (the top three rows); the caller guarantees it is invertible.
    static Transform from_rows(const std::array<double, 12>& m);
    static Transform translate(const Vec3& t);
    static Transform scale(const Vec3& s);
    /// Right-hand rule about `axis` (any non-zero length), `degrees`.
    static Transform rotate(const Vec3& axis, double degrees);

    /// `a.then(b)` applies a first, then b.
    Transform then(const Transform& b) const;

    Vec3 apply_point(const Vec3& p) const;
    Vec3 apply_vector(const Vec3& v) const;
    /// Normals transform with the inverse transpose; the result is not normalised.
    Vec3 apply_normal(const Vec3& n) const;
    Vec3 inverse_point(const Vec3& p) const;
    Vec3 inverse_vector(const Vec3& v) const;

    /// Cached: shapes ask on every intersection test.
    bool is_identity() const { return m_identity; }
    double determinant() const;
    const std::array<double, 12>& rows() const { return m_forward; }

private:
    // Row-major top three rows of the forward and inverse matrices.
    std::array<double, 12> m_forward{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};
    std::array<double, 12> m_inverse{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};
    bool m_identity = true;
};

/// Determinant of the linear 3x3 part of a row-major 3x4 matrix.
double linear_determinant(const std::array<double, 12>& m);

}  // namespace whitted
