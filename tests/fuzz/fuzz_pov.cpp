// SPDX-License-Identifier: MIT
// Fuzzes the POV-Ray writer: any scene that Whitted accepts is converted, and the SDL must
// consist only of what the writer itself emits: its keywords, punctuation, finite numbers,
// `//` comments (holding no line break), and the names it gives prototype meshes
// (`#declare whitted_prototype_I_K =`, used only after they are declared). A name, a string
// or a directive smuggled in from the scene file, or an `inf`/`nan` that POV-Ray would
// misparse, is a finding.

#include "converters/pov_writer.h"
#include "fuzz_support.h"
#include "scene/description.h"
#include "scene/scene.h"

#include <cctype>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <set>
#include <stdexcept>
#include <string>

namespace {

const std::set<std::string>& sdl_keywords() {
    static const std::set<std::string> words{
        "adc_bailout", "ambient", "ambient_light", "angle", "assumed_gamma", "background", "box", "brilliance",
        "camera", "color", "diffuse", "face_indices", "finish", "global_lights", "global_settings", "inside_vector",
        "light_group", "light_source", "location", "look_at", "matrix", "max_trace_level", "mesh2", "normal_vectors",
        "object", "off", "orthographic", "parallel", "perspective", "phong", "phong_size", "pigment", "plane",
        "point_at", "reflection", "rgb", "rgbf", "rgbt", "right", "roughness", "sky", "specular", "sphere",
        "split_union", "texture", "translate", "union", "up", "vertex_vectors",
        // Cylinders and cones (`open` for an uncapped one), and glass: the refracting interior.
        "cone", "cylinder", "open", "interior", "ior"};
    return words;
}

/// `whitted_prototype_<digits>_<digits>`: the only names the writer makes up.
bool is_prototype_name(const std::string& word) {
    static const std::string prefix = "whitted_prototype_";
    if (word.compare(0, prefix.size(), prefix) != 0) return false;
    int numbers = 0;
    size_t i = prefix.size();
    while (i < word.size()) {  // digits, '_', digits: exactly two runs of digits
        const size_t start = i;
        while (i < word.size() && std::isdigit(static_cast<unsigned char>(word[i]))) ++i;
        if (i == start) return false;
        ++numbers;
        if (i < word.size()) {
            if (word[i] != '_' || numbers == 2) return false;
            ++i;
            if (i == word.size()) return false;
        }
    }
    return numbers == 2;
}

[[noreturn]] void reject(const std::string& sdl, size_t at, const char* why) {
    std::fprintf(stderr, "fuzz_pov: %s at byte %zu: ...%s...\n", why, at,
                 sdl.substr(at > 40 ? at - 40 : 0, 80).c_str());
    __builtin_trap();
}

/// Lexes the SDL the way POV-Ray would and refuses anything the writer never writes.
void check_sdl(const std::string& sdl) {
    size_t i = 0;
    const size_t n = sdl.size();
    bool seen_version = false;
    std::set<std::string> declared;
    while (i < n) {
        const unsigned char c = sdl[i];
        if (c == ' ' || c == '\n') {
            ++i;
        } else if (c == '/' && i + 1 < n && sdl[i + 1] == '/') {
            const size_t end = sdl.find('\n', i);
            if (end == std::string::npos) reject(sdl, i, "unterminated comment");
            for (size_t k = i; k < end; ++k)
                if (sdl[k] == '\r' || static_cast<unsigned char>(sdl[k]) < 0x20 || sdl[k] == 0x7f)
                    reject(sdl, k, "control character in a comment");
            i = end + 1;
        } else if (c == '#') {
            if (!seen_version) {
                if (sdl.compare(i, 14, "#version 3.7;\n") != 0) reject(sdl, i, "directive");
                seen_version = true;
                i += 14;
                continue;
            }
            // `#declare NAME =\n`, each name once.
            static const std::string declare = "#declare ";
            if (sdl.compare(i, declare.size(), declare) != 0) reject(sdl, i, "directive");
            const size_t name_start = i + declare.size();
            const size_t name_end = sdl.find(" =\n", name_start);
            if (name_end == std::string::npos) reject(sdl, i, "unterminated #declare");
            const std::string name = sdl.substr(name_start, name_end - name_start);
            if (!is_prototype_name(name) || !declared.insert(name).second) reject(sdl, i, "#declare of a name");
            i = name_end + 3;
        } else if (std::isalpha(c) || c == '_') {
            size_t end = i;
            while (end < n && (std::isalnum(static_cast<unsigned char>(sdl[end])) || sdl[end] == '_')) ++end;
            const std::string word = sdl.substr(i, end - i);
            if (!sdl_keywords().count(word) && !declared.count(word)) reject(sdl, i, "unexpected identifier");
            i = end;
        } else if (std::isdigit(c) || c == '-' || c == '.') {
            // A number as fmt writes a double: -?digits[.digits][e[+-]digits]
            size_t k = i;
            if (sdl[k] == '-') ++k;
            const size_t digits_start = k;
            while (k < n && std::isdigit(static_cast<unsigned char>(sdl[k]))) ++k;
            if (k == digits_start) reject(sdl, i, "not a number");
            if (k < n && sdl[k] == '.') {
                ++k;
                const size_t fraction = k;
                while (k < n && std::isdigit(static_cast<unsigned char>(sdl[k]))) ++k;
                if (k == fraction) reject(sdl, i, "not a number");
            }
            if (k < n && sdl[k] == 'e') {
                ++k;
                if (k < n && (sdl[k] == '+' || sdl[k] == '-')) ++k;
                const size_t exponent = k;
                while (k < n && std::isdigit(static_cast<unsigned char>(sdl[k]))) ++k;
                if (k == exponent) reject(sdl, i, "not a number");
            }
            i = k;
        } else if (c == '{' || c == '}' || c == '<' || c == '>' || c == ',' || c == ';') {
            ++i;
        } else {
            reject(sdl, i, "unexpected character");
        }
    }
    if (!seen_version) reject(sdl, 0, "no #version");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    using namespace whitted;
    const std::string text(reinterpret_cast<const char*>(data), size);
    const std::string path = (fuzz::scratch_directory() / "scene.yaml").string();
    SceneDescription description;
    Scene scene;
    try {
        description = parse_scene_text(text, path);
        scene = validate_scene(description);  // `whitted convert` refuses what validation refuses
    } catch (const InputError&) {
        return 0;
    }
    try {
        const std::string sdl = pov::scene_to_sdl(description, scene);
        check_sdl(sdl);
        (void)pov::ini_for(description, "scene.pov", "scene.png");
        (void)pov::radiance_upper_bound(description);
    } catch (const InputError&) {
        // e.g. a value that overflows once transformed: refused, with a location.
    } catch (const std::invalid_argument&) {
    }
    return 0;
}
