// SPDX-License-Identifier: MIT
// Scene format v1 → POV-Ray 3.7 SDL, following docs/pov-model.md: a right-handed camera through
// `right -x·W/H`, lights without falloff, `parallel` lights at Whitted's directional distance,
// max_trace_level = max_depth with adc_bailout 0, and the lecture's material either as one
// texture (recipe A, where exact) or as four layers (recipe B, exact for any RGB ka, kd, ks).
//
// Nothing from the scene file is ever written as SDL text except numbers: names become
// comments only after every character outside a small safe set is replaced.

#include "converters/pov_writer.h"

#include "whitted/compat/povray/tie_order.h"
#include "whitted/core/ray.h"
#include "whitted/geometry/shapes.h"
#include "whitted/output/atomic_files.h"
#include "whitted/scene/mesh_file.h"
#include "whitted/scene/msh_file.h"
#include "whitted/scene/scene.h"
#include "whitted/scene/text_checks.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <stdexcept>

namespace whitted::pov {
namespace {

/// The shortest decimal that reads back as the same double (fmt uses Dragonbox): POV-Ray
/// parses it to exactly the value Whitted uses.
/// Thrown by num(): POV-Ray has no spelling for infinity or NaN, and a finite scene can
/// still overflow once divided or transformed here (ka/kd, 1/p, a product of matrices).
struct NotFinite : std::overflow_error {
    using std::overflow_error::overflow_error;
};

std::string num(double v) {
    if (!std::isfinite(v)) throw NotFinite(fmt::format("{}", v));
    if (v == 0) return "0";  // also turns −0 into 0
    return fmt::format("{}", v);
}
std::string vec(const Vec3& v) {
    return "<" + num(v.x) + ", " + num(v.y) + ", " + num(v.z) + ">";
}
std::string rgb(const Color& c) {
    return "rgb " + vec(c);
}

/// Text from the scene placed in an SDL comment: only characters that cannot end the comment
/// or start a directive survive.
std::string comment_safe(const std::string& text) {
    std::string out;
    for (const unsigned char c : text.substr(0, 200))
        out += (std::isalnum(c) || c == '_' || c == '-' || c == '.' || c == '/' || c == ' ') ? char(c) : '_';
    return out;
}

bool is_grey(const Color& c) {
    return c.x == c.y && c.y == c.z;
}

/// The highlight statement for a finish: Blinn-Phong is `specular s roughness 1/p`, Phong is
/// `phong s phong_size p` (docs/pov-model.md §2).
std::string highlight(Highlight kind, double strength, double p) {
    if (strength == 0) return "specular 0 phong 0";
    if (kind == Highlight::phong) return "specular 0 phong " + num(strength) + " phong_size " + num(p);
    return "phong 0 specular " + num(strength) + " roughness " + num(1.0 / p);
}

std::string mirror(const Color& km) {
    return is_zero(km) ? "" : " reflection { " + rgb(km) + " }";
}

/// A transmitting material (kt, docs/pov-model.md §5) as three layers (top first below, written
/// bottom first) over an interior of index ior, with t1 = t2 = 1/2. POV-Ray weights a layer's ambient and diffuse by
/// its opacity (1 − filter − transmit) and by the filter of the layers above (the product of their filter·colour +
/// transmit), its highlight by that filter only, and traces the refracted ray with the product over all layers, which
/// also filters shadow rays:
///   L1 white at transmit t1, ambient ka/(1 − t1), the highlight ks and the mirror km;
///   L2 kd/(t1·(1 − t2)) at transmit t2: the diffuse term;
///   L3 a pure filter kt/(t1·t2), which makes the product kt.
/// Needs a grey ks (the converter refuses a coloured one with kt) and adc_bailout 0.
std::string transmitting_texture(const Material& m) {
    constexpr double t1 = 0.5, t2 = 0.5;
    // POV-Ray lays each texture statement over the ones before it: bottom layer first.
    return "texture { pigment { rgbf <" + num(m.kt.x / (t1 * t2)) + ", " + num(m.kt.y / (t1 * t2)) + ", " +
           num(m.kt.z / (t1 * t2)) + ", 1> } finish { ambient 0 diffuse 0 specular 0 phong 0 } }\n" +
           "    texture { pigment { rgbt <" + num(m.kd.x / (t1 * (1 - t2))) + ", " + num(m.kd.y / (t1 * (1 - t2))) +
           ", " + num(m.kd.z / (t1 * (1 - t2))) + ", " + num(t2) +
           "> } finish { ambient 0 diffuse 1 brilliance 1 specular 0 phong 0 } }\n" +
           "    texture { pigment { rgbt <1, 1, 1, " + num(t1) + "> } finish { ambient " + rgb(m.ka / (1 - t1)) +
           " diffuse 0 " + highlight(m.highlight, m.ks.x, m.p) + mirror(m.km) + " } }\n" + "    interior { ior " +
           num(m.ior) + " }";
}

/// The lecture's material as POV-Ray texture(s).
std::string texture(const Material& m) {
    if (!is_zero(m.kt)) return transmitting_texture(m);
    // Recipe A (docs/pov-model.md §1a): one texture. POV multiplies ambient and diffuse by the
    // pigment, not the highlight, so it is exact when ks is grey and kd_c > 0 wherever ka_c > 0.
    bool single_texture_exact = is_grey(m.ks);
    for (int c = 0; c < 3; ++c) single_texture_exact &= !(m.ka[c] > 0 && m.kd[c] == 0);
    if (single_texture_exact) {
        if (is_zero(m.kd)) {
            return "texture { pigment { rgb 1 } finish { ambient " + rgb(m.ka) + " diffuse 0 brilliance 1 " +
                   highlight(m.highlight, m.ks.x, m.p) + mirror(m.km) + " } }";
        }
        Color ambient_ratio;
        for (int c = 0; c < 3; ++c) ambient_ratio[c] = m.kd[c] > 0 ? m.ka[c] / m.kd[c] : 0.0;
        return "texture { pigment { " + rgb(m.kd) + " } finish { ambient " + rgb(ambient_ratio) +
               " diffuse 1 brilliance 1 " + highlight(m.highlight, m.ks.x, m.p) + mirror(m.km) + " } }";
    }
    // Recipe B (docs/pov-model.md §1b): four layers, bottom first, with t1 = t2 = 1/2 and s = 1:
    //   L4 opaque black, holds the highlight lobe (never tinted by its own pigment);
    //   L3 a pure filter ks/(t1·t2) that tints L4's highlight to exactly ks;
    //   L2 kd/(t1·(1 − t2)) at transmit t2: the diffuse term;
    //   L1 white at transmit t1 with ambient ka/(1 − t1) and the mirror (reflection is not filtered).
    // Requires adc_bailout 0 (written in global_settings).
    constexpr double t1 = 0.5, t2 = 0.5;
    return "texture { pigment { rgb 0 } finish { ambient 0 diffuse 0 " + highlight(m.highlight, 1.0, m.p) +
           " } }\n    texture { pigment { rgbf <" + num(m.ks.x / (t1 * t2)) + ", " + num(m.ks.y / (t1 * t2)) + ", " +
           num(m.ks.z / (t1 * t2)) + ", 1> } finish { ambient 0 diffuse 0 specular 0 phong 0 } }\n" +
           "    texture { pigment { rgbt <" + num(m.kd.x / (t1 * (1 - t2))) + ", " + num(m.kd.y / (t1 * (1 - t2))) +
           ", " + num(m.kd.z / (t1 * (1 - t2))) + ", " + num(t2) +
           "> } finish { ambient 0 diffuse 1 brilliance 1 specular 0 phong 0 } }\n" +
           "    texture { pigment { rgbt <1, 1, 1, " + num(t1) + "> } finish { ambient " + rgb(m.ka / (1 - t1)) +
           " diffuse 0 specular 0 phong 0" + mirror(m.km) + " } }";
}

/// POV-Ray multiplies row vectors by its matrix: its rows are our columns, then the translation.
std::string matrix(const Transform& t) {
    if (t.is_identity()) return "";
    const auto& m = t.rows();
    return " matrix <" + num(m[0]) + ", " + num(m[4]) + ", " + num(m[8]) + ", " + num(m[1]) + ", " + num(m[5]) + ", " +
           num(m[9]) + ", " + num(m[2]) + ", " + num(m[6]) + ", " + num(m[10]) + ", " + num(m[3]) + ", " + num(m[7]) +
           ", " + num(m[11]) + ">";
}

/// Walks the description as validate_scene does (same transforms, same materials), writing SDL.
class SdlWriter {
public:
    SdlWriter(const SceneDescription& description, std::string& out) : m_description(description), m_out(out) {
        for (const auto& material : description.materials) m_named[material.name] = to_material(material);
    }

    void objects(const std::vector<ObjectDescription>& list, const Transform& parent) {
        for (const auto& object : list) write(object, parent);
    }

    /// Each prototype as POV-Ray shares it: every mesh2 of it `#declare`d once, in the
    /// prototype's space and without a texture, so that each instance (`object { NAME ... }`)
    /// gives its own texture and transform while POV-Ray keeps one copy of the triangles
    /// (copies of a mesh share its data). Only prototypes that some instance places.
    void prototype_declarations() {
        const auto& prototypes = m_description.prototypes;
        m_pieces.assign(prototypes.size(), {});
        // Whether an instance in `list` (or in its groups) places prototype `name`; with
        // `without_material`, one that gives no material of its own: only then do the defaults
        // of the prototype's OBJ files show (and their warnings say something true).
        std::function<bool(const std::vector<ObjectDescription>&, const std::string&, bool)> places =
            [&](const auto& list, const std::string& name, bool without_material) {
                for (const auto& object : list)
                    if ((object.type == ObjectType::instance && object.prototype.value == name &&
                         !(without_material && object.material)) ||
                        places(object.children, name, without_material))
                        return true;
                return false;
            };
        for (size_t i = 0; i < prototypes.size(); ++i) {
            if (!places(m_description.objects, prototypes[i].name, false)) continue;
            m_out += "// prototype " + comment_safe(prototypes[i].name) + "\n";
            m_collect = &m_pieces[i];
            m_collect_shows_defaults = places(m_description.objects, prototypes[i].name, true);
            write(prototypes[i].object, Transform());
            m_collect = nullptr;
            for (size_t k = 0; k < m_pieces[i].size(); ++k) {
                m_out += "#declare " + piece_name(i, k) + " =\n" + m_pieces[i][k].sdl;
                m_pieces[i][k].sdl.clear();
            }
        }
    }

private:
    /// One mesh2 of a prototype: its SDL (until declared) and its own material, if it has one.
    struct Piece {
        std::string sdl;
        std::optional<Material> material;
    };

    static std::string piece_name(size_t prototype, size_t piece) {
        return "whitted_prototype_" + std::to_string(prototype) + "_" + std::to_string(piece);
    }

    void instance(const ObjectDescription& object, const Transform& to_world) {
        size_t index = 0;
        while (m_description.prototypes[index].name != object.prototype.value) ++index;  // validate_scene checked it
        const std::vector<Piece>& pieces = m_pieces[index];
        const std::optional<Material> override =
            object.material ? std::optional<Material>(material_of(object)) : std::nullopt;
        const auto placed = [&](size_t k) {
            return "object { " + piece_name(index, k) + "\n    " + texture(override ? *override : *pieces[k].material);
        };
        if (pieces.size() == 1) {
            m_out += placed(0) + "\n   " + matrix(to_world) + " }\n";
            return;
        }
        m_out += "union {\n";
        for (size_t k = 0; k < pieces.size(); ++k) m_out += "  " + placed(k) + " }\n";
        m_out += " " + matrix(to_world) + " }\n";
    }

    static Material to_material(const MaterialDescription& d) {
        Material m{d.ka.value, d.kd.value, d.ks.value, d.p.value, d.km.value, d.highlight.value};
        m.kt = d.kt.value;
        m.ior = d.ior.value;
        return m;
    }

    /// In a prototype a mesh may leave its material to the instances.
    std::optional<Material> material_if_given(const ObjectDescription& object) const {
        if (!object.material) return std::nullopt;
        return material_of(object);
    }

    Material material_of(const ObjectDescription& object) const {
        const MaterialReference& reference = *object.material;  // validate_scene has checked it is there
        if (reference.inline_) return to_material(*reference.inline_);
        return m_named.at(reference.name);
    }

    void write(const ObjectDescription& object, const Transform& parent) {
        const Transform to_world = make_transform(object.transform).then(parent);
        switch (object.type) {
            case ObjectType::sphere:
                m_out += "sphere { " + vec(object.center.value) + ", " + num(object.radius.value) + "\n    " +
                         texture(material_of(object)) + "\n   " + matrix(to_world) + " }\n";
                break;
            case ObjectType::box:
                box(object, to_world);
                break;
            case ObjectType::cylinder:
                // POV-Ray's own cylinder: base, cap, radius, `open` for no end caps.
                m_out += "cylinder { " + vec(object.base.value) + ", " + vec(object.cap.value) + ", " +
                         num(object.radius.value) + (object.open.value ? " open" : "") + "\n    " +
                         texture(material_of(object)) + "\n   " + matrix(to_world) + " }\n";
                break;
            case ObjectType::cone:
                m_out += "cone { " + vec(object.base.value) + ", " + num(object.base_radius.value) + ", " +
                         vec(object.cap.value) + ", " + num(object.cap_radius.value) +
                         (object.open.value ? " open" : "") + "\n    " + texture(material_of(object)) + "\n   " +
                         matrix(to_world) + " }\n";
                break;
            case ObjectType::plane: {
                // World-space plane computed exactly as Whitted does; POV's `plane { n, d }` is n·x = d.
                const Vec3 normal = unit_direction(to_world.apply_normal(object.normal.value));
                const Vec3 point = to_world.apply_point(object.point.value);
                m_out += "plane { " + vec(normal) + ", " + num(dot(normal, point)) + "\n    " +
                         texture(material_of(object)) + " }\n";
                break;
            }
            case ObjectType::triangle:
                mesh(object.vertices, {}, {{0, 1, 2}}, to_world, material_if_given(object));
                break;
            case ObjectType::mesh:
                if (object.file.given)
                    mesh_file(object, to_world);
                else
                    mesh(object.vertices, object.normals, object.triangles, to_world, material_if_given(object));
                break;
            case ObjectType::group:
                objects(object.children, to_world);
                break;
            case ObjectType::instance:
                instance(object, to_world);
                break;
        }
    }

    /// A box, in a union that gives POV-Ray a bounding box sure to hold it. POV-Ray keeps each
    /// object's bounding box in single precision, its corner and size each rounded to the
    /// nearest float, and tests rays against it with no margin; a ray that crosses the box only
    /// where that rounding cut the box off (along an edge) is never tested against the box
    /// (a ray 1.4e-8 above a face's lower edge, at 1e1, passed under the box in POV-Ray; at 1e5
    /// the cut is 0.0078 wide). A union's bounding box holds those of its children, so two
    /// spheres of radius 0 (which no ray hits: POV-Ray's test needs a half chord² > 1e-10) at
    /// the corners of the box's world bounds, pushed out by 8 to 16 floats' spacing, make the
    /// union's box hold the whole box (povray_box_corners, which PovrayTestOrder also uses to
    /// rebuild POV-Ray's bounding boxes). `split_union off` keeps POV-Ray from replacing the
    /// union by its children; a union tests its children without their own bounding boxes.
    void box(const ObjectDescription& object, const Transform& to_world) {
        Vec3 lo, hi;
        povray_box_corners(to_world, object.min.value, object.max.value, lo, hi);
        m_out += "union { box { " + vec(object.min.value) + ", " + vec(object.max.value) + "\n    " +
                 texture(material_of(object)) + "\n   " + matrix(to_world) + " }\n    sphere { " + vec(lo) +
                 ", 0 } sphere { " + vec(hi) + ", 0 } split_union off }\n";
    }

    void mesh_file(const ObjectDescription& object, const Transform& to_world) {
        const bool msh = std::filesystem::path(object.file_path).extension() == ".msh";
        // As validate_scene loads it: with the object's own material the MTL files are not read.
        const MeshData data = msh ? load_msh_mesh(object.file_path, object.file.where)
                                  : load_obj_mesh(object.file_path, object.file.where, 0, !object.material);
        if (!m_collect || m_collect_shows_defaults) print_mesh_warnings(data);
        std::vector<Vec3> vertices, normals;
        for (size_t i = 0; i < data.positions.size() / 3; ++i)
            vertices.push_back({data.positions[3 * i], data.positions[3 * i + 1], data.positions[3 * i + 2]});
        for (size_t i = 0; i < data.normals.size() / 3; ++i)
            normals.push_back({data.normals[3 * i], data.normals[3 * i + 1], data.normals[3 * i + 2]});
        // One mesh2 per material: the MTL's, or the scene's override for all faces.
        std::map<int32_t, std::vector<std::array<int64_t, 3>>> by_material;
        for (size_t t = 0; t < data.indices.size() / 3; ++t) {
            const int32_t m = object.material ? -1 : data.triangle_material[t];
            by_material[m].push_back({data.indices[3 * t], data.indices[3 * t + 1], data.indices[3 * t + 2]});
        }
        for (const auto& [m, triangles] : by_material) {
            const MaterialDescription* mtl = m >= 0 ? &data.materials[size_t(m)] : nullptr;
            mesh(vertices, normals, triangles, to_world,
                 mtl ? std::optional<Material>(to_material(*mtl)) : material_if_given(object));
        }
    }

    /// A mesh2 in world space: vertices and normals transformed in double exactly as Whitted
    /// does, written about the point Whitted stores the mesh about (mesh_origin, scene.h) as the
    /// floats Whitted keeps, and moved there with `translate`: so the two renderers see the same
    /// triangles. About its own centre a far mesh also keeps its precision in POV-Ray, which
    /// holds each triangle's plane as a float normal and a float distance from the mesh's origin
    /// (spaced 1e-3 at 1e4 in world coordinates: self-shadowing speckles); the ray is moved into
    /// the mesh's frame in double.
    void mesh(const std::vector<Vec3>& vertices, const std::vector<Vec3>& normals,
              const std::vector<std::array<int64_t, 3>>& triangles, const Transform& to_world,
              const std::optional<Material>& material) {
        // In a prototype (m_collect) the mesh2 goes to its piece, without a texture: each
        // instance gives its own.
        std::string piece;
        std::string& o = m_collect ? piece : m_out;
        std::vector<Vec3> world;
        world.reserve(vertices.size());
        constexpr double inf = std::numeric_limits<double>::infinity();
        Vec3 lo(inf), hi(-inf);
        for (const Vec3& v : vertices) {
            world.push_back(to_world.apply_point(v));
            lo = min(lo, world.back()), hi = max(hi, world.back());
        }
        const Vec3 centre = mesh_origin(lo, hi);
        for (Vec3& w : world) {
            const Vec3 offset = w - centre;
            w = {float_rounded(offset.x), float_rounded(offset.y), float_rounded(offset.z)};  // the stored floats
        }
        o += "mesh2 {\n  vertex_vectors { " + std::to_string(vertices.size());
        for (const Vec3& w : world) o += ",\n    " + vec(w);
        o += " }\n";
        if (!normals.empty()) {
            o += "  normal_vectors { " + std::to_string(normals.size());
            for (const Vec3& n : normals) {
                const Vec3 w = to_world.apply_normal(n);
                const double len = length(w);
                const Vec3 unit = len > 0 ? w / len : Vec3(1, 0, 0);
                o += ",\n    " + vec({float_rounded(unit.x), float_rounded(unit.y), float_rounded(unit.z)});
            }
            o += " }\n";
        }
        o += "  face_indices { " + std::to_string(triangles.size());
        for (const auto& t : triangles)
            o += ",\n    <" + std::to_string(t[0]) + ", " + std::to_string(t[1]) + ", " + std::to_string(t[2]) + ">";
        o += " }\n";
        // Any inside_vector makes POV-Ray's mesh2 report every crossing of a ray, not only its
        // nearest: without one, Mesh::intersect_bbox_tree stops at the first triangle hit, so a
        // crossing the shadow test then throws away (t <= 1e-3) hid a farther one that blocks
        // the light, and one below 1e-4 hid the next for camera and mirror rays. Whitted takes
        // the nearest crossing inside each ray's window; with every crossing reported, POV-Ray's
        // windows pick the same one (docs/pov-model.md §3). The vector itself only serves
        // POV-Ray's inside test, which nothing here uses.
        o += "  inside_vector <0, 0, 1>\n";
        if (!m_collect) o += "  " + texture(*material) + "\n";  // validate_scene checked it is there
        if (!(centre == Vec3(0.0))) o += "  translate " + vec(centre) + "\n";
        o += "}\n";
        if (m_collect) m_collect->push_back({std::move(piece), material});
    }

    const SceneDescription& m_description;
    std::string& m_out;
    std::map<std::string, Material> m_named;
    std::vector<std::vector<Piece>> m_pieces;  ///< per prototype: its declared mesh2s
    std::vector<Piece>* m_collect = nullptr;   ///< the prototype being declared, or null
    bool m_collect_shows_defaults = false;     ///< an instance without a material places it
};

double max_channel(const Color& c) {
    return std::max({c.x, c.y, c.z});
}

}  // namespace

double radiance_upper_bound(const SceneDescription& d) {
    Color light_sum(0.0);
    for (const auto& light : d.lights) light_sum += light.intensity.value;
    std::vector<MaterialDescription> materials = d.materials;
    std::function<void(const std::vector<ObjectDescription>&)> collect = [&](const auto& objects) {
        for (const auto& object : objects) {
            if (object.material && object.material->inline_) materials.push_back(*object.material->inline_);
            collect(object.children);
        }
    };
    collect(d.objects);
    std::vector<ObjectDescription> prototype_objects;
    for (const auto& prototype : d.prototypes) prototype_objects.push_back(prototype.object);
    collect(prototype_objects);
    double local = 0, mirror = 0;
    for (const auto& m : materials) {
        local = std::max(local, max_channel(m.ka.value * d.ambient.value + (m.kd.value + m.ks.value) * light_sum));
        // Where a ray is both reflected and refracted, both paths may come back at the bound;
        // at total internal reflection POV-Ray brings the light back with weight 1.
        mirror = std::max(mirror, is_zero(m.kt.value) ? max_channel(m.km.value)
                                                      : std::max(1.0, max_channel(m.km.value + m.kt.value)));
    }
    // Meshes from files bring their own MTL materials; without reading them, assume the worst.
    std::function<bool(const std::vector<ObjectDescription>&)> has_mtl = [&](const auto& objects) {
        for (const auto& object : objects)
            if ((object.type == ObjectType::mesh && object.file.given && !object.material) || has_mtl(object.children))
                return true;
        return false;
    };
    if (has_mtl(d.objects) || has_mtl(prototype_objects)) return INFINITY;
    const double background = max_channel(d.image.background.value);
    double bound = std::max(background, local);
    for (int64_t depth = 2; depth <= d.max_depth.value; ++depth) bound = std::max(background, local + mirror * bound);
    return bound;
}

static std::string write_sdl(const SceneDescription& d, const ConvertOptions& options);

std::string scene_to_sdl(const SceneDescription& d, const ConvertOptions& options) {
    try {
        return write_sdl(d, options);
    } catch (const NotFinite& e) {
        throw InputError({d.path}, std::string("cannot convert to POV-Ray: a value becomes ") + e.what() +
                                       " once divided or transformed (ka/kd, 1/p, nested transforms); "
                                       "POV-Ray cannot read it");
    }
}

/// What POV-Ray 3.7 cannot render the same way, refused at the place it is written (the
/// Cornell course's conventions, docs/course-format.md): POV-Ray always turns normals toward the
/// ray and has no shadow-ray span, path-weight cut-off, window camera or (1 − F)-weighted
/// substrate that have been checked against it.
static void refuse_inexpressible(const SceneDescription& d) {
    const auto refuse = [](const SourceLocation& where, const std::string& what) {
        throw InputError(where, "cannot convert to POV-Ray: " + what);
    };
    if (d.convention.value != Convention::pov)
        refuse(d.convention.where,
               "render.convention: course (normals as given, not turned toward the viewer, and "
               "the course's shadow rays) has no POV-Ray equivalent");
    if (d.min_weight.value != 0)
        refuse(d.min_weight.where, "render.min_weight (a path-weight cut-off) has no exact POV-Ray equivalent");
    const CameraDescription& c = d.camera;
    if (c.view_height.given && c.type.value == CameraType::perspective && c.image_plane_normal.given)
        refuse(c.image_plane_normal.where,
               "camera.image_plane_normal (an oblique window camera) has no POV-Ray equivalent");
    std::function<void(const MaterialDescription&)> material = [&](const MaterialDescription& m) {
        if (!is_zero(m.kt.value) && !is_grey(m.ks.value))
            refuse(m.ks.where,
                   "a coloured ks on a transmitting material (kt): POV-Ray's layered texture for kt "
                   "gives a grey highlight only");
        if (m.fresnel_ior.given)
            refuse(m.fresnel_ior.where,
                   "fresnel_ior (Schlick-weighted mirror over a (1 - F)-weighted substrate) has "
                   "no POV-Ray equivalent checked against Whitted");
    };
    for (const auto& m : d.materials) material(m);
    std::function<void(const std::vector<ObjectDescription>&)> objects = [&](const auto& list) {
        for (const auto& object : list) {
            if (object.material && object.material->inline_) material(*object.material->inline_);
            objects(object.children);
        }
    };
    objects(d.objects);
    for (const auto& prototype : d.prototypes) objects({prototype.object});
}

static std::string write_sdl(const SceneDescription& d, const ConvertOptions& options) {
    refuse_inexpressible(d);
    const double exposure = options.exposure;
    const double aspect = double(d.image.width.value) / double(d.image.height.value);
    std::string o;
    o += "// POV-Ray 3.7 scene written by `whitted convert` from " + comment_safe(d.path) + " (scene format v1).\n";
    o += "// Render it with the .ini beside it (deterministic, linear); see docs/validation.md.\n";
    o += "#version 3.7;\n";
    o += "global_settings {\n  assumed_gamma 1.0\n  ambient_light " + rgb(d.ambient.value * exposure) +
         "\n  max_trace_level " + std::to_string(d.max_depth.value) + "\n  adc_bailout 0\n}\n";
    o += "background { " + rgb(d.image.background.value * exposure) + " }\n";

    const CameraDescription& c = d.camera;
    if (c.type.value == CameraType::perspective && c.view_height.given) {
        // The window camera, its window across the view direction: POV-Ray's own vectors, their
        // lengths the window's size and distance (no `angle`), turned by look_at and sky.
        o += "camera {\n  perspective\n  location " + vec(c.eye.value) + "\n  right <" + num(-c.view_width.value) +
             ", 0, 0>\n  up <0, " + num(c.view_height.value) + ", 0>\n  direction <0, 0, " +
             num(c.projection_distance.value) + ">\n  sky " + vec(c.up.value) + "\n  look_at " + vec(c.look_at.value) +
             "\n}\n";
    } else if (c.type.value == CameraType::perspective) {
        // `right -x·W/H` makes POV-Ray's camera right-handed (docs/pov-model.md §4); `angle` is the horizontal fov.
        o += "camera {\n  perspective\n  location " + vec(c.eye.value) + "\n  right <" + num(-aspect) +
             ", 0, 0>\n  up <0, 1, 0>\n  sky " + vec(c.up.value) + "\n  angle " + num(c.fov.value) + "\n  look_at " +
             vec(c.look_at.value) + "\n}\n";
    } else {
        // Explicit right/up and no angle: their lengths are the view's extent in world units.
        o += "camera {\n  orthographic\n  location " + vec(c.eye.value) + "\n  right <" + num(-c.view_width.value) +
             ", 0, 0>\n  up <0, " + num(c.view_height.given ? c.view_height.value : c.view_width.value / aspect) +
             ", 0>\n  sky " + vec(c.up.value) + "\n  look_at " + vec(c.look_at.value) + "\n}\n";
    }

    // Lights and objects go inside one light_group, whose lights light only its objects (here:
    // all of them), because POV-Ray keeps no shadow cache for a light-group light. Outside a
    // light_group POV-Ray first re-tests the object that last blocked the same light, accepting
    // it from t = 1e-4 instead of the 1e-3 its full shadow test (and Whitted) uses, so a pixel's
    // shadow would depend on which pixel POV-Ray shaded before it (docs/pov-model.md §3).
    SdlWriter writer(d, o);
    writer.prototype_declarations();
    const bool light_group = !d.lights.empty() && !d.objects.empty();
    if (light_group) o += "light_group {\n";
    for (const auto& light : d.lights) {
        const Color intensity = light.intensity.value * exposure;
        if (light.type == LightType::point) {
            o += "light_source { " + vec(light.position.value) + " color " + rgb(intensity) + " }\n";
        } else {
            // A parallel light aimed at the origin from directional_light_distance away: POV-Ray
            // then limits shadow rays exactly as Whitted does (ray.h).
            const Vec3 toward_light = -unit_direction(light.direction.value);
            o += "light_source { " + vec(toward_light * ray_limits::directional_light_distance) + " color " +
                 rgb(intensity) + " parallel point_at <0, 0, 0> }\n";
        }
    }
    writer.objects(d.objects, Transform());
    if (light_group) o += "  global_lights off\n}\n";
    return o;
}

std::string ini_for(const SceneDescription& d, const std::string& pov_file, const std::string& image_file,
                    const ConvertOptions& options) {
    for (const std::string* name : {&pov_file, &image_file})
        if (name->find_first_of("\"\n\r;") != std::string::npos)
            throw std::invalid_argument("file name '" + comment_safe(*name) +
                                        "' contains characters a POV-Ray .ini cannot hold (quote, newline, ';')");
    const int64_t n = d.image.samples.value;
    std::string o;
    o += "; POV-Ray 3.7 options written by `whitted convert`: deterministic, linear output.\n";
    if (n > 1)
        o += "; image.samples = " + std::to_string(n) + ": rendered at " + std::to_string(n) +
             "x the size; average each " + std::to_string(n) + "x" + std::to_string(n) +
             " block for Whitted's box filter.\n";
    o += "Input_File_Name=\"" + pov_file + "\"\n";
    o += "Output_File_Name=\"" + image_file + "\"\n";
    o += "+W" + std::to_string(d.image.width.value * n) + " +H" + std::to_string(d.image.height.value * n) +
         " -D -A +Q9\n";
    o += options.hdr_output ? "+FE\n" : "+FN16\nFile_Gamma=1.0\n";
    return o;
}

void check_pov_file_name(const std::string& pov_path) {
    const std::string name = std::filesystem::path(pov_path).filename().string();
    for (const unsigned char c : name)
        if (c < 0x20 || c > 0x7E || c == '"' || c == '\\')
            throw std::invalid_argument("cannot convert to '" + printable(pov_path, 4096) +
                                        "': POV-Ray 3.7 opens only files whose names are plain ASCII, without "
                                        "quotes or backslashes; choose another name for the .pov file");
}

std::string write_pov_files(const SceneDescription& d, const std::string& pov_path, const ConvertOptions& given) {
    check_pov_file_name(pov_path);
    ConvertOptions options = given;
    if (!given.hdr_output && radiance_upper_bound(d) * options.exposure > 1.0) options.hdr_output = true;
    const std::filesystem::path pov(pov_path);
    std::filesystem::path ini = pov;
    ini.replace_extension(".ini");
    std::filesystem::path image = pov.filename();
    image.replace_extension(options.hdr_output ? ".exr" : ".png");
    const std::string sdl = scene_to_sdl(d, options);
    const std::string ini_text = ini_for(d, pov.filename().string(), image.string(), options);
    // Both files appear complete or not at all, even if the program is interrupted or killed.
    write_files_atomically({{pov, sdl}, {ini, ini_text}});
    return ini.string();
}

}  // namespace whitted::pov
