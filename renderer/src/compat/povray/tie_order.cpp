// SPDX-License-Identifier: MIT
#include "compat/povray/tie_order.h"

#include "compat/povray/box.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <iterator>
#include <utility>

#include <tbb/parallel_invoke.h>

// Written from POV-Ray 3.7's documented and observed behaviour and from reading what its
// bounding code computes (docs/pov-model.md §3, "Which of two equally near objects"); the
// arithmetic below is POV-Ray's, step for step, because a tie is settled by the exact order of
// equal or nearly equal distances. This file is built without FMA contraction (CMakeLists.txt):
// POV-Ray's Debian build has none, and a fused multiply-add rounds differently.

namespace whitted {
namespace {

constexpr double bound_huge = 2.0e10;     // POV-Ray's BOUND_HUGE: "no bound"
constexpr double critical_length = 1e6;   // a union box longer than this is taken as unbounded
constexpr double epsilon = 1e-10;         // an entry or exit nearer than this is behind the ray
constexpr double unbounded_depth = -1e7;  // the queue key of an unbounded object: first of all
constexpr size_t bunching = 4;            // at most this many children end the splitting
/// POV-Ray builds its hierarchy only from this many top-level objects on (lights count): its
/// Bounding_Threshold default, as its front end passes it.
constexpr size_t bounding_threshold = 3;

using Bounds = PovrayTestOrder::Bounds;

Bounds from_min_max(const double mins[3], const double maxs[3]) {
    Bounds b;
    for (int a = 0; a < 3; ++a) {
        b.lower[a] = float(mins[a]);
        b.length[a] = float(maxs[a] - mins[a]);
    }
    return b;
}

/// The box around several boxes, grown one at a time from each one's corner and far corner
/// (corner + size, in double): how POV-Ray encloses a union's children, a node's, and the items
/// either side of a split; or around points (a mesh2's vertices).
struct Around {
    double lo[3] = {bound_huge, bound_huge, bound_huge}, hi[3] = {-bound_huge, -bound_huge, -bound_huge};

    void add(const Bounds& b) {
        for (int a = 0; a < 3; ++a) {
            const double lower = double(b.lower[a]), upper = lower + double(b.length[a]);
            if (lower < lo[a]) lo[a] = lower;
            if (upper > hi[a]) hi[a] = upper;
        }
    }
    void add(const Vec3& point) {
        for (int a = 0; a < 3; ++a) {
            if (point[a] < lo[a]) lo[a] = point[a];
            if (point[a] > hi[a]) hi[a] = point[a];
        }
    }
    /// Half its surface area, the split cost's measure.
    double area() const {
        const double x = hi[0] - lo[0], y = hi[1] - lo[1], z = hi[2] - lo[2];
        return x * (y + z) + y * z;
    }
    Bounds bounds() const { return from_min_max(lo, hi); }
};

/// A transformed shape's box: its eight corners through the matrix, as POV-Ray multiplies a
/// point by its (row-vector) matrix, whose rows are our columns (pov_writer.cpp, `matrix`).
Bounds transformed(const Bounds& b, const Transform& to_world) {
    const auto& m = to_world.rows();
    double mins[3] = {bound_huge, bound_huge, bound_huge}, maxs[3] = {-bound_huge, -bound_huge, -bound_huge};
    for (int i = 1; i <= 8; ++i) {
        double corner[3];
        for (int a = 0; a < 3; ++a) corner[a] = double(b.lower[a]);
        corner[0] += (i & 1) ? double(b.length[0]) : 0.0;
        corner[1] += (i & 2) ? double(b.length[1]) : 0.0;
        corner[2] += (i & 4) ? double(b.length[2]) : 0.0;
        for (int k = 0; k < 3; ++k) {
            const double p = corner[0] * m[4 * k] + corner[1] * m[4 * k + 1] + corner[2] * m[4 * k + 2] + m[4 * k + 3];
            if (p < mins[k]) mins[k] = p;
            if (p > maxs[k]) maxs[k] = p;
        }
    }
    for (int a = 0; a < 3; ++a) {
        mins[a] = std::max(mins[a], -bound_huge / 2);
        maxs[a] = std::min(maxs[a], bound_huge / 2);
    }
    return from_min_max(mins, maxs);
}

Bounds sphere_bounds(const Vec3& center, double radius, const Transform* to_world) {
    Bounds b;
    for (int a = 0; a < 3; ++a) {
        b.lower[a] = float(center[a] - radius);
        b.length[a] = float(2.0 * radius);
    }
    return to_world ? transformed(b, *to_world) : b;
}

/// The union `whitted convert` writes for a box: the box and a radius-0 sphere at each of two
/// corners (povray_box_corners); a union's box holds its children's.
Bounds box_bounds(const Box& box) {
    Bounds inner;
    for (int a = 0; a < 3; ++a) {
        inner.lower[a] = float(box.min[a]);
        inner.length[a] = float(box.max[a] - box.min[a]);
    }
    if (box.object_to_world) inner = transformed(inner, *box.object_to_world);
    Vec3 lo, hi;
    povray_box_corners(transform_of(box.object_to_world), box.min, box.max, lo, hi);
    Around around;
    for (const Bounds& child : {inner, sphere_bounds(lo, 0, nullptr), sphere_bounds(hi, 0, nullptr)}) around.add(child);
    Bounds b = around.bounds();
    if (double(b.length[0]) > critical_length || double(b.length[1]) > critical_length ||
        double(b.length[2]) > critical_length) {
        for (int a = 0; a < 3; ++a) b.lower[a] = float(-bound_huge / 2), b.length[a] = float(bound_huge);
    }
    return b;
}

/// POV-Ray's boxes of the mesh2 objects `whitted convert` writes for `mesh`, one per material
/// in the order of the materials' numbers, appended to `out` (the writer orders an OBJ's pieces
/// by their MTL materials, which validate_scene numbers in the MTL file's order). A mesh2's box holds its
/// triangles' float vertices (POV-Ray's Mesh::Compute_BBox: the least and greatest coordinate
/// over its triangles), written about the mesh's centre, then moved there by `translate`,
/// which recomputes the box as any transform does.
void mesh_bounds(const TriangleMesh& mesh, std::vector<Bounds>& out) {
    // The converter writes the mesh2 about the point Whitted stores it about: its float offsets.
    const Vec3& centre = mesh.origin;
    std::vector<uint32_t> materials(mesh.triangle_materials);
    std::sort(materials.begin(), materials.end());
    materials.erase(std::unique(materials.begin(), materials.end()), materials.end());
    if (materials.empty()) materials.push_back(mesh.material);
    std::vector<Around> pieces(materials.size());
    for (size_t t = 0; t < mesh.triangle_count(); ++t) {
        const size_t piece =
            mesh.triangle_materials.empty()
                ? 0
                : size_t(std::lower_bound(materials.begin(), materials.end(), mesh.triangle_materials[t]) -
                         materials.begin());
        for (int k = 0; k < 3; ++k) pieces[piece].add(mesh.offset(mesh.indices[3 * t + k]));
    }
    for (const Around& piece : pieces) {
        Bounds b = piece.bounds();
        if (!(centre == Vec3(0.0))) b = transformed(b, Transform::translate(centre));
        out.push_back(b);
    }
}

/// POV-Ray's box of one piece of an instance as `whitted convert` writes it, `object { PIECE
/// matrix }`: the piece's box through the matrix. An instance of several pieces is a `union`
/// of them with the matrix on the union; POV-Ray splits such a union (no `split_union off`, no
/// `bounded_by`) and bounds each piece on its own, each moved by the matrix (CSG::Transform
/// transforms the children).
Bounds placed_bounds(const Bounds& piece, const Transform& to_world) {
    return to_world.is_identity() ? piece : transformed(piece, to_world);  // no `matrix` for the identity
}

/// The queue: a binary heap on entry distance, 1-based, with POV-Ray's sifting (which decides
/// the order of equal keys).
class Queue {
public:
    Queue() { m_items.reserve(64), m_items.emplace_back(); }
    bool empty() const { return m_items.size() == 1; }

    void insert(double depth, uint32_t node) {
        m_items.emplace_back();
        size_t i = m_items.size() - 1;
        while (i > 1 && depth < m_items[i / 2].first) {
            m_items[i] = m_items[i / 2];
            i /= 2;
        }
        m_items[i] = {depth, node};
    }

    std::pair<double, uint32_t> pop() {
        const std::pair<double, uint32_t> top = m_items[1];
        m_items[1] = m_items.back();
        m_items.pop_back();
        const size_t size = m_items.size() - 1;
        size_t i = 1;
        while (2 * i <= size) {
            const size_t j = (2 * i == size || m_items[2 * i].first < m_items[2 * i + 1].first) ? 2 * i : 2 * i + 1;
            if (!(m_items[i].first > m_items[j].first)) break;
            std::swap(m_items[i], m_items[j]);
            i = j;
        }
        return top;
    }

private:
    std::vector<std::pair<double, uint32_t>> m_items;
};

/// The ray as POV-Ray's box test holds it: origin and reciprocal direction in single precision.
struct SlabRay {
    float origin[3];
    float reciprocal[3];
    bool nonzero[3];
    bool positive[3];

    explicit SlabRay(const Ray& ray) {
        for (int a = 0; a < 3; ++a) {
            origin[a] = float(ray.origin[a]);
            const double d = ray.direction[a];
            nonzero[a] = d != 0.0;
            reciprocal[a] = nonzero[a] ? float(1.0 / d) : 0.0f;
            positive[a] = d > 0.0;
        }
    }

    /// Where the ray enters `b` (the queue key), or false where it misses it. The float
    /// products are POV-Ray's; so are the order of the axes and which comparisons it makes.
    bool entry(const Bounds& b, double& depth) const {
        double dmin, dmax;
        if (nonzero[0]) {
            const float near_plane = (b.lower[0] - origin[0]) * reciprocal[0];
            const float across = b.length[0] * reciprocal[0];
            if (positive[0]) {
                dmin = double(near_plane);
                dmax = dmin + double(across);
                if (dmax < epsilon) return false;
            } else {
                dmax = double(near_plane);
                if (dmax < epsilon) return false;
                dmin = dmax + double(across);
            }
            if (dmin > dmax) return false;
        } else {
            if (origin[0] < b.lower[0] || origin[0] > b.length[0] + b.lower[0]) return false;
            dmin = -bound_huge;
            dmax = bound_huge;
        }
        for (int a = 1; a < 3; ++a) {
            if (!nonzero[a]) {
                if (origin[a] < b.lower[a] || origin[a] > b.length[a] + b.lower[a]) return false;
                continue;
            }
            const double lower_plane = double((b.lower[a] - origin[a]) * reciprocal[a]);  // a float product
            const double across = double(b.length[a] * reciprocal[a]);
            double tmin, tmax;
            if (positive[a]) {
                tmin = lower_plane;
                tmax = tmin + across;
            } else {
                tmax = lower_plane;
                tmin = tmax + across;
            }
            if (tmax < dmax) {
                if (tmax < epsilon) return false;
                if (tmin > dmin) {
                    if (tmin > tmax) return false;
                    dmin = tmin;
                } else if (dmin > tmax) {
                    return false;
                }
                dmax = tmax;
            } else if (tmin > dmin) {
                if (tmin > dmax) return false;
                dmin = tmin;
            }
        }
        depth = dmin;
        return true;
    }
};

}  // namespace

void povray_box_corners(const Transform& to_world, const Vec3& min, const Vec3& max, Vec3& lo, Vec3& hi) {
    world_bounds(to_world, min, max, lo, hi);
    double scale = 0;
    for (int a = 0; a < 3; ++a) scale = std::max({scale, std::fabs(lo[a]), std::fabs(hi[a]), hi[a] - lo[a]});
    const Vec3 pad(std::ldexp(scale, -20) + 1e-30);  // 2^-20: 8 to 16 floats' spacing at `scale`
    lo -= pad;
    hi += pad;
}

PovrayTestOrder::PovrayTestOrder(const Scene& scene) : m_scene(scene) {
    // The converted scene's order: every object where the scene file has it (Scene::objects).
    const size_t spheres = scene.spheres.size(), boxes = scene.boxes.size();
    // POV-Ray's box of each mesh object of the converted scene, until the leaves hold them.
    std::vector<Bounds> mesh_boxes;
    {
        // Each kind is already in file order: merge the three lists by object number.
        std::vector<std::pair<uint32_t, uint32_t>> by_object, kind, merged;  // (object, shape)
        for (size_t i = 0; i < spheres; ++i) by_object.emplace_back(scene.spheres[i].object, uint32_t(i));
        for (size_t i = 0; i < boxes; ++i) kind.emplace_back(scene.boxes[i].object, uint32_t(spheres + i));
        std::merge(by_object.begin(), by_object.end(), kind.begin(), kind.end(), std::back_inserter(merged));
        by_object.swap(merged);
        kind.clear(), merged.clear();
        for (size_t i = 0; i < scene.planes.size(); ++i)
            kind.emplace_back(scene.planes[i].object, uint32_t(spheres + boxes + i));
        std::merge(by_object.begin(), by_object.end(), kind.begin(), kind.end(), std::back_inserter(merged));
        // Then the mesh objects, each after the planes (its pieces numbered in their order).
        const uint32_t first_mesh = uint32_t(spheres + boxes + scene.planes.size());
        for (const TriangleMesh& mesh : scene.meshes) {
            const size_t before = mesh_boxes.size();
            mesh_bounds(mesh, mesh_boxes);
            for (size_t k = before; k < mesh_boxes.size(); ++k)
                merged.emplace_back(mesh.object, uint32_t(first_mesh + k));
        }
        std::vector<std::vector<Bounds>> prototype_pieces(scene.prototypes.size());
        for (size_t p = 0; p < scene.prototypes.size(); ++p)
            for (const TriangleMesh& mesh : scene.prototypes[p].meshes) mesh_bounds(mesh, prototype_pieces[p]);
        for (const Instance& instance : scene.instances) {
            for (const Bounds& piece : prototype_pieces[instance.prototype]) {
                merged.emplace_back(instance.object, uint32_t(first_mesh + mesh_boxes.size()));
                mesh_boxes.push_back(placed_bounds(piece, instance.object_to_world));
            }
        }
        if (!std::is_sorted(merged.begin(), merged.end())) std::sort(merged.begin(), merged.end());
        m_order.reserve(merged.size());
        for (const auto& [object, shape] : merged) m_order.push_back(shape);
    }
    if (scene.lights.size() + m_order.size() < bounding_threshold) {
        m_linear = true;
        return;
    }
    std::vector<Item> finite;
    std::vector<uint32_t> infinite;
    // Each pass adds a node per four items or so: room for all of them from the start.
    finite.reserve(m_order.size() + m_order.size() / 2 + 16);
    m_nodes.reserve(m_order.size() + m_order.size() / 2 + 16);
    m_children.reserve(m_order.size() + m_order.size() / 2 + 16);
    for (uint32_t shape : m_order) {
        Node leaf;
        leaf.shape = shape;
        if (shape < spheres) {
            const Sphere& s = scene.spheres[shape];
            leaf.bounds = sphere_bounds(s.center, s.radius, s.object_to_world.get());
        } else if (shape < spheres + boxes) {
            leaf.bounds = box_bounds(scene.boxes[shape - spheres]);
        } else if (shape < spheres + boxes + scene.planes.size()) {
            leaf.infinite = true;
        } else {
            leaf.bounds = mesh_boxes[shape - (spheres + boxes + scene.planes.size())];
        }
        if (leaf.infinite)
            infinite.push_back(uint32_t(m_nodes.size()));
        else
            finite.push_back({leaf.bounds, uint32_t(m_nodes.size())});
        m_nodes.push_back(leaf);
    }
    std::vector<uint32_t>().swap(m_order);  // only the order without a hierarchy needs it
    build(finite, infinite);
}

void PovrayTestOrder::build(std::vector<Item>& finite, const std::vector<uint32_t>& infinite) {
    if (finite.empty()) {
        // Only planes: no sphere or box to order (nearest finds none).
        m_linear = true;
        return;
    }
    // Pass after pass: each splits its items into groups of a few, which become the next
    // pass's items, until one pass makes a single group, the root.
    size_t low = 0, high = finite.size();
    while (!sort_and_split(finite, low, high)) {
        low = high;
        high = finite.size();
    }
    m_root = finite.back().node;
    if (infinite.empty()) return;
    // The unbounded objects become the root's first child.
    Node unbounded;
    unbounded.infinite = true;
    unbounded.first_child = uint32_t(m_children.size());
    unbounded.child_count = uint32_t(infinite.size());
    m_children.insert(m_children.end(), infinite.begin(), infinite.end());
    const uint32_t unbounded_id = uint32_t(m_nodes.size());
    m_nodes.push_back(unbounded);
    Node& root = m_nodes[m_root];
    const uint32_t first = uint32_t(m_children.size());
    m_children.push_back(unbounded_id);
    for (uint32_t c = 0; c < root.child_count; ++c) m_children.push_back(m_children[root.first_child + c]);
    root.first_child = first;
    root.child_count += 1;
    root.infinite = true;
}

PovrayTestOrder::Item PovrayTestOrder::make_parent(const std::vector<Item>& items, size_t first, size_t last) {
    Node parent;
    parent.first_child = uint32_t(m_children.size());
    parent.child_count = uint32_t(last - first);
    Around around;
    for (size_t i = first; i < last; ++i) {
        m_children.push_back(items[i].node);
        around.add(items[i].bounds);
    }
    parent.bounds = around.bounds();
    m_nodes.push_back(parent);
    return {parent.bounds, uint32_t(m_nodes.size() - 1)};
}

namespace {

/// A float's order as an unsigned integer, −0 and +0 alike (they compare equal).
uint32_t sortable(float f) {
    if (f == 0.0f) f = 0.0f;
    uint32_t bits;
    std::memcpy(&bits, &f, sizeof bits);
    return (bits & 0x80000000u) ? ~bits : (bits | 0x80000000u);
}

}  // namespace

/// One pass over [first, last): sorts each range by centre along the axis its corners spread
/// most and splits it where the items times the surface area of each side sum least, or keeps
/// it as a group (few items, or no split pays). The groups come out depth first, left before
/// right, the order in which POV-Ray's recursion makes its nodes; here a stack of its own does
/// the small ranges (a skewed scene may split a million times), and ranges large on both sides
/// are split on two threads, each side's groups then joined in order.
void PovrayTestOrder::split(std::vector<Item>& finite, size_t first, size_t last, std::vector<Range>& groups,
                            Scratch& scratch) {
    std::vector<Range> todo{{first, last}};
    auto& [area_right, keys, keys_scratch, items_scratch] = scratch;
    while (!todo.empty()) {
        // Plain variables, not a structured binding: lambdas below capture them (clang 14).
        const size_t f = todo.back().first, l = todo.back().last;
        todo.pop_back();
        const size_t size = l - f;
        if (size == 0) {
            groups.push_back({f, l});
            continue;
        }
        // The axis: POV-Ray takes the spread of the items' lower corners against the largest
        // lower corner among those whose upper corner set a new maximum.
        double mins[3] = {bound_huge, bound_huge, bound_huge}, maxs[3] = {-bound_huge, -bound_huge, -bound_huge};
        for (size_t i = f; i < l; ++i) {
            const Bounds& b = finite[i].bounds;
            for (int a = 0; a < 3; ++a) {
                if (double(b.lower[a]) < mins[a]) mins[a] = double(b.lower[a]);
                const float upper = b.lower[a] + b.length[a];  // in float, as POV-Ray adds them
                if (double(upper) > maxs[a]) maxs[a] = double(b.lower[a]);
            }
        }
        int axis = 0;
        double spread = -bound_huge;
        for (int a = 0; a < 3; ++a)
            if (maxs[a] - mins[a] > spread) spread = maxs[a] - mins[a], axis = a;
        // A stable sort by centre (2·corner + size, rounded to float): glibc's qsort, which
        // POV-Ray calls, merges (Debian 12's glibc 2.36), and equal centres (a grid) keep their
        // order. Here a radix sort of the centre's bits above the range's position: as stable,
        // and linear, so that a million boxes take a fraction of a second.
        const auto centre = [axis](const Bounds& b) {
            return float(2.0 * double(b.lower[axis]) + double(b.length[axis]));
        };
        if (size <= 64) {
            std::stable_sort(finite.begin() + std::ptrdiff_t(f), finite.begin() + std::ptrdiff_t(l),
                             [&](const Item& a, const Item& b) { return centre(a.bounds) < centre(b.bounds); });
        } else {
            keys.resize(size);
            keys_scratch.resize(size);
            for (size_t i = 0; i < size; ++i) keys[i] = (uint64_t(sortable(centre(finite[f + i].bounds))) << 32) | i;
            for (int shift = 32; shift < 64; shift += 11) {
                constexpr size_t digits = 2048;
                size_t count[digits] = {};
                for (uint64_t k : keys) ++count[(k >> shift) & (digits - 1)];
                if (count[(keys[0] >> shift) & (digits - 1)] == size) continue;  // one digit: in order
                size_t at = 0;
                for (size_t& c : count) {
                    const size_t n = c;
                    c = at;
                    at += n;
                }
                for (uint64_t k : keys) keys_scratch[count[(k >> shift) & (digits - 1)]++] = k;
                keys.swap(keys_scratch);
            }
            items_scratch.resize(size);
            for (size_t i = 0; i < size; ++i) items_scratch[i] = finite[f + (keys[i] & 0xffffffffu)];
            std::copy(items_scratch.begin(), items_scratch.end(), finite.begin() + std::ptrdiff_t(f));
        }
        // The surface area of the box around the items from i on (area_right), then, sweeping
        // from the left, around those up to i: a split after i costs (i + 1) · left + the rest
        // · right.
        area_right.resize(size);
        Around right_of;
        for (size_t i = size; i-- > 0;) {
            right_of.add(finite[f + i].bounds);
            area_right[i] = right_of.area();
        }
        double best = area_right[0] * (double(size) - 3.0);
        std::ptrdiff_t best_at = -1;
        Around left_of;
        for (size_t i = 0; i + 1 < size; ++i) {
            left_of.add(finite[f + i].bounds);
            const double cost = double(i + 1) * left_of.area() + double(size - 1 - i) * area_right[i + 1];
            if (cost < best) best = cost, best_at = std::ptrdiff_t(i + f);
        }
        if (size <= bunching || best_at < 0) {
            groups.push_back({f, l});
            continue;
        }
        const size_t middle = size_t(best_at) + 1;
        constexpr size_t worth_a_thread = 16384;
        if (middle - f >= worth_a_thread && l - middle >= worth_a_thread) {
            // The left side takes this range's scratch (idle until both sides are done).
            std::vector<Range> left, right;
            Scratch own;
            tbb::parallel_invoke([&] { split(finite, f, middle, left, scratch); },
                                 [&] { split(finite, middle, l, right, own); });
            groups.insert(groups.end(), left.begin(), left.end());
            groups.insert(groups.end(), right.begin(), right.end());
            continue;
        }
        todo.push_back({middle, l});
        todo.push_back({f, middle});
    }
}

/// One pass: the groups of [first, last) become nodes, appended to the list in the order
/// made. True when the whole range is one group (the pass made the root).
bool PovrayTestOrder::sort_and_split(std::vector<Item>& finite, size_t first, size_t last) {
    std::vector<Range> groups;
    Scratch scratch;  // reused from range to range, let go after the pass
    split(finite, first, last, groups, scratch);
    for (const Range& group : groups) finite.push_back(make_parent(finite, group.first, group.last));
    return groups.size() == 1 && groups[0].first == first && groups[0].last == last;
}

bool PovrayTestOrder::test(const Ray& ray, uint32_t shape, ShapeHit& hit) const {
    const size_t spheres = m_scene.spheres.size();
    if (shape < spheres) return intersect_sphere(m_scene.spheres[shape], ray, ray.t_min, ray.t_max, hit);
    if (shape < spheres + m_scene.boxes.size())
        return intersect_box_as_povray(m_scene.boxes[shape - spheres], ray, ray.t_min, ray.t_max, hit);
    return false;  // a plane (finish_hit weighs planes) or a mesh: not a candidate here
}

bool PovrayTestOrder::nearest(const Ray& ray, Found& out, double nearest_t) const {
    double best = bound_huge;
    bool found = false;
    // Whether the hit is known to be nearest: nothing tested later can take its place.
    const auto consider = [&](uint32_t shape) {
        ShapeHit hit;
        if (!test(ray, shape, hit) || !(hit.t < best)) return false;
        best = hit.t;
        found = true;
        out.sphere = shape < m_scene.spheres.size();
        out.index = out.sphere ? shape : uint32_t(shape - m_scene.spheres.size());
        out.hit = hit;
        return hit.t == nearest_t;
    };
    if (m_linear) {
        for (uint32_t shape : m_order)
            if (consider(shape)) break;
        return found;
    }
    const SlabRay slab(ray);
    Queue queue;
    const auto enqueue = [&](uint32_t id) {
        const Node& node = m_nodes[id];
        double depth = unbounded_depth;
        if (!node.infinite && !slab.entry(node.bounds, depth)) return;
        queue.insert(depth, id);
    };
    enqueue(m_root);
    while (!queue.empty()) {
        const auto [depth, id] = queue.pop();
        // Every box still queued is entered beyond the nearest hit so far.
        if (depth > best) break;
        const Node& node = m_nodes[id];
        if (node.child_count)
            for (uint32_t c = 0; c < node.child_count; ++c) enqueue(m_children[node.first_child + c]);
        else if (consider(node.shape))
            break;
    }
    return found;
}

}  // namespace whitted
