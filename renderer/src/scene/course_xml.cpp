// SPDX-License-Identifier: MIT
// Course XML → SceneDescription. expat parses the XML into a small tree of elements, each with
// its line and column (and those of its text); the tree is then read strictly: every element and
// attribute must be one the course's ray tracer knows, and every value becomes a Located value at
// the place of its own number.

#include "scene/course_xml.h"

#include "scene/text_checks.h"

#include <expat.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <unordered_map>

namespace whitted {
namespace {

struct Element {
    std::string name;
    SourceLocation where;
    std::vector<std::pair<std::string, std::string>> attributes;
    std::vector<std::unique_ptr<Element>> children;
    std::string text;
    SourceLocation text_where;  ///< where the text's first character is
    bool text_started = false;

    const std::string* attribute(const std::string& key) const {
        for (const auto& [k, v] : attributes)
            if (k == key) return &v;
        return nullptr;
    }
};

/// The course's parser finds the setter an element stands for by its name, ignoring case
/// (ray/Parser.java matches it with equalsIgnoreCase), so its own scenes write both <minPt> and
/// <minpt>. Each element name is read in the spelling the reader below compares with; a name
/// that is none of them is kept as written, for the message that refuses it.
std::string canonical_element_name(const char* name) {
    static const char* const known[] = {"scene",      "camera",       "image",         "samples",    "shader",
                                        "surface",    "light",        "viewPoint",     "viewDir",    "viewUp",
                                        "projNormal", "projDistance", "viewWidth",     "viewHeight", "position",
                                        "intensity",  "diffuseColor", "specularColor", "exponent",   "refractiveIndex",
                                        "substrate",  "center",       "radius",        "minPt",      "maxPt",
                                        "data",       "translate",    "rotate",        "scale"};
    const std::string_view given(name);
    for (const char* candidate : known) {
        const std::string_view k(candidate);
        if (k.size() == given.size() && std::equal(k.begin(), k.end(), given.begin(), [](char a, char b) {
                return std::tolower(static_cast<unsigned char>(a)) == std::tolower(static_cast<unsigned char>(b));
            }))
            return std::string(k);
    }
    return std::string(given);
}

/// Elements nested deeper than this are refused while reading, as YAML values are
/// (yaml_tree.h): a course scene nests a few levels (groups at most limits::max_nesting), and a
/// tree of hundreds of thousands of levels overflowed the stack when it was freed.
constexpr size_t max_xml_depth = 512;

struct TreeBuilder {
    XML_Parser parser = nullptr;
    std::string file;
    std::unique_ptr<Element> root;
    std::vector<Element*> open;
    std::optional<InputError> stopped;  ///< why the parser was stopped, if it was

    SourceLocation here() const {
        return {file, int(XML_GetCurrentLineNumber(parser)), int(XML_GetCurrentColumnNumber(parser)) + 1};
    }

    static void start(void* data, const XML_Char* name, const XML_Char** attributes) {
        auto* self = static_cast<TreeBuilder*>(data);
        if (self->open.size() >= max_xml_depth) {
            self->stopped.emplace(self->here(),
                                  "elements nested more than " + std::to_string(max_xml_depth) + " levels deep");
            XML_StopParser(self->parser, XML_FALSE);
            return;
        }
        auto element = std::make_unique<Element>();
        element->name = canonical_element_name(name);
        element->where = self->here();
        for (int i = 0; attributes[i]; i += 2) element->attributes.emplace_back(attributes[i], attributes[i + 1]);
        Element* raw = element.get();
        if (self->open.empty())
            self->root = std::move(element);
        else
            self->open.back()->children.push_back(std::move(element));
        self->open.push_back(raw);
    }
    static void end(void* data, const XML_Char*) {
        auto* self = static_cast<TreeBuilder*>(data);
        if (!self->open.empty()) self->open.pop_back();
    }
    static void text(void* data, const XML_Char* s, int length) {
        auto* self = static_cast<TreeBuilder*>(data);
        if (self->open.empty()) return;
        Element* element = self->open.back();
        // Positions are counted from the start of the first chunk that is not all blank (expat
        // hands text over in pieces, e.g. line by line); blanks before it are dropped.
        const std::string_view chunk(s, size_t(length));
        if (!element->text_started) {
            if (chunk.find_first_not_of(" \t\r\n") == std::string_view::npos) return;
            element->text_started = true;
            element->text_where = self->here();
        }
        element->text.append(chunk);
    }
};

std::unique_ptr<Element> parse_xml(const std::string& text, const std::string& path) {
    TreeBuilder builder;
    builder.file = path;
    std::unique_ptr<XML_ParserStruct, void (*)(XML_Parser)> parser(XML_ParserCreate("UTF-8"), XML_ParserFree);
    if (!parser) throw std::bad_alloc();
    builder.parser = parser.get();
    XML_SetUserData(parser.get(), &builder);
    XML_SetElementHandler(parser.get(), TreeBuilder::start, TreeBuilder::end);
    XML_SetCharacterDataHandler(parser.get(), TreeBuilder::text);
    if (text.size() > size_t(std::numeric_limits<int>::max())) throw InputError({path}, "the scene file is too large");
    if (XML_Parse(parser.get(), text.data(), int(text.size()), XML_TRUE) == XML_STATUS_ERROR) {
        if (builder.stopped) throw *builder.stopped;
        throw InputError(
            {path, int(XML_GetCurrentLineNumber(parser.get())), int(XML_GetCurrentColumnNumber(parser.get())) + 1},
            std::string("XML syntax error: ") + XML_ErrorString(XML_GetErrorCode(parser.get())));
    }
    if (!builder.root) throw InputError({path, 1, 1}, "the file has no XML element");
    return std::move(builder.root);
}

/// The whitespace-separated words of an element's text, each with its place in the file.
std::vector<std::pair<std::string, SourceLocation>> words_of(const Element& e) {
    std::vector<std::pair<std::string, SourceLocation>> words;
    SourceLocation at = e.text_where.file.empty() ? e.where : e.text_where;
    std::string word;
    SourceLocation word_at;
    for (const char c : e.text) {
        const bool space = c == ' ' || c == '\t' || c == '\n' || c == '\r';
        if (!space && word.empty()) word_at = at;
        if (!space) word += c;
        if (space && !word.empty()) words.emplace_back(std::move(word), word_at), word.clear();
        if (c == '\n')
            ++at.line, at.column = 1;
        else
            ++at.column;
    }
    if (!word.empty()) words.emplace_back(std::move(word), word_at);
    return words;
}

std::string shown(const std::string& word) {
    return word.size() > 40 ? word.substr(0, 37) + "..." : word;
}

double to_number(const std::string& word, const SourceLocation& at, const std::string& what) {
    std::string_view view = word;
    if (!view.empty() && view.front() == '+') view.remove_prefix(1);
    double value = 0;
    const auto [end, error] = std::from_chars(view.data(), view.data() + view.size(), value);
    if (error == std::errc::result_out_of_range)
        throw InputError(at, what + ": number '" + shown(word) + "' is out of range");
    if (error != std::errc() || end != view.data() + view.size() || !std::isfinite(value))
        throw InputError(at, what + ": expected a number, got '" + shown(word) + "'");
    return value;
}

/// `count` numbers from an element's text.
std::vector<Located<double>> numbers(const Element& e, size_t count) {
    const auto words = words_of(e);
    const std::string what = "<" + e.name + ">";
    if (words.size() != count)
        throw InputError(words.empty() ? e.where : words.front().second, what + ": expected " + std::to_string(count) +
                                                                             (count == 1 ? " number" : " numbers") +
                                                                             ", got " + std::to_string(words.size()));
    std::vector<Located<double>> out;
    for (const auto& [word, at] : words) {
        Located<double> v{to_number(word, at, what)};
        v.where = at;
        v.given = true;
        out.push_back(v);
    }
    return out;
}

Located<double> number(const Element& e) {
    return numbers(e, 1)[0];
}

Located<Vec3> vec3(const Element& e) {
    const auto n = numbers(e, 3);
    Located<Vec3> v{Vec3{n[0].value, n[1].value, n[2].value}};
    v.where = n[0].where;
    v.given = true;
    return v;
}

Located<int64_t> integer(const Element& e, const Located<double>& n) {
    if (n.value != std::floor(n.value) || std::fabs(n.value) > 9.0e15)
        throw InputError(n.where, "<" + e.name + ">: expected a whole number");
    Located<int64_t> out{int64_t(n.value)};
    out.where = n.where;
    out.given = true;
    return out;
}

/// Names for a message: each escaped and cut short, at most 20 of them, then how many in all (a
/// hostile file may name 100,000 shaders, each megabytes long).
std::string join(const std::vector<std::string>& words) {
    constexpr size_t most_listed = 20;
    std::string out;
    for (size_t i = 0; i < words.size() && i < most_listed; ++i)
        out += (out.empty() ? "" : ", ") + printable(words[i], 40);
    if (words.size() > most_listed) out += ", ... (" + std::to_string(words.size()) + " in all)";
    return out;
}

[[noreturn]] void unknown_element(const Element& child, const Element& parent, const std::vector<std::string>& known) {
    throw InputError(child.where, "<" + parent.name + ">: unknown element <" + printable(child.name) + ">" +
                                      did_you_mean(child.name, known) + "; expected one of: " + join(known));
}

/// Refuses attributes other than `allowed`, and text where only elements belong.
void check_attributes(const Element& e, const std::vector<std::string>& allowed) {
    for (const auto& [key, value] : e.attributes)
        if (std::find(allowed.begin(), allowed.end(), key) == allowed.end())
            throw InputError(e.where, "<" + e.name + ">: unknown attribute '" + key + "'" + did_you_mean(key, allowed) +
                                          (allowed.empty() ? "; it takes none" : "; expected: " + join(allowed)));
}
void check_no_text(const Element& e) {
    const auto words = words_of(e);
    if (!words.empty())
        throw InputError(words.front().second, "<" + e.name + ">: unexpected text '" + shown(words.front().first) +
                                                   "'; this element holds only elements");
}
void check_leaf(const Element& e) {
    check_attributes(e, {});
    if (!e.children.empty())
        throw InputError(e.children.front()->where, "<" + e.name + ">: expected a value, not elements");
}

class CourseReader {
public:
    CourseReader(std::string path) : m_path(std::move(path)) {
        m_directory = std::filesystem::path(m_path).parent_path().string();
    }

    SceneDescription read(const Element& root) {
        if (root.name != "scene")
            throw InputError(root.where, "expected the course's <scene> element, got <" + root.name + ">");
        check_attributes(root, {});
        check_no_text(root);
        SceneDescription scene;
        scene.path = m_path;
        m_shaders = &scene.materials;
        // The course's conventions, written as Whitted scene keys (docs/course-format.md).
        const auto course_default = [&](auto& located, auto value) {
            located.value = value;
            located.where = root.where;
            located.given = true;
        };
        course_default(scene.ambient, Color(0.0));
        course_default(scene.convention, Convention::course);
        course_default(scene.max_depth, int64_t(course_max_depth));
        course_default(scene.min_weight, course_min_weight);
        scene.image.where = root.where;
        bool have_camera = false, have_image = false;
        const std::vector<std::string> known{"camera", "image", "samples", "shader", "surface", "light"};
        // Shaders first, wherever they are, so a surface may refer to one defined after it.
        for (const auto& child : root.children)
            if (child->name == "shader") read_named_shader(*child, scene);
        for (const auto& child : root.children) {
            const Element& e = *child;
            if (e.name == "camera") {
                if (have_camera) throw InputError(e.where, "<scene>: a second <camera>");
                have_camera = true;
                scene.camera = read_camera(e);
            } else if (e.name == "image") {
                if (have_image) throw InputError(e.where, "<scene>: a second <image>");
                have_image = true;
                check_leaf(e);
                const auto size = numbers(e, 2);
                scene.image.width = integer(e, size[0]);
                scene.image.height = integer(e, size[1]);
            } else if (e.name == "samples") {
                check_leaf(e);
                const Located<int64_t> s = integer(e, number(e));
                const auto side = int64_t(std::llround(std::sqrt(double(std::max<int64_t>(s.value, 0)))));
                if (s.value < 1 || side * side != s.value)
                    throw InputError(s.where,
                                     "<samples>: the course samples a √s × √s grid; s must be a square "
                                     "number (1, 4, 9, ...), got " +
                                         std::to_string(s.value));
                scene.image.samples.value = side;
                scene.image.samples.where = s.where;
                scene.image.samples.given = true;
            } else if (e.name == "shader") {
                // read above
            } else if (e.name == "surface") {
                scene.objects.push_back(read_surface(e, nullptr, 0));
            } else if (e.name == "light") {
                scene.lights.push_back(read_light(e));
            } else {
                unknown_element(e, root, known);
            }
        }
        if (!have_camera) throw InputError(root.where, "<scene>: missing <camera>");
        if (!have_image) throw InputError(root.where, "<scene>: missing <image>");
        return scene;
    }

    /// The course stops a path past recursion depth 10 (the camera ray is depth 0), so up to 11
    /// surface hits, and drops a reflected ray whose path weight is below 0.01.
    static constexpr int course_max_depth = 11;
    static constexpr double course_min_weight = 0.01;

private:
    CameraDescription read_camera(const Element& e) {
        check_attributes(e, {"type"});
        check_no_text(e);
        CameraDescription camera;
        camera.where = e.where;
        // No type: the 2010 course's camera, whose image plane's normal defaults to +z. The later
        // courses' PerspectiveCamera has its plane perpendicular to the view direction.
        const std::string* type = e.attribute("type");
        bool oblique_default = true;
        if (type) {
            if (*type == "OrthographicCamera") {
                camera.type.value = CameraType::orthographic;
            } else if (*type != "PerspectiveCamera") {
                throw InputError(e.where, "<camera>: unknown type '" + *type +
                                              "'; expected PerspectiveCamera or OrthographicCamera");
            }
            camera.type.given = true;
            oblique_default = false;
        }
        camera.type.where = e.where;
        Located<Vec3> view_point{Vec3{0, 0, 0}}, view_dir{Vec3{0, 0, -1}}, proj_normal{Vec3{0, 0, 1}};
        view_point.where = view_dir.where = proj_normal.where = e.where;
        camera.up = Located<Vec3>{Vec3{0, 1, 0}};
        camera.up.where = e.where;
        camera.view_width = Located<double>{1.0};
        camera.view_height = Located<double>{1.0};
        camera.projection_distance.where = camera.view_width.where = camera.view_height.where = e.where;
        const std::vector<std::string> known{"viewPoint",    "viewDir",   "viewUp",    "projNormal",
                                             "projDistance", "viewWidth", "viewHeight"};
        for (const auto& child : e.children) {
            const Element& c = *child;
            check_leaf(c);
            if (c.name == "viewPoint")
                view_point = vec3(c);
            else if (c.name == "viewDir")
                view_dir = vec3(c);
            else if (c.name == "viewUp")
                camera.up = vec3(c);
            else if (c.name == "projNormal")
                proj_normal = vec3(c);
            else if (c.name == "projDistance")
                camera.projection_distance = number(c);
            else if (c.name == "viewWidth")
                camera.view_width = number(c);
            else if (c.name == "viewHeight")
                camera.view_height = number(c);
            else
                unknown_element(c, e, known);
        }
        if (camera.type.value == CameraType::orthographic && (proj_normal.given || camera.projection_distance.given))
            throw InputError(proj_normal.given ? proj_normal.where : camera.projection_distance.where,
                             "<camera>: an OrthographicCamera takes no projNormal or projDistance");
        if (is_zero(view_dir.value)) throw InputError(view_dir.where, "<viewDir> must not be the zero vector");
        camera.eye = view_point;
        camera.look_at = Located<Vec3>{view_point.value + view_dir.value};
        camera.look_at.where = view_dir.where;
        camera.look_at.given = true;
        // Always written out, so that the scene reads the same in Whitted's format.
        camera.view_width.given = camera.view_height.given = true;
        if (camera.type.value == CameraType::perspective) {
            camera.projection_distance.given = true;
            if (oblique_default || proj_normal.given) {
                camera.image_plane_normal = proj_normal;
                camera.image_plane_normal.given = true;
            }
        }
        return camera;
    }

    LightDescription read_light(const Element& e) {
        // Later years write <light type="PointLight">; the course's only kind of light.
        check_attributes(e, {"type"});
        if (const std::string* type = e.attribute("type"); type && *type != "PointLight")
            throw InputError(e.where, "<light>: unknown type '" + *type + "'; the course's lights are PointLight");
        check_no_text(e);
        LightDescription light;
        light.where = e.where;
        light.type = LightType::point;
        light.position = Located<Vec3>{Vec3{0, 0, 0}};
        light.position.where = light.intensity.where = e.where;
        light.position.given = true;
        for (const auto& child : e.children) {
            const Element& c = *child;
            check_leaf(c);
            if (c.name == "position")
                light.position = vec3(c);
            else if (c.name == "intensity")
                light.intensity = vec3(c);
            else
                unknown_element(c, e, {"position", "intensity"});
        }
        return light;
    }

    /// A shader's parameters as a Whitted material (no ambient: the course has none).
    MaterialDescription read_shader_body(const Element& e, bool allow_glazed) {
        const std::string* type = e.attribute("type");
        if (!type)
            throw InputError(e.where, "<" + e.name + ">: missing attribute 'type' (Lambertian, Phong or Glazed)");
        check_no_text(e);
        MaterialDescription material;
        material.where = e.where;
        material.ka = Located<Color>{Color(0.0)};
        material.ka.where = e.where;
        material.ka.given = true;
        Located<Color> diffuse{Color(1.0)}, specular{Color(1.0)};
        Located<double> exponent{1.0};
        diffuse.where = specular.where = exponent.where = e.where;
        if (*type == "Lambertian" || *type == "Phong") {
            const bool phong = *type == "Phong";
            const std::vector<std::string> known =
                phong ? std::vector<std::string>{"diffuseColor", "specularColor", "exponent"}
                      : std::vector<std::string>{"diffuseColor"};
            for (const auto& child : e.children) {
                const Element& c = *child;
                check_leaf(c);
                if (c.name == "diffuseColor")
                    diffuse = vec3(c);
                else if (phong && c.name == "specularColor")
                    specular = vec3(c);
                else if (phong && c.name == "exponent")
                    exponent = number(c);
                else
                    unknown_element(c, e, known);
            }
            material.kd = diffuse;
            material.kd.given = true;
            if (phong) {
                material.ks = specular;
                material.ks.given = true;
                material.p = exponent;
                material.p.given = true;
                material.highlight.value = Highlight::blinn;  // the course's "Phong" uses the half vector
            }
        } else if (*type == "Glazed" && allow_glazed) {
            std::optional<Located<double>> ior;
            const Element* substrate = nullptr;
            for (const auto& child : e.children) {
                const Element& c = *child;
                if (c.name == "refractiveIndex") {
                    check_leaf(c);
                    ior = number(c);
                } else if (c.name == "substrate") {
                    if (substrate) throw InputError(c.where, "<shader>: a second <substrate>");
                    substrate = &c;
                } else {
                    unknown_element(c, e, {"refractiveIndex", "substrate"});
                }
            }
            if (!substrate) throw InputError(e.where, "<shader type=\"Glazed\">: missing <substrate>");
            if (const std::string* ref = substrate->attribute("ref")) {
                check_attributes(*substrate, {"ref"});
                if (!substrate->children.empty())
                    throw InputError(substrate->where, "<substrate ref=...>: give a ref or a shader, not both");
                const MaterialDescription* named = find_shader(*ref, substrate->where);
                if (named->fresnel_ior.given)
                    throw InputError(substrate->where, "<substrate>: a Glazed shader cannot be a substrate");
                material = *named;
                material.name.clear();
                material.where = e.where;
            } else {
                check_attributes(*substrate, {"type"});
                material = read_shader_body(*substrate, false);
            }
            material.fresnel_ior = ior ? *ior : Located<double>{1.0};
            if (!ior) material.fresnel_ior.where = e.where;
            material.fresnel_ior.given = true;
        } else {
            throw InputError(e.where, "<" + e.name + ">: unknown shader type '" + *type + "'; expected " +
                                          (allow_glazed ? "Lambertian, Phong or Glazed" : "Lambertian or Phong"));
        }
        return material;
    }

    void read_named_shader(const Element& e, SceneDescription& scene) {
        check_attributes(e, {"name", "type"});
        const std::string* name = e.attribute("name");
        if (!name || name->empty()) throw InputError(e.where, "<shader>: a shader outside a surface needs a 'name'");
        if (!m_shader_index.try_emplace(*name, scene.materials.size()).second)
            throw InputError(e.where, "<shader>: '" + printable(*name) + "' is defined twice");
        MaterialDescription material = read_shader_body(e, true);
        material.name = *name;
        scene.materials.push_back(material);
    }

    /// By one hash look-up (a scene of 100,000 shaders and surfaces was quadratic); the names are
    /// gathered only for the message.
    const MaterialDescription* find_shader(const std::string& name, const SourceLocation& where) const {
        if (const auto it = m_shader_index.find(name); m_shaders && it != m_shader_index.end())
            return &(*m_shaders)[it->second];
        std::vector<std::string> names;
        if (m_shaders)
            for (const auto& m : *m_shaders) names.push_back(m.name);
        throw InputError(where, "unknown shader '" + printable(name) + "'" + did_you_mean(name, names) +
                                    (names.empty() ? "; the scene names no shaders" : "; defined: " + join(names)));
    }

    MaterialReference read_shader_use(const Element& e) {
        MaterialReference reference;
        reference.where = e.where;
        if (const std::string* ref = e.attribute("ref")) {
            check_attributes(e, {"ref"});
            if (!e.children.empty()) throw InputError(e.where, "<shader ref=...>: give a ref or a shader, not both");
            find_shader(*ref, e.where);
            reference.name = *ref;
        } else {
            check_attributes(e, {"type", "name"});
            reference.inline_ = read_shader_body(e, true);
        }
        return reference;
    }

    ObjectDescription read_surface(const Element& e, const std::optional<MaterialReference>* inherited, int depth) {
        check_attributes(e, {"type"});
        check_no_text(e);
        const std::string* type = e.attribute("type");
        if (!type) throw InputError(e.where, "<surface>: missing attribute 'type' (Sphere, Box, Mesh or Group)");
        ObjectDescription object;
        object.where = e.where;
        std::optional<MaterialReference> material;
        for (const auto& child : e.children)
            if (child->name == "shader") {
                if (material) throw InputError(child->where, "<surface>: a second <shader>");
                material = read_shader_use(*child);
            }
        if (!material && inherited && *inherited) material = **inherited;
        if (*type == "Group") {
            GroupShape& group = object.shape.emplace<GroupShape>();
            if (depth + 1 > limits::max_nesting)
                throw InputError(e.where, "<surface type=\"Group\">: groups nested deeper than " +
                                              std::to_string(limits::max_nesting) + " levels");
            // The course multiplies M = E1·E2·… in file order, so the last element acts on the
            // points first; Whitted's steps act in list order: reversed, and a rotation
            // rx ry rz (Rz·Ry·Rx) becomes the steps x, then y, then z.
            std::vector<std::vector<TransformStep>> elements;
            for (const auto& child : e.children) {
                const Element& c = *child;
                if (c.name == "shader") continue;
                if (c.name == "surface") {
                    group.objects.push_back(read_surface(c, &material, depth + 1));
                    continue;
                }
                if (c.name != "translate" && c.name != "rotate" && c.name != "scale")
                    unknown_element(c, e, {"shader", "surface", "translate", "rotate", "scale"});
                check_leaf(c);
                const Located<Vec3> v = vec3(c);
                std::vector<TransformStep> steps;
                if (c.name == "translate") {
                    steps.push_back({v.where, TransformStep::Kind::translate, v.value, 0, {}});
                } else if (c.name == "scale") {
                    steps.push_back({v.where, TransformStep::Kind::scale, v.value, 0, {}});
                } else {
                    steps.push_back({v.where, TransformStep::Kind::rotate, Vec3{1, 0, 0}, v.value.x, {}});
                    steps.push_back({v.where, TransformStep::Kind::rotate, Vec3{0, 1, 0}, v.value.y, {}});
                    steps.push_back({v.where, TransformStep::Kind::rotate, Vec3{0, 0, 1}, v.value.z, {}});
                }
                elements.push_back(std::move(steps));
            }
            for (auto it = elements.rbegin(); it != elements.rend(); ++it)
                object.transform.insert(object.transform.end(), it->begin(), it->end());
            return object;
        }
        object.material = material;
        if (!object.material) throw InputError(e.where, "<surface>: missing <shader>");
        if (*type == "Sphere") {
            SphereShape& sphere = object.shape.emplace<SphereShape>();
            sphere.center = Located<Vec3>{Vec3{0, 0, 0}};
            sphere.radius = Located<double>{1.0};
            sphere.center.where = sphere.radius.where = e.where;
            sphere.center.given = sphere.radius.given = true;
            for (const auto& child : e.children) {
                const Element& c = *child;
                if (c.name == "shader") continue;
                check_leaf(c);
                if (c.name == "center")
                    sphere.center = vec3(c);
                else if (c.name == "radius")
                    sphere.radius = number(c);
                else
                    unknown_element(c, e, {"shader", "center", "radius"});
            }
        } else if (*type == "Box") {
            BoxShape& box = object.shape.emplace<BoxShape>();
            bool have_min = false, have_max = false;
            for (const auto& child : e.children) {
                const Element& c = *child;
                if (c.name == "shader") continue;
                check_leaf(c);
                if (c.name == "minPt")
                    box.min = vec3(c), have_min = true;
                else if (c.name == "maxPt")
                    box.max = vec3(c), have_max = true;
                else
                    unknown_element(c, e, {"shader", "minPt", "maxPt"});
            }
            if (!have_min || !have_max)
                throw InputError(
                    e.where, std::string("<surface type=\"Box\">: missing <") + (have_min ? "maxPt" : "minPt") + ">");
        } else if (*type == "Mesh") {
            MeshShape& mesh = object.shape.emplace<MeshShape>();
            for (const auto& child : e.children) {
                const Element& c = *child;
                if (c.name == "shader") continue;
                check_leaf(c);
                if (c.name != "data") unknown_element(c, e, {"shader", "data"});
                const auto words = words_of(c);
                if (words.size() != 1)
                    throw InputError(words.empty() ? c.where : words.front().second,
                                     "<data>: expected one .msh file name");
                mesh.file = Located<std::string>{words[0].first};
                mesh.file.where = words[0].second;
                mesh.file.given = true;
                const std::filesystem::path file(words[0].first);
                mesh.file_path =
                    file.is_absolute() ? file.string() : (std::filesystem::path(m_directory) / file).string();
            }
            if (!mesh.file.given) throw InputError(e.where, "<surface type=\"Mesh\">: missing <data> (the .msh file)");
            if (std::filesystem::path(mesh.file.value).extension() != ".msh")
                throw InputError(mesh.file.where, "<data>: expected a .msh mesh file, got '" + mesh.file.value + "'");
        } else {
            throw InputError(e.where, "<surface>: unknown type '" + *type + "'; expected Sphere, Box, Mesh or Group");
        }
        return object;
    }

    std::string m_path, m_directory;
    const std::vector<MaterialDescription>* m_shaders = nullptr;
    std::unordered_map<std::string, size_t> m_shader_index;  ///< shader name -> index in *m_shaders
};

}  // namespace

bool is_course_xml_path(const std::string& path) {
    return std::filesystem::path(path).extension() == ".xml";
}

SceneDescription parse_course_xml_text(const std::string& text, const std::string& path) {
    check_text_is_readable(text, path);
    const std::unique_ptr<Element> root = parse_xml(text, path);
    return CourseReader(path).read(*root);
}

SceneDescription parse_course_xml_file(const std::string& path) {
    return parse_course_xml_text(read_text_file(path, limits::max_scene_file_bytes, "scene file"), path);
}

}  // namespace whitted
