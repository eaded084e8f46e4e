// SPDX-License-Identifier: MIT
// A purpose-built Wavefront OBJ + MTL reader: tinyobjloader took 0.49 s for a 1M-triangle
// file (docs/performance.md) and reports problems without line numbers; this one reads the same
// file in a fraction of that and names FILE:LINE:COL for every mistake.
//
// Read: v (x y z, extra values ignored), vn, f (v, v/t, v//n, v/t/n; negative = relative;
// polygons fanned from their first corner), usemtl, mtllib. Ignored: vt, o, g, s, l, p, and
// statements it does not know (OBJ has many). MTL: newmtl, Ka, Kd, Ks, Ns, illum.

#include "whitted/scene/mesh_file.h"

#include "whitted/scene/text_checks.h"

#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <string_view>
#include <unordered_map>

namespace whitted {
namespace {

/// The common OBJ number ("-0.123456", "12", "1.5e-3"): at most 15 digits and a small exponent,
/// so mantissa and power of ten are exact doubles and their quotient is correctly rounded; the
/// float is within an ulp of std::from_chars, which takes everything else. Both renderers get
/// the float Whitted stores (the converter writes it out), so that ulp cannot cause a mismatch.
bool parse_plain_decimal(std::string_view t, float& out) {
    static constexpr double powers_of_ten[] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,  1e8,  1e9,  1e10, 1e11,
                                               1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};
    const char* p = t.data();
    const char* const end = p + t.size();
    bool negative = false;
    if (p < end && (*p == '-' || *p == '+')) negative = *p++ == '-';
    uint64_t mantissa = 0;
    int digits = 0, exponent = 0;
    for (; p < end && unsigned(*p - '0') < 10; ++p, ++digits) mantissa = mantissa * 10 + unsigned(*p - '0');
    if (p < end && *p == '.') {
        for (++p; p < end && unsigned(*p - '0') < 10; ++p, ++digits, --exponent)
            mantissa = mantissa * 10 + unsigned(*p - '0');
    }
    if (digits == 0 || digits > 15) return false;
    if (p < end && (*p == 'e' || *p == 'E')) {
        int written = 0;
        const char* start = p + 1 + (p + 1 < end && p[1] == '+');
        const auto [stop, error] = std::from_chars(start, end, written);
        if (error != std::errc() || stop != end || written < -22 || written > 22) return false;
        exponent += written;
        p = end;
    }
    if (p != end || exponent < -22 || exponent > 22) return false;
    double value = double(mantissa);
    value = exponent < 0 ? value / powers_of_ten[-exponent] : value * powers_of_ten[exponent];
    if (!(std::fabs(value) <= double(std::numeric_limits<float>::max()))) return false;  // let the slow path say why
    out = float(negative ? -value : value);
    return true;
}

/// One line of an OBJ or MTL file, read token by token.
class LineReader {
public:
    LineReader(const std::string& path, std::string_view line, int line_number)
        : m_path(path), m_line(line), m_line_number(line_number) {}

    /// The next whitespace-separated token, or "" at the end of the line.
    std::string_view token() {
        while (m_pos < m_line.size() && (m_line[m_pos] == ' ' || m_line[m_pos] == '\t' || m_line[m_pos] == '\r'))
            ++m_pos;
        m_token_start = m_pos;
        while (m_pos < m_line.size() && m_line[m_pos] != ' ' && m_line[m_pos] != '\t' && m_line[m_pos] != '\r') ++m_pos;
        return m_line.substr(m_token_start, m_pos - m_token_start);
    }

    /// The rest of the line, trimmed (names may contain spaces).
    std::string_view rest() {
        token();
        size_t end = m_line.size();
        while (end > m_token_start && (m_line[end - 1] == ' ' || m_line[end - 1] == '\t' || m_line[end - 1] == '\r'))
            --end;
        return m_line.substr(m_token_start, end - m_token_start);
    }

    float number(const char* what) {
        const std::string_view t = token();
        if (t.empty()) fail(std::string("expected ") + what + ", found the end of the line");
        return parse_float(t, what);
    }

    float parse_float(std::string_view t, const char* what) const {
        float value = 0;
        if (parse_plain_decimal(t, value)) return value;
        const char* begin = t.data() + (t.front() == '+' ? 1 : 0);
        const auto [end, error] = std::from_chars(begin, t.data() + t.size(), value);
        if (error == std::errc::result_out_of_range || (error == std::errc() && !std::isfinite(value)))
            fail(std::string(what) + " must be a finite number, got '" + std::string(t) + "'");
        if (error != std::errc() || end != t.data() + t.size())
            fail(std::string("expected ") + what + ", got '" + std::string(t) + "'");
        return value;
    }

    [[noreturn]] void fail(const std::string& message) const {
        throw InputError({m_path, m_line_number, int(m_token_start) + 1}, message);
    }

private:
    const std::string& m_path;
    std::string_view m_line;
    int m_line_number;
    size_t m_pos = 0, m_token_start = 0;
};

/// Calls `visit(line_reader, keyword)` for every non-empty, non-comment line.
template <class Visit>
void for_each_statement(const std::string& path, std::string_view text, Visit visit) {
    int line_number = 0;
    size_t begin = 0;
    while (begin < text.size()) {
        size_t end = text.find('\n', begin);
        if (end == std::string::npos) end = text.size();
        ++line_number;
        LineReader line(path, text.substr(begin, end - begin), line_number);
        const std::string_view keyword = line.token();
        if (!keyword.empty() && keyword.front() != '#') visit(line, keyword);
        begin = end + 1;
    }
}

Color read_color(LineReader& line, const char* what) {
    Color c;
    c.x = line.number(what);
    const std::string_view g = line.token();
    if (g.empty()) return Color(c.x);  // "Kd 0.5" means grey
    c.y = line.parse_float(g, what);
    c.z = line.number(what);
    return c;
}

void read_mtl(const std::string& path, std::vector<MaterialDescription>& materials,
              std::unordered_map<std::string, int32_t>& by_name) {
    const std::string text = read_text_file(path, limits::max_mesh_file_bytes, "MTL file");
    check_text_is_readable(text, path);
    MaterialDescription* current = nullptr;
    for_each_statement(path, text, [&](LineReader& line, std::string_view keyword) {
        if (keyword == "newmtl") {
            const std::string name(line.rest());
            if (name.empty()) line.fail("newmtl needs a name");
            MaterialDescription material;
            material.name = name;
            material.where = {path};
            by_name[name] = int32_t(materials.size());
            materials.push_back(material);
            current = &materials.back();
            return;
        }
        const bool known =
            keyword == "Ka" || keyword == "Kd" || keyword == "Ks" || keyword == "Ns" || keyword == "illum";
        if (!known) return;
        if (!current) line.fail(std::string(keyword) + " before any newmtl");
        if (keyword == "Ka")
            current->ka.value = read_color(line, "a colour");
        else if (keyword == "Kd")
            current->kd.value = read_color(line, "a colour");
        else if (keyword == "Ks")
            current->ks.value = read_color(line, "a colour");
        else if (keyword == "Ns") {
            const double ns = line.number("a number");
            // MTL allows Ns 0 (no highlight to speak of); the lecture's p must be > 0.
            current->p.value = ns > 0 ? ns : 1.0;
        } else {
            const double illum = line.number("a number");
            current->km.given = illum == 3;  // resolved below, once Ks is known
        }
    });
    for (MaterialDescription& m : materials)
        if (m.km.given) m.km.value = m.ks.value;  // illum 3: mirror reflection with Ks
}

}  // namespace

MeshData load_obj_mesh(const std::string& path, const SourceLocation& referenced_at) {
    std::error_code error;
    const auto status = std::filesystem::status(path, error);
    if (error || !std::filesystem::exists(status))
        throw InputError(referenced_at, "mesh file '" + path + "' not found");
    if (!std::filesystem::is_regular_file(status))
        throw InputError(referenced_at, "mesh file '" + path + "' is not a regular file");
    const MappedTextFile file(path, limits::max_mesh_file_bytes, "mesh file");
    const std::string_view text = file.text();
    check_text_is_readable(text, path);
    const std::filesystem::path directory = std::filesystem::path(path).parent_path();

    MeshData mesh;
    std::vector<float> positions, normals;
    std::unordered_map<std::string, int32_t> material_by_name;
    struct Corner {
        int64_t position, normal;  // 0-based; normal −1 when absent
    };
    std::vector<Corner> corners;         // 3 per triangle
    std::vector<int32_t> face_material;  // 1 per triangle
    int32_t current_material = -1;
    bool every_corner_has_normal = true;
    std::vector<Corner> polygon;
    // Size the arrays from a quick count of the lines first: growing them by doubling had the
    // kernel zero (and us copy) more memory than the mesh holds, the largest cost of loading.
    size_t vertex_lines = 0, normal_lines = 0, face_lines = 0;
    for (size_t at = 0; at < text.size();) {
        if (text[at] == 'v') {
            if (at + 1 < text.size() && text[at + 1] == ' ')
                ++vertex_lines;
            else if (at + 2 < text.size() && text[at + 1] == 'n' && text[at + 2] == ' ')
                ++normal_lines;
        } else if (text[at] == 'f' && at + 1 < text.size() && text[at + 1] == ' ') {
            ++face_lines;
        }
        const void* newline = std::memchr(text.data() + at, '\n', text.size() - at);
        if (!newline) break;
        at = size_t(static_cast<const char*>(newline) - text.data()) + 1;
    }
    positions.reserve(3 * vertex_lines);
    normals.reserve(3 * normal_lines);
    corners.reserve(3 * face_lines);  // triangles; polygons grow it once
    face_material.reserve(face_lines);

    for_each_statement(path, text, [&](LineReader& line, std::string_view keyword) {
        if (keyword == "v") {
            for (int c = 0; c < 3; ++c) positions.push_back(line.number("a vertex coordinate"));
        } else if (keyword == "vn") {
            for (int c = 0; c < 3; ++c) normals.push_back(line.number("a normal coordinate"));
        } else if (keyword == "f") {
            polygon.clear();
            const int64_t vertex_count = int64_t(positions.size() / 3), normal_count = int64_t(normals.size() / 3);
            for (std::string_view t = line.token(); !t.empty(); t = line.token()) {
                // v, v/t, v//n or v/t/n; a negative index counts back from the last one read.
                const auto read_index = [&](std::string_view part, int64_t count, const char* what) -> int64_t {
                    int64_t index = 0;
                    const auto [end, ec] = std::from_chars(part.data(), part.data() + part.size(), index);
                    if (ec != std::errc() || end != part.data() + part.size())
                        line.fail(std::string("expected a ") + what + " index, got '" + std::string(part) + "'");
                    if (index == 0) line.fail(std::string(what) + " index 0: OBJ indices start at 1");
                    const int64_t resolved = index > 0 ? index - 1 : count + index;
                    if (resolved < 0 || resolved >= count)
                        line.fail("face refers to " + std::string(what) + " " + std::to_string(index) + ", but " +
                                  std::to_string(count) + " " + what + (count == 1 ? "" : "s") +
                                  " are defined before it");
                    return resolved;
                };
                const size_t slash = t.find('/');
                Corner corner{read_index(t.substr(0, slash), vertex_count, "vertex"), -1};
                if (slash != std::string_view::npos) {
                    const size_t second = t.find('/', slash + 1);
                    if (second != std::string_view::npos && second + 1 < t.size())
                        corner.normal = read_index(t.substr(second + 1), normal_count, "normal");
                }
                if (corner.normal < 0) every_corner_has_normal = false;
                polygon.push_back(corner);
            }
            if (polygon.size() < 3)
                line.fail("a face needs at least 3 vertices, this one has " + std::to_string(polygon.size()));
            for (size_t k = 1; k + 1 < polygon.size(); ++k) {  // fan from the first corner
                corners.push_back(polygon[0]);
                corners.push_back(polygon[k]);
                corners.push_back(polygon[k + 1]);
                face_material.push_back(current_material);
            }
            if (int64_t(face_material.size()) > limits::max_triangles)
                line.fail("more than " + std::to_string(limits::max_triangles) + " triangles");
        } else if (keyword == "usemtl") {
            const auto it = material_by_name.find(std::string(line.rest()));
            current_material = it == material_by_name.end() ? -1 : it->second;
        } else if (keyword == "mtllib") {
            const std::string name(line.rest());
            const std::filesystem::path mtl = directory / name;
            // A missing MTL is not fatal: faces then have no material, which is an error only
            // when the scene gives none either (validate.cpp says so).
            if (!name.empty() && std::filesystem::is_regular_file(mtl, error))
                read_mtl(mtl.string(), mesh.materials, material_by_name);
        }
    });
    if (corners.empty()) throw InputError(referenced_at, "mesh file '" + path + "' has no faces");

    const bool smooth = every_corner_has_normal && !normals.empty();
    bool normals_follow_positions = smooth;
    for (size_t i = 0; normals_follow_positions && i < corners.size(); ++i)
        normals_follow_positions = corners[i].normal == corners[i].position;
    mesh.indices.reserve(corners.size());
    mesh.triangle_material = std::move(face_material);
    if (!smooth || normals_follow_positions) {
        mesh.positions = std::move(positions);
        if (smooth) {
            normals.resize(mesh.positions.size(), 0.0f);
            mesh.normals = std::move(normals);
        }
        for (const Corner& c : corners) mesh.indices.push_back(uint32_t(c.position));
        return mesh;
    }
    // One vertex per distinct (position, normal) pair, so normals index like positions.
    std::unordered_map<uint64_t, uint32_t> pair_to_vertex;
    for (const Corner& c : corners) {
        const uint64_t key = (uint64_t(c.position) << 32) | uint64_t(c.normal);
        auto [it, inserted] = pair_to_vertex.emplace(key, uint32_t(mesh.positions.size() / 3));
        if (inserted) {
            for (int k = 0; k < 3; ++k) {
                mesh.positions.push_back(positions[3 * c.position + k]);
                mesh.normals.push_back(normals[3 * c.normal + k]);
            }
        }
        mesh.indices.push_back(it->second);
    }
    return mesh;
}

}  // namespace whitted
