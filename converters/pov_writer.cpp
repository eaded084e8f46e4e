// SPDX-License-Identifier: MIT
// Scene format v1 → POV-Ray 3.7 SDL, following docs/pov-model.md: a right-handed camera through
// `right -x·W/H`, lights without falloff, `parallel` lights at Whitted's directional distance,
// max_trace_level = max_depth with adc_bailout 0, and the lecture's material either as one
// texture (recipe A, where exact) or as four layers (recipe B, exact for any RGB ka, kd, ks).
//
// Nothing from the scene file is ever written as SDL text except numbers: names become
// comments only after every character outside a small safe set is replaced.

#include "converters/pov_writer.h"

#include "compat/povray/tie_order.h"
#include "core/ray.h"
#include "geometry/shapes.h"
#include "output/atomic_files.h"
#include "scene/scene.h"
#include "scene/text_checks.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <span>
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

/// Writes the objects of the Scene that validate_scene (or load_scene_file) built from the
/// description: its one walk of the description has folded every transform, resolved every
/// material and read every mesh file, so the SDL holds the very numbers Whitted renders (the
/// world-space planes, the float vertices about each mesh's origin) and no file is read here.
class SdlWriter {
public:
    SdlWriter(const SceneDescription& description, const Scene& scene, std::string& out) : m_scene(scene), m_out(out) {
        // The cylinders' and cones' caps as the file gives them: the Scene keeps the base, the
        // unit axis and the height, whose sum rounds. Prototypes hold no cones, so the
        // description's, in file order, are the Scene's.
        for_each_object(description.objects, [&](const ObjectDescription& object) {
            if (const auto* cylinder = std::get_if<CylinderShape>(&object.shape))
                m_caps.push_back(cylinder->cap.value);
            else if (const auto* cone = std::get_if<ConeShape>(&object.shape))
                m_caps.push_back(cone->cap.value);
        });
        // Each object's place in the list of its kind (objects are numbered from 1, file order).
        m_shape.assign(scene.objects.size(), 0);
        const auto number = [&](const auto& shapes) {
            for (size_t i = 0; i < shapes.size(); ++i)
                if (shapes[i].object != 0) m_shape[shapes[i].object - 1] = static_cast<uint32_t>(i);
        };
        number(scene.spheres), number(scene.boxes), number(scene.cones), number(scene.planes);
        number(scene.meshes), number(scene.instances);
    }

    /// The scene's objects, in file order (depth first through groups).
    void objects() {
        for (size_t id = 0; id < m_scene.objects.size(); ++id) {
            const uint32_t i = m_shape[id];
            switch (m_scene.objects[id].type) {
                case ObjectType::sphere: {
                    const Sphere& s = m_scene.spheres[i];
                    m_out += "sphere { " + vec(s.center) + ", " + num(s.radius) + "\n    " +
                             texture(m_scene.materials[s.material]) + "\n   " +
                             matrix(transform_of(s.object_to_world)) + " }\n";
                    break;
                }
                case ObjectType::box:
                    box(m_scene.boxes[i]);
                    break;
                case ObjectType::cylinder: {
                    // POV-Ray's own cylinder: base, cap, radius, `open` for no end caps.
                    const Cone& c = m_scene.cones[i];
                    m_out += "cylinder { " + vec(c.base) + ", " + vec(cap(i)) + ", " + num(c.base_radius) +
                             (c.open ? " open" : "") + "\n    " + texture(m_scene.materials[c.material]) + "\n   " +
                             matrix(transform_of(c.object_to_world)) + " }\n";
                    break;
                }
                case ObjectType::cone: {
                    const Cone& c = m_scene.cones[i];
                    m_out += "cone { " + vec(c.base) + ", " + num(c.base_radius) + ", " + vec(cap(i)) + ", " +
                             num(c.cap_radius) + (c.open ? " open" : "") + "\n    " +
                             texture(m_scene.materials[c.material]) + "\n   " +
                             matrix(transform_of(c.object_to_world)) + " }\n";
                    break;
                }
                case ObjectType::plane: {
                    // Whitted's world-space plane; POV's `plane { n, d }` is n·x = d.
                    const Plane& p = m_scene.planes[i];
                    m_out += "plane { " + vec(p.normal) + ", " + num(dot(p.normal, p.point)) + "\n    " +
                             texture(m_scene.materials[p.material]) + " }\n";
                    break;
                }
                case ObjectType::triangle:
                case ObjectType::mesh:
                    for (const Part& part : parts(m_scene.meshes[i])) mesh(m_scene.meshes[i], part);
                    break;
                case ObjectType::instance:
                    instance(m_scene.instances[i]);
                    break;
                case ObjectType::group:  // never an object: its members are
                    break;
            }
        }
    }

    /// Each prototype as POV-Ray shares it: every mesh2 of it `#declare`d once, in the
    /// prototype's space and without a texture, so that each instance (`object { NAME ... }`)
    /// gives its own texture and transform while POV-Ray keeps one copy of the triangles
    /// (copies of a mesh share its data). Only prototypes that some instance places.
    void prototype_declarations() {
        const auto& prototypes = m_scene.prototypes;
        m_pieces.assign(prototypes.size(), {});
        std::vector<bool> placed(prototypes.size(), false);
        for (const Instance& instance : m_scene.instances) placed[instance.prototype] = true;
        for (size_t i = 0; i < prototypes.size(); ++i) {
            if (!placed[i]) continue;
            m_out += "// prototype " + comment_safe(prototypes[i].name) + "\n";
            m_collect = &m_pieces[i];
            for (const TriangleMesh& triangles : prototypes[i].meshes)
                for (const Part& part : parts(triangles)) mesh(triangles, part);
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

    /// The triangles of a mesh that share a material: one mesh2 each (a mesh from a file with
    /// its MTL materials becomes one mesh2 per material, each with all the mesh's vertices).
    struct Part {
        std::vector<std::array<uint32_t, 3>> triangles;
        uint32_t material = Instance::no_material;  ///< no_material: left to each instance
    };

    /// In the order of the materials' numbers: an OBJ file's MTL materials are numbered in the
    /// order the file lists them.
    static std::vector<Part> parts(const TriangleMesh& mesh) {
        std::map<uint32_t, std::vector<std::array<uint32_t, 3>>> by_material;
        for (size_t t = 0; t < mesh.triangle_count(); ++t)
            by_material[mesh.triangle_materials.empty() ? mesh.material : mesh.triangle_materials[t]].push_back(
                {mesh.indices[3 * t], mesh.indices[3 * t + 1], mesh.indices[3 * t + 2]});
        std::vector<Part> out;
        for (auto& [material, triangles] : by_material) out.push_back({std::move(triangles), material});
        return out;
    }

    /// A description whose objects went into the Scene as they were read (load_scene_file's
    /// `settings`) holds none: its cones' caps are then base + height·axis, to a rounding.
    Vec3 cap(uint32_t cone) const {
        const Cone& c = m_scene.cones[cone];
        return cone < m_caps.size() ? m_caps[cone] : c.base + c.axis * c.height;
    }

    std::optional<Material> material_if_any(uint32_t material) const {
        if (material == Instance::no_material) return std::nullopt;
        return m_scene.materials[material];
    }

    static std::string piece_name(size_t prototype, size_t piece) {
        return "whitted_prototype_" + std::to_string(prototype) + "_" + std::to_string(piece);
    }

    void instance(const Instance& placement) {
        const size_t index = placement.prototype;
        const std::vector<Piece>& pieces = m_pieces[index];
        const std::optional<Material> override = material_if_any(placement.material);
        const auto placed = [&](size_t k) {
            return "object { " + piece_name(index, k) + "\n    " + texture(override ? *override : *pieces[k].material);
        };
        if (pieces.size() == 1) {
            m_out += placed(0) + "\n   " + matrix(placement.object_to_world) + " }\n";
            return;
        }
        m_out += "union {\n";
        for (size_t k = 0; k < pieces.size(); ++k) m_out += "  " + placed(k) + " }\n";
        m_out += " " + matrix(placement.object_to_world) + " }\n";
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
    void box(const Box& b) {
        const Transform& to_world = transform_of(b.object_to_world);
        Vec3 lo, hi;
        povray_box_corners(to_world, b.min, b.max, lo, hi);
        m_out += "union { box { " + vec(b.min) + ", " + vec(b.max) + "\n    " + texture(m_scene.materials[b.material]) +
                 "\n   " + matrix(to_world) + " }\n    sphere { " + vec(lo) + ", 0 } sphere { " + vec(hi) +
                 ", 0 } split_union off }\n";
    }

    /// A mesh2 of Whitted's triangles: its vertices written as the float offsets Whitted stores
    /// (world space, or the prototype's space, already transformed in double) and moved by
    /// `translate` to the point they are stored about (mesh_origin, scene.h), so the two
    /// renderers see the same triangles. About its own centre a far mesh also keeps its
    /// precision in POV-Ray, which holds each triangle's plane as a float normal and a float
    /// distance from the mesh's origin (spaced 1e-3 at 1e4 in world coordinates:
    /// self-shadowing speckles); the ray is moved into the mesh's frame in double.
    void mesh(const TriangleMesh& triangles, const Part& part) {
        // In a prototype (m_collect) the mesh2 goes to its piece, without a texture: each
        // instance gives its own.
        std::string piece;
        std::string& o = m_collect ? piece : m_out;
        o += "mesh2 {\n  vertex_vectors { " + std::to_string(triangles.vertex_count());
        for (size_t i = 0; i < triangles.vertex_count(); ++i) o += ",\n    " + vec(triangles.offset(i));
        o += " }\n";
        if (!triangles.normals.empty()) {
            const size_t count = triangles.normals.size() / 3;
            o += "  normal_vectors { " + std::to_string(count);
            for (size_t i = 0; i < count; ++i) {
                const float* n = &triangles.normals[3 * i];
                // Whitted keeps a zero normal (shading then takes the face's); POV-Ray needs a
                // direction, and any unit one serves where the face's normal is used.
                const bool zero = n[0] == 0 && n[1] == 0 && n[2] == 0;
                o += ",\n    " + vec(zero ? Vec3(1, 0, 0) : Vec3(n[0], n[1], n[2]));
            }
            o += " }\n";
        }
        o += "  face_indices { " + std::to_string(part.triangles.size());
        for (const auto& t : part.triangles)
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
        // Outside a prototype every triangle has a material (validate_scene checked it).
        if (!m_collect) o += "  " + texture(m_scene.materials[part.material]) + "\n";
        if (!(triangles.origin == Vec3(0.0))) o += "  translate " + vec(triangles.origin) + "\n";
        o += "}\n";
        if (m_collect) m_collect->push_back({std::move(piece), material_if_any(part.material)});
    }

    const Scene& m_scene;
    std::string& m_out;
    std::vector<uint32_t> m_shape;             ///< per object (number − 1): its index in its kind's list
    std::vector<Vec3> m_caps;                  ///< per cone or cylinder, as written
    std::vector<std::vector<Piece>> m_pieces;  ///< per prototype: its declared mesh2s
    std::vector<Piece>* m_collect = nullptr;   ///< the prototype being declared, or null
};

double max_channel(const Color& c) {
    return std::max({c.x, c.y, c.z});
}

}  // namespace

double radiance_upper_bound(const SceneDescription& d) {
    Color light_sum(0.0);
    for (const auto& light : d.lights) light_sum += light.intensity.value;
    std::vector<MaterialDescription> materials = d.materials;
    // Meshes from files bring their own MTL materials; without reading them, assume the worst.
    bool has_mtl = false;
    const auto collect = [&](const ObjectDescription& object) {
        if (object.material && object.material->inline_) materials.push_back(*object.material->inline_);
        const auto* mesh = std::get_if<MeshShape>(&object.shape);
        if (mesh && mesh->file.given && !object.material) has_mtl = true;
    };
    for_each_object(d.objects, collect);
    for (const auto& prototype : d.prototypes) for_each_object(std::span(&prototype.object, 1), collect);
    double local = 0, mirror = 0;
    for (const auto& m : materials) {
        local = std::max(local, max_channel(m.ka.value * d.ambient.value + (m.kd.value + m.ks.value) * light_sum));
        // Where a ray is both reflected and refracted, both paths may come back at the bound;
        // at total internal reflection POV-Ray brings the light back with weight 1.
        mirror = std::max(mirror, is_zero(m.kt.value) ? max_channel(m.km.value)
                                                      : std::max(1.0, max_channel(m.km.value + m.kt.value)));
    }
    if (has_mtl) return INFINITY;
    const double background = max_channel(d.image.background.value);
    double bound = std::max(background, local);
    for (int64_t depth = 2; depth <= d.max_depth.value; ++depth) bound = std::max(background, local + mirror * bound);
    return bound;
}

static std::string write_sdl(const SceneDescription& d, const Scene& scene, const ConvertOptions& options);

std::string scene_to_sdl(const SceneDescription& d, const Scene& scene, const ConvertOptions& options) {
    try {
        return write_sdl(d, scene, options);
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
    const auto inline_material = [&](const ObjectDescription& object) {
        if (object.material && object.material->inline_) material(*object.material->inline_);
    };
    for_each_object(d.objects, inline_material);
    for (const auto& prototype : d.prototypes) for_each_object(std::span(&prototype.object, 1), inline_material);
}

static std::string write_sdl(const SceneDescription& d, const Scene& scene, const ConvertOptions& options) {
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
    SdlWriter writer(d, scene, o);
    writer.prototype_declarations();
    // (A description read with its objects streamed to the Scene holds none: the Scene's count.)
    const bool light_group = !d.lights.empty() && (!d.objects.empty() || !scene.objects.empty());
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
    writer.objects();
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

std::string scene_to_sdl(const SceneDescription& d, const ConvertOptions& options) {
    refuse_inexpressible(d);  // before the mesh files are read, as `whitted convert` refuses
    return scene_to_sdl(d, validate_scene(d), options);
}

std::string write_pov_files(const SceneDescription& d, const std::string& pov_path, const ConvertOptions& given) {
    check_pov_file_name(pov_path);
    refuse_inexpressible(d);
    return write_pov_files(d, validate_scene(d), pov_path, given);
}

std::string write_pov_files(const SceneDescription& d, const Scene& scene, const std::string& pov_path,
                            const ConvertOptions& given) {
    check_pov_file_name(pov_path);
    ConvertOptions options = given;
    if (!given.hdr_output && radiance_upper_bound(d) * options.exposure > 1.0) options.hdr_output = true;
    const std::filesystem::path pov(pov_path);
    std::filesystem::path ini = pov;
    ini.replace_extension(".ini");
    std::filesystem::path image = pov.filename();
    image.replace_extension(options.hdr_output ? ".exr" : ".png");
    const std::string sdl = scene_to_sdl(d, scene, options);
    const std::string ini_text = ini_for(d, pov.filename().string(), image.string(), options);
    // Both files appear complete or not at all, even if the program is interrupted or killed.
    write_files_atomically({{pov, sdl}, {ini, ini_text}});
    return ini.string();
}

}  // namespace whitted::pov
