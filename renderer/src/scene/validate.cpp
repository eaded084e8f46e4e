// SPDX-License-Identifier: MIT
// SceneDescription → Scene: range checks that need whole values (or several of them), material
// names resolved, transforms folded, meshes loaded. Every refusal names file:line:col.

#include "scene/layer_names.h"
#include "scene/mesh_file.h"
#include "scene/msh_file.h"
#include "scene/scene.h"
#include "scene/text_checks.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <cmath>
#include <exception>
#include <filesystem>
#include <limits>
#include <memory>
#include <numbers>
#include <optional>
#include <string_view>
#include <unordered_map>
#include <unordered_set>

namespace whitted {
namespace {

[[noreturn]] void fail(const SourceLocation& where, const std::string& message) {
    throw InputError(where, message);
}

void require_non_negative(const Located<Color>& c, const std::string& what) {
    if (c.value.x < 0 || c.value.y < 0 || c.value.z < 0) fail(c.where, what + " must not be negative");
}

void require_non_zero(const Located<Vec3>& v, const std::string& what) {
    if (is_zero(v.value)) fail(v.where, what + " must not be the zero vector");
}

/// Schlick's normal-incidence reflectance R0 = ((η−1)/(η+1))² for `fresnel_ior` = η.
double fresnel_r0(const Located<double>& ior, const std::string& what) {
    if (!(ior.value > 0)) fail(ior.where, what + ".fresnel_ior: the index of refraction must be > 0");
    const double r = (ior.value - 1) / (ior.value + 1);
    return r * r;
}

/// The course's .msh meshes are told apart from OBJ files by their extension.
bool is_msh_file(const std::string& path) {
    return std::filesystem::path(path).extension() == ".msh";
}

Material make_material(const MaterialDescription& d, const std::string& what) {
    require_non_negative(d.ka, what + ".ka");
    require_non_negative(d.kd, what + ".kd");
    require_non_negative(d.ks, what + ".ks");
    require_non_negative(d.km, what + ".km");
    if (!(d.p.value > 0)) fail(d.p.where, what + ".p: the specular exponent must be > 0");
    require_non_negative(d.kt, what + ".kt");
    if (!(d.ior.value > 0 && std::isfinite(d.ior.value)))
        fail(d.ior.where, what + ".ior: the index of refraction must be a finite number > 0");
    if (d.fresnel_ior.given && !is_zero(d.kt.value))
        fail(d.kt.where, what + ": kt (refraction) and fresnel_ior (the course's glaze) cannot be combined");
    Material material{d.ka.value, d.kd.value, d.ks.value, d.p.value, d.km.value, d.highlight.value};
    if (d.fresnel_ior.given) material.fresnel_r0 = fresnel_r0(d.fresnel_ior, what);
    material.kt = d.kt.value;
    material.ior = d.ior.value;
    return material;
}

/// Builds the scene's objects one top-level object at a time, so that load_scene_file can
/// validate each as soon as it is parsed and let its description go. The named materials may
/// come later in the file than the objects using them, so objects first get provisional
/// material numbers (a name's number in order of first use, or an inline/MTL material's number
/// with `provisional_own` set); finish() validates the named materials, places them first (named
/// in file order, then inline and MTL ones as met, as Scene::materials says) and renumbers.
/// Instances get their prototype in finish() too, since `prototypes` may also come later.
/// Mistakes are reported in the order validate_scene always used: the named materials first, then
/// the prototypes, then the objects in file order, each object's own checks in the order
/// add_object makes them. The name tables finish() sets up point into its argument: they serve
/// only while it runs.
class SceneBuilder {
public:
    explicit SceneBuilder(Scene& scene) : m_scene(scene) {}

    /// One item of the scene's `objects`. Its first mistake is kept for finish(), and the rest
    /// are then ignored: nothing after a mistake can change which mistake is reported.
    void add_top_level(const ObjectDescription& object) {
        if (m_error) return;
        try {
            add_object(object, Transform());
        } catch (const InputError&) {
            m_error = std::current_exception();
            m_error_step = m_step;
        }
    }

    /// The rest, once the whole file is read: the named materials (placed first), the prototypes,
    /// the instances' prototypes, then the first mistake among the objects, then the renumbering.
    void finish(const SceneDescription& d) {
        std::vector<std::string> names;
        for (const auto& material : d.materials) {
            m_named_index.emplace(material.name, static_cast<uint32_t>(m_scene.materials.size()));
            m_scene.materials.push_back(make_material(material, "materials." + material.name));
            m_scene.material_names.push_back(material.name);
            names.push_back(material.name);
        }
        const size_t object_uses = m_uses.size();  // the prototypes' are checked as they are met
        m_names_known = &names;
        add_prototypes(d.prototypes);

        // The first mistake in the objects, in the order they were met: one kept by
        // add_top_level, an unknown material name, or an instance's prototype.
        uint64_t first_step = m_error ? m_error_step : UINT64_MAX;
        std::exception_ptr first = m_error;
        for (size_t i = 0; i < object_uses; ++i)
            if (!m_named_index.count(m_uses[i].name)) {
                if (m_uses[i].step < first_step) {
                    try {
                        fail_unknown_material(m_uses[i], names);
                    } catch (const InputError&) {
                        first = std::current_exception(), first_step = m_uses[i].step;
                    }
                }
                break;
            }
        for (PendingInstance& pending : m_pending_instances) {
            if (pending.step >= first_step) break;
            try {
                place_instance(pending);
            } catch (const InputError&) {
                first = std::current_exception(), first_step = pending.step;
                break;
            }
        }
        if (first) std::rethrow_exception(first);

        std::vector<uint32_t> final_index(m_uses.size());
        for (size_t i = 0; i < m_uses.size(); ++i) final_index[i] = m_named_index.at(m_uses[i].name);
        const uint32_t own_base = static_cast<uint32_t>(m_scene.materials.size());
        for (size_t i = 0; i < m_own.size(); ++i) {
            m_scene.materials.push_back(m_own[i]);
            m_scene.material_names.push_back(std::move(m_own_names[i]));
        }
        const auto renumber = [&](uint32_t& material) {
            if (material == Instance::no_material) return;  // left to the instance
            material = material & provisional_own ? own_base + (material & ~provisional_own) : final_index[material];
        };
        const auto renumber_mesh = [&](TriangleMesh& mesh) {
            // With MTL materials per triangle, `material` is unused (left 0, never provisional).
            if (mesh.triangle_materials.empty()) renumber(mesh.material);
            for (uint32_t& material : mesh.triangle_materials) renumber(material);
        };
        for (Sphere& sphere : m_scene.spheres) renumber(sphere.material);
        for (Box& box : m_scene.boxes) renumber(box.material);
        for (Cone& cone : m_scene.cones) renumber(cone.material);
        for (Plane& plane : m_scene.planes) renumber(plane.material);
        for (TriangleMesh& mesh : m_scene.meshes) renumber_mesh(mesh);
        for (Prototype& prototype : m_scene.prototypes)
            for (TriangleMesh& mesh : prototype.meshes) renumber_mesh(mesh);
        for (Instance& instance : m_scene.instances) renumber(instance.material);
    }

private:
    /// Every prototype, in file order. Only meshes and triangles, in groups or not, may be in one:
    /// instances share triangles through Embree's instancing; analytic shapes and planes are not
    /// instanced (and instances inside prototypes are not nested).
    void add_prototypes(const std::vector<PrototypeDescription>& prototypes) {
        // The prototypes some instance places without a material, found once: a look-up per
        // prototype, not a pass over every instance (80,000 prototypes of one instance each took
        // 29 s that way).
        std::unordered_set<std::string_view> shown_with_defaults;
        for (const PendingInstance& pending : m_pending_instances)
            if (pending.material == Instance::no_material) shown_with_defaults.insert(pending.prototype.value);
        for (const PrototypeDescription& d : prototypes) {
            m_prototype_index[d.name] = static_cast<uint32_t>(m_scene.prototypes.size());
            m_prototype_names.push_back(d.name);
            Prototype prototype;
            prototype.name = d.name;
            m_prototype = &prototype;
            // The defaults its OBJ files give (and warn of) show only through an instance
            // without a material of its own.
            m_prototype_shows_defaults = shown_with_defaults.count(d.name) > 0;
            add_object(d.object, Transform());
            m_prototype = nullptr;
            if (prototype.meshes.empty())
                fail(d.where, "prototypes." + printable(d.name) + ": the prototype holds no triangles");
            constexpr double inf = std::numeric_limits<double>::infinity();
            prototype.lo = Vec3(inf), prototype.hi = Vec3(-inf);
            for (const TriangleMesh& mesh : prototype.meshes)
                for (size_t i = 0; i < mesh.vertex_count(); ++i) {
                    const Vec3 p = mesh.vertex(i);
                    prototype.lo = min(prototype.lo, p), prototype.hi = max(prototype.hi, p);
                }
            m_scene.prototypes.push_back(std::move(prototype));
        }
    }

    static constexpr uint32_t provisional_own = 0x80000000u;

    /// A material name as first used, and where: the place an unknown name is reported.
    struct NameUse {
        std::string name;
        SourceLocation where;
        std::string kind;
        uint64_t step = 0;
    };

    [[noreturn]] static void fail_unknown_material(const NameUse& use, const std::vector<std::string>& names) {
        const std::string known = join_names(names);
        fail(use.where, use.kind + ": unknown material '" + printable(use.name) + "'" + did_you_mean(use.name, names) +
                            (known.empty() ? "; the scene defines no materials" : "; defined: " + known));
    }

    /// An instance met among the objects: its prototype is looked up once all are known.
    struct PendingInstance {
        Located<std::string> prototype;
        SourceLocation where;
        Transform to_world;
        uint32_t material = Instance::no_material;
        uint32_t object = 0;
        uint64_t step = 0;
    };

    uint32_t add_own_material(Material material, std::string name) {
        m_own.push_back(material);
        m_own_names.push_back(std::move(name));
        return provisional_own | static_cast<uint32_t>(m_own.size() - 1);
    }

    uint32_t resolve_material(const ObjectDescription& object) {
        ++m_step;
        const char* kind = to_string(object.type());
        // In a prototype the material may be left to each instance.
        if (!object.material && m_prototype) return Instance::no_material;
        if (!object.material) fail(object.where, std::string(kind) + ": missing required key 'material'");
        const MaterialReference& reference = *object.material;
        if (reference.inline_)
            return add_own_material(make_material(*reference.inline_, std::string(kind) + ".material"), "");
        // Most scenes name a handful of materials; the last one used is usually used again.
        if (m_last_use < m_uses.size() && m_uses[m_last_use].name == reference.name) return m_last_use;
        // Once the named materials are known (the prototypes, built last), a name is checked here.
        if (m_names_known && !m_named_index.count(reference.name))
            fail_unknown_material({reference.name, reference.where, kind, m_step}, *m_names_known);
        const auto [it, added] = m_use_index.try_emplace(reference.name, static_cast<uint32_t>(m_uses.size()));
        if (added) m_uses.push_back({reference.name, reference.where, kind, m_step});
        return m_last_use = it->second;
    }

    void add_object(const ObjectDescription& object, const Transform& parent) {
        ++m_step;
        for (const TransformStep& step : object.transform) check_step(step);
        const Transform to_world = make_transform(object.transform).then(parent);
        const auto finite = [](const Vec3& v) {
            return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
        };
        // Scales of 1e200 twice: not flat, but past a double (the determinant alone may overflow
        // for a legal scale of 1e300, whose vertices are then refused as beyond float range).
        if (!finite(to_world.apply_vector({1, 0, 0})) || !finite(to_world.apply_vector({0, 1, 0})) ||
            !finite(to_world.apply_vector({0, 0, 1})) || !finite(to_world.apply_point({0, 0, 0})))
            fail(object.transform.empty() ? object.where : object.transform.front().where,
                 "the transform overflows: its steps together scale the object beyond the range of a double");
        const double determinant = to_world.determinant();
        if (!(std::fabs(determinant) > 1e-300))
            fail(object.transform.empty() ? object.where : object.transform.front().where,
                 "the transform is singular (it flattens the object)");
        const ObjectType type = object.type();
        if (m_prototype && type != ObjectType::mesh && type != ObjectType::triangle && type != ObjectType::group)
            fail(object.where,
                 std::string("prototypes.") + printable(m_prototype->name) +
                     (type == ObjectType::instance ? ": an " : ": a ") + to_string(type) +
                     " cannot be in a prototype; prototypes hold meshes and triangles (in groups or not)");
        std::visit(
            Overloaded{
                [&](const SphereShape& sphere) {
                    if (!(sphere.radius.value > 0)) fail(sphere.radius.where, "sphere.radius must be > 0");
                    m_scene.spheres.push_back({shared(to_world), sphere.center.value, sphere.radius.value,
                                               resolve_material(object), add_id(object)});
                },
                [&](const PlaneShape& plane) {
                    require_non_zero(plane.normal, "plane.normal");
                    const Vec3 normal = unit_direction(to_world.apply_normal(plane.normal.value));
                    m_scene.planes.push_back(
                        {to_world.apply_point(plane.point.value), normal, resolve_material(object), add_id(object)});
                },
                [&](const BoxShape& box) {
                    const Vec3 lo = box.min.value, hi = box.max.value;
                    if (!(lo.x < hi.x && lo.y < hi.y && lo.z < hi.z))
                        fail(box.max.where, "box: min must be less than max on every axis (min " + format(lo) +
                                                ", max " + format(hi) + ")");
                    m_scene.boxes.push_back({shared(to_world), lo, hi, resolve_material(object), add_id(object)});
                },
                // A cylinder is a cone with equal radii (docs/scene-format.md §3.9).
                [&](const CylinderShape& cylinder) {
                    add_cone(object, true, cylinder.base, cylinder.radius, cylinder.cap, cylinder.radius, cylinder.open,
                             to_world);
                },
                [&](const ConeShape& cone) {
                    add_cone(object, false, cone.base, cone.base_radius, cone.cap, cone.cap_radius, cone.open,
                             to_world);
                },
                [&](const TriangleShape& triangle) {
                    TriangleMesh mesh;
                    mesh.material = resolve_material(object);
                    set_positions(
                        mesh, 3, [&](size_t i) { return to_world.apply_point(triangle.vertices[i]); },
                        triangle.vertices_where);
                    mesh.indices = {0, 1, 2};
                    mesh.object = add_id(object);
                    add_mesh(std::move(mesh));
                },
                [&](const MeshShape& mesh) {
                    if (mesh.file.given)
                        add_mesh_file(object, mesh, to_world);
                    else
                        add_inline_mesh(object, mesh, to_world);
                },
                [&](const GroupShape& group) {
                    for (const auto& child : group.objects) add_object(child, to_world);
                },
                [&](const InstanceShape& instance) { add_instance(object, instance, to_world); }},
            object.shape);
    }

    /// A cylinder has one radius for both ends (`radius`: base_radius and cap_radius are the same
    /// value), a cone one for each.
    void add_cone(const ObjectDescription& object, bool cylinder, const Located<Vec3>& base,
                  const Located<double>& base_radius, const Located<Vec3>& cap, const Located<double>& cap_radius,
                  const Located<bool>& open, const Transform& to_world) {
        const std::string kind = cylinder ? "cylinder" : "cone";
        if (!(base_radius.value >= 0))
            fail(base_radius.where, kind + (cylinder ? ".radius must be > 0" : ".base_radius must be >= 0"));
        if (!(cap_radius.value >= 0)) fail(cap_radius.where, kind + ".cap_radius must be >= 0");
        if (!(base_radius.value > 0 || cap_radius.value > 0))
            fail(cap_radius.where,
                 kind + (cylinder ? ".radius must be > 0" : ": base_radius and cap_radius must not both be 0"));
        const Vec3 axis = cap.value - base.value;
        const double height = length(axis);
        if (!(height > 0 && std::isfinite(height)))
            fail(cap.where, kind + ": base and cap must be different points (at a finite distance)");
        Cone cone;
        cone.object_to_world = shared(to_world);
        cone.base = base.value;
        cone.axis = axis / height;
        cone.height = height;
        cone.base_radius = base_radius.value;
        cone.cap_radius = cap_radius.value;
        cone.open = open.value;
        cone.material = resolve_material(object);
        cone.object = add_id(object);
        m_scene.cones.push_back(std::move(cone));
    }

    /// The instance's material now (a provisional number, as every object's), its prototype in
    /// finish(): the prototypes may come after the objects in the file.
    void add_instance(const ObjectDescription& object, const InstanceShape& instance, const Transform& to_world) {
        PendingInstance pending;
        pending.prototype = instance.prototype;
        pending.where = object.where;
        pending.to_world = to_world;
        pending.step = m_step;
        if (object.material) pending.material = resolve_material(object);
        pending.object = add_id(object);
        m_pending_instances.push_back(std::move(pending));
    }

    void place_instance(const PendingInstance& pending) {
        const auto it = m_prototype_index.find(pending.prototype.value);
        if (it == m_prototype_index.end())
            fail(pending.prototype.where,
                 "instance: unknown prototype '" + printable(pending.prototype.value) + "'" +
                     did_you_mean(pending.prototype.value, m_prototype_names) +
                     (m_prototype_names.empty() ? "; the scene defines no prototypes"
                                                : "; defined: " + join_names(m_prototype_names)));
        const Prototype& prototype = m_scene.prototypes[it->second];
        Instance instance;
        instance.object_to_world = pending.to_world;
        instance.prototype = it->second;
        instance.material = pending.material;
        if (pending.material == Instance::no_material) {
            for (const TriangleMesh& mesh : prototype.meshes)
                if (mesh.triangle_materials.empty() && mesh.material == Instance::no_material)
                    fail(pending.where, "instance: prototype '" + printable(prototype.name) +
                                            "' has triangles without a material; give the instance a 'material'");
        }
        // Embree holds the transform and the prototype's bounds in float.
        for (int corner = 0; corner < 8; ++corner) {
            const Vec3 p = pending.to_world.apply_point({corner & 1 ? prototype.hi.x : prototype.lo.x,
                                                         corner & 2 ? prototype.hi.y : prototype.lo.y,
                                                         corner & 4 ? prototype.hi.z : prototype.lo.z});
            if (!(std::isfinite(float(p.x)) && std::isfinite(float(p.y)) && std::isfinite(float(p.z))))
                fail(pending.where, "instance: prototype '" + printable(prototype.name) +
                                        "' placed here reaches beyond float range (about 3.4e38)");
        }
        instance.object = pending.object;
        m_scene.instances.push_back(instance);
    }

    /// The first 20 names as printable() shows them, and how many there are in all beyond that.
    static std::string join_names(const std::vector<std::string>& names) {
        constexpr size_t most_listed = 20;
        std::string out;
        for (size_t i = 0; i < names.size() && i < most_listed; ++i) {
            if (i > 0) out += ", ";
            out += printable(names[i], 40);
        }
        if (names.size() > most_listed) out += ", ... (" + std::to_string(names.size()) + " in all)";
        return out;
    }

    void add_inline_mesh(const ObjectDescription& object, const MeshShape& shape, const Transform& to_world) {
        const size_t n = shape.vertices.size();
        if (n < 3) fail(shape.vertices_where, "mesh.vertices: a mesh needs at least 3 vertices");
        if (shape.triangles.empty()) fail(shape.triangles_where, "mesh.triangles: a mesh needs at least one triangle");
        if (!shape.normals.empty() && shape.normals.size() != n)
            fail(shape.normals_where, "mesh.normals: " + std::to_string(shape.normals.size()) + " normals for " +
                                          std::to_string(n) + " vertices; give one per vertex");
        TriangleMesh mesh;
        mesh.material = resolve_material(object);
        set_positions(
            mesh, n, [&](size_t i) { return to_world.apply_point(shape.vertices[i]); }, shape.vertices_where);
        mesh.indices.reserve(3 * shape.triangles.size());
        for (size_t t = 0; t < shape.triangles.size(); ++t)
            for (const int64_t index : shape.triangles[t]) {
                if (index < 0 || index >= static_cast<int64_t>(n))
                    fail(t < shape.triangle_where.size() ? shape.triangle_where[t] : shape.triangles_where,
                         "mesh.triangles[" + std::to_string(t) + "]: vertex index " + std::to_string(index) +
                             " is out of range (0.." + std::to_string(n - 1) + ")");
                mesh.indices.push_back(static_cast<uint32_t>(index));
            }
        mesh.normals.reserve(3 * shape.normals.size());
        for (size_t i = 0; i < shape.normals.size(); ++i) {
            if (is_zero(shape.normals[i]))
                fail(shape.normals_where, "mesh.normals[" + std::to_string(i) + "] must not be the zero vector");
            push_normal(mesh, to_world.apply_normal(shape.normals[i]));
        }
        mesh.object = add_id(object);
        add_mesh(std::move(mesh));
    }

    void add_mesh_file(const ObjectDescription& object, const MeshShape& shape, const Transform& to_world) {
        // A mistake inside the OBJ/MTL names that file; also say which scene line loads it.
        const auto with_reference = [&](const InputError& e) {
            return InputError(e.where(), e.message() + " (mesh loaded at " + shape.file.where.str() + ")");
        };
        MeshData data;
        m_scene.mesh_files.push_back(shape.file_path);
        try {
            // With the object's own material the MTL files are not needed (nor read).
            data = is_msh_file(shape.file_path) ? load_msh_mesh(shape.file_path, shape.file.where)
                                                : load_obj_mesh(shape.file_path, shape.file.where, 0, !object.material);
        } catch (const InputError& e) {
            if (e.where().file == shape.file.where.file) throw;
            throw with_reference(e);
        }
        if (!m_prototype || m_prototype_shows_defaults) print_mesh_warnings(data);
        TriangleMesh mesh;
        if (object.material) {
            mesh.material = resolve_material(object);
        } else {
            std::vector<uint32_t> mtl_index;
            for (size_t i = 0; i < data.materials.size(); ++i) {
                try {
                    mtl_index.push_back(
                        add_own_material(make_material(data.materials[i],
                                                       shape.file_path + ": material '" + data.materials[i].name + "'"),
                                         data.materials[i].name));
                } catch (const InputError& e) {
                    throw with_reference(e);
                }
            }
            for (const int32_t m : data.triangle_material) {
                if (m < 0)
                    fail(object.where,
                         "mesh: '" + shape.file.value +
                             "' has faces without an MTL material (usemtl), and the object has no 'material'");
                mesh.triangle_materials.push_back(mtl_index[m]);
            }
        }
        const size_t n = data.positions.size() / 3;
        set_positions(
            mesh, n,
            [&](size_t i) {
                return to_world.apply_point(
                    {data.positions[3 * i], data.positions[3 * i + 1], data.positions[3 * i + 2]});
            },
            shape.file.where);
        if (!data.normals.empty()) {
            mesh.normals.resize(3 * n);
            for_each_vertex(n, [&](size_t i) {
                set_normal(&mesh.normals[3 * i], to_world.apply_normal({data.normals[3 * i], data.normals[3 * i + 1],
                                                                        data.normals[3 * i + 2]}));
            });
        }
        mesh.indices = std::move(data.indices);
        mesh.object = add_id(object);
        add_mesh(std::move(mesh));
    }

    void add_mesh(TriangleMesh mesh) {
        (m_prototype ? m_prototype->meshes : m_scene.meshes).push_back(std::move(mesh));
    }

    /// The object's number (1-based, file order): see SceneObject. Inside a prototype none: the
    /// instance is the object.
    uint32_t add_id(const ObjectDescription& object) {
        if (m_prototype) return 0;
        m_scene.objects.push_back({object.type(), object.where});
        return static_cast<uint32_t>(m_scene.objects.size());
    }

    /// The mesh's `count` vertices, given in world space (double) by `world_point`: stored as
    /// float offsets from mesh_origin (scene.h). So a mesh keeps float's precision relative to its
    /// own size wherever it stands: moved or scaled with the whole scene, its triangles are the
    /// same to a float's rounding of its own size (docs/validation.md, "Far from the origin"), as
    /// a sphere's or a box's are. A world coordinate beyond float range is refused, naming the
    /// vertex: Embree's BVH needs finite float bounds.
    /// A mesh of a million vertices is transformed on every core; the bounds are joined in
    /// vertex order (min and max pick the same of equal values however the runs are cut), and
    /// the vertex named in an error is the first beyond range, as when read one by one.
    template <class WorldPoint>
    void set_positions(TriangleMesh& mesh, size_t count, const WorldPoint& world_point, const SourceLocation& where) {
        constexpr double inf = std::numeric_limits<double>::infinity();
        constexpr double float_max = std::numeric_limits<float>::max();
        struct Bounds {
            Vec3 lo, hi;
            size_t first_beyond;  ///< the first vertex beyond float range, or count
        };
        const auto take = [&](const tbb::blocked_range<size_t>& range, Bounds b) {
            for (size_t i = range.begin(); i != range.end() && b.first_beyond == count; ++i) {
                const Vec3 p = world_point(i);
                if (!(std::fabs(p.x) <= float_max && std::fabs(p.y) <= float_max && std::fabs(p.z) <= float_max))
                    b.first_beyond = i;
                else
                    b.lo = min(b.lo, p), b.hi = max(b.hi, p);
            }
            return b;
        };
        const Bounds none{Vec3(inf), Vec3(-inf), count};
        const tbb::blocked_range<size_t> all(0, count, vertices_per_task);
        const Bounds bounds = count <= vertices_per_task
                                  ? take(all, none)  // the usual triangle or small mesh: no tasks
                                  : tbb::parallel_reduce(all, none, take, [count](const Bounds& a, const Bounds& b) {
                                        if (a.first_beyond != count) return a;  // a holds the earlier vertices
                                        return Bounds{min(a.lo, b.lo), max(a.hi, b.hi), b.first_beyond};
                                    });
        if (bounds.first_beyond != count)
            fail(where, "vertex " + std::to_string(bounds.first_beyond) +
                            " is beyond float range (about 3.4e38) once transformed to world space");
        mesh.origin = mesh_origin(bounds.lo, bounds.hi);
        mesh.positions.assign(4 * count, 0.0f);
        for_each_vertex(count, [&](size_t i) {
            const Vec3 p = world_point(i) - mesh.origin;
            float* out = &mesh.positions[4 * i];
            out[0] = float(p.x), out[1] = float(p.y), out[2] = float(p.z);
        });
    }
    /// Vertices per task of the loops over a mesh's vertices: a mesh of a few thousand stays on
    /// one thread.
    static constexpr size_t vertices_per_task = 16384;
    /// body(i) for each vertex i < count, on every core when there are more than one task's worth.
    template <class Body>
    static void for_each_vertex(size_t count, const Body& body) {
        const auto run = [&body](const tbb::blocked_range<size_t>& range) {
            for (size_t i = range.begin(); i != range.end(); ++i) body(i);
        };
        const tbb::blocked_range<size_t> all(0, count, vertices_per_task);
        count <= vertices_per_task ? run(all) : tbb::parallel_for(all, run);
    }
    static void set_normal(float* out, const Vec3& n) {
        // A zero normal from the file (rare) stays zero; shading then falls back to the face normal.
        const double len = length(n);
        const Vec3 unit = len > 0 ? n / len : Vec3();
        out[0] = float(unit.x), out[1] = float(unit.y), out[2] = float(unit.z);
    }
    static void push_normal(TriangleMesh& mesh, const Vec3& n) {
        mesh.normals.resize(mesh.normals.size() + 3);
        set_normal(&mesh.normals[mesh.normals.size() - 3], n);
    }

    static void check_step(const TransformStep& step) {
        switch (step.kind) {
            case TransformStep::Kind::scale:
                if (step.vector.x == 0 || step.vector.y == 0 || step.vector.z == 0)
                    fail(step.where, "transform: a scale factor of 0 flattens the object");
                break;
            case TransformStep::Kind::rotate:
                if (is_zero(step.vector)) fail(step.where, "transform: the rotation axis must not be the zero vector");
                break;
            case TransformStep::Kind::translate:
                break;
            case TransformStep::Kind::matrix: {
                const auto& m = step.matrix;
                if (m[12] != 0 || m[13] != 0 || m[14] != 0 || m[15] != 1)
                    fail(step.where, "transform.matrix: the last row must be 0 0 0 1 (affine transforms only)");
                break;
            }
        }
    }

    static std::string format(const Vec3& v) {
        char buffer[96];
        std::snprintf(buffer, sizeof buffer, "[%g, %g, %g]", v.x, v.y, v.z);
        return buffer;
    }

    /// Null for the identity, so that the shapes take their untransformed path.
    static SharedTransform shared(const Transform& to_world) {
        return to_world.is_identity() ? nullptr : std::make_shared<const Transform>(to_world);
    }

    Scene& m_scene;
    /// Whether some instance places the prototype being added without a material (add_prototypes).
    bool m_prototype_shows_defaults = false;
    std::vector<NameUse> m_uses;  ///< material names in order of first use
    std::unordered_map<std::string, uint32_t> m_use_index;
    uint32_t m_last_use = UINT32_MAX;
    std::unordered_map<std::string_view, uint32_t> m_named_index;  ///< finish(): the named materials
    const std::vector<std::string>* m_names_known = nullptr;       ///< set once they are known
    std::vector<Material> m_own;                                   ///< inline and MTL materials, as met
    std::vector<std::string> m_own_names;
    uint64_t m_step = 0;  ///< objects and material references seen: orders mistakes as met
    std::exception_ptr m_error;
    uint64_t m_error_step = 0;
    std::vector<PendingInstance> m_pending_instances;
    std::unordered_map<std::string, uint32_t> m_prototype_index;
    std::vector<std::string> m_prototype_names;
    Prototype* m_prototype = nullptr;  ///< the prototype being built, or null: the scene's own objects
};

}  // namespace

size_t Scene::triangle_count() const {
    size_t n = 0;
    for (const auto& mesh : meshes) n += mesh.triangle_count();
    for (const auto& prototype : prototypes)
        for (const auto& mesh : prototype.meshes) n += mesh.triangle_count();
    return n;
}

size_t Scene::instanced_triangle_count() const {
    size_t n = 0;
    for (const auto& mesh : meshes) n += mesh.triangle_count();
    for (const auto& instance : instances)
        for (const auto& mesh : prototypes[instance.prototype].meshes) n += mesh.triangle_count();
    return n;
}

Transform make_transform(const std::vector<TransformStep>& steps) {
    Transform result;
    for (const TransformStep& step : steps) {
        switch (step.kind) {
            case TransformStep::Kind::scale:
                result = result.then(Transform::scale(step.vector));
                break;
            case TransformStep::Kind::rotate:
                result = result.then(Transform::rotate(step.vector, step.angle));
                break;
            case TransformStep::Kind::translate:
                result = result.then(Transform::translate(step.vector));
                break;
            case TransformStep::Kind::matrix: {
                const auto& m = step.matrix;
                if (std::fabs(linear_determinant(
                        {m[0], m[1], m[2], m[3], m[4], m[5], m[6], m[7], m[8], m[9], m[10], m[11]})) <= 1e-300)
                    throw InputError(step.where, "transform.matrix is singular");
                result = result.then(
                    Transform::from_rows({m[0], m[1], m[2], m[3], m[4], m[5], m[6], m[7], m[8], m[9], m[10], m[11]}));
                break;
            }
        }
    }
    return result;
}

namespace {
/// A perspective camera aimed through a window (the Cornell course's camera): the window's
/// centre is projection_distance along the unit view direction; its plane has the unit normal
/// w = image_plane_normal (default −forward), screen up V = `up` projected into that plane and
/// screen right U = V × w; the window spans view_width·U by view_height·V. With an oblique w
/// the window is not perpendicular to the view direction, which gives the course's sheared views.
void make_window_camera(const CameraDescription& d, const Vec3& forward, Camera& camera) {
    if (!(d.view_width.value > 0)) fail(d.view_width.where, "camera.view_width must be > 0");
    if (!(d.view_height.value > 0)) fail(d.view_height.where, "camera.view_height must be > 0");
    if (!(d.projection_distance.value > 0)) fail(d.projection_distance.where, "camera.projection_distance must be > 0");
    Vec3 w = -forward;
    if (d.image_plane_normal.given) {
        require_non_zero(d.image_plane_normal, "camera.image_plane_normal");
        w = normalize(d.image_plane_normal.value);
        if (!(std::fabs(dot(w, forward)) > 1e-9))
            fail(d.image_plane_normal.where, "camera.image_plane_normal is perpendicular to the view direction");
    }
    const Vec3 up_in_plane = d.up.value - w * dot(d.up.value, w);
    if (length(up_in_plane) <= 1e-9 * length(d.up.value))
        fail(d.up.where, "camera.up is parallel to image_plane_normal; pick another up");
    const Vec3 screen_up = normalize(up_in_plane);
    const Vec3 screen_right = cross(screen_up, w);
    camera.forward = forward * d.projection_distance.value;
    camera.right = screen_right * d.view_width.value;
    camera.up = screen_up * d.view_height.value;
}
}  // namespace

Camera make_camera(const CameraDescription& d, int width, int height) {
    // Rays start at the eye (or across an orthographic view), and Embree, in float, stops the
    // program on a ray beyond about 1.8e19: refused with the scene's own range (accelerator_frame.cpp).
    constexpr double max_reach = 1e15;
    const auto far = [](const Vec3& v) {
        return !(std::max({std::fabs(v.x), std::fabs(v.y), std::fabs(v.z)}) <= max_reach);
    };
    if (far(d.eye.value))
        fail(d.eye.where, "camera.eye is beyond 1e15 from the origin; Whitted renders scenes within it");
    if (far(d.look_at.value))
        fail(d.look_at.where, "camera.look_at is beyond 1e15 from the origin; Whitted renders scenes within it");
    if (d.type.value == CameraType::orthographic &&
        !(d.view_width.value <= max_reach && d.view_height.value <= max_reach))
        fail(d.view_width.where, "camera: the orthographic view is wider than 1e15; Whitted renders scenes within it");
    const Vec3 view = d.look_at.value - d.eye.value;
    if (is_zero(view)) fail(d.look_at.where, "camera: look_at must differ from eye");
    if (is_zero(d.up.value)) fail(d.up.where, "camera.up must not be the zero vector");
    const Vec3 forward = normalize(view);
    const Vec3 side = cross(forward, d.up.value);
    if (length(side) <= 1e-9 * length(d.up.value))
        fail(d.up.where, "camera.up is parallel to the view direction (eye → look_at); pick another up");
    // The same construction as POV-Ray's camera with `right -x*W/H`, `sky up` (docs/pov-model.md §4):
    // screen right = normalize(forward × up), screen up = forward × normalize(up × forward).
    const Vec3 right_unit = normalize(side);
    const Vec3 up_unit = cross(forward, normalize(cross(d.up.value, forward)));
    const double aspect = double(width) / double(height);
    Camera camera;
    camera.type = d.type.value;
    camera.eye = d.eye.value;
    if (d.type.value == CameraType::perspective && d.view_height.given) {
        make_window_camera(d, forward, camera);
    } else if (d.type.value == CameraType::perspective) {
        if (!(d.fov.value > 0 && d.fov.value < 180))
            fail(d.fov.where,
                 "camera.fov must be between 0 and 180 degrees (exclusive), got " + std::to_string(d.fov.value));
        const double direction_length = aspect / (2.0 * std::tan(d.fov.value * std::numbers::pi / 360.0));
        camera.forward = forward * direction_length;
        camera.right = right_unit * aspect;
        camera.up = up_unit;
    } else {
        if (!(d.view_width.value > 0)) fail(d.view_width.where, "camera.view_width must be > 0");
        camera.forward = forward;
        camera.right = right_unit * d.view_width.value;
        if (d.view_height.given && !(d.view_height.value > 0))
            fail(d.view_height.where, "camera.view_height must be > 0");
        camera.up = up_unit * (d.view_height.given ? d.view_height.value : d.view_width.value / aspect);
    }
    return camera;
}

namespace {

/// Everything but the objects: image, render settings, camera and lights.
void validate_settings(const SceneDescription& d, Scene& scene) {
    scene.path = d.path;
    const auto& image = d.image;
    if (image.width.value < 1) fail(image.width.where, "image.width must be at least 1");
    if (image.height.value < 1) fail(image.height.where, "image.height must be at least 1");
    if (image.width.value > limits::max_image_side || image.height.value > limits::max_image_side ||
        image.width.value * image.height.value > limits::max_image_pixels)
        fail(image.width.where, "image is " + std::to_string(image.width.value) + "x" +
                                    std::to_string(image.height.value) + "; the limit is " +
                                    std::to_string(limits::max_image_side) + " per side and " +
                                    std::to_string(limits::max_image_pixels) + " pixels");
    if (image.samples.value < 1 || image.samples.value > limits::max_samples)
        fail(image.samples.where, "image.samples must be between 1 and " + std::to_string(limits::max_samples));
    require_non_negative(image.background, "image.background");
    if (d.max_depth.value < 1 || d.max_depth.value > limits::max_depth)
        fail(d.max_depth.where, "render.max_depth must be between 1 and " + std::to_string(limits::max_depth));
    require_non_negative(d.ambient, "ambient");
    for (const Located<std::string>& layer : d.layers) {
        try {
            parse_layers({layer.value});
        } catch (const std::invalid_argument& e) {
            fail(layer.where, std::string("render.layers: ") + e.what());
        }
        scene.layers.push_back(layer.value);
    }
    if (!(d.min_weight.value >= 0 && d.min_weight.value <= 1))
        fail(d.min_weight.where, "render.min_weight must be between 0 and 1");
    scene.convention = d.convention.value;
    scene.min_weight = d.min_weight.value;
    scene.intersection = d.intersection.value;
    scene.width = static_cast<int>(image.width.value);
    scene.height = static_cast<int>(image.height.value);
    scene.samples = static_cast<int>(image.samples.value);
    scene.max_depth = static_cast<int>(d.max_depth.value);
    scene.background = image.background.value;
    scene.ambient = d.ambient.value;
    scene.camera = make_camera(d.camera, scene.width, scene.height);

    for (size_t i = 0; i < d.lights.size(); ++i) {
        const LightDescription& light = d.lights[i];
        const std::string what = "lights[" + std::to_string(i) + "]";
        require_non_negative(light.intensity, what + ".intensity");
        Light out;
        out.type = light.type;
        out.intensity = light.intensity.value;
        if (light.type == LightType::point) {
            out.position = light.position.value;
        } else {
            require_non_zero(light.direction, what + ".direction");
            out.toward_light = -unit_direction(light.direction.value);
        }
        scene.lights.push_back(out);
    }
}

void check_triangle_limit(const Scene& scene) {
    if (static_cast<int64_t>(scene.triangle_count()) > limits::max_triangles)
        throw InputError({scene.path}, "the scene has " + std::to_string(scene.triangle_count()) +
                                           " triangles; the limit is " + std::to_string(limits::max_triangles));
}

}  // namespace

Scene validate_scene(const SceneDescription& d) {
    Scene scene;
    SceneBuilder builder(scene);
    for (const ObjectDescription& object : d.objects) builder.add_top_level(object);
    validate_settings(d, scene);
    builder.finish(d);
    check_triangle_limit(scene);
    return scene;
}

namespace {

/// The one pass of load_scene_file/_text: `parse` reads the file, handing each object to the sink.
template <class Parse>
Scene load_scene(const Parse& parse, SceneDescription* settings, const SettingOverrides& overrides) {
    Scene scene;
    SceneBuilder builder(scene);
    const ObjectSink sink = [&](ObjectDescription&& object, size_t) { builder.add_top_level(object); };
    SceneDescription d = parse(&sink);
    apply_overrides(overrides, d);
    validate_settings(d, scene);
    builder.finish(d);
    check_triangle_limit(scene);
    if (settings) *settings = std::move(d);
    return scene;
}

}  // namespace

void apply_overrides(const SettingOverrides& overrides, SceneDescription& d) {
    const SourceLocation where{FileName(overrides.where)};
    const auto set = [&](auto& field, const auto& value) {
        if (!value) return;
        field.value = *value;
        field.where = where;
        field.given = true;
    };
    // One side alone keeps the file's aspect ratio (at least one pixel; a file's own sides are
    // checked below, so a bad one is reported as it stands).
    const int64_t file_width = d.image.width.value, file_height = d.image.height.value;
    const bool file_sides_valid = file_width >= 1 && file_height >= 1;
    // (Clamped far beyond the image limit, so that the rounding stays within int64_t.)
    const auto side = [](int64_t given, int64_t numerator, int64_t denominator) {
        const double exact = double(given) * double(numerator) / double(denominator);
        return std::optional<int64_t>(std::llround(std::clamp(exact, 1.0, 1e15)));
    };
    if (overrides.width && !overrides.height && file_sides_valid && *overrides.width >= 1)
        set(d.image.height, side(*overrides.width, file_height, file_width));
    if (overrides.height && !overrides.width && file_sides_valid && *overrides.height >= 1)
        set(d.image.width, side(*overrides.height, file_width, file_height));
    set(d.image.width, overrides.width);
    set(d.image.height, overrides.height);
    set(d.image.samples, overrides.samples);
    set(d.max_depth, overrides.max_depth);
    set(d.intersection, overrides.intersection);
}

Scene load_scene_file(const std::string& path, SceneDescription* settings, const SettingOverrides& overrides) {
    return load_scene([&](const ObjectSink* sink) { return parse_scene_file(path, sink); }, settings, overrides);
}

Scene load_scene_text(std::string_view text, const std::string& path, SceneDescription* settings,
                      const SettingOverrides& overrides) {
    return load_scene([&](const ObjectSink* sink) { return parse_any_scene_text(text, path, sink); }, settings,
                      overrides);
}

}  // namespace whitted
