// SPDX-License-Identifier: MIT
#include "converters/yaml_writer.h"

#include "output/atomic_files.h"

#include <charconv>
#include <filesystem>

namespace whitted::yaml {
namespace {

/// The shortest text that parses back to exactly `value` (std::to_chars' guarantee).
std::string number(double value) {
    char buffer[64];
    const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
    return std::string(buffer, result.ptr);
}
std::string integer(int64_t value) {
    return std::to_string(value);
}
std::string vec3(const Vec3& v) {
    return "[" + number(v.x) + ", " + number(v.y) + ", " + number(v.z) + "]";
}

/// A double-quoted YAML string (names and paths may hold any character) that reads back as the
/// same text: besides `"` and `\`, every character YAML does not print as itself is escaped (C0 and
/// C1 controls, DEL, and U+0085, U+2028, U+2029, which a YAML reader takes for line breaks and
/// folds, U+FEFF, U+FFFE, U+FFFF). A byte that is not UTF-8 is written as the character of that
/// number (Latin-1's reading of it).
std::string quoted(const std::string& text) {
    std::string out = "\"";
    const auto escape = [&out](uint32_t code) {
        char buffer[12];
        if (code <= 0xFF)
            std::snprintf(buffer, sizeof buffer, "\\x%02x", unsigned(code));
        else
            std::snprintf(buffer, sizeof buffer, "\\u%04x", unsigned(code));
        out += buffer;
    };
    const auto* bytes = reinterpret_cast<const unsigned char*>(text.data());
    for (size_t i = 0; i < text.size();) {
        const unsigned char c = bytes[i];
        if (c == '"' || c == '\\') {
            out += '\\';
            out += char(c);
            ++i;
            continue;
        }
        if (c < 0x80) {
            if (c < 0x20 || c == 0x7F)
                escape(c);
            else
                out += char(c);
            ++i;
            continue;
        }
        // One UTF-8 character: its length and code point, or a stray byte.
        const size_t length = (c & 0xE0) == 0xC0 ? 2 : (c & 0xF0) == 0xE0 ? 3 : (c & 0xF8) == 0xF0 ? 4 : 0;
        bool valid = length > 0 && i + length <= text.size();
        uint32_t code = length == 2 ? c & 0x1F : length == 3 ? c & 0x0F : c & 0x07;
        for (size_t k = 1; valid && k < length; ++k) {
            valid = (bytes[i + k] & 0xC0) == 0x80;
            code = (code << 6) | (bytes[i + k] & 0x3F);
        }
        if (!valid) {
            escape(c);
            ++i;
            continue;
        }
        if ((code >= 0x80 && code <= 0x9F) || code == 0x2028 || code == 0x2029 || code == 0xFEFF || code == 0xFFFE ||
            code == 0xFFFF)
            escape(code);
        else
            out.append(text, i, length);
        i += length;
    }
    return out + "\"";
}

std::string material_map(const MaterialDescription& m) {
    std::string out = "{ ka: " + vec3(m.ka.value) + ", kd: " + vec3(m.kd.value) + ", ks: " + vec3(m.ks.value) +
                      ", p: " + number(m.p.value);
    if (m.fresnel_ior.given)
        out += ", fresnel_ior: " + number(m.fresnel_ior.value);
    else
        out += ", km: " + vec3(m.km.value);
    if (!is_zero(m.kt.value)) out += ", kt: " + vec3(m.kt.value);
    if (m.ior.given) out += ", ior: " + number(m.ior.value);
    out += std::string(", highlight: ") + (m.highlight.value == Highlight::blinn ? "blinn" : "phong") + " }";
    return out;
}

std::string transform_steps(const std::vector<TransformStep>& steps) {
    std::string out = "[";
    for (size_t i = 0; i < steps.size(); ++i) {
        const TransformStep& s = steps[i];
        out += i ? ", " : "";
        switch (s.kind) {
            case TransformStep::Kind::scale:
                out += "{ scale: " + vec3(s.vector) + " }";
                break;
            case TransformStep::Kind::translate:
                out += "{ translate: " + vec3(s.vector) + " }";
                break;
            case TransformStep::Kind::rotate:
                out += "{ rotate: { axis: " + vec3(s.vector) + ", angle: " + number(s.angle) + " } }";
                break;
            case TransformStep::Kind::matrix: {
                out += "{ matrix: [";
                for (size_t k = 0; k < 16; ++k) out.append(k ? ", " : "").append(number(s.matrix[k]));
                out += "] }";
                break;
            }
        }
    }
    return out + "]";
}

class Writer {
public:
    explicit Writer(const std::string& output_path) {
        std::error_code error;
        const std::filesystem::path parent = std::filesystem::path(output_path).parent_path();
        m_directory = parent.empty() ? std::filesystem::current_path(error) : std::filesystem::absolute(parent, error);
    }

    std::string mesh_path(const MeshShape& mesh) const {
        std::error_code error;
        const std::filesystem::path file = std::filesystem::absolute(mesh.file_path, error);
        const std::filesystem::path relative = std::filesystem::relative(file, m_directory, error);
        return error || relative.empty() ? file.string() : relative.string();
    }

    void objects(const std::vector<ObjectDescription>& list, const std::string& indent, std::string& out) const {
        for (const ObjectDescription& o : list) {
            out += indent + "- type: " + to_string(o.type()) + "\n";
            const std::string in = indent + "  ";
            if (!o.transform.empty()) out += in + "transform: " + transform_steps(o.transform) + "\n";
            if (o.material) {
                out += in + "material: " +
                       (o.material->inline_ ? material_map(*o.material->inline_) : quoted(o.material->name)) + "\n";
            }
            std::visit(
                Overloaded{
                    [&](const SphereShape& sphere) {
                        out += in + "center: " + vec3(sphere.center.value) + "\n" + in +
                               "radius: " + number(sphere.radius.value) + "\n";
                    },
                    [&](const PlaneShape& plane) {
                        out += in + "point: " + vec3(plane.point.value) + "\n" + in +
                               "normal: " + vec3(plane.normal.value) + "\n";
                    },
                    [&](const BoxShape& box) {
                        out += in + "min: " + vec3(box.min.value) + "\n" + in + "max: " + vec3(box.max.value) + "\n";
                    },
                    [&](const CylinderShape& cylinder) {
                        out += in + "base: " + vec3(cylinder.base.value) + "\n" + in +
                               "cap: " + vec3(cylinder.cap.value) + "\n" + in +
                               "radius: " + number(cylinder.radius.value) + "\n";
                        if (cylinder.open.value) out += in + "open: true\n";
                    },
                    [&](const ConeShape& cone) {
                        out += in + "base: " + vec3(cone.base.value) + "\n" + in +
                               "base_radius: " + number(cone.base_radius.value) + "\n" + in +
                               "cap: " + vec3(cone.cap.value) + "\n" + in +
                               "cap_radius: " + number(cone.cap_radius.value) + "\n";
                        if (cone.open.value) out += in + "open: true\n";
                    },
                    [&](const TriangleShape& triangle) { out += in + "vertices: " + vec3_list(triangle.vertices); },
                    [&](const MeshShape& mesh) {
                        if (mesh.file.given) {
                            out += in + "file: " + quoted(mesh_path(mesh)) + "\n";
                            return;
                        }
                        out += in + "vertices: " + vec3_list(mesh.vertices);
                        out += in + "triangles: [";
                        for (size_t i = 0; i < mesh.triangles.size(); ++i)
                            out.append(i ? ", [" : "[") += integer(mesh.triangles[i][0]) + ", " +
                                                           integer(mesh.triangles[i][1]) + ", " +
                                                           integer(mesh.triangles[i][2]) + "]";
                        out += "]\n";
                        if (!mesh.normals.empty()) out += in + "normals: " + vec3_list(mesh.normals);
                    },
                    [&](const GroupShape& group) {
                        out += in + "objects:" + (group.objects.empty() ? " []\n" : "\n");
                        objects(group.objects, in + "  ", out);
                    },
                    [&](const InstanceShape& instance) {
                        out += in + "prototype: " + quoted(instance.prototype.value) + "\n";
                    }},
                o.shape);
        }
    }

    /// `[[x, y, z], ...]` and the end of the line.
    static std::string vec3_list(const std::vector<Vec3>& list) {
        std::string out = "[";
        for (size_t i = 0; i < list.size(); ++i) out.append(i ? ", " : "").append(vec3(list[i]));
        return out + "]\n";
    }

private:
    std::filesystem::path m_directory;
};

}  // namespace

std::string scene_to_yaml(const SceneDescription& scene, const std::string& output_path) {
    const Writer writer(output_path);
    std::string out = "# Converted by whitted convert from " + std::filesystem::path(scene.path).filename().string() +
                      "; every value written out, defaults included.\nversion: 1\n";
    const CameraDescription& c = scene.camera;
    out += "camera:\n  type: " + std::string(c.type.value == CameraType::perspective ? "perspective" : "orthographic") +
           "\n  eye: " + vec3(c.eye.value) + "\n  look_at: " + vec3(c.look_at.value) + "\n  up: " + vec3(c.up.value) +
           "\n  fov: " + number(c.fov.value) + "\n";
    if (c.view_width.given || c.type.value == CameraType::orthographic)
        out += "  view_width: " + number(c.view_width.value) + "\n";
    if (c.view_height.given) out += "  view_height: " + number(c.view_height.value) + "\n";
    if (c.projection_distance.given) out += "  projection_distance: " + number(c.projection_distance.value) + "\n";
    if (c.image_plane_normal.given) out += "  image_plane_normal: " + vec3(c.image_plane_normal.value) + "\n";
    const ImageDescription& image = scene.image;
    out += "image: { width: " + integer(image.width.value) + ", height: " + integer(image.height.value) +
           ", background: " + vec3(image.background.value) + ", samples: " + integer(image.samples.value) + " }\n";
    out += "render: { max_depth: " + integer(scene.max_depth.value) +
           ", convention: " + (scene.convention.value == Convention::course ? "course" : "pov") +
           ", min_weight: " + number(scene.min_weight.value) + " }\n";
    out += "ambient: " + vec3(scene.ambient.value) + "\n";
    out += "lights:" + std::string(scene.lights.empty() ? " []\n" : "\n");
    for (const LightDescription& l : scene.lights) {
        if (l.type == LightType::point)
            out += "  - { type: point, position: " + vec3(l.position.value);
        else
            out += "  - { type: directional, direction: " + vec3(l.direction.value);
        out += ", intensity: " + vec3(l.intensity.value) + " }\n";
    }
    out += "materials:" + std::string(scene.materials.empty() ? " {}\n" : "\n");
    for (const MaterialDescription& m : scene.materials) out += "  " + quoted(m.name) + ": " + material_map(m) + "\n";
    if (!scene.prototypes.empty()) {
        // Each prototype as a group holding it: a map entry, written with the list writer.
        out += "prototypes:\n";
        for (const PrototypeDescription& p : scene.prototypes) {
            out += "  " + quoted(p.name) + ":\n    type: group\n    objects:\n";
            writer.objects({p.object}, "      ", out);
        }
    }
    out += "objects:" + std::string(scene.objects.empty() ? " []\n" : "\n");
    writer.objects(scene.objects, "  ", out);
    return out;
}

void write_yaml_file(const SceneDescription& scene, const std::string& path) {
    const std::string text = scene_to_yaml(scene, path);
    write_files_atomically({{std::filesystem::path(path), text}});
}

}  // namespace whitted::yaml
