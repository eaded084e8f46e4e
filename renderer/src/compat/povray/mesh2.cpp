// SPDX-License-Identifier: MIT
#include "compat/povray/mesh2.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cmath>
#include <utility>

namespace whitted {

namespace {

/// A mesh2 triangle as POV-Ray sets it up when it reads the mesh: the plane with its normal
/// (p3 − p1) × (p2 − p1) scaled by the reciprocal of its length, the distance −n·p1 rounded to
/// float and the normal then rounded to float too; the normal's largest axis (ties going to
/// the later axis); and p1, p2 swapped where needed so that the edge tests see the corners
/// turning one way (`swapped`). Each operation is written out in POV-Ray's order, so that the
/// roundings are the same.
struct Mesh2Triangle {
    Vec3 p1, p2, p3;       ///< after the swap
    bool swapped = false;  ///< p1 and p2 are the face's second and first vertex
    Vec3 stored_normal;    ///< float
    double distance = 0;   ///< float
    int axis = 2;
    bool degenerate = false;

    Mesh2Triangle(const Vec3& v1, const Vec3& v2, const Vec3& v3) : p1(v1), p2(v2), p3(v3) {
        const Vec3 a = v2 - v1, b = v3 - v1;
        Vec3 n{b.y * a.z - b.z * a.y, b.z * a.x - b.x * a.z, b.x * a.y - b.y * a.x};
        const double n_length = std::sqrt(n.x * n.x + n.y * n.y + n.z * n.z);
        if (n_length == 0) {
            degenerate = true;  // POV-Ray drops the triangle
            return;
        }
        const double inverse = 1.0 / n_length;
        n.x *= inverse;
        n.y *= inverse;
        n.z *= inverse;
        distance = -float_rounded(n.x * v1.x + n.y * v1.y + n.z * v1.z);
        stored_normal = {float_rounded(n.x), float_rounded(n.y), float_rounded(n.z)};
        const double x = std::fabs(n.x), y = std::fabs(n.y), z = std::fabs(n.z);
        axis = x > y ? (x > z ? 0 : 2) : (y > z ? 1 : 2);
        const int i = projected_i(), j = projected_j();
        if ((p2[i] - p3[i]) * (p2[j] - p1[j]) < (p2[j] - p3[j]) * (p2[i] - p1[i])) {
            std::swap(p1, p2);
            swapped = true;
        }
    }
    /// The two axes of the projection along `axis`, in POV-Ray's order.
    int projected_i() const { return axis == 0 ? 1 : 0; }
    int projected_j() const { return axis == 2 ? 1 : 2; }
};

}  // namespace

bool intersect_mesh2_triangle(const Vec3& p1_in, const Vec3& p2_in, const Vec3& p3_in, const Vec3& origin,
                              const Vec3& direction, double& depth, bool& inside) {
    const Mesh2Triangle triangle(p1_in, p2_in, p3_in);
    if (triangle.degenerate) return false;
    const Vec3 &n = triangle.stored_normal, &p1 = triangle.p1, &p2 = triangle.p2, &p3 = triangle.p3;
    const double normal_dot_direction = n.x * direction.x + n.y * direction.y + n.z * direction.z;
    if (std::fabs(normal_dot_direction) < 1e-10) return false;
    const double normal_dot_origin = n.x * origin.x + n.y * origin.y + n.z * origin.z;
    depth = -(triangle.distance + normal_dot_origin) / normal_dot_direction;
    if (depth < 1e-6 || depth > 1e7) return false;
    const int i = triangle.projected_i(), j = triangle.projected_j();
    const double s = origin[i] + depth * direction[i], t = origin[j] + depth * direction[j];
    inside = !((p2[i] - s) * (p2[j] - p1[j]) < (p2[j] - t) * (p2[i] - p1[i])) &&
             !((p3[i] - s) * (p3[j] - p2[j]) < (p3[j] - t) * (p3[i] - p2[i])) &&
             !((p1[i] - s) * (p1[j] - p3[j]) < (p1[j] - t) * (p1[i] - p3[i]));
    return true;
}

Vec3 mesh2_smooth_normal(const Vec3& p1_in, const Vec3& p2_in, const Vec3& p3_in, const Vec3& n1_in, const Vec3& n2_in,
                         const Vec3& n3_in, const Vec3& point) {
    const Mesh2Triangle triangle(p1_in, p2_in, p3_in);
    const Vec3 &p1 = triangle.p1, &p2 = triangle.p2, &p3 = triangle.p3;
    const Vec3& n1 = triangle.swapped ? n2_in : n1_in;
    const Vec3& n2 = triangle.swapped ? n1_in : n2_in;
    const Vec3& n3 = n3_in;
    // What POV-Ray keeps per triangle for it: the axis along which p3 − p2 is longest, and
    // `perp`, a float vector in the plane across the edge p2 p3, scaled so that its dot
    // product with a point minus p1 runs from 0 at p1 to 1 on that edge.
    const Vec3 p3_minus_p2 = p3 - p2;
    const double x = std::fabs(p3_minus_p2.x), y = std::fabs(p3_minus_p2.y), z = std::fabs(p3_minus_p2.z);
    const int v_axis = x > y ? (x > z ? 0 : 2) : (y > z ? 1 : 2);
    Vec3 edge = p2 - p3;
    const double edge_inverse = 1.0 / std::sqrt(edge.x * edge.x + edge.y * edge.y + edge.z * edge.z);
    edge = {edge.x * edge_inverse, edge.y * edge_inverse, edge.z * edge_inverse};
    const Vec3 p1_from_p3 = p1 - p3;
    const double projection = p1_from_p3.x * edge.x + p1_from_p3.y * edge.y + p1_from_p3.z * edge.z;
    edge = {edge.x * projection, edge.y * projection, edge.z * projection};
    // `perp` is a float vector, normalised and scaled in single precision. Each float
    // operation is done in double and rounded (float_rounded), which for +, ×, / and sqrt
    // gives the float result exactly.
    const auto r = float_rounded;
    double perp[3] = {r(edge.x - p1_from_p3.x), r(edge.y - p1_from_p3.y), r(edge.z - p1_from_p3.z)};
    const double perp_length = r(std::sqrt(r(r(r(perp[0] * perp[0]) + r(perp[1] * perp[1])) + r(perp[2] * perp[2]))));
    const double perp_inverse = r(1.0 / perp_length);
    for (double& c : perp) c = r(c * perp_inverse);
    const double u_denominator = p1_from_p3.x * perp[0] + p1_from_p3.y * perp[1] + p1_from_p3.z * perp[2];
    const double scale = r(1.0 / r(-u_denominator));
    for (double& c : perp) c = r(c * scale);
    // The normal at the point: n1 at p1, blended toward the edge p2 p3 by u, along it by v.
    const Vec3 from_p1 = point - p1;
    const double u = from_p1.x * perp[0] + from_p1.y * perp[1] + from_p1.z * perp[2];
    if (u < 1e-10) return n1;
    const double k1 = p1[v_axis], k2 = p2[v_axis], k3 = p3[v_axis];
    const double v = (from_p1[v_axis] / u + k1 - k2) / (k3 - k2);
    return {n1.x + u * (n2.x - n1.x + v * (n3.x - n2.x)), n1.y + u * (n2.y - n1.y + v * (n3.y - n2.y)),
            n1.z + u * (n2.z - n1.z + v * (n3.z - n2.z))};
}

MeshAsPovray::MeshAsPovray(const TriangleMesh& mesh, Intersection rule) : decided(rule == Intersection::povray) {
    if (!decided || mesh.normals.empty()) return;
    normals.resize(mesh.normals.size());
    tbb::parallel_for(tbb::blocked_range<size_t>(0, mesh.normals.size() / 3, 8192),
                      [&](const tbb::blocked_range<size_t>& range) {
                          for (size_t i = range.begin(); i != range.end(); ++i) {
                              const float* n = &mesh.normals[3 * i];
                              const double x = n[0], y = n[1], z = n[2];
                              const double inverse = 1.0 / std::sqrt(x * x + y * y + z * z);
                              // Stored into floats: rounded whatever the vectoriser does.
                              normals[3 * i] = float(x * inverse);
                              normals[3 * i + 1] = float(y * inverse);
                              normals[3 * i + 2] = float(z * inverse);
                          }
                      });
}

bool MeshAsPovray::smooth_normal(const TriangleMesh& mesh, uint32_t prim, const Vec3& point, Convention convention,
                                 Vec3& out) const {
    if (!shaded_smooth(mesh, prim, convention)) return false;
    const uint32_t* index = &mesh.indices[3 * size_t(prim)];
    const auto as_read = [&](uint32_t i) {
        const float* n = &normals[3 * size_t(i)];
        return Vec3(n[0], n[1], n[2]);
    };
    const Vec3 blended =
        mesh2_smooth_normal(mesh.offset(index[0]), mesh.offset(index[1]), mesh.offset(index[2]), as_read(index[0]),
                            as_read(index[1]), as_read(index[2]), point - mesh.origin);
    const double len = length(blended);
    if (!(len > 0)) return false;
    out = blended / len;
    return true;
}

bool intersect_mesh2(const TriangleMesh& mesh, uint32_t prim, const Ray& ray, bool instanced, ShapeHit& hit) {
    const uint32_t* index = &mesh.indices[3 * size_t(prim)];
    const Vec3 p0 = mesh.offset(index[0]), p1 = mesh.offset(index[1]), p2 = mesh.offset(index[2]);
    const Vec3 origin = ray.origin - mesh.origin;
    double t = 0;
    bool inside = false;
    if (instanced) {
        const Vec3& d = ray.direction;
        const double len = std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
        const double inverse = 1.0 / len;
        if (!intersect_mesh2_triangle(p0, p1, p2, origin, {d.x * inverse, d.y * inverse, d.z * inverse}, t, inside))
            return false;
        t /= len;
    } else if (!intersect_mesh2_triangle(p0, p1, p2, origin, ray.direction, t, inside)) {
        return false;
    }
    if (!inside || !(t > ray.t_min && t < ray.t_max)) return false;
    const Vec3 v0 = mesh.vertex(index[0]), v1 = mesh.vertex(index[1]), v2 = mesh.vertex(index[2]);
    hit.t = t;
    hit.u = hit.v = 0;
    hit.normal = cross(v1 - v0, v2 - v0);
    return true;
}

}  // namespace whitted
