// SPDX-License-Identifier: MIT
// The Cornell CS4620 course's .msh mesh files: whitespace-separated words, read strictly, every
// word with its line and column so that a mistake names FILE.msh:LINE:COL.

#include "scene/msh_file.h"

#include "scene/text_checks.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <string_view>

namespace whitted {
namespace {

class Words {
public:
    Words(std::string_view text, std::string file) : m_text(text), m_file(std::move(file)) {}

    /// The next word, or an empty view at the end of the file; `where` receives its place.
    std::string_view next(SourceLocation& where) {
        while (m_pos < m_text.size() && is_space(m_text[m_pos])) advance();
        where = {m_file, m_line, m_column};
        const size_t begin = m_pos;
        while (m_pos < m_text.size() && !is_space(m_text[m_pos])) advance();
        return m_text.substr(begin, m_pos - begin);
    }
    SourceLocation here() const { return {m_file, m_line, m_column}; }

private:
    static bool is_space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v'; }
    void advance() {
        if (ends_line(m_text, m_pos++)) {
            ++m_line;
            m_column = 1;
        } else {
            ++m_column;
        }
    }
    std::string_view m_text;
    std::string m_file;
    size_t m_pos = 0;
    int m_line = 1, m_column = 1;
};

/// A word of the file as a message names it: quoted and escaped (a terminal never sees its
/// control characters) when it is short enough to be a mistyped number or section name, else by
/// its length only, so that a .msh that is a link to another file (/etc/passwd) shows none of it.
std::string shown(std::string_view word) {
    if (word.size() > 12) return "a word of " + std::to_string(word.size()) + " bytes";
    return "'" + printable(word, 12) + "'";
}

double read_number(Words& words, const std::string& what) {
    SourceLocation where;
    const std::string_view word = words.next(where);
    if (word.empty()) throw InputError(where, "the file ends early: expected " + what);
    std::string_view digits = word;
    if (digits.front() == '+') digits.remove_prefix(1);
    double value = 0;
    const auto [end, error] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
    if (error == std::errc::result_out_of_range)
        throw InputError(where, what + ": " + shown(word) + " is out of range");
    if (error != std::errc() || end != digits.data() + digits.size() || !std::isfinite(value))
        throw InputError(where, what + ": expected a number, got " + shown(word));
    if (std::fabs(value) > 3.4e38) throw InputError(where, what + ": " + shown(word) + " is beyond float range");
    return value;
}

int64_t read_count(Words& words, const std::string& what, int64_t limit) {
    SourceLocation where;
    const std::string_view word = words.next(where);
    if (word.empty()) throw InputError(where, "the file ends early: expected " + what);
    int64_t value = -1;
    const auto [end, error] = std::from_chars(word.data(), word.data() + word.size(), value);
    if (error != std::errc() || end != word.data() + word.size() || value < 0)
        throw InputError(where, what + ": expected a whole number ≥ 0, got " + shown(word));
    if (value > limit)
        throw InputError(where,
                         what + ": " + std::to_string(value) + " is more than the limit of " + std::to_string(limit));
    return value;
}

}  // namespace

MeshData load_msh_mesh(const std::string& path, const SourceLocation& referenced_at) {
    std::string text;
    try {
        text = read_text_file(path, limits::max_mesh_file_bytes, "mesh file");
    } catch (const InputError& e) {
        throw InputError(referenced_at, e.message() + ": " + path);
    }
    Words words(text, path);
    const int64_t vertex_count = read_count(words, "the vertex count (line 1)", limits::max_triangles * 3);
    const int64_t triangle_count = read_count(words, "the triangle count (line 2)", limits::max_triangles);
    if (vertex_count < 3) throw InputError({path, 1, 1}, "a mesh needs at least 3 vertices");
    if (triangle_count < 1) throw InputError({path, 2, 1}, "a mesh needs at least one triangle");
    // The counts reserve no more than the file can hold (a number and a space take two bytes at
    // least): a header's count is not trusted with memory before the numbers are there.
    const size_t most_numbers = text.size() / 2 + 1;
    MeshData mesh;
    bool seen_vertices = false, seen_triangles = false, seen_normals = false, seen_texcoords = false;
    for (;;) {
        SourceLocation where;
        const std::string_view section = words.next(where);
        if (section.empty()) break;
        const auto once = [&](bool& seen) {
            if (seen) throw InputError(where, "section '" + std::string(section) + "' is given twice");
            seen = true;
        };
        if (section == "vertices") {
            once(seen_vertices);
            mesh.positions.reserve(std::min(3 * size_t(vertex_count), most_numbers));
            for (int64_t i = 0; i < 3 * vertex_count; ++i)
                mesh.positions.push_back(float(read_number(words, "vertex " + std::to_string(i / 3))));
        } else if (section == "triangles") {
            once(seen_triangles);
            mesh.indices.reserve(std::min(3 * size_t(triangle_count), most_numbers));
            for (int64_t i = 0; i < 3 * triangle_count; ++i) {
                SourceLocation at;
                const std::string what = "triangle " + std::to_string(i / 3);
                const std::string_view word = words.next(at);
                if (word.empty()) throw InputError(at, "the file ends early: expected " + what);
                int64_t index = -1;
                const auto [end, error] = std::from_chars(word.data(), word.data() + word.size(), index);
                if (error != std::errc() || end != word.data() + word.size())
                    throw InputError(at, what + ": expected a vertex index, got " + shown(word));
                if (index < 0 || index >= vertex_count)
                    throw InputError(at, what + ": vertex index " + std::to_string(index) + " is out of range (0.." +
                                             std::to_string(vertex_count - 1) + ")");
                mesh.indices.push_back(uint32_t(index));
            }
        } else if (section == "normals") {
            once(seen_normals);
            mesh.normals.reserve(std::min(3 * size_t(vertex_count), most_numbers));
            for (int64_t i = 0; i < 3 * vertex_count; ++i)
                mesh.normals.push_back(float(read_number(words, "normal " + std::to_string(i / 3))));
        } else if (section == "texcoords") {
            once(seen_texcoords);  // texture coordinates: Whitted has no textures
            for (int64_t i = 0; i < 2 * vertex_count; ++i)
                read_number(words, "texture coordinate " + std::to_string(i / 2));
        } else {
            throw InputError(
                where, "unknown section " + shown(section) + "; expected vertices, triangles, normals or texcoords");
        }
    }
    if (!seen_vertices) throw InputError(words.here(), "the file has no 'vertices' section");
    if (!seen_triangles) throw InputError(words.here(), "the file has no 'triangles' section");
    mesh.triangle_material.assign(size_t(triangle_count), -1);
    return mesh;
}

}  // namespace whitted
