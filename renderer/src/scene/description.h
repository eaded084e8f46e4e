// SPDX-License-Identifier: MIT
#pragma once

// The plain scene description: what the scene file says, value by value, each with the place
// it was written. Parsing produces it; validation turns it into a renderable Scene; converters
// (POV-Ray, ...) read it directly, never the render objects. Defaults of scene format v1 are
// filled in here, so a reader never has to know them.

#include "core/vec3.h"
#include "scene/source_location.h"

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <type_traits>
#include <variant>
#include <vector>

namespace whitted {

/// A value and where it was written (`where` is the enclosing map's location for a default).
template <class T>
struct Located {
    Located() = default;
    Located(T v) : value(std::move(v)) {}  // NOLINT: implicit, so defaults read like `{45.0}`

    T value{};
    SourceLocation where;
    bool given = false;  ///< written in the file, rather than defaulted
};

/// An optional value kept on the heap: 8 bytes in every object of the description, where a
/// std::optional<T> would take all of sizeof(T) in each, set or not (a scene may have millions of
/// objects and few inline materials). Reads like std::optional.
template <class T>
class Boxed {
public:
    Boxed() = default;
    Boxed(const Boxed& other) : m_value(other.m_value ? std::make_unique<T>(*other.m_value) : nullptr) {}
    Boxed(Boxed&&) noexcept = default;
    Boxed& operator=(const Boxed& other) {
        if (this != &other) m_value = other.m_value ? std::make_unique<T>(*other.m_value) : nullptr;
        return *this;
    }
    Boxed& operator=(Boxed&&) noexcept = default;
    Boxed& operator=(T value) {
        m_value = std::make_unique<T>(std::move(value));
        return *this;
    }
    explicit operator bool() const { return m_value != nullptr; }
    bool has_value() const { return m_value != nullptr; }
    const T& operator*() const { return *m_value; }
    T& operator*() { return *m_value; }
    const T* operator->() const { return m_value.get(); }
    T* operator->() { return m_value.get(); }

private:
    std::unique_ptr<T> m_value;
};

enum class CameraType { perspective, orthographic };
enum class LightType { point, directional };
enum class Highlight { blinn, phong };
/// Shading conventions (docs/scene-format.md §2.3): `pov` is POV-Ray 3.7's, the default;
/// `course` the Cornell CS4620 ray tracer's (normals as given, its shadow-ray span, no n·l gate
/// on the highlight).
enum class Convention { pov, course };
/// How a ray's nearest surface is decided (docs/scene-format.md §2.3, `render.intersection`).
/// `exact`, the default: in double from the scene's own numbers, watertight, and a tie at exactly
/// one distance goes to the object first in the file, whatever order the BVH meets them in.
/// `povray`: POV-Ray 3.7's own decisions where they differ from the exact answer (its float
/// mesh2 triangle test and smooth normals, its box edge and depth constants, its test order for
/// tied spheres and boxes, a plane keeping a tie within an ulp), which `whitted check` selects so
/// that the two renderers agree pixel by pixel (renderer/src/compat/povray.h).
enum class Intersection { exact, povray };

struct CameraDescription {
    SourceLocation where;
    Located<CameraType> type{CameraType::perspective};
    Located<Vec3> eye;
    Located<Vec3> look_at;
    Located<Vec3> up{Vec3{0, 1, 0}};
    Located<double> fov{45.0};        ///< horizontal, degrees (perspective)
    Located<double> view_width{0.0};  ///< world units (orthographic; perspective with a window)
    // The image-plane window (docs/scene-format.md §2.1): a perspective camera with
    // `view_height` aims its rays through a view_width × view_height rectangle centred
    // projection_distance along the view direction, on a plane perpendicular to
    // image_plane_normal (default: the view direction itself).
    Located<double> view_height{0.0};
    Located<double> projection_distance{1.0};
    Located<Vec3> image_plane_normal;  ///< `given` = false: perpendicular to the view direction
};

struct ImageDescription {
    SourceLocation where;
    Located<int64_t> width;
    Located<int64_t> height;
    Located<Color> background{Color{0.0}};
    Located<int64_t> samples{1};
};

struct LightDescription {
    SourceLocation where;
    LightType type = LightType::point;
    Located<Vec3> position;   ///< point lights
    Located<Vec3> direction;  ///< directional lights: the way the light travels
    Located<Color> intensity{Color{1.0}};
};

/// The lecture's material: L = ka·Ia + Σ[kd·I·(n·l) + ks·I·(n·h)^p] + km·L(r).
struct MaterialDescription {
    SourceLocation where;
    std::string name;  ///< empty for an inline material
    Located<Color> ka{Color{0.0}};
    Located<Color> kd{Color{0.0}};
    Located<Color> ks{Color{0.0}};
    Located<double> p{1.0};
    Located<Color> km{Color{0.0}};
    Located<Highlight> highlight{Highlight::blinn};
    /// Given: the mirror weight is Schlick's Fresnel factor F for this index of refraction
    /// instead of km, and the other terms are weighted by 1 − F (the course's "Glazed").
    Located<double> fresnel_ior{0.0};
    /// Transmission: the weight of the refracted ray, L gains kt·L(t) (Whitted 1980).
    Located<Color> kt{Color{0.0}};
    /// The index of refraction inside the surface (outside: 1), for the refracted ray.
    Located<double> ior{1.0};
};

/// `material:` on an object: a name from `materials`, or an inline map.
struct MaterialReference {
    SourceLocation where;
    std::string name;                    ///< set for a reference by name
    Boxed<MaterialDescription> inline_;  ///< set for an inline material
};

struct TransformStep {
    enum class Kind { scale, rotate, translate, matrix };
    SourceLocation where;
    Kind kind = Kind::translate;
    Vec3 vector;                      ///< scale factors, rotation axis or translation
    double angle = 0;                 ///< rotate: degrees, right-hand rule
    std::array<double, 16> matrix{};  ///< matrix: row-major 4x4
};

/// The kinds of object in the scene format (docs/scene-format.md §3), in the order of the
/// alternatives of ObjectDescription::Shape; the built Scene keeps it for each object (scene.h).
enum class ObjectType { sphere, plane, box, triangle, mesh, group, instance, cylinder, cone };

struct ObjectDescription;

// One struct per object kind, with the keys that kind takes in the scene format (§3), so that no
// kind's value is visible on another. ObjectDescription holds the keys every kind shares.

struct SphereShape {
    Located<Vec3> center;
    Located<double> radius;
};

struct PlaneShape {
    Located<Vec3> point;
    Located<Vec3> normal;
};

struct BoxShape {
    Located<Vec3> min;
    Located<Vec3> max;
};

struct TriangleShape {
    SourceLocation vertices_where;
    std::vector<Vec3> vertices;  ///< exactly 3
};

/// Inline (`vertices`, `triangles`, optional `normals`) or from a `file` (OBJ or a course .msh).
struct MeshShape {
    SourceLocation vertices_where;
    std::vector<Vec3> vertices;
    SourceLocation triangles_where;
    std::vector<std::array<int64_t, 3>> triangles;
    /// One per triangle, for index errors; empty where the reader made the indices (NFF).
    std::vector<SourceLocation> triangle_where;
    SourceLocation normals_where;
    std::vector<Vec3> normals;
    Located<std::string> file;  ///< as written in the scene; `given` for a mesh from a file
    std::string file_path;      ///< resolved against the scene file's directory
};

/// `group`: its `objects` share its transform (and, in a course scene, its material).
struct GroupShape {
    std::vector<ObjectDescription> objects;
};

/// `instance`: a placement of a prototype (SceneDescription::prototypes), declared once and
/// shared by every placement (docs/scene-format.md §3.8).
struct InstanceShape {
    Located<std::string> prototype;  ///< the name of an entry in `prototypes`
};

/// The centres of the two ends, one radius, and whether the ends are left open (no caps).
struct CylinderShape {
    Located<Vec3> base;
    Located<Vec3> cap;
    Located<double> radius;
    Located<bool> open{false};
};

/// The centres of the two ends, each end's radius, and whether the ends are left open.
struct ConeShape {
    Located<Vec3> base;
    Located<double> base_radius;
    Located<Vec3> cap;
    Located<double> cap_radius;
    Located<bool> open{false};
};

/// An overload set of lambdas for std::visit: with no catch-all among them, a kind left out is a
/// compile error rather than a silent default.
template <class... F>
struct Overloaded : F... {
    using F::operator()...;
};
template <class... F>
Overloaded(F...) -> Overloaded<F...>;

struct ObjectDescription {
    /// One alternative per ObjectType, in its order (type() relies on it).
    using Shape = std::variant<SphereShape, PlaneShape, BoxShape, TriangleShape, MeshShape, GroupShape, InstanceShape,
                               CylinderShape, ConeShape>;

    SourceLocation where;
    std::vector<TransformStep> transform;  ///< applied in list order
    std::optional<MaterialReference> material;
    Shape shape;

    ObjectType type() const { return static_cast<ObjectType>(shape.index()); }
};

template <ObjectType kind, class S>
inline constexpr bool shape_of_kind =
    std::is_same_v<std::variant_alternative_t<size_t(kind), ObjectDescription::Shape>, S>;
static_assert(shape_of_kind<ObjectType::sphere, SphereShape> && shape_of_kind<ObjectType::plane, PlaneShape> &&
              shape_of_kind<ObjectType::box, BoxShape> && shape_of_kind<ObjectType::triangle, TriangleShape> &&
              shape_of_kind<ObjectType::mesh, MeshShape> && shape_of_kind<ObjectType::group, GroupShape> &&
              shape_of_kind<ObjectType::instance, InstanceShape> &&
              shape_of_kind<ObjectType::cylinder, CylinderShape> && shape_of_kind<ObjectType::cone, ConeShape>);
static_assert(std::variant_size_v<ObjectDescription::Shape> == size_t(ObjectType::cone) + 1);

/// Calls `f` on each object of `list` in file order, and on the members of each group right after
/// the group itself (depth first): for what every kind has alike (material, transform); what a
/// kind alone has is reached with std::visit or std::get_if on `shape`.
template <class List, class F>
void for_each_object(List&& list, F&& f) {
    for (auto& object : list) {
        f(object);
        if (auto* group = std::get_if<GroupShape>(&object.shape)) for_each_object(group->objects, f);
    }
}

/// `prototypes:` entry: a mesh, triangle or group of them, declared once in a space of its own
/// and placed by `instance` objects, each with its own transform and optionally its own material.
struct PrototypeDescription {
    SourceLocation where;  ///< the name's key
    std::string name;
    ObjectDescription object;
};

struct SceneDescription {
    std::string path;  ///< the scene file as given
    Located<int64_t> version{1};
    CameraDescription camera;
    ImageDescription image;
    Located<int64_t> max_depth{5};
    /// render.layers: the EXR render layers asked for, as written (docs/layers.md).
    std::vector<Located<std::string>> layers;
    Located<Convention> convention{Convention::pov};
    Located<double> min_weight{0.0};  ///< a mirror ray whose path weight is below this is not traced
    Located<Intersection> intersection{Intersection::exact};
    Located<Color> ambient{Color{1.0}};
    std::vector<LightDescription> lights;
    std::vector<MaterialDescription> materials;  ///< in file order
    std::vector<ObjectDescription> objects;
    std::vector<PrototypeDescription> prototypes;  ///< in file order

    const MaterialDescription* find_material(const std::string& name) const;
    const PrototypeDescription* find_prototype(const std::string& name) const;
};

/// Limits that keep a hostile or mistaken scene from exhausting the machine; each is reported
/// with a clear message rather than a crash (docs/scene-format.md lists them).
namespace limits {
inline constexpr int64_t max_image_side = 65536;
inline constexpr int64_t max_image_pixels = int64_t(1) << 28;  // 268 M pixels
inline constexpr int64_t max_samples = 16;                     // 256 rays per pixel
inline constexpr int64_t max_depth = 256;
inline constexpr int max_nesting = 64;  ///< groups inside groups
inline constexpr int64_t max_scene_file_bytes = int64_t(256) << 20;
inline constexpr int64_t max_mesh_file_bytes = int64_t(2) << 30;
inline constexpr int64_t max_triangles = int64_t(64) << 20;  // 67 M triangles
/// Values held at once while reading, and values all aliases stand for ("billion laughs").
inline constexpr int64_t max_yaml_nodes = 10'000'000;
}  // namespace limits

/// Receives each top-level object as soon as it is parsed, with its index in `objects`, so that a
/// reader can use it and let it go (load_scene_file). Each index comes once, in order, whichever
/// way the reader read the text.
using ObjectSink = std::function<void(ObjectDescription&&, size_t index)>;

/// Reads a scene file (YAML or JSON; a `.xml` file is read as a Cornell CS4620 course scene,
/// course_xml.h). Throws InputError naming file:line:col on any problem. With a `sink`, the
/// top-level objects go there (only until the first mistake in them) and `objects` stays empty.
SceneDescription parse_scene_file(const std::string& path, const ObjectSink* sink = nullptr);
/// Same, from text already in memory; `path` is used for messages and relative mesh paths.
SceneDescription parse_scene_text(std::string_view text, const std::string& path, const ObjectSink* sink = nullptr);

/// The three kinds of scene text Whitted reads.
enum class SceneFormat { yaml, course_xml, nff };
/// A scene's format by its name's extension (`.xml`, `.nff`; `.yaml`, `.yml`, `.json` are YAML),
/// as parse_scene_file decides; for a name without one of those (`<stdin>`, `<string>`), by how
/// its text begins: NFF's one-letter entities (after `#` comment lines), XML's `<`, else YAML
/// (JSON included).
SceneFormat scene_format(const std::string& path, std::string_view text);
/// parse_scene_text, parse_course_xml_text or parse_nff_text, as scene_format says.
SceneDescription parse_any_scene_text(std::string_view text, const std::string& path, const ObjectSink* sink = nullptr);

const char* to_string(ObjectType type);

}  // namespace whitted
