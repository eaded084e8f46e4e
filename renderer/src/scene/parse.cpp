// SPDX-License-Identifier: MIT
// Scene format v1 (YAML, or JSON as YAML) → SceneDescription. Every value keeps its file, line
// and column; every mistake becomes an InputError at the place it was made. Ranges that need
// more than one value (eye ≠ look_at, min < max, ...) are checked in validate.cpp. The text is
// read into a yaml_tree::Document (yaml_tree.h), whose top-level `objects` items are parsed here
// one by one as they are read, so that a scene of a million spheres never holds a million trees.

#include "scene/course_xml.h"
#include "scene/description.h"
#include "scene/nff_file.h"
#include "scene/text_checks.h"

#include "scene/yaml_tree.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <exception>
#include <filesystem>
#include <unordered_set>

namespace whitted {
namespace {

using Node = yaml_tree::Node;

/// A value's name in messages, such as "objects[3] (sphere).center": a prefix and a key, joined
/// only when a message is written. A million objects read without a mistake need no names, and
/// building them cost a fifth of the time spent reading a file of spheres (docs/performance.md).
/// Holds a reference: pass it down, never keep it.
class What {
public:
    What(const std::string& name) : m_prefix(name) {}  // NOLINT: implicit, names used to be strings
    What(const std::string& prefix, std::string_view key) : m_prefix(prefix), m_key(key) {}
    std::string str() const { return m_key.empty() ? m_prefix : m_prefix + "." + std::string(m_key); }
    friend std::string operator+(const What& what, std::string_view tail) {
        std::string text = what.str();
        text += tail;
        return text;
    }

private:
    const std::string& m_prefix;
    std::string_view m_key;
};

struct ParseContext {
    FileName file;
    std::string directory;
    std::vector<ObjectDescription> objects;  ///< the top-level objects, parsed as they are read
    std::exception_ptr objects_error;        ///< the first mistake in them, reported in turn
    /// Given: each top-level object goes here as soon as it is parsed, instead of into `objects`.
    const ObjectSink* sink = nullptr;

    SourceLocation at(const Node& node) const {
        SourceLocation where = node.location();
        if (where.file.empty()) where.file = file;
        return where;
    }
    [[noreturn]] void fail(const Node& node, const std::string& message) const { throw InputError(at(node), message); }
};

std::string describe(const Node& node) {
    switch (node.kind()) {
        case yaml_tree::Kind::null:
            return "nothing (null)";
        case yaml_tree::Kind::sequence:
            return "a list";
        case yaml_tree::Kind::map:
            return "a map";
        case yaml_tree::Kind::scalar: {
            const std::string s = printable(node.scalar_view(), 40);
            return node.IsQuoted() ? "the string \"" + s + "\"" : "'" + s + "'";
        }
        default:
            return "nothing";
    }
}

/// `true` or `false`, unquoted (YAML 1.2's core schema spellings).
bool parse_boolean(const ParseContext& ctx, const Node& node, const What& what) {
    if (node.IsScalar() && !node.IsQuoted()) {
        const std::string_view v = node.scalar_view();
        if (v == "true" || v == "True" || v == "TRUE") return true;
        if (v == "false" || v == "False" || v == "FALSE") return false;
    }
    ctx.fail(node, what + ": expected true or false, got " + describe(node));
}

double parse_number(const ParseContext& ctx, const Node& node, const What& what) {
    if (!node.IsScalar() || node.IsQuoted()) ctx.fail(node, what + ": expected a number, got " + describe(node));
    const std::string_view whole = node.scalar_view();
    const auto text = [&] { return printable(whole, 40); };  // for messages only
    std::string_view view = whole;
    if (!view.empty() && view.front() == '+') view.remove_prefix(1);
    // YAML's own spellings of the special values, so that they get the "finite" message below.
    if (view.size() <= 9 && !view.empty() && !std::isdigit(static_cast<unsigned char>(view.back()))) {
        std::string lowered(view);
        std::transform(lowered.begin(), lowered.end(), lowered.begin(), ::tolower);
        if (lowered == ".nan" || lowered == "nan" || lowered == ".inf" || lowered == "inf" || lowered == "-.inf" ||
            lowered == "-inf" || lowered == "infinity" || lowered == "-infinity")
            ctx.fail(node, what + ": must be a finite number, got '" + text() + "'");
    }
    double value = 0;
    const auto [end, error] = std::from_chars(view.data(), view.data() + view.size(), value);
    if (error == std::errc::result_out_of_range) ctx.fail(node, what + ": number '" + text() + "' is out of range");
    if (error != std::errc() || end != view.data() + view.size())
        ctx.fail(node, what + ": expected a number, got " + describe(node));
    if (!std::isfinite(value)) ctx.fail(node, what + ": must be a finite number, got '" + text() + "'");
    return value;
}

int64_t parse_integer(const ParseContext& ctx, const Node& node, const What& what) {
    const double value = parse_number(ctx, node, what);
    if (value != std::floor(value) || std::fabs(value) > 9.0e15)
        ctx.fail(node, what + ": expected a whole number, got " + describe(node));
    return static_cast<int64_t>(value);
}

Vec3 parse_vec3(const ParseContext& ctx, const Node& node, const What& what) {
    if (!node.IsSequence()) ctx.fail(node, what + ": expected a list of 3 numbers [x, y, z], got " + describe(node));
    if (node.size() != 3) ctx.fail(node, what + ": expected 3 numbers, got a list of " + std::to_string(node.size()));
    return {parse_number(ctx, node[0], what), parse_number(ctx, node[1], what), parse_number(ctx, node[2], what)};
}

/// A colour: [r, g, b], or one number c meaning [c, c, c].
Color parse_color(const ParseContext& ctx, const Node& node, const What& what) {
    if (node.IsScalar()) return Color(parse_number(ctx, node, what));
    if (!node.IsSequence()) ctx.fail(node, what + ": expected a colour [r, g, b] or a number, got " + describe(node));
    return parse_vec3(ctx, node, what);
}

std::string parse_string(const ParseContext& ctx, const Node& node, const What& what) {
    if (!node.IsScalar()) ctx.fail(node, what + ": expected a name, got " + describe(node));
    return node.Scalar();
}

size_t edit_distance(const std::string& a, const std::string& b) {
    std::vector<size_t> row(b.size() + 1);
    for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
    for (size_t i = 1; i <= a.size(); ++i) {
        size_t diagonal = row[0];
        row[0] = i;
        for (size_t j = 1; j <= b.size(); ++j) {
            const size_t above = row[j];
            row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] != b[j - 1])});
            diagonal = above;
        }
    }
    return row[b.size()];
}

}  // namespace

std::string did_you_mean(const std::string& word, const std::vector<std::string>& candidates) {
    // Bounded work whatever the input: names longer than a word anyone types get no suggestion,
    // a candidate whose length alone puts it out of reach is not compared, and at most a few
    // thousand are (a hostile file may define a million names, each a megabyte long).
    constexpr size_t longest = 64, most_compared = 4096;
    if (word.size() > longest) return {};
    std::string best;
    size_t best_distance = std::max<size_t>(2, word.size() / 3) + 1, compared = 0;
    for (const auto& candidate : candidates) {
        if (candidate.size() > longest) continue;
        const size_t apart =
            candidate.size() > word.size() ? candidate.size() - word.size() : word.size() - candidate.size();
        if (apart >= best_distance) continue;
        if (++compared > most_compared) break;
        const size_t d = edit_distance(word, candidate);
        if (d < best_distance) best_distance = d, best = candidate;
    }
    return best.empty() ? std::string() : " (did you mean '" + printable(best) + "'?)";
}

namespace {

std::string join(const std::vector<std::string>& words) {  // for messages
    std::string out;
    for (const auto& w : words) out += (out.empty() ? "" : ", ") + w;
    return out;
}

/// Reads one YAML map: rejects unknown keys (with a suggestion) and finds values by key. The
/// allowed keys and the keys found are views (of string literals and of the document), kept in
/// place: a reader is made for every object of a file that may hold millions.
class MapReader {
public:
    static constexpr size_t max_keys = 12;

    MapReader(ParseContext& ctx, const Node& node, std::string what, std::initializer_list<std::string_view> allowed)
        : MapReader(ctx, node, std::move(what), allowed.begin(), allowed.size()) {}
    MapReader(ParseContext& ctx, const Node& node, std::string what, const std::string_view* allowed, size_t count)
        : m_ctx(ctx), m_node(node), m_what(std::move(what)), m_allowed_count(count) {
        if (count > max_keys) throw std::logic_error("MapReader: too many keys");
        std::copy(allowed, allowed + count, m_allowed.begin());
        if (!node.IsMap()) ctx.fail(node, m_what + ": expected a map of keys, got " + describe(node));
        for (const auto& entry : node.pairs()) {
            const Node& key = entry.first;
            if (!key.IsScalar()) ctx.fail(key, m_what + ": keys must be plain names");
            const std::string_view name = key.scalar_view();
            if (std::find(allowed_begin(), allowed_end(), name) == allowed_end()) {
                const std::vector<std::string> names(allowed_begin(), allowed_end());
                ctx.fail(key, m_what + ": unknown key '" + printable(name) + "'" +
                                  did_you_mean(std::string(name), names) + "; expected one of: " + join(names));
            }
            if (has(name)) ctx.fail(key, m_what + ": key '" + printable(name) + "' is given twice");
            m_keys[m_key_count++] = name;  // room: every key is allowed and none is given twice
        }
    }

    bool has(std::string_view key) const {
        return std::find(m_keys.begin(), m_keys.begin() + m_key_count, key) != m_keys.begin() + m_key_count;
    }
    Node get(std::string_view key) const { return m_node[key]; }
    SourceLocation where() const { return m_ctx.at(m_node); }
    const std::string& name() const { return m_what; }
    What what(std::string_view key) const { return What(m_what, key); }

    Node require(std::string_view key) const {
        if (!has(key)) m_ctx.fail(m_node, m_what + ": missing required key '" + std::string(key) + "'");
        return get(key);
    }

    template <class T, class ParseFn>
    void read(Located<T>& out, std::string_view key, ParseFn parse, bool required = false) const {
        if (!has(key)) {
            if (required) require(key);
            out.where = where();
            return;
        }
        const Node value = get(key);
        out.value = parse(m_ctx, value, what(key));
        out.where = m_ctx.at(value);
        out.given = true;
    }
    void number(Located<double>& out, std::string_view key, bool required = false) const {
        read(out, key, parse_number, required);
    }
    void integer(Located<int64_t>& out, std::string_view key, bool required = false) const {
        read(out, key, parse_integer, required);
    }
    void vec3(Located<Vec3>& out, std::string_view key, bool required = false) const {
        read(out, key, parse_vec3, required);
    }
    void color(Located<Color>& out, std::string_view key, bool required = false) const {
        read(out, key, parse_color, required);
    }

private:
    const std::string_view* allowed_begin() const { return m_allowed.data(); }
    const std::string_view* allowed_end() const { return m_allowed.data() + m_allowed_count; }

    ParseContext& m_ctx;
    Node m_node;
    std::string m_what;
    std::array<std::string_view, max_keys> m_allowed{};
    size_t m_allowed_count = 0;
    std::array<std::string_view, max_keys> m_keys{};
    size_t m_key_count = 0;
};

/// Picks one of a fixed set of words, e.g. a camera type.
template <class Enum>
Enum parse_choice(const ParseContext& ctx, const Node& node, const What& what,
                  const std::vector<std::pair<std::string, Enum>>& choices) {
    const std::string word = parse_string(ctx, node, what);
    for (const auto& [name, value] : choices)
        if (name == word) return value;
    std::vector<std::string> names;
    for (const auto& choice : choices) names.push_back(choice.first);
    ctx.fail(node, what + ": unknown value '" + printable(word) + "'" + did_you_mean(word, names) +
                       "; expected one of: " + join(names));
}

/// The image-plane window keys (the Cornell course's camera); a perspective camera with
/// `view_height` needs `view_width` too.
void parse_camera_window(const MapReader& map, CameraDescription& camera) {
    map.number(camera.view_height, "view_height");
    map.number(camera.projection_distance, "projection_distance");
    map.vec3(camera.image_plane_normal, "image_plane_normal");
    if (camera.type.value == CameraType::perspective && camera.view_height.given) map.require("view_width");
}

CameraDescription parse_camera(ParseContext& ctx, const Node& node) {
    MapReader map(ctx, node, "camera",
                  {"type", "eye", "look_at", "up", "fov", "view_width", "view_height", "projection_distance",
                   "image_plane_normal"});
    CameraDescription camera;
    camera.where = map.where();
    map.read(camera.type, "type", [](const ParseContext& c, const Node& n, const What& w) {
        return parse_choice<CameraType>(
            c, n, w, {{"perspective", CameraType::perspective}, {"orthographic", CameraType::orthographic}});
    });
    map.vec3(camera.eye, "eye", true);
    map.vec3(camera.look_at, "look_at", true);
    map.vec3(camera.up, "up");
    map.number(camera.fov, "fov");
    map.number(camera.view_width, "view_width", camera.type.value == CameraType::orthographic);
    parse_camera_window(map, camera);
    return camera;
}

ImageDescription parse_image(ParseContext& ctx, const Node& node) {
    MapReader map(ctx, node, "image", {"width", "height", "background", "samples"});
    ImageDescription image;
    image.where = map.where();
    map.integer(image.width, "width", true);
    map.integer(image.height, "height", true);
    map.color(image.background, "background");
    map.integer(image.samples, "samples");
    return image;
}

LightDescription parse_light(ParseContext& ctx, const Node& node, const std::string& what) {
    if (!node.IsMap()) ctx.fail(node, what + ": expected a map with 'type', got " + describe(node));
    const Node type_node = node["type"];
    if (!type_node) ctx.fail(node, what + ": missing required key 'type' (point or directional)");
    LightDescription light;
    light.type = parse_choice<LightType>(ctx, type_node, what + ".type",
                                         {{"point", LightType::point}, {"directional", LightType::directional}});
    if (light.type == LightType::point) {
        MapReader map(ctx, node, what + " (point)", {"type", "position", "intensity"});
        light.where = map.where();
        map.vec3(light.position, "position", true);
        map.color(light.intensity, "intensity");
    } else {
        MapReader map(ctx, node, what + " (directional)", {"type", "direction", "intensity"});
        light.where = map.where();
        map.vec3(light.direction, "direction", true);
        map.color(light.intensity, "intensity");
    }
    return light;
}

MaterialDescription parse_material(ParseContext& ctx, const Node& node, const std::string& what) {
    MapReader map(ctx, node, what, {"ka", "kd", "ks", "p", "km", "highlight", "fresnel_ior", "kt", "ior"});
    MaterialDescription material;
    material.where = map.where();
    map.color(material.ka, "ka");
    map.color(material.kd, "kd");
    map.color(material.ks, "ks");
    map.number(material.p, "p");
    map.color(material.km, "km");
    map.read(material.highlight, "highlight", [](const ParseContext& c, const Node& n, const What& w) {
        return parse_choice<Highlight>(c, n, w, {{"blinn", Highlight::blinn}, {"phong", Highlight::phong}});
    });
    map.number(material.fresnel_ior, "fresnel_ior");
    map.color(material.kt, "kt");
    map.number(material.ior, "ior");
    if (material.fresnel_ior.given && material.km.given)
        ctx.fail(map.get("fresnel_ior"),
                 what + ": give km or fresnel_ior, not both (fresnel_ior sets the mirror weight)");
    return material;
}

MaterialReference parse_material_reference(ParseContext& ctx, const Node& node, const What& what) {
    MaterialReference reference;
    reference.where = ctx.at(node);
    if (node.IsScalar() && !node.IsQuoted() && node.Scalar().empty())
        ctx.fail(node, what + ": expected a material name or an inline material map");
    if (node.IsScalar()) {
        reference.name = node.Scalar();
    } else if (node.IsMap()) {
        reference.inline_ = parse_material(ctx, node, what.str());
    } else {
        ctx.fail(node, what + ": expected a material name or an inline material map, got " + describe(node));
    }
    return reference;
}

std::vector<TransformStep> parse_transform(ParseContext& ctx, const Node& node, const What& what) {
    const auto parse_step = [&](const Node& step_node, const std::string& step_what) {
        MapReader map(ctx, step_node, step_what, {"scale", "rotate", "translate", "matrix"});
        int count = map.has("scale") + map.has("rotate") + map.has("translate") + map.has("matrix");
        if (count != 1)
            ctx.fail(step_node, step_what + ": each step is exactly one of scale, rotate, translate or matrix");
        TransformStep step;
        step.where = map.where();
        if (map.has("scale")) {
            const Node value = map.get("scale");
            step.kind = TransformStep::Kind::scale;
            step.where = ctx.at(value);
            step.vector = value.IsScalar() ? Vec3(parse_number(ctx, value, step_what + ".scale"))
                                           : parse_vec3(ctx, value, step_what + ".scale");
        } else if (map.has("translate")) {
            const Node value = map.get("translate");
            step.kind = TransformStep::Kind::translate;
            step.where = ctx.at(value);
            step.vector = parse_vec3(ctx, value, step_what + ".translate");
        } else if (map.has("rotate")) {
            MapReader rotate(ctx, map.get("rotate"), step_what + ".rotate", {"axis", "angle"});
            step.kind = TransformStep::Kind::rotate;
            step.where = rotate.where();
            step.vector = parse_vec3(ctx, rotate.require("axis"), step_what + ".rotate.axis");
            step.angle = parse_number(ctx, rotate.require("angle"), step_what + ".rotate.angle");
        } else {
            const Node value = map.get("matrix");
            step.kind = TransformStep::Kind::matrix;
            step.where = ctx.at(value);
            if (!value.IsSequence() || value.size() != 16)
                ctx.fail(value,
                         step_what + ".matrix: expected 16 numbers (a row-major 4x4 matrix), got " +
                             (value.IsSequence() ? "a list of " + std::to_string(value.size()) : describe(value)));
            for (size_t i = 0; i < 16; ++i) step.matrix[i] = parse_number(ctx, value[i], step_what + ".matrix");
        }
        return step;
    };

    std::vector<TransformStep> steps;
    if (node.IsMap()) {
        steps.push_back(parse_step(node, what.str()));
    } else if (node.IsSequence()) {
        for (size_t i = 0; i < node.size(); ++i)
            steps.push_back(parse_step(node[i], what + "[" + std::to_string(i) + "]"));
    } else {
        ctx.fail(node, what +
                           ": expected a list of steps (scale, rotate, translate) or { matrix: [16 numbers] }, got " +
                           describe(node));
    }
    return steps;
}

std::vector<Vec3> parse_vec3_list(ParseContext& ctx, const Node& node, const What& what) {
    if (!node.IsSequence()) ctx.fail(node, what + ": expected a list of [x, y, z], got " + describe(node));
    std::vector<Vec3> out;
    out.reserve(node.size());
    for (size_t i = 0; i < node.size(); ++i)
        out.push_back(parse_vec3(ctx, node[i], what + "[" + std::to_string(i) + "]"));
    return out;
}

ObjectDescription parse_object(ParseContext& ctx, const Node& node, const std::string& what, int depth);

std::vector<ObjectDescription> parse_objects(ParseContext& ctx, const Node& node, const std::string& what, int depth) {
    if (node.IsNull()) return {};
    if (node.IsStreamed()) {  // the top-level list, parsed while it was read
        if (ctx.objects_error) std::rethrow_exception(ctx.objects_error);
        if (ctx.sink) return {};
        if (ctx.objects.size() < ctx.objects.capacity() / 2) ctx.objects.shrink_to_fit();
        return std::move(ctx.objects);
    }
    if (!node.IsSequence()) ctx.fail(node, what + ": expected a list of objects, got " + describe(node));
    std::vector<ObjectDescription> objects;
    for (size_t i = 0; i < node.size(); ++i)
        objects.push_back(parse_object(ctx, node[i], what + "[" + std::to_string(i) + "]", depth));
    return objects;
}

ObjectDescription parse_object(ParseContext& ctx, const Node& node, const std::string& what, int depth) {
    if (!node.IsMap()) ctx.fail(node, what + ": expected a map with 'type', got " + describe(node));
    const Node type_node = node["type"];
    if (!type_node)
        ctx.fail(node, what +
                           ": missing required key 'type' (sphere, plane, box, cylinder, cone, triangle, mesh, group "
                           "or instance)");
    ObjectDescription object;
    static const std::vector<std::pair<std::string, ObjectDescription::Shape>> object_kinds = {
        {"sphere", SphereShape{}},     {"plane", PlaneShape{}},       {"box", BoxShape{}},
        {"triangle", TriangleShape{}}, {"mesh", MeshShape{}},         {"group", GroupShape{}},
        {"instance", InstanceShape{}}, {"cylinder", CylinderShape{}}, {"cone", ConeShape{}}};
    object.shape = parse_choice<ObjectDescription::Shape>(ctx, type_node, what + ".type", object_kinds);
    // The keys each kind takes: type, transform, material (not for groups), then its own.
    std::array<std::string_view, MapReader::max_keys> keys{"type", "transform"};
    size_t key_count = 2;
    const auto allow = [&](std::initializer_list<std::string_view> more) {
        for (const std::string_view key : more) keys[key_count++] = key;
    };
    if (object.type() != ObjectType::group) allow({"material"});
    std::visit(
        Overloaded{[&](const SphereShape&) {
                       allow({"center", "radius"});
                   },
                   [&](const PlaneShape&) {
                       allow({"point", "normal"});
                   },
                   [&](const BoxShape&) {
                       allow({"min", "max"});
                   },
                   [&](const CylinderShape&) {
                       allow({"base", "cap", "radius", "open"});
                   },
                   [&](const ConeShape&) {
                       allow({"base", "base_radius", "cap", "cap_radius", "open"});
                   },
                   [&](const TriangleShape&) { allow({"vertices"}); },
                   [&](const MeshShape&) {
                       allow({"file", "vertices", "triangles", "normals"});
                   },
                   [&](const GroupShape&) { allow({"objects"}); }, [&](const InstanceShape&) { allow({"prototype"}); }},
        object.shape);
    MapReader map(ctx, node, what + " (" + to_string(object.type()) + ")", keys.data(), key_count);
    const std::string& label = map.name();
    object.where = map.where();
    if (map.has("transform")) object.transform = parse_transform(ctx, map.get("transform"), label + ".transform");
    if (map.has("material")) object.material = parse_material_reference(ctx, map.get("material"), label + ".material");

    std::visit(
        Overloaded{
            [&](SphereShape& sphere) {
                map.vec3(sphere.center, "center", true);
                map.number(sphere.radius, "radius", true);
            },
            [&](PlaneShape& plane) {
                map.vec3(plane.point, "point", true);
                map.vec3(plane.normal, "normal", true);
            },
            [&](BoxShape& box) {
                map.vec3(box.min, "min", true);
                map.vec3(box.max, "max", true);
            },
            [&](CylinderShape& cylinder) {
                map.vec3(cylinder.base, "base", true);
                map.vec3(cylinder.cap, "cap", true);
                map.number(cylinder.radius, "radius", true);
                map.read(cylinder.open, "open", parse_boolean);
            },
            [&](ConeShape& cone) {
                map.vec3(cone.base, "base", true);
                map.number(cone.base_radius, "base_radius", true);
                map.vec3(cone.cap, "cap", true);
                map.number(cone.cap_radius, "cap_radius", true);
                map.read(cone.open, "open", parse_boolean);
            },
            [&](TriangleShape& triangle) {
                const Node vertices = map.require("vertices");
                triangle.vertices_where = ctx.at(vertices);
                triangle.vertices = parse_vec3_list(ctx, vertices, label + ".vertices");
                if (triangle.vertices.size() != 3)
                    ctx.fail(vertices, label + ".vertices: a triangle needs exactly 3 vertices, got " +
                                           std::to_string(triangle.vertices.size()));
            },
            [&](MeshShape& mesh) {
                if (map.has("file")) {
                    for (const char* inline_key : {"vertices", "triangles", "normals"})
                        if (map.has(inline_key))
                            ctx.fail(map.get(inline_key),
                                     label + ": give either 'file' or inline 'vertices'/'triangles', not both");
                    map.read(mesh.file, "file", parse_string);
                    if (mesh.file.value.empty()) ctx.fail(map.get("file"), label + ".file: empty path");
                    const std::filesystem::path file(mesh.file.value);
                    mesh.file_path =
                        file.is_absolute() ? file.string() : (std::filesystem::path(ctx.directory) / file).string();
                    return;
                }
                if (!map.has("vertices") && !map.has("triangles"))
                    ctx.fail(node, label + ": a mesh needs 'file', or inline 'vertices' and 'triangles'");
                const Node vertices = map.require("vertices");
                mesh.vertices_where = ctx.at(vertices);
                mesh.vertices = parse_vec3_list(ctx, vertices, label + ".vertices");
                const Node triangles = map.require("triangles");
                mesh.triangles_where = ctx.at(triangles);
                if (!triangles.IsSequence())
                    ctx.fail(triangles, label + ".triangles: expected a list of [i, j, k], got " + describe(triangles));
                for (size_t i = 0; i < triangles.size(); ++i) {
                    const Node triangle = triangles[i];
                    const std::string item = label + ".triangles[" + std::to_string(i) + "]";
                    if (!triangle.IsSequence() || triangle.size() != 3)
                        ctx.fail(triangle, item + ": expected 3 vertex indices [i, j, k], got " +
                                               (triangle.IsSequence() ? "a list of " + std::to_string(triangle.size())
                                                                      : describe(triangle)));
                    mesh.triangles.push_back({parse_integer(ctx, triangle[0], item),
                                              parse_integer(ctx, triangle[1], item),
                                              parse_integer(ctx, triangle[2], item)});
                    mesh.triangle_where.push_back(ctx.at(triangle));
                }
                if (map.has("normals")) {
                    const Node normals = map.get("normals");
                    mesh.normals_where = ctx.at(normals);
                    mesh.normals = parse_vec3_list(ctx, normals, label + ".normals");
                }
            },
            [&](GroupShape& group) {
                if (depth + 1 > limits::max_nesting)
                    ctx.fail(node,
                             label + ": groups nested deeper than " + std::to_string(limits::max_nesting) + " levels");
                const Node children = map.require("objects");
                group.objects = parse_objects(ctx, children, label + ".objects", depth + 1);
            },
            // Resolved in validation, where every prototype is known (they may come after `objects`).
            [&](InstanceShape& instance) { map.read(instance.prototype, "prototype", parse_string, true); }},
        object.shape);
    return object;
}

/// render.layers: a list of layer names (checked against the known layers in validation).
std::vector<Located<std::string>> parse_render_layers(ParseContext& ctx, const Node& node) {
    if (!node.IsSequence()) ctx.fail(node, "render.layers: expected a list of layer names, got " + describe(node));
    std::vector<Located<std::string>> layers;
    for (size_t i = 0; i < node.size(); ++i) {
        Located<std::string> layer(parse_string(ctx, node[i], "render.layers[" + std::to_string(i) + "]"));
        layer.where = ctx.at(node[i]);
        layer.given = true;
        layers.push_back(std::move(layer));
    }
    return layers;
}

/// `render.convention` and `render.min_weight`: the Cornell course's shading rules, kept out of
/// the default (POV-Ray's) path.
void parse_render_conventions(const MapReader& render, SceneDescription& scene) {
    render.read(scene.convention, "convention", [](const ParseContext& c, const Node& n, const What& w) {
        return parse_choice<Convention>(c, n, w, {{"pov", Convention::pov}, {"course", Convention::course}});
    });
    render.number(scene.min_weight, "min_weight");
    render.read(scene.intersection, "intersection", [](const ParseContext& c, const Node& n, const What& w) {
        return parse_choice<Intersection>(c, n, w, {{"exact", Intersection::exact}, {"povray", Intersection::povray}});
    });
}

SceneDescription parse_document(ParseContext& ctx, const Node& root) {
    if (!root || root.IsNull())
        throw InputError({ctx.file, 1, 1}, "the scene is empty: expected a map with 'camera', 'image' and 'objects'");
    MapReader map(ctx, root, "scene",
                  {"version", "camera", "image", "render", "ambient", "lights", "materials", "prototypes", "objects"});
    SceneDescription scene;
    scene.path = ctx.file;
    map.integer(scene.version, "version");
    if (scene.version.value != 1)
        throw InputError(scene.version.where, "unsupported scene format version " +
                                                  std::to_string(scene.version.value) +
                                                  "; this Whitted reads version 1");
    scene.camera = parse_camera(ctx, map.require("camera"));
    scene.image = parse_image(ctx, map.require("image"));
    if (map.has("render")) {
        MapReader render(ctx, map.get("render"), "render",
                         {"max_depth", "layers", "convention", "min_weight", "intersection"});
        render.integer(scene.max_depth, "max_depth");
        if (render.has("layers")) scene.layers = parse_render_layers(ctx, render.get("layers"));
        parse_render_conventions(render, scene);
    } else {
        scene.max_depth.where = scene.convention.where = scene.min_weight.where = scene.intersection.where =
            map.where();
    }
    map.color(scene.ambient, "ambient");
    if (map.has("lights")) {
        const Node lights = map.get("lights");
        if (!lights.IsNull()) {
            if (!lights.IsSequence()) ctx.fail(lights, "lights: expected a list of lights, got " + describe(lights));
            for (size_t i = 0; i < lights.size(); ++i)
                scene.lights.push_back(parse_light(ctx, lights[i], "lights[" + std::to_string(i) + "]"));
        }
    }
    // Names defined so far, to find one defined twice in one look each (not a walk of the list).
    std::unordered_set<std::string> material_names, prototype_names;
    if (map.has("materials")) {
        const Node materials = map.get("materials");
        if (!materials.IsNull()) {
            if (!materials.IsMap())
                ctx.fail(materials, "materials: expected a map of name: material, got " + describe(materials));
            for (const auto& entry : materials.pairs()) {
                if (!entry.first.IsScalar() || entry.first.Scalar().empty())
                    ctx.fail(entry.first, "materials: names must be plain, non-empty words");
                const std::string name = entry.first.Scalar();
                if (!material_names.insert(name).second)
                    ctx.fail(entry.first, "materials: '" + printable(name) + "' is defined twice");
                MaterialDescription material = parse_material(ctx, entry.second, "materials." + name);
                material.name = name;
                scene.materials.push_back(std::move(material));
            }
        }
    }
    if (map.has("prototypes")) {
        const Node prototypes = map.get("prototypes");
        if (!prototypes.IsNull()) {
            if (!prototypes.IsMap())
                ctx.fail(prototypes, "prototypes: expected a map of name: object, got " + describe(prototypes));
            for (const auto& entry : prototypes.pairs()) {
                if (!entry.first.IsScalar() || entry.first.Scalar().empty())
                    ctx.fail(entry.first, "prototypes: names must be plain, non-empty words");
                PrototypeDescription prototype;
                prototype.name = entry.first.Scalar();
                prototype.where = ctx.at(entry.first);
                if (!prototype_names.insert(prototype.name).second)
                    ctx.fail(entry.first, "prototypes: '" + printable(prototype.name) + "' is defined twice");
                prototype.object = parse_object(ctx, entry.second, "prototypes." + prototype.name, 0);
                scene.prototypes.push_back(std::move(prototype));
            }
        }
    }
    if (map.has("objects")) scene.objects = parse_objects(ctx, map.get("objects"), "objects", 0);
    return scene;
}

}  // namespace

const MaterialDescription* SceneDescription::find_material(const std::string& name) const {
    for (const auto& material : materials)
        if (material.name == name) return &material;
    return nullptr;
}

const PrototypeDescription* SceneDescription::find_prototype(const std::string& name) const {
    for (const auto& prototype : prototypes)
        if (prototype.name == name) return &prototype;
    return nullptr;
}

const char* to_string(ObjectType type) {
    switch (type) {
        case ObjectType::sphere:
            return "sphere";
        case ObjectType::plane:
            return "plane";
        case ObjectType::box:
            return "box";
        case ObjectType::triangle:
            return "triangle";
        case ObjectType::mesh:
            return "mesh";
        case ObjectType::group:
            return "group";
        case ObjectType::instance:
            return "instance";
        case ObjectType::cylinder:
            return "cylinder";
        case ObjectType::cone:
            return "cone";
    }
    return "object";
}

namespace {

/// parse_scene_text, telling `done_before` (if given) how far through the text it is.
SceneDescription parse_text(std::string_view text, const std::string& path, const ObjectSink* sink,
                            const DoneBefore& done_before) {
    ParseContext ctx;
    ctx.sink = sink;
    ctx.file = path;
    ctx.directory = std::filesystem::path(path).parent_path().string();
    check_text_is_readable(text, path, done_before);
    yaml_tree::Document document;
    // Room for as many objects as a file of one-line objects holds (a sphere takes 64 bytes of
    // text at least): moving hundreds of thousands of descriptions each time the list grows cost
    // more than reading them. Pages never written are never resident; what is left is given back.
    try {
        if (!sink) ctx.objects.reserve(std::min<size_t>(text.size() / 64, size_t(1) << 24));
    } catch (const std::bad_alloc&) {  // a machine without overcommit: grow as needed
    }
    // Each top-level object is parsed as soon as it is read; its first mistake is kept and
    // reported when parse_document reaches `objects`, so that mistakes are reported in the
    // order the keys are checked, as for the rest of the scene.
    // Where the fast scanner leaves the text to libyaml, libyaml reads it again from the start
    // and index 0 comes again. The items the scanner handed over it had read completely, and
    // libyaml reads them alike (yaml_tree_test compares the two readers), so those that already
    // went to the sink are not handed over twice: the restart stays inside the reader.
    size_t handed = 0;  // items already given to the sink
    const auto on_object = [&ctx, &handed](const Node& item, size_t index) {
        if (index == 0) ctx.objects.clear(), ctx.objects_error = nullptr;
        if (ctx.objects_error || (ctx.sink && index < handed)) return;
        try {
            ObjectDescription object = parse_object(ctx, item, "objects[" + std::to_string(index) + "]", 0);
            if (ctx.sink) {
                (*ctx.sink)(std::move(object), index);
                handed = index + 1;
            } else {
                ctx.objects.push_back(std::move(object));
            }
        } catch (const InputError&) {
            ctx.objects_error = std::current_exception();
        }
    };
    yaml_tree::Limits tree_limits;
    tree_limits.max_nodes_at_once = tree_limits.max_alias_values = uint64_t(limits::max_yaml_nodes);
    document.read(text, ctx.file, on_object, tree_limits, nullptr, done_before);
    return parse_document(ctx, document.root());
}

}  // namespace

SceneDescription parse_scene_text(std::string_view text, const std::string& path, const ObjectSink* sink) {
    return parse_text(text, path, sink, {});
}

namespace {

/// A description read whole, its objects handed to `sink` as a streaming reader would.
SceneDescription hand_objects_to(const ObjectSink* sink, SceneDescription description) {
    if (sink) {
        for (size_t i = 0; i < description.objects.size(); ++i) (*sink)(std::move(description.objects[i]), i);
        description.objects.clear();
    }
    return description;
}

}  // namespace

SceneFormat scene_format(const std::string& path, std::string_view text) {
    if (is_course_xml_path(path)) return SceneFormat::course_xml;
    if (is_nff_path(path)) return SceneFormat::nff;
    // A name that says YAML or JSON is read so, as parse_scene_file reads such a file.
    std::string extension = std::filesystem::path(path).extension().string();
    std::transform(extension.begin(), extension.end(), extension.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    if (extension == ".yaml" || extension == ".yml" || extension == ".json") return SceneFormat::yaml;
    // An NFF file's first entity, after any `#` comment lines, is a one-letter keyword on its own
    // word (a YAML scene may begin with `#` comments too, then a key such as `version:`).
    size_t line = 0;
    while (line < text.size() && (text[line] == '#' || text[line] == '\n' || text[line] == '\r')) {
        const size_t end = text.find('\n', line);
        if (end == std::string_view::npos) return SceneFormat::yaml;
        line = end + 1;
    }
    const std::string_view rest = text.substr(line);
    const std::string_view word = rest.substr(0, rest.find_first_of(" \t\r\n"));
    for (const std::string_view keyword : {"v", "b", "l", "f", "c", "s", "p", "pp"})
        if (word == keyword) return SceneFormat::nff;
    const size_t first = text.find_first_not_of(" \t\r\n");
    if (first != std::string_view::npos && text[first] == '<') return SceneFormat::course_xml;
    return SceneFormat::yaml;
}

SceneDescription parse_any_scene_text(std::string_view text, const std::string& path, const ObjectSink* sink) {
    switch (scene_format(path, text)) {
        case SceneFormat::nff:
            return parse_nff_text(text, path, sink);
        case SceneFormat::course_xml:
            return hand_objects_to(sink, parse_course_xml_text(std::string(text), path));
        case SceneFormat::yaml:
            break;
    }
    return parse_scene_text(text, path, sink);
}

SceneDescription parse_scene_file(const std::string& path, const ObjectSink* sink) {
    // The Cornell course's XML scenes are small: read whole, then handed over.
    if (is_course_xml_path(path)) return hand_objects_to(sink, parse_course_xml_file(path));
    if (is_nff_path(path)) return parse_nff_file(path, sink);  // Eric Haines' NFF (docs/nff.md)
    // Mapped, not copied; devices, fifos and other files that are not regular files are refused
    // before a byte is read (/dev/urandom would never end).
    // The text is gone through once (or twice, where libyaml reads it again), and nothing read
    // from it points back into it: the pages behind the reader are let go as it goes, so that a
    // large scene file does not add its size to the peak memory.
    MappedTextFile file(path, limits::max_scene_file_bytes, "scene file");
    return file.read(
        [&] { return parse_text(file.text(), path, sink, [&file](size_t offset) { file.reader_at(offset); }); });
}

}  // namespace whitted
