// SPDX-License-Identifier: MIT
// `whitted live`: the lecture's LightMaterial demo, ray traced. A small HTTP server on 127.0.0.1
// serves one page (live_page.html, embedded) and renders the scene file with the page's slider
// values written over the file's: each render parses the file's text again, replaces the values
// in the description and validates it, exactly as `whitted render` reads a file that says them,
// so the image equals that render bit for bit (docs/live.md).

#include "live_command.h"

#include "api/api_internal.h"
#include "converters/yaml_writer.h"
#include "live_page_html.h"
#include "render/accelerator.h"
#include "render/reshade.h"
#include "scene/description.h"
#include "scene/errors.h"
#include "scene/scene.h"
#include "whitted/whitted.h"

#include <httplib.h>
#include <nlohmann/json.hpp>

#include <fcntl.h>
#include <pthread.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <thread>

extern char** environ;

namespace whitted {
namespace {

using json = nlohmann::json;

using api::exit_bad_input, api::exit_failure;

/// A mistake in what the page sent (HTTP 400), as opposed to one in the scene file (422).
struct BadRequest : std::invalid_argument {
    using std::invalid_argument::invalid_argument;
};

/// What tells an editor's save apart from no change: the file's modification time and size.
struct FileStamp {
    int64_t mtime_ns = -1, size = -1;
    bool operator==(const FileStamp&) const = default;
};

FileStamp stamp_of(const std::string& path) {
    struct stat st {};
    if (::stat(path.c_str(), &st) != 0) return {};
    return {int64_t(st.st_mtim.tv_sec) * 1'000'000'000 + st.st_mtim.tv_nsec, int64_t(st.st_size)};
}

std::string read_scene_text(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw std::runtime_error(path + ": cannot be read");
    std::ostringstream text;
    text << in.rdbuf();
    if (int64_t(text.str().size()) > limits::max_scene_file_bytes)
        throw std::runtime_error(path + ": more than " + std::to_string(limits::max_scene_file_bytes) +
                                 " bytes, the scene file limit");
    return text.str();
}

json to_json(const Vec3& v) {
    return json::array({v.x, v.y, v.z});
}

/// A member of the request that names a choice: its text, the default when it is absent, and an
/// empty string (which no choice is) when it is not a string.
std::string string_member(const json& body, const char* key, const char* fallback) {
    const auto member = body.find(key);
    if (member == body.end()) return fallback;
    const auto* text = member->get_ptr<const json::string_t*>();
    return text ? *text : std::string();
}

double finite_number(const json& value, const std::string& what) {
    if (!value.is_number()) throw BadRequest(what + ": expected a number, got " + value.dump());
    const double number = value.get<double>();
    if (!std::isfinite(number)) throw BadRequest(what + ": must be a finite number");
    return number;
}

/// A colour or point from the page: [x, y, z], or one number for a grey.
Vec3 vector_from(const json& value, const std::string& what) {
    if (value.is_number()) return Vec3(finite_number(value, what));
    if (!value.is_array() || value.size() != 3) throw BadRequest(what + ": expected [x, y, z] or a number");
    return {finite_number(value[0], what), finite_number(value[1], what), finite_number(value[2], what)};
}

template <class T>
void set(Located<T>& field, T value) {
    field.value = value;
    field.given = true;  // as if written in the file: the validator treats it so
}

/// Writes the page's values over the file's: {"materials": {NAME: {"kd": [r, g, b], "p": 10,
/// ...}}, "lights": [{"intensity": ..., "position": ...}, ...]} (lights in file order).
void apply_page_values(SceneDescription& description, const json& values) {
    if (!values.is_object()) throw BadRequest("the values: expected a JSON object");
    for (const auto& [key, entries] : values.items()) {
        if (key == "materials") {
            if (!entries.is_object()) throw BadRequest("materials: expected an object of material names");
            for (const auto& [name, fields] : entries.items()) {
                MaterialDescription* material = nullptr;
                for (MaterialDescription& m : description.materials)
                    if (m.name == name) material = &m;
                if (!material) throw BadRequest("materials: the scene has no material named '" + name + "'");
                if (!fields.is_object()) throw BadRequest("materials." + name + ": expected an object");
                for (const auto& [field, value] : fields.items()) {
                    const std::string what = "materials." + name + "." + field;
                    if (field == "ka")
                        set(material->ka, vector_from(value, what));
                    else if (field == "kd")
                        set(material->kd, vector_from(value, what));
                    else if (field == "ks")
                        set(material->ks, vector_from(value, what));
                    else if (field == "km")
                        set(material->km, vector_from(value, what));
                    else if (field == "kt")
                        set(material->kt, vector_from(value, what));
                    else if (field == "p")
                        set(material->p, finite_number(value, what));
                    else if (field == "ior")
                        set(material->ior, finite_number(value, what));
                    else
                        throw BadRequest(what + ": not a material value the page can set (ka kd ks p km kt ior)");
                }
            }
        } else if (key == "lights") {
            if (!entries.is_array() || entries.size() > description.lights.size())
                throw BadRequest("lights: expected an array of at most " + std::to_string(description.lights.size()) +
                                 " light(s), in file order");
            for (size_t i = 0; i < entries.size(); ++i) {
                if (entries[i].is_null()) continue;
                if (!entries[i].is_object()) throw BadRequest("lights[" + std::to_string(i) + "]: expected an object");
                LightDescription& light = description.lights[i];
                for (const auto& [field, value] : entries[i].items()) {
                    const std::string what = "lights[" + std::to_string(i) + "]." + field;
                    if (field == "intensity")
                        set(light.intensity, vector_from(value, what));
                    else if (field == "position" && light.type == LightType::point)
                        set(light.position, vector_from(value, what));
                    else if (field == "direction" && light.type == LightType::directional)
                        set(light.direction, vector_from(value, what));
                    else
                        throw BadRequest(what + ": not a value this light has");
                }
            }
        } else {
            throw BadRequest("'" + key + "': the page sets only materials and lights");
        }
    }
}

/// The scene as the page's panels show it: the file's values.
json describe_scene(const SceneDescription& d) {
    json materials = json::array();
    for (const MaterialDescription& m : d.materials)
        materials.push_back({{"name", m.name},
                             {"where", m.where.str()},
                             {"ka", to_json(m.ka.value)},
                             {"kd", to_json(m.kd.value)},
                             {"ks", to_json(m.ks.value)},
                             {"p", m.p.value},
                             {"km", to_json(m.km.value)},
                             {"kt", to_json(m.kt.value)},
                             {"ior", m.ior.value},
                             {"highlight", m.highlight.value == Highlight::phong ? "phong" : "blinn"},
                             {"glazed", m.fresnel_ior.given}});
    json lights = json::array();
    for (const LightDescription& l : d.lights) {
        json light = {{"type", l.type == LightType::point ? "point" : "directional"},
                      {"intensity", to_json(l.intensity.value)}};
        if (l.type == LightType::point)
            light["position"] = to_json(l.position.value);
        else
            light["direction"] = to_json(l.direction.value);
        lights.push_back(light);
    }
    return {{"path", d.path},
            {"width", d.image.width.value},
            {"height", d.image.height.value},
            {"samples", d.image.samples.value},
            {"ambient", to_json(d.ambient.value)},
            {"materials", materials},
            {"lights", lights}};
}

/// What the server shares between its threads: the file's latest text, whether it loads, and a
/// version the page polls to know when to render again.
class LiveState {
public:
    explicit LiveState(std::string path) : m_path(std::move(path)) {}

    /// Reads the file if its stamp changed since the last look; true if it did.
    bool refresh() {
        const FileStamp stamp = stamp_of(m_path);
        {
            std::lock_guard lock(m_mutex);
            if (m_version > 0 && stamp == m_stamp) return false;
        }
        std::string text, error;
        try {
            text = read_scene_text(m_path);
            (void)validate_scene(parse_any_scene_text(text, m_path));  // meshes included
        } catch (const std::exception& e) {
            error = e.what();  // an InputError says FILE:LINE:COL
        }
        std::lock_guard lock(m_mutex);
        m_stamp = stamp;
        if (error.empty()) m_text = std::move(text);
        m_error = std::move(error);
        ++m_version;
        return true;
    }

    struct Snapshot {
        std::string text, error;
        uint64_t version = 0;
    };
    Snapshot snapshot() const {
        std::lock_guard lock(m_mutex);
        return {m_text, m_error, m_version};
    }
    const std::string& path() const { return m_path; }

private:
    const std::string m_path;
    mutable std::mutex m_mutex;
    FileStamp m_stamp;
    std::string m_text, m_error;  // the text is the last one that loaded
    uint64_t m_version = 0;
};

/// The file's text with the page's values written over it, as a description.
SceneDescription edited_description(const std::string& text, const std::string& path, const json& values) {
    SceneDescription description = parse_any_scene_text(text, path);
    apply_page_values(description, values);
    return description;
}

/// The colour render layers the page can show instead of the beauty (docs/layers.md): each is
/// an RGB image; light<k> (1-based) comes from the `lights` layer.
const char* const colour_layers[] = {"ambient", "diffuse", "specular", "mirror", "transmission", "background"};
/// The data layers, shown through a mapping to colours (data_view_colours).
const char* const data_layers[] = {"N", "Ng", "P", "Z", "albedo", "objectId", "materialId", "hits"};

bool is_data_layer(const std::string& view) {
    for (const char* layer : data_layers)
        if (view == layer) return true;
    return false;
}

/// The layer to ask the render for to show `view` ("beauty": none), or BadRequest.
std::string layer_for_view(const std::string& view, size_t light_count) {
    if (view == "beauty") return "none";
    for (const char* layer : colour_layers)
        if (view == layer) return view;
    if (is_data_layer(view)) return view;
    if (view.size() > 5 && view.compare(0, 5, "light") == 0 && view[5] != '0' &&
        view.find_first_not_of("0123456789", 5) == std::string::npos && view.size() < 10) {
        const long k = std::stol(view.substr(5));
        if (k >= 1 && size_t(k) <= light_count) return "lights";
    }
    throw BadRequest("view '" + view + "': expected beauty, ambient, diffuse, specular, mirror, transmission, " +
                     "background, light1.." + "light" + std::to_string(light_count) +
                     ", N, Ng, P, Z, albedo, objectId, materialId or hits");
}

/// A distinct colour for each id (0, nothing hit: black): hues a golden angle apart, so that
/// neighbouring ids differ clearly.
void id_colour(float id, float* rgb) {
    if (id == 0) {
        rgb[0] = rgb[1] = rgb[2] = 0;
        return;
    }
    const double hue = std::fmod(double(id) * 0.618033988749895, 1.0) * 6;
    const int sector = int(hue);
    const float f = float(hue - sector), up = 0.25f + 0.7f * f, down = 0.95f - 0.7f * f;
    const float table[6][3] = {{0.95f, up, 0.25f},   {down, 0.95f, 0.25f}, {0.25f, 0.95f, up},
                               {0.25f, down, 0.95f}, {up, 0.25f, 0.95f},   {0.95f, 0.25f, down}};
    for (int c = 0; c < 3; ++c) rgb[c] = table[sector % 6][c];
}

/// A data layer's values as colours to show (docs/live.md): N and Ng as 0.5 + 0.5·n; P each
/// axis scaled to [0, 1] over the image's hits; Z as 1 at the nearest hit to 0.1 at the farthest;
/// albedo as it is; objectId and materialId a colour per id; hits as hits / the image's most.
/// Where the camera ray misses: black.
std::vector<float> data_view_colours(const ImageLayer& layer) {
    const size_t n = layer.channels.size(), pixels = layer.values.size() / n;
    const std::vector<float>& v = layer.values;
    std::vector<float> rgb(pixels * 3, 0.0f);
    const auto missed_vector = [&](size_t i) { return v[3 * i] == 0 && v[3 * i + 1] == 0 && v[3 * i + 2] == 0; };
    if (layer.name == "N" || layer.name == "Ng") {
        for (size_t i = 0; i < pixels; ++i)
            if (!missed_vector(i))
                for (int c = 0; c < 3; ++c) rgb[3 * i + c] = 0.5f + 0.5f * v[3 * i + c];
    } else if (layer.name == "P") {
        float low[3] = {INFINITY, INFINITY, INFINITY}, high[3] = {-INFINITY, -INFINITY, -INFINITY};
        for (size_t i = 0; i < pixels; ++i)
            if (!missed_vector(i))
                for (int c = 0; c < 3; ++c) {
                    low[c] = std::min(low[c], v[3 * i + c]);
                    high[c] = std::max(high[c], v[3 * i + c]);
                }
        for (size_t i = 0; i < pixels; ++i)
            if (!missed_vector(i))
                for (int c = 0; c < 3; ++c)
                    rgb[3 * i + c] = high[c] > low[c] ? (v[3 * i + c] - low[c]) / (high[c] - low[c]) : 0.5f;
    } else if (layer.name == "Z") {
        float near = INFINITY, far = -INFINITY;
        for (float z : v)
            if (std::isfinite(z)) near = std::min(near, z), far = std::max(far, z);
        for (size_t i = 0; i < pixels; ++i)
            if (std::isfinite(v[i]))
                rgb[3 * i] = rgb[3 * i + 1] = rgb[3 * i + 2] =
                    far > near ? 0.1f + 0.9f * ((far - v[i]) / (far - near)) : 1.0f;
    } else if (layer.name == "albedo") {
        rgb = v;
    } else if (layer.name == "objectId" || layer.name == "materialId") {
        for (size_t i = 0; i < pixels; ++i) id_colour(v[i], &rgb[3 * i]);
    } else {  // hits
        float most = 0;
        for (float h : v) most = std::max(most, h);
        for (size_t i = 0; i < pixels; ++i) rgb[3 * i] = rgb[3 * i + 1] = rgb[3 * i + 2] = most > 0 ? v[i] / most : 0;
    }
    return rgb;
}

/// The render at `level` "coarse" (a quarter of the width and height, one sample per pixel: the
/// first image while the slider moves), "preview" (the full width and height, one sample per
/// pixel: a quarter of the work of the usual 2×2 samples) or "full" (the scene's own settings,
/// the image that equals `whitted render`'s), as PNG through the
/// default display transform (as `whitted render -o x.png`) or linear EXR (as `-o x.exr`). A
/// `view` other than "beauty" is that render layer, rendered as `whitted render --layers` does:
/// a colour layer written as the image's R, G, B; a data layer as its colours
/// (data_view_colours), which a PNG holds as they are (the display's Raw view: they are not
/// light), and an EXR as its R, G, B with the layer's own channels beside them.
struct Rendered {
    std::string bytes;
    double render_seconds = 0, encode_seconds = 0;
};
Rendered encode_image(const Image& shown, const api::WriteOptions& write, const std::filesystem::path& temp_file);

Rendered render_image(SceneDescription description, const std::string& view, const std::string& level, int threads,
                      const std::filesystem::path& temp_file) {
    auto impl = std::make_unique<api::Scene::Impl>();
    impl->description = std::move(description);
    const std::string layer = layer_for_view(view, impl->description.lights.size());
    ImageDescription& image = impl->description.image;
    if (level == "coarse") {
        image.width.value = std::max<int64_t>(1, image.width.value / 4);
        image.height.value = std::max<int64_t>(1, image.height.value / 4);
    }
    if (level != "full") image.samples.value = 1;
    impl->scene = validate_scene(impl->description);
    const api::Scene scene(std::move(impl));
    api::RenderOptions options;
    options.threads = threads;
    options.layers = {layer};  // the beauty alone renders with none, as `whitted render` without layers
    api::Expected<api::RenderResult> result = api::render(scene, options);
    if (!result) throw std::runtime_error(result.error().what());
    Image shown;
    api::WriteOptions write;
    const bool exr = temp_file.extension() == ".exr";
    if (view == "beauty") {
        shown = std::move(result->image);
        shown.layers.clear();
    } else {
        shown.width = result->image.width;
        shown.height = result->image.height;
        for (ImageLayer& l : result->image.layers) {
            if (l.name != view) continue;
            if (!is_data_layer(view)) {
                shown.rgb = std::move(l.values);
            } else {
                shown.rgb = data_view_colours(l);
                if (exr) shown.layers.push_back(std::move(l));
                if (view != "albedo") write.view = "Raw";  // albedo is a colour, the others are not
            }
        }
        if (shown.rgb.size() != size_t(shown.width) * size_t(shown.height) * 3)
            throw std::runtime_error("the render has no layer " + view);
    }
    if (exr) write.view.clear();
    Rendered rendered = encode_image(shown, write, temp_file);
    rendered.render_seconds = result->stats.seconds;
    return rendered;
}

/// `shown` written as `temp_file` says (PNG or EXR) and read back.
Rendered encode_image(const Image& shown, const api::WriteOptions& write, const std::filesystem::path& temp_file) {
    const auto encode_start = std::chrono::steady_clock::now();
    if (const auto written = api::write_image(shown, temp_file.string(), write); !written)
        throw std::runtime_error(written.error().what());
    Rendered rendered;
    {
        std::ifstream in(temp_file, std::ios::binary);
        std::ostringstream bytes;
        bytes << in.rdbuf();
        rendered.bytes = bytes.str();
    }
    rendered.encode_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - encode_start).count();
    std::error_code ignored;
    std::filesystem::remove(temp_file, ignored);
    return rendered;
}

/// The page's values without those re-shading covers (each material's ka, kd, ks, p, km and
/// each light's intensity): two requests with the same file version and the same rest have the
/// same rays, hits and shadow rays.
std::string geometry_key(uint64_t version, json values) {
    if (const auto materials = values.find("materials"); materials != values.end() && materials->is_object())
        for (auto& [name, fields] : materials->items())
            if (fields.is_object())
                for (const char* field : {"ka", "kd", "ks", "p", "km"}) fields.erase(field);
    if (const auto lights = values.find("lights"); lights != values.end() && lights->is_array())
        for (json& light : *lights)
            if (light.is_object()) light.erase("intensity");
    // What is left empty says nothing: {"materials": {"shiny": {}}} is {}.
    if (const auto materials = values.find("materials"); materials != values.end() && materials->is_object()) {
        for (auto entry = materials->begin(); entry != materials->end();)
            entry = entry->is_object() && entry->empty() ? materials->erase(entry) : std::next(entry);
        if (materials->empty()) values.erase("materials");
    }
    if (const auto lights = values.find("lights"); lights != values.end() && lights->is_array()) {
        for (json& light : *lights)
            if (light.is_object() && light.empty()) light = nullptr;
        while (!lights->empty() && lights->back().is_null()) lights->erase(lights->end() - 1);
        if (lights->empty()) values.erase("lights");
    }
    return std::to_string(version) + "\n" + values.dump();
}

/// The beauty's full image through the shading cache (render/reshade.h): re-shaded from the last
/// full render's paths when only what re-shading covers changed, else rendered (with `level`
/// "reshade": nothing, `reshaded` false and no image) and recorded for the next change.
struct LiveShadingCache {
    std::string key;
    ShadingCache cache;
};
struct Beauty {
    Image image;
    bool reshaded = false;
    double seconds = 0;
};
Beauty full_beauty(const SceneDescription& description, const std::string& key, bool reshade_only, int threads,
                   LiveShadingCache& cached) {
    const Scene scene = validate_scene(description);
    Beauty beauty;
    const auto start = std::chrono::steady_clock::now();
    if (cached.key == key && cached.cache.reshade(scene, threads, beauty.image)) {
        beauty.reshaded = true;
    } else if (!reshade_only) {
        cached = LiveShadingCache();  // the old cache's memory goes before the new one's comes
        const Accelerator accelerator(scene, threads);
        cached.cache = ShadingCache::record(scene, accelerator, threads, beauty.image);
        cached.key = key;
    }
    beauty.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return beauty;
}

/// Where the page asks to save: a .yaml or .yml path, relative ones beside the scene file.
std::filesystem::path save_target(const json& body, const std::string& scene_path) {
    const std::string text = string_member(body, "path", "");
    if (text.empty()) throw BadRequest("path: expected the name of the file to write (a .yaml or .yml file)");
    std::filesystem::path target(text);
    if (target.is_relative()) target = std::filesystem::path(scene_path).parent_path() / target;
    const std::string ext = target.extension().string();
    if (ext != ".yaml" && ext != ".yml")
        throw BadRequest("path '" + text + "': the scene is saved in Whitted's own format, a .yaml or .yml file");
    return target.lexically_normal();
}

void send_error(httplib::Response& response, int status, const std::string& message) {
    response.status = status;
    response.set_content(json{{"error", message}}.dump(), "application/json");
}

/// Opens the page in the desktop's browser (xdg-open); a machine without one only says so.
void open_in_browser(const std::string& url) {
    pid_t pid = 0;
    const char* argv[] = {"xdg-open", url.c_str(), nullptr};
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
    posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, "/dev/null", O_WRONLY, 0);
    const int error = posix_spawnp(&pid, "xdg-open", &actions, nullptr, const_cast<char* const*>(argv), environ);
    posix_spawn_file_actions_destroy(&actions);
    if (error != 0) {
        std::fprintf(stderr, "whitted live: could not open a browser (xdg-open: %s); open the address above\n",
                     std::strerror(error));
        return;
    }
    std::thread([pid] { ::waitpid(pid, nullptr, 0); }).detach();
}

}  // namespace

int run_live(const LiveArguments& args) {
    // SIGINT and SIGTERM go to one thread that stops the server (a handler could not): blocked
    // here, before any thread exists, so every thread inherits the mask.
    sigset_t stop_signals;
    sigemptyset(&stop_signals);
    sigaddset(&stop_signals, SIGINT);
    sigaddset(&stop_signals, SIGTERM);
    pthread_sigmask(SIG_BLOCK, &stop_signals, nullptr);

    LiveState state(args.scene);
    state.refresh();
    if (const std::string error = state.snapshot().error; !error.empty()) {
        std::fprintf(stderr, "whitted: error: %s\n", error.c_str());
        return exit_bad_input;
    }

    // The images are written through the image output code, which writes files: here, then read.
    const char* temp_base = std::getenv("TMPDIR");
    std::string pattern =
        (temp_base && *temp_base ? std::string(temp_base) : std::string("/tmp")) + "/whitted-live-XXXXXX";
    if (!::mkdtemp(pattern.data())) {
        std::fprintf(stderr, "whitted: error: cannot make a temporary directory %s: %s\n", pattern.c_str(),
                     std::strerror(errno));
        return exit_failure;
    }
    const std::filesystem::path temp_dir = pattern;

    httplib::Server server;
    const int port = args.port > 0 ? (server.bind_to_port("127.0.0.1", args.port) ? args.port : -1)
                                   : server.bind_to_any_port("127.0.0.1");
    if (port <= 0) {
        std::error_code ignored;
        std::filesystem::remove_all(temp_dir, ignored);
        std::fprintf(stderr, "whitted: error: --port %d: cannot listen on 127.0.0.1:%d (in use?)\n", args.port,
                     args.port);
        return exit_bad_input;
    }
    const std::string self_origin = "http://127.0.0.1:" + std::to_string(port);
    const std::string url = self_origin + "/";

    // Only this machine's pages: a Host other than ours is a DNS-rebinding page on another name,
    // an Origin other than ours another site's script.
    server.set_pre_routing_handler([&](const httplib::Request& request, httplib::Response& response) {
        const std::string host = request.get_header_value("Host");
        const std::string origin = request.get_header_value("Origin");
        const std::string port_text = std::to_string(port);
        const bool host_ok = host == "127.0.0.1:" + port_text || host == "localhost:" + port_text;
        const bool origin_ok = origin.empty() || origin == self_origin || origin == "http://localhost:" + port_text;
        if (host_ok && origin_ok) return httplib::Server::HandlerResponse::Unhandled;
        response.status = 403;
        response.set_content(host_ok ? "whitted live: requests from another origin are refused\n"
                                     : "whitted live: requests for another host are refused\n",
                             "text/plain");
        return httplib::Server::HandlerResponse::Handled;
    });

    server.Get("/", [](const httplib::Request&, httplib::Response& response) {
        response.set_header("Cache-Control", "no-store");
        response.set_header("Content-Security-Policy",
                            "default-src 'none'; img-src 'self' blob:; script-src 'unsafe-inline'; "
                            "style-src 'unsafe-inline'; connect-src 'self'");
        response.set_content(live_page_html, "text/html; charset=utf-8");
    });
    server.Get("/state", [&](const httplib::Request&, httplib::Response& response) {
        const LiveState::Snapshot snapshot = state.snapshot();
        response.set_header("Cache-Control", "no-store");
        response.set_content(json{{"version", snapshot.version}, {"error", snapshot.error}}.dump(), "application/json");
    });
    server.Get("/scene", [&](const httplib::Request&, httplib::Response& response) {
        const LiveState::Snapshot snapshot = state.snapshot();
        response.set_header("Cache-Control", "no-store");
        try {
            json scene = describe_scene(parse_any_scene_text(snapshot.text, state.path()));
            scene["version"] = snapshot.version;
            response.set_content(scene.dump(), "application/json");
        } catch (const std::exception& e) {
            send_error(response, 422, e.what());
        }
    });
    // Set by a stop signal: a running check ends POV-Ray and returns at once.
    std::atomic<bool> stopping{false};
    // One render (or explain, or check) at a time: two at once would only share the two cores
    // and both be late.
    std::mutex render_mutex;
    uint64_t render_count = 0, check_count = 0;
    LiveShadingCache shading_cache;  // the last full beauty's paths; under render_mutex
    // A POST whose body is a JSON object about the file as it loads now, with its errors sent
    // as 400 (the page's request), 422 (the scene refuses the values), 409 (the file does not
    // load) or 500.
    using Handler = std::function<void(const json&, const LiveState::Snapshot&, httplib::Response&)>;
    const auto post = [&](const std::string& route, const Handler& handler) {
        server.Post(route, [&, handler, route](const httplib::Request& request, httplib::Response& response) {
            json body;
            try {
                body = json::parse(request.body);
            } catch (const std::exception& e) {
                return send_error(response, 400, std::string("the request is not JSON: ") + e.what());
            }
            if (!body.is_object()) return send_error(response, 400, "the request must be a JSON object");
            const LiveState::Snapshot snapshot = state.snapshot();
            if (!snapshot.error.empty()) return send_error(response, 409, snapshot.error);
            response.set_header("Cache-Control", "no-store");
            try {
                handler(body, snapshot, response);
            } catch (const BadRequest& e) {
                send_error(response, 400, e.what());
            } catch (...) {
                // Bad input is a page value the scene format refuses, at its place in the file.
                const api::Error error = api::current_error({"serving " + route + " for " + state.path()});
                send_error(response, error.kind == api::Error::Kind::bad_input ? 422 : 500, error.what());
            }
        });
    };
    const auto values_of = [](const json& body) { return body.value("values", json::object()); };

    post("/render", [&](const json& body, const LiveState::Snapshot& snapshot, httplib::Response& response) {
        const std::string level = string_member(body, "level", "full"), format = string_member(body, "format", "png");
        if ((level != "full" && level != "preview" && level != "coarse" && level != "reshade") ||
            (format != "png" && format != "exr"))
            throw BadRequest("level must be full, preview, coarse or reshade, format png or exr");
        const std::string view = string_member(body, "view", "beauty");
        if (level == "reshade" && view != "beauty") throw BadRequest("level reshade: only the beauty is re-shaded");
        std::lock_guard lock(render_mutex);
        const std::filesystem::path file = temp_dir / ("render-" + std::to_string(++render_count) + "." + format);
        const auto start = std::chrono::steady_clock::now();
        SceneDescription description = edited_description(snapshot.text, state.path(), values_of(body));
        Rendered rendered;
        if (view == "beauty" && (level == "full" || level == "reshade")) {
            Beauty beauty = full_beauty(description, geometry_key(snapshot.version, values_of(body)),
                                        level == "reshade", args.threads, shading_cache);
            response.set_header("X-Whitted-Reshaded", beauty.reshaded ? "1" : "0");
            if (level == "reshade" && !beauty.reshaded) {
                response.status = 204;  // the cache does not cover these values: render them
                return;
            }
            api::WriteOptions write;
            if (format == "exr") write.view.clear();
            rendered = encode_image(beauty.image, write, file);
            rendered.render_seconds = beauty.seconds;
        } else {
            rendered = render_image(std::move(description), view, level, args.threads, file);
        }
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        response.set_header("X-Whitted-Version", std::to_string(snapshot.version));
        response.set_header("X-Whitted-Render-Ms", std::to_string(int(rendered.render_seconds * 1000 + 0.5)));
        response.set_header("X-Whitted-Encode-Ms", std::to_string(int(rendered.encode_seconds * 1000 + 0.5)));
        response.set_header("X-Whitted-Total-Ms", std::to_string(int(seconds * 1000 + 0.5)));
        response.set_content(rendered.bytes, format == "exr" ? "image/x-exr" : "image/png");
    });

    // `whitted explain --json` of one pixel of the edited scene.
    post("/explain", [&](const json& body, const LiveState::Snapshot& snapshot, httplib::Response& response) {
        const auto coordinate = [&](const char* key) {
            const auto member = body.find(key);
            if (member == body.end() || !member->is_number_integer())
                throw BadRequest(std::string(key) + ": expected the pixel's whole-number column (x) and row (y)");
            return member->get<int64_t>();
        };
        const int64_t x = coordinate("x"), y = coordinate("y");
        auto impl = std::make_unique<api::Scene::Impl>();
        impl->description = edited_description(snapshot.text, state.path(), values_of(body));
        impl->scene = validate_scene(impl->description);
        const api::Scene scene(std::move(impl));
        if (x < 0 || y < 0 || x >= scene.width() || y >= scene.height())
            throw BadRequest("pixel " + std::to_string(x) + "," + std::to_string(y) + " is outside the " +
                             std::to_string(scene.width()) + "x" + std::to_string(scene.height()) + " image");
        std::lock_guard lock(render_mutex);
        api::ExplainOptions options;
        options.threads = args.threads;
        api::Expected<std::string> explained = api::explain(scene, int(x), int(y), options);
        if (!explained) {
            const api::Error& error = explained.error();
            return send_error(response, error.kind == api::Error::Kind::bad_input ? 422 : 500, error.what());
        }
        std::string text = std::move(explained).value();
        text.pop_back();  // the newline `whitted explain --json` ends its output with
        response.set_content(text, "application/json");
    });

    // The edited scene written to a new file, in Whitted's own format; an existing file only
    // with the page's explicit "overwrite": true (the page asks the user first).
    post("/save", [&](const json& body, const LiveState::Snapshot& snapshot, httplib::Response& response) {
        const std::filesystem::path target = save_target(body, state.path());
        const auto overwrite = body.find("overwrite");
        if (overwrite != body.end() && !overwrite->is_boolean()) throw BadRequest("overwrite: expected true or false");
        const SceneDescription description = edited_description(snapshot.text, state.path(), values_of(body));
        (void)validate_scene(description);  // only a scene that renders is written
        std::error_code error;
        const std::filesystem::file_status status = std::filesystem::symlink_status(target, error);
        if (std::filesystem::exists(status)) {
            if (!std::filesystem::is_regular_file(status))
                throw BadRequest("'" + target.string() + "' exists and is not a plain file: not written");
            if (overwrite == body.end() || !overwrite->get<bool>()) {
                response.status = 409;
                response.set_content(
                    json{{"error", "'" + target.string() + "' exists: not written (send overwrite to replace it)"},
                         {"exists", true},
                         {"path", target.string()}}
                        .dump(),
                    "application/json");
                return;
            }
        }
        if (!std::filesystem::is_directory(target.parent_path(), error))
            throw BadRequest("'" + target.parent_path().string() + "' is not a directory: not written");
        yaml::write_yaml_file(description, target.string());
        response.set_content(json{{"path", target.string()}, {"written", true}}.dump(), "application/json");
    });

    // `whitted check` of the edited scene: written as YAML into the temporary directory, checked
    // against POV-Ray with a report, whose ours.png and povray.png the page wipes between.
    post("/check", [&](const json& body, const LiveState::Snapshot& snapshot, httplib::Response& response) {
        const SceneDescription description = edited_description(snapshot.text, state.path(), values_of(body));
        (void)validate_scene(description);
        std::lock_guard lock(render_mutex);
        const uint64_t number = ++check_count;
        std::error_code ignored;
        if (number > 1) std::filesystem::remove_all(temp_dir / ("check-" + std::to_string(number - 1)), ignored);
        const std::filesystem::path dir = temp_dir / ("check-" + std::to_string(number));
        std::filesystem::create_directories(dir);
        const std::string file = (dir / std::filesystem::path(state.path()).filename()).replace_extension(".yaml");
        yaml::write_yaml_file(description, file);
        api::CheckOptions options;
        options.threads = args.threads;
        options.report_dir = (dir / "report").string();
        options.cancel = &stopping;
        const api::Expected<api::CheckResult> result = api::check(file, options);
        if (!result) throw std::runtime_error(result.error().what());
        // The verdict names the file checked: the edited scene, not its temporary copy.
        std::string verdict = result->verdict;
        if (const size_t at = verdict.find(file); at != std::string::npos)
            verdict.replace(at, file.size(), std::filesystem::path(state.path()).filename().string() + " (edited)");
        const std::string images = "/check/" + std::to_string(number) + "/";
        response.set_content(json{{"passed", result->passed},
                                  {"fraction_within", result->fraction_within},
                                  {"max_error_codes", result->max_error_codes},
                                  {"psnr", result->psnr},
                                  {"failures", result->failures},
                                  {"verdict", verdict},
                                  {"ours", images + "ours.png"},
                                  {"povray", images + "povray.png"},
                                  {"diff", images + "diff.png"}}
                                 .dump(),
                             "application/json");
    });
    server.Get(R"(/check/(\d{1,18})/(ours|povray|diff)\.png)",
               [&](const httplib::Request& request, httplib::Response& response) {
                   const std::filesystem::path file = temp_dir / ("check-" + request.matches[1].str()) / "report" /
                                                      (request.matches[2].str() + ".png");
                   std::ifstream in(file, std::ios::binary);
                   if (!in) return send_error(response, 404, "no such check image (a newer check replaced it?)");
                   std::ostringstream bytes;
                   bytes << in.rdbuf();
                   response.set_header("Cache-Control", "no-store");
                   response.set_content(bytes.str(), "image/png");
               });

    std::atomic<bool> done{false};
    std::atomic<int> stop_signal{0};
    std::thread watcher([&] {
        while (!done.load()) {
            std::this_thread::sleep_for(std::chrono::milliseconds(200));
            if (!done.load()) state.refresh();
        }
    });
    std::thread stopper([&] {
        const timespec poll{0, 100'000'000};
        while (!done.load()) {
            const int signal = sigtimedwait(&stop_signals, nullptr, &poll);
            if (signal > 0) {
                stop_signal.store(signal);
                stopping.store(true);
                break;
            }
        }
        // stop() acts only on a running server: repeated until listen() has returned.
        while (!done.load()) {
            server.stop();
            std::this_thread::sleep_for(std::chrono::milliseconds(20));
        }
    });

    std::printf("whitted live: %s\n", url.c_str());
    std::fflush(stdout);
    if (args.open_browser) open_in_browser(url);
    const bool listened = stop_signal.load() != 0 || server.listen_after_bind();
    done.store(true);
    watcher.join();
    stopper.join();
    std::error_code ignored;
    std::filesystem::remove_all(temp_dir, ignored);
    if (const int signal = stop_signal.load()) {
        std::fprintf(stderr, "whitted live: stopped\n");
        return 128 + signal;
    }
    if (!listened) {
        std::fprintf(stderr, "whitted: error: the server on %s stopped serving\n", url.c_str());
        return exit_failure;
    }
    return 0;
}

}  // namespace whitted

// The entry point of lib/libwhitted_live.so (live_plugin.cpp loads it).
extern "C" __attribute__((visibility("default"))) int whitted_run_live(const whitted::LiveArguments& args) {
    return whitted::run_live(args);
}
