// SPDX-License-Identifier: MIT
// The public API (whitted/whitted.h) over the private libraries: every exception of theirs is
// turned into an Error value here, with the location an InputError carries.

#include "api_internal.h"
#include "converters/pov_writer.h"
#include "core/plugin.h"
#include "output/atomic_files.h"
#include "output/color_management.h"
#include "output/image_output.h"
#include "reference/check.h"
#include "render/distributed.h"
#include "render/layers.h"
#include "render/renderer.h"
#include "scene/errors.h"
#include "scene/text_checks.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <new>
#include <optional>
#include <stdexcept>
#include <thread>

namespace whitted::api {
namespace {

using clock = std::chrono::steady_clock;

double seconds_since(clock::time_point start) {
    return std::chrono::duration<double>(clock::now() - start).count();
}

Error plain_error(std::string message, Error::Kind kind) {
    Error error;
    error.message = std::move(message);
    error.kind = kind;
    return error;
}

/// `read` fills the description and the validated scene of a new Scene::Impl. An error without
/// a place names `label`; one reading a file (a filesystem error) is the caller's input.
Expected<Scene> load(const std::string& label, const std::function<void(Scene::Impl&)>& read) {
    try {
        auto impl = std::make_unique<Scene::Impl>();
        const auto start = clock::now();
        const InputFilesNoted noting;  // the scene file, its meshes and MTL files, as they are read
        read(*impl);
        impl->inputs = noting.noted();
        impl->read_seconds = seconds_since(start);
        return Scene(std::move(impl));
    } catch (...) {
        return current_error({"reading the scene", label, Error::Kind::bad_input});
    }
}

/// The layers a render computes: the options', else the scene's render.layers.
LayerSet layers_for(const Scene& scene, const RenderOptions& options) {
    std::vector<std::string> names = options.layers;
    if (names.empty()) names = scene.layers();
    const LayerSet layers = parse_layers(names);
    // The colour layers split each hit's terms at weight 1; a glazed (fresnel_ior) material
    // scales them by 1 − F, which the layers do not yet follow, so they would not add up.
    if (!layers.empty())
        for (const whitted::Material& material : impl_of(scene).scene.materials)
            if (material.fresnel_r0 >= 0)
                throw std::invalid_argument(
                    "render layers are not available for scenes with a fresnel_ior (glazed) material yet");
    return layers;
}

/// The crop window in the renderer's terms, refused unless it lies inside the image.
std::optional<TileRect> crop_window(const Scene& scene, const RenderOptions& options) {
    if (!options.crop) return std::nullopt;
    const PixelWindow& w = *options.crop;
    const int64_t x_end = int64_t(w.x) + w.width, y_end = int64_t(w.y) + w.height;
    if (w.x < 0 || w.y < 0 || w.width < 1 || w.height < 1 || x_end > scene.width() || y_end > scene.height())
        throw std::invalid_argument("the crop window " + std::to_string(w.x) + "," + std::to_string(w.y) + "," +
                                    std::to_string(w.width) + "," + std::to_string(w.height) +
                                    " (X,Y,WIDTH,HEIGHT) does not lie inside the " + std::to_string(scene.width()) +
                                    "x" + std::to_string(scene.height()) + " image");
    return TileRect{w.x, int(x_end), w.y, int(y_end)};
}

whitted::RenderedTiles render_internal(const Scene& scene, const RenderOptions& options, LayerSet layers,
                                       WorkExchange* exchange = nullptr) {
    const std::optional<TileRect> crop = crop_window(scene, options);
    const Accelerator& accelerator = impl_of(scene).accelerator(options.threads);
    // The progress callback may cancel too: then one flag of ours for both, set by either (the
    // caller's copied in by a watcher); without a callback the tiles check the caller's own.
    std::atomic<bool> stop{options.cancel && options.cancel->load()};
    whitted::RenderJob internal;
    internal.threads = options.threads;
    internal.crop = crop;
    internal.layers = layers;
    internal.cancel = options.on_progress || !options.cancel ? &stop : options.cancel;
    std::atomic<bool> watching{true};
    std::thread watcher;
    if (options.cancel && options.on_progress) {
        // The caller's flag is copied into ours while the render runs (tiles check ours).
        watcher = std::thread([&] {
            while (watching.load()) {
                if (options.cancel->load()) stop.store(true);
                std::this_thread::sleep_for(std::chrono::milliseconds(5));
            }
        });
    }
    if (options.on_progress)
        internal.on_progress = [&](const Progress& progress) {
            if (!options.on_progress(progress)) stop.store(true);
        };
    whitted::RenderedTiles result;
    try {
        result = exchange ? whitted::render_distributed(impl_of(scene).scene, accelerator, internal, *exchange)
                          : whitted::render(impl_of(scene).scene, accelerator, internal);
    } catch (...) {
        watching.store(false);
        if (watcher.joinable()) watcher.join();
        throw;
    }
    watching.store(false);
    if (watcher.joinable()) watcher.join();
    if (crop) result.image = crop_image(result.image, *crop);
    return result;
}

RenderStats stats_of(const whitted::RenderedTiles& result) {
    return {result.rays.camera, result.rays.shadow, result.rays.reflected, result.seconds};
}

SourceLocation builder_where(int call) {
    return {FileName("<SceneBuilder>"), call, 1};
}

template <class T>
Located<T> given(T value, const SourceLocation& where) {
    Located<T> located(std::move(value));
    located.where = where;
    located.given = true;
    return located;
}

whitted::Vec3 vec(const Vec3& v) {
    return {v.x, v.y, v.z};
}

}  // namespace

const char* version() {
    return WHITTED_VERSION_STRING;
}

const Accelerator& Scene::Impl::accelerator(int threads) const {
    std::lock_guard lock(m_mutex);
    if (!m_accelerator) m_accelerator = std::make_unique<Accelerator>(scene, threads);
    return *m_accelerator;
}

const SceneDescription& Scene::Impl::converter_description() const {
    if (!objects_kept)
        throw std::invalid_argument(
            "the scene was loaded with SceneUse::render_only, which keeps no description of its objects to "
            "convert: load it with SceneUse::any");
    return description;
}

Scene::Scene(std::unique_ptr<Impl> impl) : m_impl(std::move(impl)) {}
Scene::Scene(Scene&&) noexcept = default;
Scene& Scene::operator=(Scene&&) noexcept = default;
Scene::~Scene() = default;

int Scene::width() const {
    return m_impl->scene.width;
}
int Scene::height() const {
    return m_impl->scene.height;
}
int Scene::samples() const {
    return m_impl->scene.samples;
}
int Scene::max_depth() const {
    return m_impl->scene.max_depth;
}
const std::string& Scene::path() const {
    return m_impl->description.path;
}
std::vector<std::string> Scene::layers() const {
    std::vector<std::string> names;
    for (const auto& layer : m_impl->description.layers) names.push_back(layer.value);
    return names;
}
std::string Scene::layers_location() const {
    const auto& layers = m_impl->description.layers;
    return layers.empty() ? std::string() : layers.front().where.str();
}
std::string Scene::intersection() const {
    return m_impl->scene.intersection == Intersection::exact ? "exact" : "povray";
}
std::vector<std::string> Scene::mesh_files() const {
    return m_impl->scene.mesh_files;
}
SceneCounts Scene::counts() const {
    const whitted::Scene& scene = m_impl->scene;
    return {scene.triangle_count(),
            scene.spheres.size(),
            scene.boxes.size(),
            scene.planes.size(),
            scene.lights.size(),
            scene.instances.size(),
            scene.instanced_triangle_count()};
}
double Scene::read_seconds() const {
    return m_impl->read_seconds;
}
std::string Scene::input_file_at(const std::string& path) const {
    return whitted::input_file_at(path, m_impl->inputs);
}
const Scene::Impl& impl_of(const Scene& scene) {
    return *scene.m_impl;
}

/// The public overrides in the reader's terms; `intersection` is checked here.
SettingOverrides setting_overrides(const SceneOverrides& given) {
    SettingOverrides overrides;
    overrides.where = "SceneOverrides";
    if (given.width) overrides.width = *given.width;
    if (given.height) overrides.height = *given.height;
    if (given.samples) overrides.samples = *given.samples;
    if (given.max_depth) overrides.max_depth = *given.max_depth;
    if (given.intersection) {
        if (*given.intersection == "exact")
            overrides.intersection = Intersection::exact;
        else if (*given.intersection == "povray")
            overrides.intersection = Intersection::povray;
        else
            throw InputError({FileName(overrides.where)},
                             "intersection must be 'exact' or 'povray', not '" + printable(*given.intersection) + "'");
    }
    return overrides;
}

Expected<Scene> load_scene_file(const std::string& path, const SceneOverrides& overrides, SceneUse use) {
    return load(path, [&](Scene::Impl& impl) {
        if (use == SceneUse::render_only) {
            // In one pass (scene.h): the objects are validated as they are read and their
            // descriptions not kept, so a million spheres cost bytes each, not kilobytes.
            impl.scene = whitted::load_scene_file(path, &impl.description, setting_overrides(overrides));
            impl.objects_kept = false;
            return;
        }
        impl.description = parse_scene_file(path);
        apply_overrides(setting_overrides(overrides), impl.description);
        impl.scene = validate_scene(impl.description);
    });
}

Expected<Scene> load_scene_string(const std::string& text, const std::string& name, const SceneOverrides& overrides) {
    return load(name, [&](Scene::Impl& impl) {
        impl.description = parse_any_scene_text(text, name);
        apply_overrides(setting_overrides(overrides), impl.description);
        impl.scene = validate_scene(impl.description);
    });
}

struct SceneBuilder::Impl {
    SceneDescription description;
    int calls = 0;
    int image_call = 0, camera_call = 0;

    SourceLocation next() { return builder_where(++calls); }

    /// The file reader refuses a number that is not finite where it reads it (`must be a finite
    /// number`); the builder does the same for the first such argument, and build() reports it.
    std::optional<InputError> first_error;
    void require_finite(const SourceLocation& where, const std::string& what, std::initializer_list<double> values) {
        if (first_error) return;
        for (const double value : values)
            if (!std::isfinite(value)) {
                first_error.emplace(where, what + ": must be a finite number, got " + std::to_string(value));
                return;
            }
    }
    void require_finite(const SourceLocation& where, const std::string& what, const Vec3& v) {
        require_finite(where, what, {v.x, v.y, v.z});
    }

    void add_object(ObjectDescription::Shape shape, const SourceLocation& where, const api::Material& m) {
        require_finite(where, "material.ka", m.ka);
        require_finite(where, "material.kd", m.kd);
        require_finite(where, "material.ks", m.ks);
        require_finite(where, "material.p", {m.p});
        require_finite(where, "material.km", m.km);
        ObjectDescription& object = description.objects.emplace_back();
        object.where = where;
        object.shape = std::move(shape);
        MaterialDescription material;
        material.where = where;
        material.ka = given(vec(m.ka), where);
        material.kd = given(vec(m.kd), where);
        material.ks = given(vec(m.ks), where);
        material.p = given(m.p, where);
        material.km = given(vec(m.km), where);
        MaterialReference reference;
        reference.where = where;
        reference.inline_ = std::move(material);
        object.material = std::move(reference);
    }
};

SceneBuilder::SceneBuilder() : m_impl(std::make_unique<Impl>()) {
    m_impl->description.path = "<SceneBuilder>";
}
SceneBuilder::SceneBuilder(SceneBuilder&&) noexcept = default;
SceneBuilder& SceneBuilder::operator=(SceneBuilder&&) noexcept = default;
SceneBuilder::~SceneBuilder() = default;

SceneBuilder& SceneBuilder::image(int width, int height, int samples) {
    const SourceLocation where = m_impl->next();
    ImageDescription& image = m_impl->description.image;
    image.where = where;
    image.width = given<int64_t>(width, where);
    image.height = given<int64_t>(height, where);
    image.samples = given<int64_t>(samples, where);
    m_impl->image_call = m_impl->calls;
    return *this;
}

SceneBuilder& SceneBuilder::background(Vec3 color) {
    m_impl->description.image.background = given(vec(color), m_impl->next());
    m_impl->require_finite(m_impl->description.image.background.where, "image.background", color);
    return *this;
}

SceneBuilder& SceneBuilder::camera(Vec3 eye, Vec3 look_at, Vec3 up, double fov_degrees) {
    const SourceLocation where = m_impl->next();
    CameraDescription& camera = m_impl->description.camera;
    camera.where = where;
    camera.eye = given(vec(eye), where);
    camera.look_at = given(vec(look_at), where);
    camera.up = given(vec(up), where);
    camera.fov = given(fov_degrees, where);
    m_impl->require_finite(where, "camera.eye", eye);
    m_impl->require_finite(where, "camera.look_at", look_at);
    m_impl->require_finite(where, "camera.up", up);
    m_impl->require_finite(where, "camera.fov", {fov_degrees});
    m_impl->camera_call = m_impl->calls;
    return *this;
}

SceneBuilder& SceneBuilder::ambient(Vec3 intensity) {
    m_impl->description.ambient = given(vec(intensity), m_impl->next());
    m_impl->require_finite(m_impl->description.ambient.where, "ambient", intensity);
    return *this;
}

SceneBuilder& SceneBuilder::max_depth(int depth) {
    m_impl->description.max_depth = given<int64_t>(depth, m_impl->next());
    return *this;
}

SceneBuilder& SceneBuilder::point_light(Vec3 position, Vec3 intensity) {
    const SourceLocation where = m_impl->next();
    LightDescription& light = m_impl->description.lights.emplace_back();
    light.where = where;
    light.type = LightType::point;
    light.position = given(vec(position), where);
    light.intensity = given(vec(intensity), where);
    m_impl->require_finite(where, "point_light.position", position);
    m_impl->require_finite(where, "point_light.intensity", intensity);
    return *this;
}

SceneBuilder& SceneBuilder::directional_light(Vec3 direction, Vec3 intensity) {
    const SourceLocation where = m_impl->next();
    LightDescription& light = m_impl->description.lights.emplace_back();
    light.where = where;
    light.type = LightType::directional;
    light.direction = given(vec(direction), where);
    light.intensity = given(vec(intensity), where);
    m_impl->require_finite(where, "directional_light.direction", direction);
    m_impl->require_finite(where, "directional_light.intensity", intensity);
    return *this;
}

SceneBuilder& SceneBuilder::sphere(Vec3 center, double radius, const Material& material) {
    const SourceLocation where = m_impl->next();
    m_impl->add_object(SphereShape{given(vec(center), where), given(radius, where)}, where, material);
    m_impl->require_finite(where, "sphere.center", center);
    m_impl->require_finite(where, "sphere.radius", {radius});
    return *this;
}

SceneBuilder& SceneBuilder::plane(Vec3 point, Vec3 normal, const Material& material) {
    const SourceLocation where = m_impl->next();
    m_impl->add_object(PlaneShape{given(vec(point), where), given(vec(normal), where)}, where, material);
    m_impl->require_finite(where, "plane.point", point);
    m_impl->require_finite(where, "plane.normal", normal);
    return *this;
}

SceneBuilder& SceneBuilder::box(Vec3 min, Vec3 max, const Material& material) {
    const SourceLocation where = m_impl->next();
    m_impl->add_object(BoxShape{given(vec(min), where), given(vec(max), where)}, where, material);
    m_impl->require_finite(where, "box.min", min);
    m_impl->require_finite(where, "box.max", max);
    return *this;
}

SceneBuilder& SceneBuilder::triangle(Vec3 a, Vec3 b, Vec3 c, const Material& material) {
    const SourceLocation where = m_impl->next();
    m_impl->add_object(TriangleShape{where, {vec(a), vec(b), vec(c)}}, where, material);
    m_impl->require_finite(where, "triangle.vertices", {a.x, a.y, a.z, b.x, b.y, b.z, c.x, c.y, c.z});
    return *this;
}

Expected<Scene> SceneBuilder::build() const {
    const Impl& impl = *m_impl;
    return load("<SceneBuilder>", [&](Scene::Impl& built) {
        const FileName file("<SceneBuilder>");
        if (!impl.image_call) throw InputError({file, 0, 0}, "no image(width, height) given: the scene needs its size");
        if (!impl.camera_call)
            throw InputError({file, 0, 0}, "no camera(eye, look_at) given: the scene needs a camera");
        if (impl.first_error) throw *impl.first_error;
        built.description = impl.description;
        built.scene = validate_scene(built.description);
    });
}

Expected<void> check_render_options(const Scene& scene, const RenderOptions& options) {
    return guarded<void>("checking the options for " + scene.path(), [&]() -> Expected<void> {
        crop_window(scene, options);
        layers_for(scene, options);
        return {};
    });
}

Expected<AcceleratorInfo> prepare(const Scene& scene, int threads) {
    return guarded<AcceleratorInfo>("building the BVH of " + scene.path(), [&]() -> Expected<AcceleratorInfo> {
        const Accelerator& accelerator = impl_of(scene).accelerator(threads);
        return AcceleratorInfo{accelerator.embree_bytes(), accelerator.peak_embree_bytes(), accelerator.isa(),
                               accelerator.lane_width(), accelerator.has_bvh()};
    });
}

Expected<RenderResult> render(const Scene& scene, const RenderOptions& options) {
    return guarded<RenderResult>("rendering " + scene.path(), [&]() -> Expected<RenderResult> {
        WorkExchange* const exchange = options.mpi_job ? impl_of(*options.mpi_job).exchange.get() : nullptr;
        whitted::RenderedTiles internal = render_internal(scene, options, layers_for(scene, options), exchange);
        RenderResult result;
        result.image = std::move(internal.image);
        result.stats = stats_of(internal);
        result.cancelled = internal.cancelled;
        return result;
    });
}

Expected<RenderStats> render_into(const Scene& scene, float* rgb, size_t floats, const RenderOptions& options) {
    const int width = options.crop ? options.crop->width : scene.width();
    const int height = options.crop ? options.crop->height : scene.height();
    const size_t needed = size_t(std::max(width, 0)) * size_t(std::max(height, 0)) * 3;
    if (!rgb || floats != needed)
        return plain_error("render_into: the buffer holds " + std::to_string(floats) + " floats; the " +
                               std::to_string(width) + "x" + std::to_string(height) +
                               (options.crop ? " crop window" : " image") + " needs " + std::to_string(needed) +
                               " (width*height*3)",
                           Error::Kind::bad_input);
    return guarded<RenderStats>("rendering " + scene.path(), [&]() -> Expected<RenderStats> {
        RenderOptions beauty = options;
        beauty.layers = {"none"};
        whitted::RenderedTiles internal = render_internal(scene, beauty, LayerSet());
        std::memcpy(rgb, internal.image.rgb.data(), needed * sizeof(float));
        if (internal.cancelled) return plain_error("the render was cancelled", Error::Kind::cancelled);
        return stats_of(internal);
    });
}

OutputOptions output_options(const WriteOptions& options) {
    OutputOptions output;
    output.half = options.half;
    output.exr_compression = options.exr_compression;
    output.bit_depth = options.bit_depth;
    output.ocio_config = options.ocio_config;
    output.display = options.display;
    output.view = options.view;
    output.metadata = options.metadata;
    return output;
}

Expected<void> write_image(const Image& image, const std::string& path, const WriteOptions& options) {
    return guarded<void>("writing " + path, [&]() -> Expected<void> {
        OutputOptions output = output_options(options);
        if (!image.layers.empty()) output.layers_from = "the image's layers";
        check_output_path(path);
        check_output_options(path, output);
        whitted::write_image(image, path, output);
        return {};
    });
}

Expected<std::string> to_povray(const Scene& scene) {
    return guarded<std::string>("converting " + scene.path(), [&]() -> Expected<std::string> {
        const Scene::Impl& loaded = impl_of(scene);
        return pov::scene_to_sdl(loaded.converter_description(), loaded.scene);
    });
}

Expected<std::string> write_povray(const Scene& scene, const std::string& pov_path) {
    return guarded<std::string>("converting " + scene.path(), [&]() -> Expected<std::string> {
        // Refused before anything is written: an empty name fails only at the final rename.
        if (pov_path.empty())
            return plain_error("cannot write the POV-Ray scene: the path is empty", Error::Kind::bad_input);
        const Scene::Impl& loaded = impl_of(scene);
        return pov::write_pov_files(loaded.converter_description(), loaded.scene, pov_path);
    });
}

Expected<CheckResult> check(const std::string& scene_path, const CheckOptions& options) {
    // A scene or option it cannot check with is the caller's input (the plug-in missing
    // included), as for every command.
    try {
        reference::CheckRun internal;
        internal.threads = options.threads;
        internal.rule.tolerance = options.tolerance_codes / 65535.0;
        internal.rule.required_fraction = options.min_fraction;
        internal.rule.max_error = options.max_error_codes / 65535.0;
        internal.report_dir = options.report_dir;
        internal.quiet = options.quiet;
        internal.layers = parse_layers(options.layers);
        internal.terms = options.terms;
        internal.povray_image = options.povray_image;
        internal.exposure = options.exposure;
        internal.cancel = options.cancel;
        internal.exit_at_once = options.nothing_created_yet;
        // `check` lives in the OpenImageIO plug-in (core/plugin.h). Its errors come back
        // as values: exceptions do not cross into the plug-in's own copy of the libraries.
        using RunCheck = bool (*)(const std::string&, const reference::CheckRun&, reference::CheckRecord&,
                                  std::vector<std::string>&, std::string&, Error&);
        const auto run_check = reinterpret_cast<RunCheck>(image_io_plugin_symbol("whitted_api_check"));
        reference::CheckRecord result;
        std::vector<std::string> failed_terms;
        CheckResult out;
        Error error;
        if (!run_check(scene_path, internal, result, failed_terms, out.verdict, error)) return error;
        out.passed = result.passed;
        if (options.terms) {
            out.failures = failed_terms;
            return out;
        }
        out.fraction_within = result.comparison.fraction_within();
        out.max_error_codes = result.comparison.max_error * 65535.0;
        out.psnr = result.comparison.psnr;
        out.failures = result.failures;
        return out;
    } catch (...) {
        return current_error({"checking " + scene_path, "", Error::Kind::bad_input});
    }
}

Expected<Comparison> compare_image_files(const std::string& first, const std::string& second, const PassRule& rule,
                                         bool clip) {
    try {
        // In the OpenImageIO plug-in, like check; its errors come back as values.
        using RunCompare = bool (*)(const std::string&, const std::string&, const PassRule&, bool, Comparison&, Error&);
        const auto run_compare = reinterpret_cast<RunCompare>(image_io_plugin_symbol("whitted_api_compare"));
        Comparison result;
        Error error;
        if (!run_compare(first, second, rule, clip, result, error)) return error;
        return result;
    } catch (...) {  // the plug-in cannot be loaded
        return current_error({"comparing " + first + " and " + second, "", Error::Kind::bad_input});
    }
}

Expected<std::string> describe_colour_config(const std::string& config_path) {
    return guarded<std::string>("reading the colour config", [&]() -> Expected<std::string> {
        return DisplayTransform::describe_config(config_path);
    });
}

Expected<void> write_colour_config(const std::string& path) {
    return guarded<void>("writing the colour config", [&]() -> Expected<void> {
        // Before a byte is written; /dev/full stays a device. An empty name would fail only at
        // the final rename.
        if (path.empty())
            return plain_error("cannot write the colour config: the path is empty", Error::Kind::bad_input);
        check_can_write(path);
        refuse_symlink_target(path);
        const std::string text = DisplayTransform::builtin_config_text();
        write_files_atomically({{path, text}});
        return {};
    });
}

}  // namespace whitted::api
