// SPDX-License-Identifier: MIT
#include "core/transform.h"

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

/// The inverse as POV-Ray computes it for a `matrix` (its 4x4 row-vector form, inverted by
/// cofactors with each 3x3 minor's six products in a fixed order, then divided by the
/// determinant), bit for bit: `whitted convert` writes each object's whole transform as one
/// matrix, and a ray taken into an object's space with the same rounding in both renderers meets
/// it at the same t. Where two objects are met at nearly the same t, a last-bit difference
/// decided which one showed (docs/pov-model.md §3, "Which of two equally near objects").
Rows invert(const Rows& rows) {
    // POV-Ray's m[r][c]: rows 0-2 are our columns (the linear part), row 3 the translation;
    // its last column is (0, 0, 0, 1).
    double m[4][4];
    for (int r = 0; r < 4; ++r) {
        for (int c = 0; c < 3; ++c) m[r][c] = rows[4 * c + r];
        m[r][3] = r == 3 ? 1.0 : 0.0;
    }
    // The minor without row `skip_row` and column `skip_col`: with rows a < b < c and columns
    // x < y < z left, the three products along the diagonals, less the three along the
    // anti-diagonals (each from the bottom row up), summed left to right.
    const auto minor = [&](int skip_row, int skip_col) {
        int r[3], c[3];
        for (int i = 0, n = 0; i < 4; ++i)
            if (i != skip_row) r[n++] = i;
        for (int i = 0, n = 0; i < 4; ++i)
            if (i != skip_col) c[n++] = i;
        return m[r[0]][c[0]] * m[r[1]][c[1]] * m[r[2]][c[2]] + m[r[0]][c[1]] * m[r[1]][c[2]] * m[r[2]][c[0]] +
               m[r[0]][c[2]] * m[r[1]][c[0]] * m[r[2]][c[1]] - m[r[2]][c[0]] * m[r[1]][c[1]] * m[r[0]][c[2]] -
               m[r[2]][c[1]] * m[r[1]][c[2]] * m[r[0]][c[0]] - m[r[2]][c[2]] * m[r[1]][c[0]] * m[r[0]][c[1]];
    };
    double d[4][4];
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) d[i][j] = minor(i, j);
    const double det = m[0][0] * d[0][0] - m[0][1] * d[0][1] + m[0][2] * d[0][2] - m[0][3] * d[0][3];
    // POV-Ray's inverse r[i][j] = ±d[j][i] / det; ours is its transpose, rows 0-2.
    Rows inverse{};
    for (int i = 0; i < 3; ++i)      // our row: POV-Ray's column
        for (int j = 0; j < 4; ++j)  // our column: POV-Ray's row
            inverse[4 * i + j] = ((i + j) % 2 ? -d[i][j] : d[i][j]) / det;
    return inverse;
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
    Rows rows{c + a.x * a.x * k,       a.x * a.y * k - a.z * s, a.x * a.z * k + a.y * s, 0,
              a.y * a.x * k + a.z * s, c + a.y * a.y * k,       a.y * a.z * k - a.x * s, 0,
              a.z * a.x * k - a.y * s, a.z * a.y * k + a.x * s, c + a.z * a.z * k,       0};
    // About a coordinate axis that axis's own entry is exactly 1, not c + (1 − c), which rounds
    // to 1 − 2⁻⁵³ for some angles: a box turned about y then keeps its top at exactly its
    // height, and two boxes of one height turned differently meet a ray at exactly the same t,
    // in both renderers, which then settle the tie the same way (PovrayTestOrder).
    for (int i = 0; i < 3; ++i)
        if (std::fabs(a[i]) == 1.0) rows[5 * i] = 1.0;
    return from_rows(rows);
}

Transform Transform::then(const Transform& b) const {
    // With the identity on either side the product is the other (and its inverse, from the same
    // rows); multiplying would give the same values, though a −0 entry could come out +0. Most
    // objects have no transform, and inverting costs.
    if (b.m_identity) return *this;
    if (m_identity) return b;
    Transform r;
    r.m_forward = multiply(b.m_forward, m_forward);
    r.m_inverse = invert(r.m_forward);  // of the whole, as POV-Ray inverts it (invert)
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
