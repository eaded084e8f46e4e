// SPDX-License-Identifier: MIT
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "core/ray.h"
#include "geometry/shapes.h"
#include "scene/scene.h"

namespace whitted {

/// The order in which POV-Ray 3.7 tests a scene's spheres and boxes along a ray, to settle
/// exact ties as it does. Two overlapping boxes whose tops lie in one plane (a field of equal
/// cubes) are met at the very same t; POV-Ray keeps the first object its traversal tests and
/// Embree's own order is another, so the two renderers showed different boxes on 9 % of such
/// a field's pixels (docs/pov-model.md §3, "Which of two equally near objects").
///
/// POV-Ray's order comes from its bounding hierarchy ("bounding slabs") and a priority queue
/// of the boxes' entry distances. Both are rebuilt here, as POV-Ray builds them from the scene
/// `whitted convert` writes (each box in a union with two corner spheres, pov_writer.cpp), in
/// the same arithmetic (single-precision bounding boxes, the same sorts and splits). Only the
/// rays with a tie are traced through it (the accelerator finds them), so a scene without ties
/// never builds it.
///
/// Meshes and instances take their places in the hierarchy with the bounding boxes POV-Ray
/// gives the mesh2 objects (and their unions) that `whitted convert` writes, so the spheres
/// and boxes among them are met in POV-Ray's order; a mesh itself is never a candidate here
/// (an exact tie with a triangle keeps Embree's order).
class PovrayTestOrder {
public:
    explicit PovrayTestOrder(const Scene& scene);

    /// The sphere or box POV-Ray shows on `ray`: the nearest hit in (t_min, t_max), and of
    /// equally near ones the first POV-Ray tests. Planes are not among the candidates (they
    /// take a tie anyway: POV-Ray tests unbounded objects first). False when none is hit.
    struct Found {
        bool sphere = false;  ///< else a box
        uint32_t index = 0;   ///< in Scene::spheres or Scene::boxes
        ShapeHit hit;
    };
    /// `nearest_t`, where the caller knows the nearest hit's t: the search ends at the first
    /// shape met there (POV-Ray would keep it), without going on to prove it nearest.
    bool nearest(const Ray& ray, Found& out, double nearest_t = -1) const;

    /// POV-Ray's bounding box of a shape or node: a single-precision corner and size.
    struct Bounds {
        float lower[3] = {0, 0, 0};
        float length[3] = {0, 0, 0};
    };

private:
    struct Node {
        Bounds bounds;
        bool infinite = false;
        uint32_t first_child = 0;  ///< in m_children
        uint32_t child_count = 0;  ///< 0: a leaf
        /// A leaf's shape: spheres first, then boxes (index − spheres.size()), then planes, then
        /// the converted scene's mesh objects (a mesh2 per material of a mesh; per instance one
        /// per mesh2 of its prototype, POV-Ray splitting their union).
        uint32_t shape = 0;
    };

    /// An entry of the list being split: a node and (a copy of) its box, side by side so that
    /// the sorts and sweeps over a million of them read memory in order.
    struct Item {
        Bounds bounds;
        uint32_t node = 0;
    };

    struct Range {
        size_t first = 0, last = 0;
    };

    void build(std::vector<Item>& finite, const std::vector<uint32_t>& infinite);
    bool sort_and_split(std::vector<Item>& finite, size_t first, size_t last);
    /// split's working memory: the surface areas to the right, the sort keys, the sorted items.
    struct Scratch {
        std::vector<double> area_right;
        std::vector<uint64_t> keys, keys_scratch;
        std::vector<Item> items_scratch;
    };
    static void split(std::vector<Item>& finite, size_t first, size_t last, std::vector<Range>& groups,
                      Scratch& scratch);
    Item make_parent(const std::vector<Item>& items, size_t first, size_t last);
    bool test(const Ray& ray, uint32_t shape, ShapeHit& hit) const;

    const Scene& m_scene;
    bool m_linear = false;  ///< too few objects: POV-Ray tests them in order, without a hierarchy
    std::vector<Node> m_nodes;
    std::vector<uint32_t> m_children;
    std::vector<uint32_t> m_order;  ///< shapes in the order of the converted scene (m_linear only)
    uint32_t m_root = 0;
};

/// Under POV-Ray's rules, a sphere or box met at exactly the t of the sphere or box held, the
/// two looking different (another material or normal): whether the candidate takes the held
/// one's place. A plain face at the same t replaces a face the edge rule chose
/// (ShapeHit::edge_tie: a ray along one box's edge, inside another's top), POV-Ray then testing
/// the other box first, its bounding box being met earlier (bench/generate.py --boxes 1000000,
/// row 383). Where that is the only difference (one material) the rule decides; otherwise
/// `order_decides` is set, and PovrayTestOrder says which shows (the accelerator's finish_hit).
/// Building that order costs a million equal cubes 0.6 s, which ties of one material whose
/// faces differ only by the edge rule need not pay.
inline bool povray_tie_replaces(bool same_material, bool held_edge_tie, bool candidate_edge_tie, bool& order_decides) {
    if (!(same_material && candidate_edge_tie != held_edge_tie)) order_decides = true;
    return held_edge_tie && !candidate_edge_tie;
}

/// The two radius-0 spheres `whitted convert` places at a box's corners so that POV-Ray's
/// single-precision bounding box of the union holds the whole box (pov_writer.cpp): the world
/// bounds pushed out by 8 to 16 floats' spacing.
void povray_box_corners(const Transform& to_world, const Vec3& min, const Vec3& max, Vec3& lo, Vec3& hi);

}  // namespace whitted
