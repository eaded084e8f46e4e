// SPDX-License-Identifier: MIT
#include "whitted/core/transform.h"

#include <cmath>
#include <numbers>

namespace whitted {
namespace {

using Rows = std::array<double, 12>;

Rows multiply(const Rows& a, const Rows& b) {  // a·b, both affine
    Rows r{};
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 4; ++j) {
            double s = (j == 3) ? a[i * 4 + 3] : 0.0;
            for (int k = 0; k < 3; ++k) s += a[i * 4 + k] * b[k * 4 + j];
            r[i * 4 + j] = s;
        }
    }
    return r;
}

Rows invert(const Rows& m) {
    const double det = linear_determinant(m);
    const double inv_det = 1.0 / det;
    // Inverse of the 3x3 part by cofactors, then the translation is −A⁻¹·t.
    Rows r{};
    r[0] = (m[5] * m[10] - m[6] * m[9]) * inv_det;
    r[1] = (m[2] * m[9] - m[1] * m[10]) * inv_det;
    r[2] = (m[1] * m[6] - m[2] * m[5]) * inv_det;
    r[4] = (m[6] * m[8] - m[4] * m[10]) * inv_det;
    r[5] = (m[0] * m[10] - m[2] * m[8]) * inv_det;
    r[6] = (m[2] * m[4] - m[0] * m[6]) * inv_det;
    r[8] = (m[4] * m[9] - m[5] * m[8]) * inv_det;
    r[9] = (m[1] * m[8] - m[0] * m[9]) * inv_det;
    r[10] = (m[0] * m[5] - m[1] * m[4]) * inv_det;
    for (int i = 0; i < 3; ++i) r[i * 4 + 3] = -(r[i * 4] * m[3] + r[i * 4 + 1] * m[7] + r[i * 4 + 2] * m[11]);
    return r;
}

}  // namespace

double linear_determinant(const Rows& m) {
    return m[0] * (m[5] * m[10] - m[6] * m[9]) - m[1] * (m[4] * m[10] - m[6] * m[8]) +
           m[2] * (m[4] * m[9] - m[5] * m[8]);
}

Transform Transform::from_rows(const Rows& m) {
    Transform t;
    t.m_forward = m;
    t.m_inverse = invert(m);
    t.m_identity = m == Rows{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};
    return t;
}

Transform Transform::translate(const Vec3& v) {
    return from_rows({1, 0, 0, v.x, 0, 1, 0, v.y, 0, 0, 1, v.z});
}

Transform Transform::scale(const Vec3& s) {
    return from_rows({s.x, 0, 0, 0, 0, s.y, 0, 0, 0, 0, s.z, 0});
}

Transform Transform::rotate(const Vec3& axis, double degrees) {
    const Vec3 a = normalize(axis);
    const double radians = degrees * std::numbers::pi / 180.0;
    const double c = std::cos(radians), s = std::sin(radians), k = 1.0 - c;
    // Rodrigues' formula, counter-clockwise looking down the axis toward the origin.
    return from_rows({c + a.x * a.x * k, a.x * a.y * k - a.z * s, a.x * a.z * k + a.y * s, 0, a.y * a.x * k + a.z * s,
                      c + a.y * a.y * k, a.y * a.z * k - a.x * s, 0, a.z * a.x * k - a.y * s, a.z * a.y * k + a.x * s,
                      c + a.z * a.z * k, 0});
}

Transform Transform::then(const Transform& b) const {
    Transform r;
    r.m_forward = multiply(b.m_forward, m_forward);
    r.m_inverse = multiply(m_inverse, b.m_inverse);
    r.m_identity = r.m_forward == Rows{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};
    return r;
}

namespace {

Vec3 multiply_point(const Rows& m, const Vec3& p) {
    return {m[0] * p.x + m[1] * p.y + m[2] * p.z + m[3], m[4] * p.x + m[5] * p.y + m[6] * p.z + m[7],
            m[8] * p.x + m[9] * p.y + m[10] * p.z + m[11]};
}

Vec3 multiply_vector(const Rows& m, const Vec3& v) {
    return {m[0] * v.x + m[1] * v.y + m[2] * v.z, m[4] * v.x + m[5] * v.y + m[6] * v.z,
            m[8] * v.x + m[9] * v.y + m[10] * v.z};
}

}  // namespace

Vec3 Transform::apply_point(const Vec3& p) const {
    return multiply_point(m_forward, p);
}
Vec3 Transform::apply_vector(const Vec3& v) const {
    return multiply_vector(m_forward, v);
}
Vec3 Transform::inverse_point(const Vec3& p) const {
    return multiply_point(m_inverse, p);
}
Vec3 Transform::inverse_vector(const Vec3& v) const {
    return multiply_vector(m_inverse, v);
}

Vec3 Transform::apply_normal(const Vec3& n) const {
    const Rows& m = m_inverse;  // transpose of the inverse
    return {m[0] * n.x + m[4] * n.y + m[8] * n.z, m[1] * n.x + m[5] * n.y + m[9] * n.z,
            m[2] * n.x + m[6] * n.y + m[10] * n.z};
}

double Transform::determinant() const {
    return linear_determinant(m_forward);
}

}  // namespace whitted
