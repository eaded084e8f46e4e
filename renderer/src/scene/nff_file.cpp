// SPDX-License-Identifier: MIT
// NFF → SceneDescription (docs/nff.md). NFF is a stream of whitespace-separated tokens: an
// entity's code, then its numbers, which may run over any number of lines. The reader keeps the
// line and column of every token, so that each value of the description says where it was
// written and the validator's messages name the NFF token, as they name a YAML key.
#include "scene/nff_file.h"

#include "scene/mesh_file.h"
#include "scene/text_checks.h"

#include <algorithm>
#include <array>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <map>
#include <numbers>
#include <optional>

namespace whitted {

namespace {

/// The most corners one `p` or `pp` may have: the OBJ reader's cap on a face, for the same
/// reason (a polygon is cut into triangles in time that grows faster than its size).
constexpr int64_t max_polygon_corners = 20000;

/// What a byte is to the tokenizer: part of a token, a blank, the end of a line or the start of
/// a comment. One table lookup per byte: the large SPD files are hundreds of megabytes.
enum ByteClass : unsigned char { token_byte = 0, blank_byte = 1, line_end_byte = 2, comment_byte = 3 };
constexpr std::array<unsigned char, 256> byte_classes = [] {
    std::array<unsigned char, 256> classes{};
    for (const unsigned char c : {' ', '\t', '\f', '\v'}) classes[c] = blank_byte;
    classes['\n'] = classes['\r'] = line_end_byte;
    classes['#'] = comment_byte;
    return classes;
}();

inline ByteClass byte_class(char c) {
    return ByteClass(byte_classes[static_cast<unsigned char>(c)]);
}

struct Token {
    std::string_view text;
    int line = 0;
    int column = 0;
};

class NffReader {
public:
    NffReader(std::string_view text, std::string path, const ObjectSink* sink)
        : m_text(text), m_path(std::move(path)), m_file(m_path), m_sink(sink) {}

    SceneDescription read() {
        m_scene.path = m_path;
        m_scene.image.where = at_start();
        // NFF has no ambient term: nothing is lit but by its lights.
        set(m_scene.ambient, Color(0.0), at_start());
        std::optional<Token> view;
        while (std::optional<Token> code = next()) {
            const std::string_view c = code->text;
            if (c == "v") {
                if (view) fail(*code, "a second view entity 'v' (the first is at " + where(*view).str() + ")");
                view = code;
                read_view(*code);
            } else if (c == "b") {
                set(m_scene.image.background, colour("background colour"), where(*code));
            } else if (c == "l") {
                read_light(*code);
            } else if (c == "f") {
                read_fill(*code);
            } else if (c == "s") {
                read_sphere(*code);
            } else if (c == "c") {
                read_cone(*code);
            } else if (c == "p" || c == "pp") {
                read_polygon(*code, c == "pp");
            } else {
                fail(*code, "unknown NFF entity '" + printable(c) + "' (expected v, b, l, f, c, s, p, pp or #)");
            }
        }
        if (!view) throw InputError(at_start(), "the NFF file has no view entity 'v' (from, at, up, angle)");
        end_meshes();
        // "Lights have a non-zero intensity of no particular value": SPD's own translations give
        // each of N lights 1/√N, so that the scene is as bright for any number of lights.
        const double share = 1.0 / std::sqrt(double(m_scene.lights.size()));
        for (LightDescription& light : m_scene.lights)
            if (!light.intensity.given) light.intensity.value = Color(share);
        return std::move(m_scene);
    }

private:
    // --- tokens ------------------------------------------------------------------------------

    /// The next token, past white space and comments ('#' to the end of its line), or none at
    /// the end of the text.
    std::optional<Token> next() {
        for (;;) {
            if (m_pos >= m_text.size()) return std::nullopt;
            const char c = m_text[m_pos];
            const ByteClass kind = byte_class(c);
            if (kind == token_byte) break;
            if (kind == blank_byte) {
                ++m_pos;
            } else if (kind == line_end_byte) {
                // CR LF, LF and CR alone each end one line.
                if (c == '\r' && m_pos + 1 < m_text.size() && m_text[m_pos + 1] == '\n') ++m_pos;
                ++m_pos;
                ++m_line;
                m_line_start = m_pos;
            } else {
                while (m_pos < m_text.size() && m_text[m_pos] != '\n' && m_text[m_pos] != '\r') ++m_pos;
            }
        }
        const size_t start = m_pos;
        while (m_pos < m_text.size() && byte_class(m_text[m_pos]) == token_byte) ++m_pos;
        m_end_line = m_line;
        m_end_column = int(m_pos - m_line_start) + 1;
        return Token{m_text.substr(start, m_pos - start), m_line, int(start - m_line_start) + 1};
    }

    /// The next token without taking it.
    std::optional<Token> peek() {
        const size_t pos = m_pos, line_start = m_line_start;
        const int line = m_line, end_line = m_end_line, end_column = m_end_column;
        std::optional<Token> token = next();
        m_pos = pos, m_line_start = line_start, m_line = line, m_end_line = end_line, m_end_column = end_column;
        return token;
    }

    SourceLocation where(const Token& token) const { return {m_file, token.line, token.column}; }
    SourceLocation at_start() const { return {m_file, 1, 1}; }
    /// Just past the last token read: where a missing value should have been.
    SourceLocation here() const { return {m_file, m_end_line, m_end_column}; }
    [[noreturn]] void fail(const Token& token, const std::string& message) const {
        throw InputError(where(token), message);
    }

    static bool parse_double(std::string_view t, double& out) {
        if (t.empty()) return false;
        const char* begin = t.data() + (t.front() == '+' && t.size() > 1 ? 1 : 0);
        const char* const end = t.data() + t.size();
        const auto [stop, error] = std::from_chars(begin, end, out);
        if (stop != end) return false;
        if (error == std::errc::result_out_of_range) {
            // Too small for a double: its nearest double is 0; too large is refused.
            const std::string_view digits(begin, size_t(end - begin));
            const size_t e = digits.find_first_of("eE");
            if (e == std::string_view::npos || e + 1 >= digits.size() || digits[e + 1] != '-') return false;
            out = digits.front() == '-' ? -0.0 : 0.0;
            return true;
        }
        return error == std::errc() && std::isfinite(out);
    }

    /// The next token as a finite number; `what` names it in the message if it is not one.
    Located<double> number(const std::string& what) {
        const std::optional<Token> token = next();
        if (!token) throw InputError(here(), "the file ends where " + what + " was expected");
        Located<double> value;
        if (!parse_double(token->text, value.value))
            fail(*token, "expected a number for " + what + ", got '" + printable(token->text) + "'");
        value.where = where(*token);
        value.given = true;
        return value;
    }

    Located<int64_t> whole_number(const std::string& what, int64_t low, int64_t high) {
        const std::optional<Token> token = next();
        if (!token) throw InputError(here(), "the file ends where " + what + " was expected");
        Located<int64_t> value;
        const char* const end = token->text.data() + token->text.size();
        const auto [stop, error] = std::from_chars(token->text.data(), end, value.value);
        if (stop != end || error != std::errc())
            fail(*token, "expected a whole number for " + what + ", got '" + printable(token->text) + "'");
        if (value.value < low || value.value > high)
            fail(*token, what + " must be from " + std::to_string(low) + " to " + std::to_string(high) + ", got " +
                             std::to_string(value.value));
        value.where = where(*token);
        value.given = true;
        return value;
    }

    Located<Vec3> vector(const std::string& what) {
        const Located<double> x = number(what), y = number(what), z = number(what);
        Located<Vec3> v{Vec3{x.value, y.value, z.value}};
        v.where = x.where;
        v.given = true;
        return v;
    }

    Color colour(const std::string& what) {
        const double r = number(what).value, g = number(what).value, b = number(what).value;
        return Color{r, g, b};
    }

    template <class T>
    static void set(Located<T>& located, T value, const SourceLocation& at) {
        located.value = std::move(value);
        located.where = at;
        located.given = true;
    }

    // --- entities ----------------------------------------------------------------------------

    /// `v` then the keywords from, at, up, angle (required), hither and resolution (optional),
    /// each once, in any order.
    void read_view(const Token& code) {
        CameraDescription& camera = m_scene.camera;
        camera.where = where(code);
        set(camera.type, CameraType::perspective, where(code));
        std::optional<Located<double>> angle;
        std::optional<Located<int64_t>> width, height;
        bool from = false, at = false, up = false, hither = false;
        for (;;) {
            const std::optional<Token> key = peek();
            if (!key) break;
            const std::string_view k = key->text;
            bool* seen = k == "from" ? &from : k == "at" ? &at : k == "up" ? &up : k == "hither" ? &hither : nullptr;
            const bool is_angle = k == "angle", is_resolution = k == "resolution";
            if (!seen && !is_angle && !is_resolution) break;
            next();
            if ((seen && *seen) || (is_angle && angle) || (is_resolution && width))
                fail(*key, "view: '" + std::string(k) + "' is given twice");
            if (k == "from") camera.eye = vector("view 'from'");
            if (k == "at") camera.look_at = vector("view 'at'");
            if (k == "up") camera.up = vector("view 'up'");
            if (k == "hither") number("view 'hither'");  // no near plane in a ray tracer (docs/nff.md)
            if (is_angle) angle = number("view 'angle'");
            if (is_resolution) {
                width = whole_number("view 'resolution' width", 1, limits::max_image_side);
                height = whole_number("view 'resolution' height", 1, limits::max_image_side);
            }
            if (seen) *seen = true;
        }
        if (!from) fail(code, "view: 'from' (the eye) is missing");
        if (!at) fail(code, "view: 'at' (the point looked at) is missing");
        if (!up) fail(code, "view: 'up' is missing");
        if (!angle) fail(code, "view: 'angle' (the field of view in degrees) is missing");
        if (!(angle->value > 0 && angle->value < 180))
            throw InputError(angle->where, "view 'angle' must be between 0 and 180 degrees (exclusive)");
        // SPD's generators all write 512 × 512 (its README) when no resolution is given.
        m_scene.image.width = width ? *width : Located<int64_t>{512};
        m_scene.image.height = height ? *height : Located<int64_t>{512};
        if (!width) m_scene.image.width.where = m_scene.image.height.where = where(code);
        // `angle` spans the image from side to side and from top to bottom alike (SPD's own
        // POV-Ray output makes both frustum sides 2·tan(angle/2) at distance 1), so a
        // non-square image has non-square pixels. A square image is Whitted's horizontal fov;
        // any other is the window camera with that square window.
        if (m_scene.image.width.value == m_scene.image.height.value) {
            camera.fov = *angle;
        } else {
            const double side = 2.0 * std::tan(angle->value * std::numbers::pi / 360.0);
            set(camera.view_width, side, angle->where);
            set(camera.view_height, side, angle->where);
            set(camera.projection_distance, 1.0, angle->where);
        }
    }

    /// `l x y z [r g b]`.
    void read_light(const Token& code) {
        LightDescription light;
        light.where = where(code);
        light.type = LightType::point;
        light.position = vector("light position");
        // The colour is optional: what follows is a number only if it is given.
        const std::optional<Token> more = peek();
        double ignored;
        if (more && parse_double(more->text, ignored)) set(light.intensity, colour("light colour"), where(*more));
        m_scene.lights.push_back(std::move(light));
    }

    /// `f r g b Kd Ks Shine T ior` (docs/nff.md, the mapping). A fill whose eight numbers are
    /// those of an earlier one is that material again: SPD's lattice writes one of five fills
    /// before each of its 8,281 objects, and a material per line (416 bytes each, an array
    /// grown into fresh memory) costs its reading four times what the objects do.
    void read_fill(const Token& code) {
        const Located<double> r = number("fill colour (red)"), g = number("fill colour (green)"),
                              b = number("fill colour (blue)");
        const Located<double> kd = number("fill Kd"), ks = number("fill Ks"), shine = number("fill Shine"),
                              t = number("fill T"), ior = number("fill index of refraction");
        end_meshes();
        // Keyed by the bits of the eight numbers: a fill is that material again only if it is
        // the same exactly.
        Fill key;
        const double numbers[] = {r.value, g.value, b.value, kd.value, ks.value, shine.value, t.value, ior.value};
        for (size_t i = 0; i < key.size(); ++i) key[i] = std::bit_cast<uint64_t>(numbers[i]);
        const auto [known, added] = m_fills.try_emplace(key, m_scene.materials.size());
        m_fill = known->second;
        if (!added) return;
        MaterialDescription m;
        m.where = where(code);
        m.name = "f" + std::to_string(m_scene.materials.size() + 1);
        set(m.kd, Color{kd.value * r.value, kd.value * g.value, kd.value * b.value}, kd.where);
        set(m.ks, Color(ks.value), ks.where);
        set(m.km, Color(ks.value), ks.where);
        set(m.highlight, Highlight::phong, shine.where);
        set(m.p, shine.value, shine.where);
        set(m.kt, Color(t.value), t.where);
        // SPD writes an index of 0 for surfaces that transmit nothing; it means nothing there.
        if (t.value != 0) set(m.ior, ior.value, ior.where);
        m_scene.materials.push_back(std::move(m));
    }

    /// The material of an object that comes now: the latest `f`. An object before any `f` gets
    /// a white Lambertian one, with a warning.
    MaterialReference material_for(const Token& code) {
        if (m_scene.materials.empty()) {
            std::fprintf(stderr,
                         "whitted: warning: %s: an object before any fill 'f': it is given a white "
                         "Lambertian surface (f 1 1 1 1 0 0 0 1)\n",
                         where(code).str().c_str());
            MaterialDescription m;
            m.where = where(code);
            m.name = "f0";
            set(m.kd, Color(1.0), where(code));
            m_scene.materials.push_back(std::move(m));
            m_fill = 0;
        }
        MaterialReference reference;
        reference.where = where(code);
        reference.name = m_scene.materials[m_fill].name;
        return reference;
    }

    /// `s x y z r`: a negative radius means "only the inside is visible", and every surface
    /// has two sides in Whitted.
    void read_sphere(const Token& code) {
        ObjectDescription object;
        object.where = where(code);
        object.material = material_for(code);
        SphereShape& sphere = object.shape.emplace<SphereShape>();
        sphere.center = vector("sphere centre");
        sphere.radius = number("sphere radius");
        if (sphere.radius.value < 0) sphere.radius.value = -sphere.radius.value;
        emit(std::move(object));
    }

    /// `c`, base point and radius, apex point and radius: an open cylinder (equal radii) or
    /// an open cone. Both radii negative: only the inside is visible, which two-sided surfaces
    /// show anyway.
    void read_cone(const Token& code) {
        ObjectDescription object;
        object.where = where(code);
        object.material = material_for(code);
        const Located<Vec3> base = vector("cone base");
        Located<double> base_radius = number("cone base radius");
        const Located<Vec3> apex = vector("cone apex");
        Located<double> apex_radius = number("cone apex radius");
        if (base_radius.value < 0 && apex_radius.value <= 0) {
            base_radius.value = -base_radius.value;
            apex_radius.value = -apex_radius.value;
        }
        Located<bool> open;
        set(open, true, object.where);
        if (base_radius.value == apex_radius.value)
            object.shape = CylinderShape{base, apex, base_radius, open};
        else
            object.shape = ConeShape{base, base_radius, apex, apex_radius, open};
        emit(std::move(object));
    }

    /// `p n` and n corners, or `pp n` and n corners each with its normal. Polygons may be
    /// concave (gears): each is cut into triangles in its own plane, wound as it is. Polygons
    /// that follow one another with the same fill share one inline mesh (patches another, with
    /// their vertex normals).
    void read_polygon(const Token& code, bool patch) {
        // The names for messages are made once: a large file has millions of polygons.
        static const std::string polygon = "polygon", patch_name = "patch", polygon_count = "polygon corner count",
                                 patch_count = "patch corner count", polygon_corner = "polygon corner",
                                 patch_corner = "patch corner", patch_normal = "patch normal";
        const std::string& what = patch ? patch_name : polygon;
        const Located<int64_t> count = whole_number(patch ? patch_count : polygon_count, 3, max_polygon_corners);
        const auto n = size_t(count.value);
        // Each corner takes at least "0 0 0 " (or twice that with a normal): a small file cannot
        // claim a huge count and have it reserved.
        if (n * (patch ? 12 : 6) > m_text.size() - std::min(m_pos, m_text.size()) + 1)
            throw InputError(count.where, "the file ends before the " + what + "'s " + std::to_string(n) + " corners");
        m_corners.clear();
        m_normals.clear();
        for (size_t i = 0; i < n; ++i) {
            m_corners.push_back(vector(patch ? patch_corner : polygon_corner).value);
            if (patch) {
                const Located<Vec3> normal = vector(patch_normal);
                if (normal.value.x == 0 && normal.value.y == 0 && normal.value.z == 0)
                    throw InputError(normal.where, "patch normal must not be the zero vector");
                m_normals.push_back(normal.value);
            }
        }
        std::optional<ObjectDescription>& slot = patch ? m_smooth : m_flat;
        if (!slot) {
            slot.emplace();
            slot->where = where(code);
            slot->material = material_for(code);
            MeshShape& mesh = slot->shape.emplace<MeshShape>();
            mesh.vertices_where = mesh.triangles_where = where(code);
            if (patch) mesh.normals_where = where(code);
        }
        MeshShape& mesh = std::get<MeshShape>(slot->shape);
        const auto first = int64_t(mesh.vertices.size());
        if (first + int64_t(n) > int64_t(UINT32_MAX))
            throw InputError(count.where, "more than 2^32 corners in the polygons of one fill");
        // A triangle is its own cut (most polygons of most databases are triangles).
        static const std::vector<uint32_t> one_triangle = {0, 1, 2};
        const std::vector<uint32_t> cut = n == 3 ? std::vector<uint32_t>() : triangulate_polygon(m_corners);
        const std::vector<uint32_t>& triangles = n == 3 ? one_triangle : cut;
        m_triangles += int64_t(triangles.size() / 3);
        if (m_triangles > limits::max_triangles)
            throw InputError(where(code), "more than " + std::to_string(limits::max_triangles) +
                                              " triangles in the scene's polygons (docs/nff.md, limits)");
        mesh.vertices.insert(mesh.vertices.end(), m_corners.begin(), m_corners.end());
        if (patch) mesh.normals.insert(mesh.normals.end(), m_normals.begin(), m_normals.end());
        // No triangle_where: the reader makes the indices, none can be out of range, and on the
        // VMs measured the 16 bytes a triangle of fresh memory cost mount -s 9 a tenth of its read.
        for (size_t i = 0; i + 2 < triangles.size(); i += 3)
            mesh.triangles.push_back({first + triangles[i], first + triangles[i + 1], first + triangles[i + 2]});
    }

    /// An object is handed on (to the sink, or to the description's list) when it is complete:
    /// a sphere or cone at once, a mesh when its fill ends. The order is the same either way.
    void emit(ObjectDescription&& object) {
        if (m_sink)
            (*m_sink)(std::move(object), m_emitted++);
        else
            m_scene.objects.push_back(std::move(object));
    }
    void end_meshes() {
        for (std::optional<ObjectDescription>* mesh : {&m_flat, &m_smooth})
            if (*mesh) emit(std::move(**mesh)), mesh->reset();
    }

    std::string_view m_text;
    std::string m_path;
    /// The path as kept for every location: made once, since making one looks the name up in
    /// the shared table (a lock and a hash), and every number read records where it was.
    FileName m_file;
    const ObjectSink* m_sink = nullptr;
    size_t m_emitted = 0;
    size_t m_pos = 0, m_line_start = 0;
    int m_line = 1;
    int m_end_line = 1, m_end_column = 1;  ///< just past the last token read
    SceneDescription m_scene;
    std::optional<ObjectDescription> m_flat, m_smooth;  ///< the meshes the current fill's polygons go to
    /// Each fill met so far, by the bits of its eight numbers, to its index in m_scene.materials,
    /// and the current one's index.
    using Fill = std::array<uint64_t, 8>;
    std::map<Fill, size_t> m_fills;
    size_t m_fill = 0;
    int64_t m_triangles = 0;
    std::vector<Vec3> m_corners, m_normals;
};

}  // namespace

bool is_nff_path(const std::string& path) {
    std::string extension = std::filesystem::path(path).extension().string();
    std::transform(extension.begin(), extension.end(), extension.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    return extension == ".nff";
}

SceneDescription parse_nff_text(std::string_view text, const std::string& path, const ObjectSink* sink) {
    check_text_is_readable(text, path);
    return NffReader(text, path, sink).read();
}

SceneDescription parse_nff_file(const std::string& path, const ObjectSink* sink) {
    // NFF files are mesh-sized (SPD's larger sizes are hundreds of megabytes): the mesh limit.
    const MappedTextFile file(path, limits::max_mesh_file_bytes, "NFF scene file");
    return file.read([&] { return parse_nff_text(file.text(), path, sink); });
}

}  // namespace whitted
