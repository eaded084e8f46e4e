// SPDX-License-Identifier: MIT
#include "output/chromaticities.h"

namespace whitted {
namespace {

std::array<double, 3> xy_to_xyz(const double xy[2]) {
    return {xy[0] / xy[1], 1.0, (1.0 - xy[0] - xy[1]) / xy[1]};
}

std::array<double, 3> apply(const Matrix3& m, const std::array<double, 3>& v) {
    std::array<double, 3> out{};
    for (int i = 0; i < 3; ++i) out[i] = m[i][0] * v[0] + m[i][1] * v[1] + m[i][2] * v[2];
    return out;
}

}  // namespace

Matrix3 multiply(const Matrix3& a, const Matrix3& b) {
    Matrix3 out{};
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            for (int k = 0; k < 3; ++k) out[i][j] += a[i][k] * b[k][j];
    return out;
}

Matrix3 inverse(const Matrix3& m) {
    const double det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
                       m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                       m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    Matrix3 out{};
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
            // The cofactor of m[j][i], from the cyclic neighbours (signs come out right).
            const int r0 = (j + 1) % 3, r1 = (j + 2) % 3, c0 = (i + 1) % 3, c1 = (i + 2) % 3;
            out[i][j] = (m[r0][c0] * m[r1][c1] - m[r0][c1] * m[r1][c0]) / det;
        }
    return out;
}

Matrix3 rgb_to_xyz(const Chromaticities& c) {
    const std::array<double, 3> r = xy_to_xyz(c.red), g = xy_to_xyz(c.green), b = xy_to_xyz(c.blue);
    const Matrix3 primaries{{{r[0], g[0], b[0]}, {r[1], g[1], b[1]}, {r[2], g[2], b[2]}}};
    // Each primary scaled so that RGB (1, 1, 1) is the white point.
    const std::array<double, 3> scale = apply(inverse(primaries), xy_to_xyz(c.white));
    Matrix3 out{};
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) out[i][j] = primaries[i][j] * scale[j];
    return out;
}

Matrix3 bradford(const std::array<double, 3>& from, const std::array<double, 3>& to) {
    const Matrix3 cone{{{0.8951, 0.2664, -0.1614}, {-0.7502, 1.7135, 0.0367}, {0.0389, -0.0685, 1.0296}}};
    const std::array<double, 3> a = apply(cone, from), b = apply(cone, to);
    const Matrix3 gain{{{b[0] / a[0], 0, 0}, {0, b[1] / a[1], 0}, {0, 0, b[2] / a[2]}}};
    return multiply(inverse(cone), multiply(gain, cone));
}

}  // namespace whitted
