// SPDX-License-Identifier: MIT
// A purpose-built Wavefront OBJ + MTL reader: tinyobjloader took 0.49 s for a 1M-triangle
// file (docs/performance.md) and reports problems without line numbers; this one reads the same
// file in a fraction of that and names FILE:LINE:COL for every mistake. Plain `v`, `vn` and `f`
// lines are read in one pass over the characters; a large file is cut into runs of lines that
// the cores read at once, after a quick count that says where each run's vertices go.
//
// Read: v (x y z, extra values ignored), vn, f (v, v/t, v//n, v/t/n; negative = relative),
// usemtl, mtllib. Ignored: vt, o, g, s, l, p, and statements it does not know (OBJ has many).
// MTL: newmtl, Ka, Kd, Ks, Ns, illum. Polygons: a convex one is fanned from its first corner;
// any other is cut into ears in its own plane (triangulate_polygon), once all positions are
// known, since a face may use positions another run of lines reads. Text is bytes: names may
// hold any (Latin-1 is common), a UTF-8 byte-order mark is skipped, control bytes are refused.

#include "scene/mesh_file.h"

#include "scene/text_checks.h"

#include <sys/stat.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <memory>
#include <optional>
#include <set>
#include <stdexcept>
#include <string_view>
#include <unordered_map>
#include <unordered_set>
#include <utility>

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

/// OBJ and MTL have no encoding: keywords and numbers are ASCII, and names are whatever bytes
/// the exporter wrote (Latin-1 from older tools, UTF-8 from newer). So any byte is accepted but
/// NUL, DEL and the C0 control bytes other than tab, line feed and carriage return, which no text
/// has and which mark a binary file (or could drive a terminal from a comment or a name); the
/// first is named by line and column, in comments too. Called only for text that is not plain
/// (is_plain_text).
void check_text_bytes(std::string_view text, const std::string& path) {
    int line = 1, column = 1;
    for (size_t i = 0; i < text.size(); ++i) {
        const auto c = static_cast<unsigned char>(text[i]);
        if (ends_line(text, i)) {
            ++line, column = 1;
            continue;
        }
        if (c == 0) throw InputError({path, line, column}, "the file contains a NUL byte: is it a binary file?");
        if ((c < 0x20 && c != '\t' && c != '\r') || c == 0x7F) {
            char hex[8];
            std::snprintf(hex, sizeof hex, "0x%02X", unsigned(c));
            throw InputError({path, line, column},
                             std::string("the file contains the control byte ") + hex + ": is it a binary file?");
        }
        ++column;
    }
}

/// True when every byte is printable ASCII, a tab, a line feed or a carriage return: such text
/// needs no closer look (check_text_bytes). Eight bytes at a time (mesh files are tens of
/// megabytes): a word with no byte below 0x20, none at 0x7F and none above is plain at once; the
/// others (most hold a line end) are looked at byte by byte.
bool is_plain_text(std::string_view text) {
    const auto* bytes = reinterpret_cast<const unsigned char*>(text.data());
    const size_t n = text.size();
    const auto plain_byte = [](unsigned char c) {
        return (c >= 0x20 && c < 0x7F) || c == '\t' || c == '\n' || c == '\r';
    };
    size_t i = 0;
    for (; i + 8 <= n; i += 8) {
        uint64_t word;
        std::memcpy(&word, bytes + i, 8);
        constexpr uint64_t high = 0x8080808080808080ull, ones = 0x0101010101010101ull;
        if (word & high) return false;
        const uint64_t del = word ^ (ones * 0x7F);
        if ((del - ones) & ~del & high) return false;  // a byte 0x7F
        if ((word - ones * 0x20) & ~word & high)       // a byte below 0x20
            for (size_t k = 0; k < 8; ++k)
                if (!plain_byte(bytes[i + k])) return false;
    }
    for (; i < n; ++i)
        if (!plain_byte(bytes[i])) return false;
    return true;
}

/// The text with every CR that no LF follows made a LF: a lone CR ends a line (and so a
/// statement) in OBJ and MTL files, as in tinyobjloader (its safeGetline) and Assimp, and as CR,
/// LF and CRLF all end lines in every text format Whitted reads (ends_line). The byte count stays
/// the same, so every column is what it was. `storage` holds the copy, made only when the text
/// has a lone CR (CRLF files are read as they are: a CR is blank before the LF).
std::string_view with_lone_carriage_returns_as_line_feeds(std::string_view text, std::string& storage) {
    if (text.empty()) return text;  // an empty file's view may hold no pointer, which memchr must not get
    const char* const end = text.data() + text.size();
    const char* p = text.data();
    for (; (p = static_cast<const char*>(std::memchr(p, '\r', size_t(end - p)))); ++p)
        if (p + 1 == end || p[1] != '\n') break;
    if (!p) return text;
    storage.assign(text);
    for (size_t i = size_t(p - text.data()); i < storage.size(); ++i)
        if (storage[i] == '\r' && (i + 1 == storage.size() || storage[i + 1] != '\n')) storage[i] = '\n';
    return storage;
}

/// The text without a leading UTF-8 byte-order mark (some Windows tools write one; it is not
/// part of the first statement). A UTF-16 file is refused: every other byte would be NUL.
std::string_view without_byte_order_mark(std::string_view text, const std::string& path) {
    if (text.substr(0, 3) == "\xEF\xBB\xBF") return text.substr(3);
    if (text.substr(0, 2) == "\xFE\xFF" || text.substr(0, 2) == "\xFF\xFE")
        throw InputError({path, 1, 1},
                         "the file is UTF-16 text; OBJ and MTL files are read as bytes (ASCII, UTF-8 "
                         "or Latin-1): convert it first, e.g. iconv -f UTF-16 -t UTF-8");
    return text;
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

/// Any finite float std::from_chars reads as the whole token (a leading '+' allowed), the
/// nearest float; a value too small for a float (1e-50, even 1e-400) is its nearest float, a
/// subnormal or 0, as every C library's strtof gives it. False for everything the caller must
/// refuse (not a number, or beyond float range).
bool parse_any_float(std::string_view t, float& out) {
    if (t.empty()) return false;
    const char* begin = t.data() + (t.front() == '+' ? 1 : 0);
    const char* const end = t.data() + t.size();
    const auto [stop, error] = std::from_chars(begin, end, out);
    if (stop != end) return false;
    if (error == std::errc()) return std::isfinite(out);
    if (error != std::errc::result_out_of_range) return false;
    // Out of float range: too large (refused), or too small (underflow: the nearest float). A
    // double tells them apart, and for what is out of double range too the exponent's sign.
    double wide = 0;
    const auto [wide_stop, wide_error] = std::from_chars(begin, end, wide);
    if (wide_stop != end) return false;
    if (wide_error == std::errc()) {
        out = float(wide);  // underflows to a subnormal or ±0; a finite double beyond float is refused
        return std::isfinite(out);
    }
    const std::string_view digits(begin, size_t(end - begin));
    const size_t e = digits.find_first_of("eE");
    const bool tiny = e != std::string_view::npos && e + 1 < digits.size() && digits[e + 1] == '-';
    if (!tiny) return false;
    out = digits.front() == '-' ? -0.0f : 0.0f;
    return true;
}

/// "1 vertex", "8 vertices": a count and its noun ("vertex", "normal", "triangle", ...).
std::string count_of(int64_t count, const std::string& noun) {
    std::string plural = noun == "vertex" ? "vertices" : noun + "s";
    return std::to_string(count) + " " + (count == 1 ? noun : plural);
}

/// A name (material, file) for a message, in quotes: printable ASCII and valid UTF-8 as they
/// are, every other byte (Latin-1 letters, control bytes) as \xHH, so that a message is
/// always valid text whatever bytes the file had.
std::string quote_name(std::string_view name) {
    static const char hex[] = "0123456789ABCDEF";
    // A name of megabytes (a hostile usemtl) is cut: a message stays a line.
    constexpr size_t longest = 60;
    if (name.size() > longest)
        return quote_name(name.substr(0, longest)) + "... (" + std::to_string(name.size()) + " bytes)";
    std::string out = "'";
    const auto* bytes = reinterpret_cast<const unsigned char*>(name.data());
    for (size_t i = 0; i < name.size();) {
        const unsigned char c = bytes[i];
        // Bytes after c that a valid UTF-8 character starting with c has (0: not such a start).
        size_t extra = (c & 0xE0) == 0xC0 && c >= 0xC2   ? 1
                       : (c & 0xF0) == 0xE0              ? 2
                       : (c & 0xF8) == 0xF0 && c <= 0xF4 ? 3
                                                         : 0;
        for (size_t k = 1; extra > 0 && k <= extra; ++k)
            if (i + k >= name.size() || (bytes[i + k] & 0xC0) != 0x80) extra = 0;
        if (extra > 0) {
            out.append(name.substr(i, extra + 1));
            i += extra + 1;
        } else if (c >= 0x20 && c < 0x7F && c != '\\') {
            out += char(c), ++i;
        } else {
            out += "\\x", out += hex[c >> 4], out += hex[c & 15], ++i;
        }
    }
    return out + "'";
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
        // Why not: a number beyond float range (or inf, nan), or no number at all.
        const char* begin = t.data() + (t.front() == '+' ? 1 : 0);
        double wide = 0;
        const auto [end, error] = std::from_chars(begin, t.data() + t.size(), wide);
        if (end == t.data() + t.size() && (error == std::errc::result_out_of_range || error == std::errc()))
            fail(std::string(what) + " must be a finite number within float range (about 3.4e38), got " +
                 quote_name(t));
        fail(std::string("expected ") + what + ", got " + quote_name(t));
    }

    [[noreturn]] void fail(const std::string& message) const { throw InputError(where(), message); }
    /// The place of the last token, or rest().
    SourceLocation where() const { return {m_path, m_line_number, int(m_token_start) + 1}; }

    /// The column (from 1) where the last token, or rest(), began.
    size_t token_column() const { return m_token_start + 1; }

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

/// Reads an MTL file's materials. A statement before any `newmtl` belongs to no material: it is
/// left out with a warning, as other readers forgive it.
void read_mtl(const std::string& path, std::vector<MaterialDescription>& materials,
              std::unordered_map<std::string, int32_t>& by_name, std::vector<std::string>& warnings) {
    const std::string file_text = read_text_file(path, limits::max_mesh_file_bytes, "MTL file");
    std::string line_feeds;
    const std::string_view text =
        with_lone_carriage_returns_as_line_feeds(without_byte_order_mark(file_text, path), line_feeds);
    if (!is_plain_text(text)) check_text_bytes(text, path);
    MaterialDescription* current = nullptr;
    for_each_statement(path, text, [&](LineReader& line, std::string_view keyword) {
        if (keyword == "newmtl") {
            // Any bytes, spaces inside included; even none (Blender writes `newmtl ` for an
            // unnamed material, and `usemtl ` then picks it).
            const std::string name(line.rest());
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
        if (!current) {
            warnings.push_back(line.where().str() + ": " + std::string(keyword) +
                               " before any newmtl belongs to no material; it is left out");
            return;
        }
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
    bool plain_text = true;  ///< no byte that check_text_bytes must look at

    void count() {
        plain_text = is_plain_text(text);
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

/// A face of more than three corners: its first triangle (in its run, or in the mesh once
/// joined) and how many corners it has; its n − 2 triangles follow one another.
struct Polygon {
    size_t first_triangle;
    uint32_t corners;
    int line;
};

/// A file `mtllib` names: its path, the name as written, where, and whether it exists.
struct MtlFile {
    std::string path, name;
    SourceLocation where;
    bool exists;
};

/// What reading an OBJ file gives besides the triangles: what the materials are resolved from.
struct ObjContents {
    MeshData mesh;
    std::vector<std::pair<std::string, SourceLocation>> usemtl_names;
    std::vector<MtlFile> mtl_files;
    size_t lines_and_points = 0;
    int first_face_line_without_material = 0;  ///< 0: every face follows a usemtl
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
              size_t faces_before, size_t faces_held, Output output, MeshData* materials_into)
        : m_path(path),
          m_lines(lines),
          m_positions_before(positions_before),
          m_normals_before(normals_before),
          m_faces_before(faces_before),
          m_out(output),
          m_materials_into(materials_into) {
        position_index.reserve(3 * faces_held);  // triangles; polygons grow it once
        face_material.reserve(faces_held);
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
    std::vector<int32_t> face_material;  ///< 1 per triangle: index into usemtl_names, −1 = none
    bool every_corner_has_normal = true;
    bool normals_follow_positions = true;
    size_t positions_read = 0, normals_read = 0;
    size_t lines_and_points = 0;  ///< `l` and `p` statements, which are not drawn
    int first_face_line_without_material = 0;
    /// Faces of more than 3 corners, fanned for now: triangulate_polygons looks at each again
    /// once every position is known.
    std::vector<Polygon> polygons;
    /// The names `usemtl` gave, each with where it was first given; resolved against the MTL
    /// files once the whole file is read (mtllib may come after usemtl).
    std::vector<std::pair<std::string, SourceLocation>> usemtl_names;
    std::vector<MtlFile> mtl_files;  ///< in mtllib order

private:
    static constexpr uint32_t no_normal = std::numeric_limits<uint32_t>::max();
    static constexpr int max_fast_corners = 16;
    std::unordered_set<std::string> m_mtl_names_seen;  ///< add_mtl_files: each name once

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
        if (m_current_material < 0 && !first_face_line_without_material) first_face_line_without_material = line_number;
        if (corners > 3) polygons.push_back({face_material.size(), uint32_t(corners), line_number});
        for (int k = 1; k + 1 < corners; ++k) {  // fan from the first corner (see triangulate_polygons)
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
            const std::string name(line.rest());  // any bytes, spaces inside included
            const SourceLocation where{m_path, line_number, int(line.token_column())};
            if (keyword == "usemtl") {
                const auto [it, added] = m_usemtl_index.try_emplace(name, int32_t(usemtl_names.size()));
                if (added) usemtl_names.emplace_back(name, where);
                m_current_material = it->second;
            } else {
                add_mtl_files(name, where);
            }
        } else if (keyword == "l" || keyword == "p") {
            ++lines_and_points;
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
                    line.fail(std::string("expected a ") + what + " index, got " + quote_name(part));
                if (index == 0) line.fail(std::string(what) + " index 0: OBJ indices start at 1");
                const int64_t written = index;
                if (!resolve(index, count))
                    line.fail("face refers to " + std::string(what) + " " + std::to_string(written) + ", but " +
                              count_of(count, what) + (count == 1 ? " is" : " are") + " defined before it");
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
    std::unordered_map<std::string, int32_t> m_usemtl_index;  ///< name → index into usemtl_names
    int32_t m_current_material = -1;

    /// `mtllib` takes a list of file names separated by blanks, but exporters also write one name
    /// with spaces in it: the rest of the line is one file name if a file of that name exists
    /// beside the OBJ file, otherwise it is split at blanks. A file named again is read once:
    /// each reading would add its materials again (a file naming one MTL file of 100,000
    /// materials on 50 lines took 29 s and 2.8 GB).
    void add_mtl_files(const std::string& rest, const SourceLocation& where) {
        const std::filesystem::path folder = std::filesystem::path(m_path).parent_path();
        const auto exists = [&](const std::string& name) {
            std::error_code error;
            return !name.empty() && std::filesystem::is_regular_file(folder / name, error);
        };
        if (rest.empty()) return;
        if (exists(rest)) {
            if (m_mtl_names_seen.insert(rest).second)
                mtl_files.push_back({(folder / rest).string(), rest, where, true});
            return;
        }
        size_t begin = 0;
        while (begin < rest.size()) {
            while (begin < rest.size() && is_blank(rest[begin])) ++begin;
            size_t end = begin;
            while (end < rest.size() && !is_blank(rest[end])) ++end;
            if (end > begin && m_mtl_names_seen.insert(rest.substr(begin, end - begin)).second) {
                const std::string name = rest.substr(begin, end - begin);
                mtl_files.push_back({(folder / name).string(),
                                     name,
                                     {where.file, where.line, where.column + int(begin)},
                                     exists(name)});
            }
            begin = end;
        }
    }
};

/// The polygon in its own plane: the normal by Newell's method (the sum over the edges, which
/// is the polygon's vector area and stays right for any corner order, collinear and repeated
/// corners included), then the corners projected onto the coordinate plane most nearly
/// perpendicular to it, mirrored if need be so that the polygon runs anticlockwise.
struct PlanarPolygon {
    std::vector<double> u, v;

    PlanarPolygon() = default;
    explicit PlanarPolygon(const std::vector<Vec3>& corners) { set(corners); }

    /// Takes these corners (the storage is kept from one polygon to the next).
    void set(const std::vector<Vec3>& corners) {
        const size_t n = corners.size();
        Vec3 normal;
        // Relative to the first corner: coordinates far from the origin then lose no digits.
        const Vec3 origin = corners.empty() ? Vec3() : corners[0];
        for (size_t i = 0; i < n; ++i) {
            const Vec3 a = corners[i] - origin, b = corners[(i + 1) % n] - origin;
            normal += Vec3{(a.y - b.y) * (a.z + b.z), (a.z - b.z) * (a.x + b.x), (a.x - b.x) * (a.y + b.y)};
        }
        const int axis = std::fabs(normal.x) >= std::fabs(normal.y) && std::fabs(normal.x) >= std::fabs(normal.z) ? 0
                         : std::fabs(normal.y) >= std::fabs(normal.z)                                             ? 1
                                                                                                                  : 2;
        // Dropping x keeps (y, z), dropping y (z, x), dropping z (x, y): each pair is right-handed
        // about the dropped axis, so the area there has the sign of that normal component.
        const int first = (axis + 1) % 3, second = (axis + 2) % 3;
        const double mirror = normal[axis] < 0 ? -1.0 : 1.0;
        u.resize(n), v.resize(n);
        for (size_t i = 0; i < n; ++i) {
            const Vec3 p = corners[i] - origin;
            u[i] = mirror * p[first];
            v[i] = p[second];
        }
    }

    /// Twice the signed area of the triangle (a, b, c): > 0 when it turns left (anticlockwise).
    double turn(size_t a, size_t b, size_t c) const {
        return (u[b] - u[a]) * (v[c] - v[a]) - (v[b] - v[a]) * (u[c] - u[a]);
    }

    /// Whether corner p lies inside the triangle (a, b, c), which turns left, or on its edges.
    bool in_triangle(size_t p, size_t a, size_t b, size_t c) const {
        return turn(a, b, p) >= 0 && turn(b, c, p) >= 0 && turn(c, a, p) >= 0;
    }

    bool same_point(size_t a, size_t b) const { return u[a] == u[b] && v[a] == v[b]; }

    /// No corner turns right: the fan from any corner covers the polygon exactly once.
    bool is_convex() const {
        const size_t n = u.size();
        for (size_t i = 0; i < n; ++i)
            if (turn((i + n - 1) % n, i, (i + 1) % n) < 0) return false;
        return true;
    }
};

/// Reads the MTL files and gives every triangle its material: the one its `usemtl` names, or the
/// default one (with a warning) where there is none to give: no usemtl before the face, an
/// empty name, or a name while the OBJ file names no MTL file at all (then the names are only
/// labels). A name that the MTL files do not define is an error at that usemtl, saying why.
void resolve_materials(const std::string& path, ObjContents& contents) {
    MeshData& mesh = contents.mesh;
    std::unordered_map<std::string, int32_t> by_name;
    std::vector<const MtlFile*> missing;
    std::string read_names;  // "a.mtl, b.mtl" for messages
    // One file under many spellings (`./a.mtl`, `././a.mtl`, a link) is read once, as one name
    // on many lines is: by its identity, not its name.
    std::set<std::pair<dev_t, ino_t>> files_read;
    for (const MtlFile& mtl : contents.mtl_files) {
        if (!mtl.exists) {
            missing.push_back(&mtl);
            continue;
        }
        struct stat info {};
        if (::stat(mtl.path.c_str(), &info) == 0 && !files_read.insert({info.st_dev, info.st_ino}).second) continue;
        read_mtl(mtl.path, mesh.materials, by_name, mesh.warnings);
        read_names += (read_names.empty() ? "" : ", ") + quote_name(mtl.name);
    }
    std::vector<std::string> defined;
    for (const MaterialDescription& m : mesh.materials) defined.push_back(m.name);

    constexpr int32_t use_default = -2;
    std::vector<int32_t> material_of(contents.usemtl_names.size());
    std::vector<std::string> why_default(contents.usemtl_names.size());
    for (size_t k = 0; k < contents.usemtl_names.size(); ++k) {
        const auto& [name, where] = contents.usemtl_names[k];
        const auto it = by_name.find(name);
        if (it != by_name.end()) {
            material_of[k] = it->second;
            continue;
        }
        material_of[k] = use_default;
        if (name.empty()) {
            why_default[k] = where.str() + ": usemtl without a name, and no MTL material has the empty name";
        } else if (contents.mtl_files.empty()) {
            why_default[k] = where.str() + ": usemtl " + quote_name(name) + ", but the file names no MTL file (mtllib)";
        } else {
            std::string message = "material " + quote_name(name) + " is not defined";
            if (!read_names.empty()) message += " in " + read_names;
            for (const MtlFile* mtl : missing) {
                // A FIFO or device is never read (it may block or never end): say so, rather than
                // "not found" for a name the user can see in the folder.
                std::error_code error;
                const bool there = std::filesystem::exists(mtl->path, error);
                message += std::string(message.find(": the MTL file") == std::string::npos ? ": " : "; ") +
                           "the MTL file " + quote_name(mtl->name) + " (mtllib at " + mtl->where.str() +
                           (there ? ") is not a regular file" : ") was not found");
            }
            // did_you_mean writes the name as it is: quote it like the rest of the message.
            const std::string suggestion = did_you_mean(name, defined), head = " (did you mean '";
            if (suggestion.size() > head.size() + 3)
                message += " (did you mean " +
                           quote_name(suggestion.substr(head.size(), suggestion.size() - head.size() - 3)) + "?)";
            // Drawn, as other readers draw it, in the default material, with a warning.
            why_default[k] = where.str() + ": " + message;
        }
    }
    size_t default_triangles = 0;
    std::vector<size_t> default_triangles_of(contents.usemtl_names.size(), 0);
    size_t without_usemtl = 0;
    for (int32_t& m : mesh.triangle_material) {
        if (m >= 0 && material_of[size_t(m)] >= 0) {
            m = material_of[size_t(m)];
            continue;
        }
        m >= 0 ? ++default_triangles_of[size_t(m)] : ++without_usemtl;
        ++default_triangles;
        m = int32_t(mesh.materials.size());  // the default material, added below
    }
    if (default_triangles == 0) return;
    MaterialDescription fallback;
    fallback.name = default_obj_material_name;
    fallback.where = {path};
    fallback.kd.value = Color(0.6);
    mesh.materials.push_back(fallback);
    const std::string what = "; they get the default material (kd 0.6 grey; ka, ks, km 0)";
    if (without_usemtl > 0)
        mesh.warnings.push_back(SourceLocation{path, contents.first_face_line_without_material, 1}.str() +
                                ": faces without usemtl, from this one on (" +
                                count_of(int64_t(without_usemtl), "triangle") + ")" + what);
    for (size_t k = 0; k < contents.usemtl_names.size(); ++k)
        if (default_triangles_of[k] > 0)
            mesh.warnings.push_back(why_default[k] + " (" + count_of(int64_t(default_triangles_of[k]), "triangle") +
                                    ")" + what);
}

/// Above this many corners a face that is not convex is refused: ear clipping takes time that
/// grows with the square of the corners (triangulate_polygon bounds it at n²/2 tests, about 2 s
/// at this size on one core).
constexpr size_t max_concave_corners = 20000;

/// The ear clipping of one OBJ file, counted as triangulate_polygon's bound of n²/2 corner-in-
/// triangle tests per face: two faces at the corner limit (each face is bounded, but ten of them
/// took 25 s). Faces past it keep the fan from their first corner, with one warning.
constexpr uint64_t max_ear_clipping_tests_per_file = 400'000'000;

/// Looks again at every polygon, fanned while reading: where the fan is wrong (the polygon is
/// not convex) its n − 2 triangles are replaced by triangulate_polygon's, in place, while the
/// file's budget of ear clipping lasts (granted in file order). The polygons are independent, so
/// the cores share them; the result does not depend on how.
void triangulate_polygons(const std::string& path, const FloatArray& positions, const std::vector<Polygon>& polygons,
                          std::vector<uint32_t>& indices, std::vector<uint32_t>& normal_index,
                          std::vector<std::string>& warnings) {
    if (polygons.empty()) return;
    // The fan (0, j, j+1) for j = 1 … n−2 names corner 0, corner 1, then one more each.
    const auto fan_corners = [&](const Polygon& polygon, const std::vector<uint32_t>& index,
                                 std::vector<uint32_t>& out) {
        const size_t n = polygon.corners, t0 = polygon.first_triangle;
        out.assign({index[3 * t0], index[3 * t0 + 1]});
        for (size_t j = 0; j + 2 < n; ++j) out.push_back(index[3 * (t0 + j) + 2]);
    };
    const auto corners_of = [&](const std::vector<uint32_t>& position_of, std::vector<Vec3>& corners) {
        corners.resize(position_of.size());
        for (size_t c = 0; c < position_of.size(); ++c) {
            const float* xyz = &positions[3 * size_t(position_of[c])];
            corners[c] = {xyz[0], xyz[1], xyz[2]};
        }
    };
    // Which polygons the fan does not cover.
    std::vector<char> needs_ears(polygons.size(), 0);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, polygons.size(), 256), [&](const tbb::blocked_range<size_t>& r) {
        std::vector<uint32_t> position_of;
        std::vector<Vec3> corners;
        PlanarPolygon plane;
        for (size_t k = r.begin(); k != r.end(); ++k) {
            const Polygon& polygon = polygons[k];
            const size_t n = polygon.corners, t0 = polygon.first_triangle;
            if (n == 4) {
                // Quads, most polygons by far, in a few multiplications: the fan's two triangles
                // (0, 1, 2) and (0, 2, 3) face the same way exactly when corners 1 and 3 lie on
                // either side of the diagonal from 0 to 2, and then they cover the quad.
                const auto at = [&](size_t corner) {
                    const float* xyz = &positions[3 * size_t(indices[corner])];
                    return Vec3{xyz[0], xyz[1], xyz[2]};
                };
                const Vec3 p0 = at(3 * t0), p1 = at(3 * t0 + 1), p2 = at(3 * t0 + 2), p3 = at(3 * t0 + 5);
                if (dot(cross(p1 - p0, p2 - p0), cross(p2 - p0, p3 - p0)) > 0) continue;
            }
            fan_corners(polygon, indices, position_of);
            corners_of(position_of, corners);
            plane.set(corners);
            needs_ears[k] = !plane.is_convex();
        }
    });
    // In file order, so that which faces get ears does not depend on the threads: the first face
    // too large to cut is refused; the others are cut while the budget lasts.
    uint64_t granted = 0;
    size_t fanned = 0, first_fanned = 0;
    for (size_t k = 0; k < polygons.size(); ++k) {
        if (!needs_ears[k]) continue;
        const Polygon& polygon = polygons[k];
        if (polygon.corners > max_concave_corners)
            throw InputError({path, polygon.line, 1}, "a face of " + count_of(polygon.corners, "corner") +
                                                          " that is not convex; Whitted triangulates such faces of up "
                                                          "to " +
                                                          std::to_string(max_concave_corners) + " corners");
        const uint64_t tests = uint64_t(polygon.corners) * polygon.corners / 2;
        if (granted + tests <= max_ear_clipping_tests_per_file) {
            granted += tests;
        } else {
            needs_ears[k] = 0;
            if (fanned++ == 0) first_fanned = k;
        }
    }
    tbb::parallel_for(tbb::blocked_range<size_t>(0, polygons.size(), 256), [&](const tbb::blocked_range<size_t>& r) {
        std::vector<uint32_t> position_of, normal_of;
        std::vector<Vec3> corners;
        for (size_t k = r.begin(); k != r.end(); ++k) {
            if (!needs_ears[k]) continue;
            const Polygon& polygon = polygons[k];
            fan_corners(polygon, indices, position_of);
            corners_of(position_of, corners);
            const std::vector<uint32_t> triangles = triangulate_polygon(corners);
            if (!normal_index.empty()) fan_corners(polygon, normal_index, normal_of);
            const size_t t0 = polygon.first_triangle;
            for (size_t c = 0; c < triangles.size(); ++c) {
                indices[3 * t0 + c] = position_of[triangles[c]];
                if (!normal_index.empty()) normal_index[3 * t0 + c] = normal_of[triangles[c]];
            }
        }
    });
    if (fanned > 0)
        warnings.push_back(SourceLocation{path, polygons[first_fanned].line, 1}.str() + ": " +
                           count_of(int64_t(fanned), "face") + (fanned == 1 ? " that is" : " that are") +
                           " not convex, from this one on, keep the fan from the first corner (which may "
                           "cover more or less than the face): cutting them into ears would pass the file's limit of " +
                           std::to_string(max_ear_clipping_tests_per_file) +
                           " corner tests (n²/2 for a face of n corners)");
}

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
std::optional<ObjContents> read_obj(const std::string& path, std::string_view text, size_t parts) {
    std::vector<Lines> runs = split_lines(text, parts);
    tbb::parallel_for(size_t(0), runs.size(), [&](size_t k) { runs[k].count(); });
    for (const Lines& run : runs)
        if (!run.plain_text) {
            check_text_bytes(text, path);  // refuses binary files, names the line
            break;
        }
    const bool parallel = runs.size() > 1;
    size_t positions = 0, normals = 0, faces = 0;
    for (Lines& run : runs) {
        if (parallel && run.materials) return std::nullopt;
        positions += run.positions, normals += run.normals, faces += run.faces;
    }
    for (size_t k = 1; k < runs.size(); ++k) runs[k].first_line = runs[k - 1].first_line + int(runs[k - 1].newlines);

    ObjContents contents;
    MeshData& mesh = contents.mesh;
    mesh.positions = FloatArray(3 * positions);  // each run writes its own (not zeroed here)
    FloatArray all_normals(3 * normals);
    std::vector<std::unique_ptr<ObjReader>> readers;
    size_t positions_before = 0, normals_before = 0, faces_before = 0;
    for (const Lines& run : runs) {
        // The first run's arrays become the mesh's, the others' are appended to them: room for
        // every face (a triangle each; polygons grow them) is reserved there, untouched till read.
        const size_t faces_held = readers.empty() ? faces : run.faces;
        const ObjReader::Output output{mesh.positions.data() + 3 * positions_before,
                                       all_normals.data() + 3 * normals_before, run.positions, run.normals};
        readers.push_back(std::make_unique<ObjReader>(path, run, positions_before, normals_before, faces_before,
                                                      faces_held, output, parallel ? nullptr : &mesh));
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
        contents.lines_and_points += readers[k]->lines_and_points;
        if (!contents.first_face_line_without_material)
            contents.first_face_line_without_material = readers[k]->first_face_line_without_material;
    }
    contents.usemtl_names = std::move(readers[0]->usemtl_names);  // only a run read alone has them
    contents.mtl_files = std::move(readers[0]->mtl_files);
    if (triangles > size_t(limits::max_triangles)) return std::nullopt;  // one go names the line
    if (triangles == 0) return contents;                                 // the caller refuses it

    // Join the runs' faces in file order.
    std::vector<uint32_t> normal_index;
    std::vector<Polygon> polygons;
    mesh.indices = std::move(readers[0]->position_index);
    mesh.triangle_material = std::move(readers[0]->face_material);
    polygons = std::move(readers[0]->polygons);
    if (readers.size() == 1) {
        normal_index = std::move(readers[0]->normal_index);
    } else {
        if (every_corner_has_normal && !normals_follow_positions) {
            const auto& first = readers[0]->normals_follow_positions ? mesh.indices : readers[0]->normal_index;
            normal_index.assign(first.begin(), first.end());
        }
        for (size_t k = 1; k < readers.size(); ++k) {
            const auto& reader = readers[k];
            const size_t triangles_before = mesh.triangle_material.size();
            for (Polygon polygon : reader->polygons) {
                polygon.first_triangle += triangles_before;
                polygons.push_back(polygon);
            }
            mesh.indices.insert(mesh.indices.end(), reader->position_index.begin(), reader->position_index.end());
            mesh.triangle_material.insert(mesh.triangle_material.end(), reader->face_material.begin(),
                                          reader->face_material.end());
            if (every_corner_has_normal && !normals_follow_positions) {
                const auto& own = reader->normals_follow_positions ? reader->position_index : reader->normal_index;
                normal_index.insert(normal_index.end(), own.begin(), own.end());
            }
        }
    }

    triangulate_polygons(path, mesh.positions, polygons, mesh.indices, normal_index, mesh.warnings);

    const bool smooth = every_corner_has_normal && normals > 0;
    if (!smooth) return contents;
    if (normals_follow_positions) {
        all_normals.resize(mesh.positions.size(), 0.0f);
        mesh.normals = std::move(all_normals);
        return contents;
    }
    // One vertex per distinct (position, normal) pair, numbered in order of first use, so that
    // normals index like positions. Each position keeps a short chain of the vertices made from it.
    const FloatArray file_positions = std::move(mesh.positions);
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
    return contents;
}

}  // namespace

bool is_convex_polygon(const std::vector<Vec3>& corners) {
    return PlanarPolygon(corners).is_convex();
}

std::vector<uint32_t> triangulate_polygon(const std::vector<Vec3>& corners) {
    const size_t n = corners.size();
    std::vector<uint32_t> triangles;
    if (n < 3) return triangles;
    triangles.reserve(3 * (n - 2));
    const PlanarPolygon polygon(corners);
    if (polygon.is_convex()) {
        for (size_t k = 1; k + 1 < n; ++k) triangles.insert(triangles.end(), {0, uint32_t(k), uint32_t(k + 1)});
        return triangles;
    }
    // Ear clipping: a corner whose triangle with its two neighbours turns left and holds no other
    // corner is an ear; cutting it off leaves a polygon of one corner fewer that covers the rest.
    // Corners that turn neither way (collinear, or repeated) are cut first: their triangle covers
    // nothing, and they would otherwise make their neighbours look like non-ears. A simple polygon
    // always has an ear (two, in fact); should none be found (the polygon crosses itself) the
    // corner that turns left most is cut, so that every polygon still gets its n − 2 triangles.
    //
    // The time is bounded whatever the corners: each corner's turn is kept and worked out again
    // only for the two corners beside a cut (nothing else changes), the ear test looks only at
    // the corners that do not turn left (only they can lie inside an ear), and the corner-in-
    // triangle tests of the ear search are limited to n²/2 in all. A polygon that needs more
    // (one that crosses itself, typically: a search then finds no ear in each of n steps) has
    // its remaining corners cut as a crossing polygon's are, sharpest left turn first.
    std::vector<size_t> previous(n), next(n);
    for (size_t i = 0; i < n; ++i) previous[i] = (i + n - 1) % n, next[i] = (i + 1) % n;
    std::vector<double> turn(n);
    std::vector<char> cut_off(n, 0);
    std::vector<size_t> not_left;  // corners that did not turn left when last looked at
    size_t flat = 0;               // corners whose turn is 0
    const auto look_at = [&](size_t i) {
        if (turn[i] == 0) --flat;
        turn[i] = polygon.turn(previous[i], i, next[i]);
        if (turn[i] == 0) ++flat;
        if (turn[i] <= 0) not_left.push_back(i);  // a corner may be listed twice: harmless
    };
    for (size_t i = 0; i < n; ++i) {
        turn[i] = 1;  // so that look_at counts a flat corner once
        look_at(i);
    }
    const auto cut = [&](size_t i) {
        triangles.insert(triangles.end(), {uint32_t(previous[i]), uint32_t(i), uint32_t(next[i])});
        next[previous[i]] = next[i];
        previous[next[i]] = previous[i];
        cut_off[i] = 1;
        if (turn[i] == 0) --flat;
        look_at(previous[i]);
        look_at(next[i]);
    };
    uint64_t tests_left = uint64_t(n) * uint64_t(n) / 2;
    const auto is_ear = [&](size_t i) {
        const size_t a = previous[i], c = next[i];
        if (turn[i] <= 0) return false;
        // Only a corner that does not turn left can lie inside an ear of a simple polygon; one
        // at the same place as a corner of the ear (a polygon with a slit to a hole) does not count.
        for (size_t k = 0; k < not_left.size();) {
            const size_t p = not_left[k];
            if (cut_off[p] || turn[p] > 0) {  // gone, or turns left now: off the list
                not_left[k] = not_left.back();
                not_left.pop_back();
                continue;
            }
            ++k;
            if (p == a || p == i || p == c) continue;
            if (polygon.same_point(p, a) || polygon.same_point(p, i) || polygon.same_point(p, c)) continue;
            if (tests_left == 0) return false;
            --tests_left;
            if (polygon.in_triangle(p, a, i, c)) return false;
        }
        return true;
    };
    size_t remaining = n, i = 0;
    while (remaining > 3) {
        size_t chosen = n;
        // A corner that covers nothing, else the first ear from where the last cut was.
        if (flat > 0)
            for (size_t k = 0, j = i; k < remaining && chosen == n; ++k, j = next[j])
                if (turn[j] == 0) chosen = j;
        for (size_t k = 0, j = i; k < remaining && chosen == n && tests_left > 0; ++k, j = next[j])
            if (is_ear(j)) chosen = j;
        if (chosen == n) {  // not a simple polygon (or the tests are used up): the sharpest left turn
            double best = -std::numeric_limits<double>::infinity();
            for (size_t k = 0, j = i; k < remaining; ++k, j = next[j])
                if (turn[j] > best) best = turn[j], chosen = j;
        }
        i = next[chosen];
        cut(chosen);
        --remaining;
    }
    triangles.insert(triangles.end(), {uint32_t(previous[i]), uint32_t(i), uint32_t(next[i])});
    return triangles;
}

MeshData load_obj_mesh(const std::string& path, const SourceLocation& referenced_at, int parts, bool need_materials) {
    std::error_code error;
    const auto status = std::filesystem::status(path, error);
    if (error || !std::filesystem::exists(status))
        throw InputError(referenced_at, "mesh file '" + path + "' not found");
    if (!std::filesystem::is_regular_file(status))
        throw InputError(referenced_at, "mesh file '" + path + "' is not a regular file");
    const MappedTextFile file(path, limits::max_mesh_file_bytes, "mesh file");
    // Through read(): a file truncated while the parts are read is an error, never SIGBUS.
    return file.read([&]() -> MeshData {
        std::string line_feeds;
        const std::string_view text =
            with_lone_carriage_returns_as_line_feeds(without_byte_order_mark(file.text(), path), line_feeds);
        // Large files are read by every core at once, a run of lines each (below a few megabytes
        // the threads would cost more than they save).
        if (parts <= 0) {
            constexpr size_t bytes_per_part = size_t(4) << 20;
            parts = int(std::clamp<size_t>(text.size() / bytes_per_part, 1,
                                           size_t(std::max(1, tbb::this_task_arena::max_concurrency()))));
        }
        std::optional<ObjContents> contents;
        if (parts > 1) contents = read_obj(path, text, size_t(parts));
        if (!contents) contents = read_obj(path, text, 1);
        MeshData& mesh = contents->mesh;
        if (mesh.indices.empty()) {
            std::string why;
            if (text.find_first_not_of(" \t\r\n\v\f") == std::string_view::npos)
                why = text.empty() ? ": the file is empty" : ": the file is blank";
            else if (contents->lines_and_points > 0)
                why = ": its " + count_of(int64_t(contents->lines_and_points), "line (l) or point (p) statement") +
                      (contents->lines_and_points == 1 ? " is" : " are") + " not drawn (Whitted renders faces, f)";
            else if (!mesh.positions.empty())
                why = ": only vertices (v), no f statements";
            throw InputError(referenced_at, "mesh file '" + path + "' has no faces" + why);
        }
        if (need_materials) {
            resolve_materials(path, *contents);
        } else {
            std::fill(mesh.triangle_material.begin(), mesh.triangle_material.end(), -1);
        }
        return std::move(mesh);
    });
}

void print_mesh_warnings(const MeshData& mesh) {
    for (const std::string& warning : mesh.warnings) std::fprintf(stderr, "whitted: warning: %s\n", warning.c_str());
}

}  // namespace whitted
