// SPDX-License-Identifier: MIT
#pragma once

// The validated, renderable scene: every value checked, every transform folded into world
// space where that is exact (triangles, planes), kept beside the shape where it is not
// (spheres, boxes and cones stay analytic in their own space).

#include "core/transform.h"
#include "core/vec3.h"
#include "scene/description.h"

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace whitted {

/// The lecture's material, a plain struct of coefficients (colours are per channel).
struct Material {
    Color ka;      ///< ambient
    Color kd;      ///< diffuse (Lambert)
    Color ks;      ///< specular
    double p = 1;  ///< specular exponent
    Color km;      ///< mirror
    Highlight highlight = Highlight::blinn;
    /// Schlick's R0 = ((η−1)/(η+1))² when the material has `fresnel_ior`, else negative: km is
    /// then the mirror weight, unscaled.
    double fresnel_r0 = -1;
    Color kt = Color(0.0);  ///< transmission: the weight of the refracted ray (Whitted 1980)
    double ior = 1;         ///< index of refraction inside the surface
};

struct Camera {
    CameraType type = CameraType::perspective;
    Vec3 eye;
    Vec3 forward;  ///< unit view direction
    Vec3 right;    ///< scaled: screen x in [-0.5, 0.5] maps to ±right/2
    Vec3 up;       ///< scaled like right, for screen y
};

struct Light {
    LightType type = LightType::point;
    Vec3 position;      ///< point lights
    Vec3 toward_light;  ///< directional lights: unit l, minus the travel direction
    Color intensity;
};

/// An object-to-world transform held by reference, null for the identity: most spheres and boxes
/// have none, and a scene of a million spheres should not carry a million 200-byte identities
/// (docs/performance.md, "Reading large scenes").
using SharedTransform = std::shared_ptr<const Transform>;

/// The transform a SharedTransform stands for.
inline const Transform& transform_of(const SharedTransform& transform) {
    static const Transform identity;
    return transform ? *transform : identity;
}

struct Sphere {
    SharedTransform object_to_world;  ///< null (the identity) for most spheres
    Vec3 center;
    double radius = 1;
    uint32_t material = 0;
    uint32_t object = 0;  ///< Scene::objects index + 1
};

struct Box {
    SharedTransform object_to_world;  ///< null: the identity
    Vec3 min, max;
    uint32_t material = 0;
    uint32_t object = 0;  ///< Scene::objects index + 1
};

/// A cylinder or cone (docs/scene-format.md §3.9): the side joining a disc of base_radius at
/// `base` to a disc of cap_radius at `base + height·axis`, with those discs as caps unless
/// `open`. A cylinder is a cone with equal radii.
struct Cone {
    SharedTransform object_to_world;  ///< null: the identity
    Vec3 base;
    Vec3 axis;  ///< unit, from the base toward the cap
    double height = 1;
    double base_radius = 1, cap_radius = 1;
    bool open = false;
    uint32_t material = 0;
    uint32_t object = 0;  ///< Scene::objects index + 1
};

struct Plane {
    Vec3 point;
    Vec3 normal;  ///< unit
    uint32_t material = 0;
    uint32_t object = 0;  ///< Scene::objects index + 1
};

/// The point a mesh whose vertices (world space, double) span [lo, hi] is stored about
/// (TriangleMesh::origin): the centre of its bounds when that lies further from the origin than
/// the mesh's half extent, else the origin itself (whose floats then hold each coordinate to
/// 2^-24 of the mesh's own size already). So a mesh keeps float's precision relative to its own
/// size wherever it stands and at any scale. `whitted convert` writes each mesh2 about the same
/// point, so that POV-Ray reads the same float triangles.
inline Vec3 mesh_origin(const Vec3& lo, const Vec3& hi) {
    if (!(lo.x <= hi.x)) return Vec3(0.0);  // no vertices
    const Vec3 centre = (lo + hi) * 0.5, half = (hi - lo) * 0.5;
    const double far = std::max({std::fabs(centre.x), std::fabs(centre.y), std::fabs(centre.z)});
    return far > std::max({half.x, half.y, half.z}) ? centre : Vec3(0.0);
}

/// Triangles in world space: each vertex is `origin` (double) plus a float offset, stored as
/// Embree wants them (xyz + padding). The origin is the centre of the mesh's bounds, or the
/// world's origin for a mesh around it, so that the floats keep precision relative to the mesh's
/// own size wherever it stands (mesh_origin); hits are computed in double from these vertices
/// (vertex()).
struct TriangleMesh {
    Vec3 origin;
    std::vector<float> positions;              ///< 4 floats per vertex (x, y, z, unused): offsets from `origin`
    std::vector<uint32_t> indices;             ///< 3 per triangle
    std::vector<float> normals;                ///< empty, or 3 floats per vertex: smooth shading
    std::vector<uint32_t> triangle_materials;  ///< empty when every triangle uses `material`
    uint32_t material = 0;
    uint32_t object = 0;  ///< Scene::objects index + 1 (one object per mesh or triangle)
    size_t triangle_count() const { return indices.size() / 3; }
    size_t vertex_count() const { return positions.size() / 4; }
    /// Vertex `index` as its float offset from `origin`.
    Vec3 offset(size_t index) const {
        const float* p = &positions[4 * index];
        return {p[0], p[1], p[2]};
    }
    /// Vertex `index` in world space (a prototype's mesh: in the prototype's space).
    Vec3 vertex(size_t index) const { return origin + offset(index); }
};

/// A prototype (docs/scene-format.md §3.8): triangles in a space of their own, stored once and
/// shared by all its instances (Embree builds one BVH for it). A mesh whose `material` is
/// no_material takes each instance's.
struct Prototype {
    std::string name;
    std::vector<TriangleMesh> meshes;  ///< in the prototype's space; TriangleMesh::object is unused (0)
    Vec3 lo, hi;                       ///< bounds of the vertices, prototype space
};

/// One placement of a prototype: its transform and, if the instance names one, the material
/// that replaces every material of the prototype's triangles.
struct Instance {
    static constexpr uint32_t no_material = 0xFFFFFFFFu;
    Transform object_to_world;
    uint32_t prototype = 0;           ///< Scene::prototypes index
    uint32_t material = no_material;  ///< the override, or no_material: the prototype's own
    uint32_t object = 0;              ///< Scene::objects index + 1
};

/// A shape as the scene file wrote it: sphere, plane, box, triangle or mesh (groups are not
/// objects; their members are; an instance is one object, whatever its prototype holds). Numbered 1, 2, ... in file
/// order, depth first through groups: the `objectId` layer and `whitted explain` use these numbers (0 = nothing hit).
struct SceneObject {
    ObjectType type = ObjectType::sphere;
    SourceLocation where;
};

struct Scene {
    std::string path;
    int width = 0, height = 0;
    int samples = 1;
    int max_depth = 5;
    Convention convention = Convention::pov;
    double min_weight = 0;  ///< mirror rays whose path weight (largest channel) is below it are not traced
    Intersection intersection = Intersection::exact;  ///< render.intersection (description.h)
    Color background;
    Color ambient;  ///< I_a
    Camera camera;
    std::vector<Light> lights;
    std::vector<Material> materials;          ///< named ones in file order, then inline and MTL ones as met
    std::vector<std::string> material_names;  ///< per material: as in `materials` or the MTL; "" inline
    std::vector<SceneObject> objects;
    std::vector<std::string> layers;  ///< render.layers: the EXR layers asked for (docs/layers.md)
    std::vector<Sphere> spheres;
    std::vector<Box> boxes;
    std::vector<Cone> cones;  ///< cylinders and cones
    std::vector<Plane> planes;
    std::vector<TriangleMesh> meshes;
    std::vector<std::string> mesh_files;  ///< the mesh files read, as resolved paths
    std::vector<Prototype> prototypes;
    std::vector<Instance> instances;

    /// Triangles stored: each prototype's once, however many instances place it.
    size_t triangle_count() const;
    /// Triangles as seen: each instance counts its prototype's triangles.
    size_t instanced_triangle_count() const;
};

/// Checks every value of a description and builds the scene (loading mesh files). Throws
/// InputError naming file:line:col for anything out of range.
Scene validate_scene(const SceneDescription& description);

/// Settings given from outside the file (`whitted render --width ...`, api::SceneOverrides). Each
/// replaces the file's value before anything is checked, so the file's limits hold for it; its
/// place in messages is `where` (the option's name). A width without a height (or the other way
/// round) keeps the scene's aspect ratio, the other side rounded to the nearest pixel.
struct SettingOverrides {
    std::optional<int64_t> width, height, samples, max_depth;
    std::optional<Intersection> intersection;
    std::string where = "<overrides>";
};
void apply_overrides(const SettingOverrides& overrides, SceneDescription& description);

/// parse_scene_file and validate_scene in one pass: each top-level object is validated as soon as
/// it is parsed and its description let go, so that a file of a million spheres never holds a
/// million descriptions (docs/performance.md, "Reading large scenes"). The same checks, the same
/// mistake reported, the same Scene as validate_scene(parse_scene_file(path)). `settings`, if
/// given, receives the description without its objects.
/// `overrides` replace settings of the file before they are checked.
Scene load_scene_file(const std::string& path, SceneDescription* settings = nullptr,
                      const SettingOverrides& overrides = {});
/// Same, from text already in memory, in the format its name's extension says (.nff, .xml), else
/// the one its first line says (scene_format_of_text).
Scene load_scene_text(std::string_view text, const std::string& path, SceneDescription* settings = nullptr,
                      const SettingOverrides& overrides = {});

/// Builds the camera's basis from its description (also used by the converters' tests).
Camera make_camera(const CameraDescription& camera, int width, int height);

/// The object-to-world transform of a list of steps (applied in list order).
Transform make_transform(const std::vector<TransformStep>& steps);

}  // namespace whitted
