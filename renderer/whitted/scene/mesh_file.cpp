// SPDX-License-Identifier: MIT
// A purpose-built Wavefront OBJ + MTL reader: tinyobjloader took 0.49 s for a 1M-triangle
// file (docs/performance.md) and reports problems without line numbers; this one reads the same
// file in a fraction of that and names FILE:LINE:COL for every mistake. Plain `v`, `vn` and `f`
// lines are read in one pass over the characters; a large file is cut into runs of lines that
// the cores read at once, after a quick count that says where each run's vertices go.
//
// Read: v (x y z, extra values ignored), vn, f (v, v/t, v//n, v/t/n; negative = relative;
// polygons fanned from their first corner), usemtl, mtllib. Ignored: vt, o, g, s, l, p, and
// statements it does not know (OBJ has many). MTL: newmtl, Ka, Kd, Ks, Ns, illum.

#include "whitted/scene/mesh_file.h"

#include "whitted/scene/text_checks.h"

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string_view>
#include <unordered_map>

namespace whitted {
namespace {

bool is_blank(char c) {
    return c == ' ' || c == '\t' || c == '\r';
}

/// The end of the token that starts at p (tokens end at a blank or the end of the line).
const char* token_end(const char* p, const char* end) {
    while (p < end && !is_blank(*p) && *p != '\n') ++p;
    return p;
}

/// Reads the common OBJ number ("-0.123456", "12", "1.5e-3") at p and returns where it ends, or
/// nullptr when it is not one: at most 15 digits and a small exponent, so mantissa and power of
/// ten are exact doubles and their quotient is correctly rounded; the float is within an ulp of
/// std::from_chars, which takes everything else. Both renderers get the float Whitted stores
/// (the converter writes it out), so that ulp cannot cause a mismatch.
const char* scan_plain_decimal(const char* p, const char* end, float& out) {
    static constexpr double powers_of_ten[] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,  1e8,  1e9,  1e10, 1e11,
                                               1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};
    bool negative = false;
    if (p < end && (*p == '-' || *p == '+')) negative = *p++ == '-';
    uint64_t mantissa = 0;
    int digits = 0, exponent = 0;
    for (; p < end && unsigned(*p - '0') < 10; ++p, ++digits) mantissa = mantissa * 10 + unsigned(*p - '0');
    if (p < end && *p == '.') {
        for (++p; p < end && unsigned(*p - '0') < 10; ++p, ++digits, --exponent)
            mantissa = mantissa * 10 + unsigned(*p - '0');
    }
    if (digits == 0 || digits > 15) return nullptr;
    if (p < end && (*p == 'e' || *p == 'E')) {
        ++p;
        bool exponent_negative = false;
        if (p < end && (*p == '-' || *p == '+')) exponent_negative = *p++ == '-';
        int written = 0, exponent_digits = 0;
        for (; p < end && unsigned(*p - '0') < 10; ++p, ++exponent_digits)
            written = std::min(written * 10 + int(*p - '0'), 1000);
        if (exponent_digits == 0 || written > 22) return nullptr;
        exponent += exponent_negative ? -written : written;
    }
    if (exponent < -22 || exponent > 22) return nullptr;
    double value = double(mantissa);
    value = exponent < 0 ? value / powers_of_ten[-exponent] : value * powers_of_ten[exponent];
    if (!(std::fabs(value) <= double(std::numeric_limits<float>::max()))) return nullptr;  // the slow path says why
    out = float(negative ? -value : value);
    return p;
}

/// A whole token as a plain decimal (see scan_plain_decimal).
bool parse_plain_decimal(std::string_view t, float& out) {
    return scan_plain_decimal(t.data(), t.data() + t.size(), out) == t.data() + t.size();
}

/// Any finite float std::from_chars reads as the whole token (a leading '+' allowed); false
/// for everything the caller must refuse.
bool parse_any_float(std::string_view t, float& out) {
    if (t.empty()) return false;
    const char* begin = t.data() + (t.front() == '+' ? 1 : 0);
    const auto [stop, error] = std::from_chars(begin, t.data() + t.size(), out);
    return error == std::errc() && stop == t.data() + t.size() && std::isfinite(out);
}

/// Reads an OBJ index ("12", "-3") at p and returns where it ends, or nullptr when there is none.
const char* scan_index(const char* p, const char* end, int64_t& out) {
    const bool negative = p < end && *p == '-';
    if (negative) ++p;
    const char* const digits = p;
    int64_t value = 0;
    for (; p < end && unsigned(*p - '0') < 10; ++p) {
        if (p - digits >= 18) return nullptr;  // beyond any count: the slow path says so
        value = value * 10 + int64_t(*p - '0');
    }
    if (p == digits) return nullptr;
    out = negative ? -value : value;
    return p;
}

/// One line of an OBJ or MTL file, read token by token.
class LineReader {
public:
    LineReader(const std::string& path, std::string_view line, int line_number)
        : m_path(path), m_line(line), m_line_number(line_number) {}

    /// The next whitespace-separated token, or "" at the end of the line.
    std::string_view token() {
        while (m_pos < m_line.size() && is_blank(m_line[m_pos])) ++m_pos;
        m_token_start = m_pos;
        while (m_pos < m_line.size() && !is_blank(m_line[m_pos])) ++m_pos;
        return m_line.substr(m_token_start, m_pos - m_token_start);
    }

    /// The rest of the line, trimmed (names may contain spaces).
    std::string_view rest() {
        token();
        size_t end = m_line.size();
        while (end > m_token_start && is_blank(m_line[end - 1])) --end;
        return m_line.substr(m_token_start, end - m_token_start);
    }

    float number(const char* what) {
        const std::string_view t = token();
        if (t.empty()) fail(std::string("expected ") + what + ", found the end of the line");
        return parse_float(t, what);
    }

    float parse_float(std::string_view t, const char* what) const {
        float value = 0;
        if (parse_plain_decimal(t, value) || parse_any_float(t, value)) return value;
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

/// What a statement is, decided from its keyword the same way by the count and by the reader,
/// so that the count of `v` and `vn` statements in a run of lines is exactly what reading adds.
enum class Statement { position, normal, face, material, other };

Statement classify(const char* keyword, const char* end) {
    const std::string_view word(keyword, size_t(token_end(keyword, end) - keyword));
    if (word == "v") return Statement::position;
    if (word == "vn") return Statement::normal;
    if (word == "f") return Statement::face;
    if (word == "usemtl" || word == "mtllib") return Statement::material;
    return Statement::other;
}

const char* skip_blanks(const char* p, const char* end) {
    while (p < end && is_blank(*p)) ++p;
    return p;
}

/// Just past the end of the line p is on.
const char* next_line(const char* p, const char* end) {
    const void* newline = std::memchr(p, '\n', size_t(end - p));
    return newline ? static_cast<const char*>(newline) + 1 : end;
}

/// One run of whole lines of an OBJ file, and what a first quick pass counted in it.
struct Lines {
    std::string_view text;
    int first_line = 1;
    size_t newlines = 0, positions = 0, normals = 0, faces = 0;
    bool materials = false;  ///< has usemtl or mtllib, which carry state from line to line
    bool plain_ascii = true;

    void count() {
        plain_ascii = is_plain_ascii(text);
        const char* const end = text.data() + text.size();
        for (const char* p = text.data(); p < end;) {
            const char* keyword = skip_blanks(p, end);
            switch (classify(keyword, end)) {
                case Statement::position:
                    ++positions;
                    break;
                case Statement::normal:
                    ++normals;
                    break;
                case Statement::face:
                    ++faces;
                    break;
                case Statement::material:
                    materials = true;
                    break;
                case Statement::other:
                    break;
            }
            p = next_line(keyword, end);
            newlines += p[-1] == '\n';
        }
    }
};

/// Reads the statements of one run of lines. Positions and normals go straight to their place
/// in the mesh's arrays (the count says how many come before); faces are kept here and joined
/// in file order afterwards. Lines the fast path does not recognise as plain `v`, `vn` or `f`
/// go through LineReader, which also words every error, so both paths accept the same text.
class ObjReader {
public:
    struct Output {
        float* positions;  ///< 3 per vertex, this run's first at index 0
        float* normals;
        size_t position_capacity, normal_capacity;
    };

    ObjReader(const std::string& path, const Lines& lines, size_t positions_before, size_t normals_before,
              size_t faces_before, Output output, MeshData* materials_into)
        : m_path(path),
          m_lines(lines),
          m_positions_before(positions_before),
          m_normals_before(normals_before),
          m_faces_before(faces_before),
          m_out(output),
          m_materials_into(materials_into) {
        position_index.reserve(3 * lines.faces);  // triangles; polygons grow it once
        face_material.reserve(lines.faces);
    }

    void read() {
        const char* p = m_lines.text.data();
        const char* const end = p + m_lines.text.size();
        int line_number = m_lines.first_line;
        for (; p < end; ++line_number) {
            const char* const line_begin = p;
            const char* const keyword = skip_blanks(p, end);
            const char* next = nullptr;  // the next line, once the fast path has read this one
            if (keyword < end) {
                if (keyword[0] == '\n') {
                    next = keyword + 1;
                } else if (keyword[0] == 'v' && keyword + 1 < end && is_blank(keyword[1])) {
                    next = read_position(keyword + 2, end);
                } else if (keyword[0] == 'v' && keyword + 2 < end && keyword[1] == 'n' && is_blank(keyword[2])) {
                    next = read_normal(keyword + 3, end);
                } else if (keyword[0] == 'f' && keyword + 1 < end && is_blank(keyword[1])) {
                    next = read_face(keyword + 2, end, line_number);
                } else if (keyword[0] == '#' ||
                           (keyword[0] == 'v' && keyword + 2 < end && keyword[1] == 't' && is_blank(keyword[2]))) {
                    next = next_line(keyword, end);  // comments and texture coordinates: not used
                }
            }
            p = next ? next : read_statement(line_begin, end, line_number);
        }
    }

    std::vector<uint32_t> position_index;  ///< 3 per triangle
    /// 3 per triangle; empty while every corner so far names the normal with its position's
    /// number (the usual export), which then needs no copy, and once a corner has no normal.
    std::vector<uint32_t> normal_index;
    std::vector<int32_t> face_material;  ///< 1 per triangle
    bool every_corner_has_normal = true;
    bool normals_follow_positions = true;
    size_t positions_read = 0, normals_read = 0;

private:
    static constexpr uint32_t no_normal = std::numeric_limits<uint32_t>::max();
    static constexpr int max_fast_corners = 16;

    /// x y z as plain numbers, then anything (extra values are ignored), then the line's end.
    const char* read_xyz(const char* p, const char* end, float xyz[3]) const {
        for (int c = 0; c < 3; ++c) {
            p = skip_blanks(p, end);
            const char* stop = scan_plain_decimal(p, end, xyz[c]);
            if (!stop || (stop < end && !is_blank(*stop) && *stop != '\n')) {
                stop = token_end(p, end);
                if (!parse_any_float({p, size_t(stop - p)}, xyz[c])) return nullptr;
            }
            p = stop;
        }
        p = skip_blanks(p, end);
        if (p == end) return end;
        return *p == '\n' ? p + 1 : next_line(p, end);
    }

    const char* read_position(const char* p, const char* end) {
        float xyz[3];
        const char* next = read_xyz(p, end, xyz);
        if (next) add_position(xyz);
        return next;
    }

    const char* read_normal(const char* p, const char* end) {
        float xyz[3];
        const char* next = read_xyz(p, end, xyz);
        if (next) add_normal(xyz);
        return next;
    }

    /// A face of plain corners (v, v/t, v//n, v/t/n) whose indices are in range; anything else
    /// is left to read_statement, which refuses it or reads it the same way.
    const char* read_face(const char* p, const char* end, int line_number) {
        uint32_t positions[max_fast_corners], normals[max_fast_corners];
        int corners = 0;
        const int64_t position_count = int64_t(m_positions_before + positions_read);
        const int64_t normal_count = int64_t(m_normals_before + normals_read);
        for (p = skip_blanks(p, end); p < end && *p != '\n'; p = skip_blanks(p, end)) {
            if (corners == max_fast_corners) return nullptr;
            int64_t index;
            p = scan_index(p, end, index);
            if (!p || !resolve(index, position_count)) return nullptr;
            positions[corners] = uint32_t(index);
            normals[corners] = no_normal;
            if (p < end && *p == '/') {
                p = std::find_if(p + 1, end, [](char c) { return c == '/' || is_blank(c) || c == '\n'; });
                if (p < end && *p == '/' && p + 1 < end && !is_blank(p[1]) && p[1] != '\n') {
                    p = scan_index(p + 1, end, index);
                    if (!p || !resolve(index, normal_count)) return nullptr;
                    normals[corners] = uint32_t(index);
                } else if (p < end && *p == '/') {
                    ++p;  // "v//" or "v/t/": no normal
                }
            }
            if (p < end && !is_blank(*p) && *p != '\n') return nullptr;
            ++corners;
        }
        if (corners < 3) return nullptr;
        add_face(positions, normals, corners, line_number);
        return p == end ? end : p + 1;
    }

    /// An OBJ index (1-based, or negative = counted back from the last one read) → 0-based, if
    /// in range.
    static bool resolve(int64_t& index, int64_t count) {
        if (index == 0) return false;
        index = index > 0 ? index - 1 : count + index;
        return index >= 0 && index < count;
    }

    void add_position(const float xyz[3]) {
        if (positions_read == m_out.position_capacity) throw std::logic_error("OBJ reader: more v than counted");
        std::memcpy(m_out.positions + 3 * positions_read++, xyz, 3 * sizeof(float));
    }

    void add_normal(const float xyz[3]) {
        if (normals_read == m_out.normal_capacity) throw std::logic_error("OBJ reader: more vn than counted");
        std::memcpy(m_out.normals + 3 * normals_read++, xyz, 3 * sizeof(float));
    }

    void add_face(const uint32_t* positions, const uint32_t* normals, int corners, int line_number) {
        for (int k = 0; k < corners; ++k)
            if (normals[k] == no_normal) every_corner_has_normal = false;
        // A corner without a normal makes the mesh flat: normal numbers are no longer needed.
        const bool keep_normals = every_corner_has_normal;
        if (!keep_normals && !normal_index.empty()) std::vector<uint32_t>().swap(normal_index);
        for (int k = 0; keep_normals && normals_follow_positions && k < corners; ++k) {
            if (normals[k] != positions[k]) {
                normals_follow_positions = false;
                normal_index = position_index;  // until now they were the same
            }
        }
        for (int k = 1; k + 1 < corners; ++k) {  // fan from the first corner
            for (const int c : {0, k, k + 1}) {
                position_index.push_back(positions[c]);
                if (keep_normals && !normals_follow_positions) normal_index.push_back(normals[c]);
            }
            face_material.push_back(m_current_material);
        }
        // Each face line before this run made at least one triangle: enough to refuse early;
        // the exact total is checked once the runs are joined.
        if (m_faces_before + face_material.size() > size_t(limits::max_triangles))
            throw InputError({m_path, line_number, 1},
                             "more than " + std::to_string(limits::max_triangles) + " triangles");
    }

    /// The general reader for one line (OBJ has many statements; v, vn, f, usemtl and mtllib
    /// are read, the rest ignored). Returns the next line.
    const char* read_statement(const char* line_begin, const char* end, int line_number) {
        const char* const next = next_line(line_begin, end);
        const size_t length = size_t(next - line_begin) - (next[-1] == '\n' ? 1 : 0);
        LineReader line(m_path, {line_begin, length}, line_number);
        const std::string_view keyword = line.token();
        if (keyword.empty() || keyword.front() == '#') return next;
        if (keyword == "v" || keyword == "vn") {
            const char* what = keyword == "v" ? "a vertex coordinate" : "a normal coordinate";
            float xyz[3];
            for (float& value : xyz) value = line.number(what);
            keyword == "v" ? add_position(xyz) : add_normal(xyz);
        } else if (keyword == "f") {
            read_face_slowly(line, line_number);
        } else if (keyword == "usemtl" || keyword == "mtllib") {
            if (!m_materials_into) throw std::logic_error("OBJ reader: materials in a parallel run");
            if (keyword == "usemtl") {
                const auto it = m_material_by_name.find(std::string(line.rest()));
                m_current_material = it == m_material_by_name.end() ? -1 : it->second;
            } else {
                const std::string name(line.rest());
                const std::filesystem::path mtl = std::filesystem::path(m_path).parent_path() / name;
                // A missing MTL is not fatal: faces then have no material, which is an error
                // only when the scene gives none either (validate.cpp says so).
                std::error_code error;
                if (!name.empty() && std::filesystem::is_regular_file(mtl, error))
                    read_mtl(mtl.string(), m_materials_into->materials, m_material_by_name);
            }
        }
        return next;
    }

    void read_face_slowly(LineReader& line, int line_number) {
        std::vector<uint32_t> positions, normals;
        const int64_t position_count = int64_t(m_positions_before + positions_read);
        const int64_t normal_count = int64_t(m_normals_before + normals_read);
        for (std::string_view t = line.token(); !t.empty(); t = line.token()) {
            // v, v/t, v//n or v/t/n; a negative index counts back from the last one read.
            const auto read_index = [&](std::string_view part, int64_t count, const char* what) -> uint32_t {
                int64_t index = 0;
                const auto [stop, ec] = std::from_chars(part.data(), part.data() + part.size(), index);
                if (ec != std::errc() || stop != part.data() + part.size())
                    line.fail(std::string("expected a ") + what + " index, got '" + std::string(part) + "'");
                if (index == 0) line.fail(std::string(what) + " index 0: OBJ indices start at 1");
                const int64_t written = index;
                if (!resolve(index, count))
                    line.fail("face refers to " + std::string(what) + " " + std::to_string(written) + ", but " +
                              std::to_string(count) + " " + what + (count == 1 ? "" : "s") + " are defined before it");
                return uint32_t(index);
            };
            const size_t slash = t.find('/');
            positions.push_back(read_index(t.substr(0, slash), position_count, "vertex"));
            normals.push_back(no_normal);
            if (slash != std::string_view::npos) {
                const size_t second = t.find('/', slash + 1);
                if (second != std::string_view::npos && second + 1 < t.size())
                    normals.back() = read_index(t.substr(second + 1), normal_count, "normal");
            }
        }
        if (positions.size() < 3)
            line.fail("a face needs at least 3 vertices, this one has " + std::to_string(positions.size()));
        add_face(positions.data(), normals.data(), int(positions.size()), line_number);
    }

    const std::string& m_path;
    const Lines& m_lines;
    size_t m_positions_before, m_normals_before, m_faces_before;
    Output m_out;
    MeshData* m_materials_into;  ///< where MTL materials go; null in a run read in parallel
    std::unordered_map<std::string, int32_t> m_material_by_name;
    int32_t m_current_material = -1;
};

/// Splits `text` into at most `parts` runs of whole lines of roughly equal size.
std::vector<Lines> split_lines(std::string_view text, size_t parts) {
    std::vector<Lines> runs;
    const char* const end = text.data() + text.size();
    const char* begin = text.data();
    for (size_t k = 1; k <= parts && begin < end; ++k) {
        const char* stop = k == parts ? end : text.data() + text.size() * k / parts;
        stop = stop <= begin ? next_line(begin, end) : stop == end ? end : next_line(stop - 1, end);
        runs.push_back({std::string_view(begin, size_t(stop - begin))});
        begin = stop;
    }
    if (runs.empty()) runs.push_back({text});
    return runs;
}

/// Reads the OBJ text as `parts` runs of lines at once; nullopt when that cannot give the same
/// result as reading it in one go (usemtl/mtllib, an error anywhere: the caller then reads it in
/// one go, which words the error for the first bad line).
std::optional<MeshData> read_obj(const std::string& path, std::string_view text, size_t parts) {
    std::vector<Lines> runs = split_lines(text, parts);
    tbb::parallel_for(size_t(0), runs.size(), [&](size_t k) { runs[k].count(); });
    for (const Lines& run : runs)
        if (!run.plain_ascii) {
            check_text_is_readable(text, path);  // refuses binary files, names the line
            break;
        }
    const bool parallel = runs.size() > 1;
    size_t positions = 0, normals = 0, faces = 0;
    for (Lines& run : runs) {
        if (parallel && run.materials) return std::nullopt;
        positions += run.positions, normals += run.normals, faces += run.faces;
    }
    for (size_t k = 1; k < runs.size(); ++k) runs[k].first_line = runs[k - 1].first_line + int(runs[k - 1].newlines);

    MeshData mesh;
    mesh.positions = std::vector<float>(3 * positions);
    std::vector<float> all_normals(3 * normals);
    std::vector<std::unique_ptr<ObjReader>> readers;
    size_t positions_before = 0, normals_before = 0, faces_before = 0;
    for (const Lines& run : runs) {
        const ObjReader::Output output{mesh.positions.data() + 3 * positions_before,
                                       all_normals.data() + 3 * normals_before, run.positions, run.normals};
        readers.push_back(std::make_unique<ObjReader>(path, run, positions_before, normals_before, faces_before, output,
                                                      parallel ? nullptr : &mesh));
        positions_before += run.positions, normals_before += run.normals, faces_before += run.faces;
    }
    if (!parallel) {
        readers[0]->read();  // errors go to the caller as they are
    } else {
        std::atomic<bool> failed{false};
        tbb::parallel_for(size_t(0), readers.size(), [&](size_t k) {
            try {
                readers[k]->read();
            } catch (const InputError&) {
                failed = true;
            }
        });
        if (failed) return std::nullopt;
    }
    size_t triangles = 0;
    bool every_corner_has_normal = true, normals_follow_positions = true;
    for (size_t k = 0; k < runs.size(); ++k) {
        if (readers[k]->positions_read != runs[k].positions || readers[k]->normals_read != runs[k].normals)
            throw std::logic_error("OBJ reader: fewer v or vn than counted");
        triangles += readers[k]->face_material.size();
        every_corner_has_normal &= readers[k]->every_corner_has_normal;
        normals_follow_positions &= readers[k]->normals_follow_positions;
    }
    if (triangles > size_t(limits::max_triangles)) return std::nullopt;  // one go names the line
    if (triangles == 0) return mesh;                                     // the caller refuses it

    // Join the runs' faces in file order.
    std::vector<uint32_t> normal_index;
    if (readers.size() == 1) {
        mesh.indices = std::move(readers[0]->position_index);
        mesh.triangle_material = std::move(readers[0]->face_material);
        normal_index = std::move(readers[0]->normal_index);
    } else {
        for (const auto& reader : readers) {
            mesh.indices.insert(mesh.indices.end(), reader->position_index.begin(), reader->position_index.end());
            mesh.triangle_material.insert(mesh.triangle_material.end(), reader->face_material.begin(),
                                          reader->face_material.end());
            if (every_corner_has_normal && !normals_follow_positions) {
                const auto& own = reader->normals_follow_positions ? reader->position_index : reader->normal_index;
                normal_index.insert(normal_index.end(), own.begin(), own.end());
            }
        }
    }

    const bool smooth = every_corner_has_normal && normals > 0;
    if (!smooth) return mesh;
    if (normals_follow_positions) {
        all_normals.resize(mesh.positions.size(), 0.0f);
        mesh.normals = std::move(all_normals);
        return mesh;
    }
    // One vertex per distinct (position, normal) pair, numbered in order of first use, so that
    // normals index like positions. Each position keeps a short chain of the vertices made from it.
    const std::vector<float> file_positions = std::move(mesh.positions);
    mesh.positions.clear();
    constexpr uint32_t none = std::numeric_limits<uint32_t>::max();
    std::vector<uint32_t> first_vertex(positions, none), next_vertex, vertex_normal;
    for (size_t c = 0; c < mesh.indices.size(); ++c) {
        const uint32_t position = mesh.indices[c], normal = normal_index[c];
        uint32_t vertex = first_vertex[position];
        while (vertex != none && vertex_normal[vertex] != normal) vertex = next_vertex[vertex];
        if (vertex == none) {
            vertex = uint32_t(vertex_normal.size());
            vertex_normal.push_back(normal);
            next_vertex.push_back(first_vertex[position]);
            first_vertex[position] = vertex;
            mesh.positions.insert(mesh.positions.end(), &file_positions[3 * size_t(position)],
                                  &file_positions[3 * size_t(position)] + 3);
            mesh.normals.insert(mesh.normals.end(), &all_normals[3 * size_t(normal)],
                                &all_normals[3 * size_t(normal)] + 3);
        }
        mesh.indices[c] = vertex;
    }
    return mesh;
}

}  // namespace

MeshData load_obj_mesh(const std::string& path, const SourceLocation& referenced_at, int parts) {
    std::error_code error;
    const auto status = std::filesystem::status(path, error);
    if (error || !std::filesystem::exists(status))
        throw InputError(referenced_at, "mesh file '" + path + "' not found");
    if (!std::filesystem::is_regular_file(status))
        throw InputError(referenced_at, "mesh file '" + path + "' is not a regular file");
    const MappedTextFile file(path, limits::max_mesh_file_bytes, "mesh file");
    const std::string_view text = file.text();
    // Large files are read by every core at once, a run of lines each (below a few megabytes
    // the threads would cost more than they save).
    if (parts <= 0) {
        constexpr size_t bytes_per_part = size_t(4) << 20;
        parts = int(std::clamp<size_t>(text.size() / bytes_per_part, 1,
                                       size_t(std::max(1, tbb::this_task_arena::max_concurrency()))));
    }
    std::optional<MeshData> mesh;
    if (parts > 1) mesh = read_obj(path, text, size_t(parts));
    if (!mesh) mesh = read_obj(path, text, 1);
    if (mesh->indices.empty()) throw InputError(referenced_at, "mesh file '" + path + "' has no faces");
    return std::move(*mesh);
}

}  // namespace whitted
