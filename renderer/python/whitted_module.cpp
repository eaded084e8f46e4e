// SPDX-License-Identifier: MIT
// The Python module `whitted` over the public C++ API (whitted/whitted.h); docs/library.md.
//
// Rendering runs on a thread of its own with the GIL released, while the calling (main) thread
// waits in slices of 50 ms: after each it takes the GIL to run Python's signal handlers
// (PyErr_CheckSignals: Ctrl-C raises KeyboardInterrupt there, and only in the main thread) and
// the progress callback. Either raising cancels the render, which stops within a tile, and the
// exception propagates to the caller.

#include "whitted/whitted.h"

#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <array>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>

namespace py = pybind11;
namespace api = whitted::api;

namespace {

PyObject* g_error_type = nullptr;  // whitted.Error

[[noreturn]] void raise(const api::Error& error) {
    py::object type = py::reinterpret_borrow<py::object>(g_error_type);
    py::object exception = type(error.what());
    exception.attr("message") = error.message;
    exception.attr("file") = error.file;
    exception.attr("line") = error.line;
    exception.attr("column") = error.column;
    exception.attr("kind") = error.kind == api::Error::Kind::bad_input ? "bad_input"
                             : error.kind == api::Error::Kind::failure ? "failure"
                                                                       : "cancelled";
    PyErr_SetObject(g_error_type, exception.ptr());
    throw py::error_already_set();
}

template <class T>
T take(api::Expected<T>&& expected) {
    if (!expected) raise(expected.error());
    return std::move(expected).value();
}
void take(api::Expected<void>&& expected) {
    if (!expected) raise(expected.error());
}

/// `threads` as the program takes it (-t): 0 (all cores) to 4096.
int checked_threads(int threads) {
    if (threads < 0 || threads > 4096)
        throw py::value_error("threads: " + std::to_string(threads) + " not in [0 - 4096] (0: all cores)");
    return threads;
}

/// The render's options from the module's arguments; `crop` is None or (x, y, width, height).
api::RenderOptions render_options(int threads, const std::vector<std::string>& layers, const py::object& crop) {
    api::RenderOptions options;
    options.threads = checked_threads(threads);
    options.layers = layers;
    if (!crop.is_none()) {
        std::array<int, 4> window{};
        try {
            window = crop.cast<std::array<int, 4>>();
        } catch (const py::cast_error&) {
            throw py::value_error("crop: expected (x, y, width, height), four whole numbers");
        }
        options.crop = api::PixelWindow{window[0], window[1], window[2], window[3]};
    }
    return options;
}

/// An image's floats as a NumPy array (H×W×C) that owns the Image: no copy.
py::array_t<float> array_of(std::shared_ptr<whitted::Image> image, float* data, size_t channels) {
    auto* holder = new std::shared_ptr<whitted::Image>(std::move(image));
    py::capsule owner(holder, [](void* p) { delete static_cast<std::shared_ptr<whitted::Image>*>(p); });
    const auto h = py::ssize_t((*holder)->height), w = py::ssize_t((*holder)->width), c = py::ssize_t(channels);
    return py::array_t<float>(
        {h, w, c}, {py::ssize_t(sizeof(float)) * w * c, py::ssize_t(sizeof(float)) * c, py::ssize_t(sizeof(float))},
        data, owner);
}

/// api::render on a worker thread; the GIL is released meanwhile and this (calling) thread runs
/// the signal handlers and `progress` every 50 ms. Rethrows what either raised, after the render
/// has stopped.
api::RenderResult render_releasing_gil(const api::Scene& scene, api::RenderOptions options,
                                       const py::object& progress) {
    std::atomic<bool> cancel{false};
    std::mutex mutex;
    std::condition_variable finished;
    bool done = false;
    std::optional<api::Progress> latest;
    std::optional<api::Expected<api::RenderResult>> result;
    std::optional<py::error_already_set> raised;

    options.cancel = &cancel;
    options.on_progress = [&](const api::Progress& p) {
        std::lock_guard lock(mutex);
        latest = p;
        return true;
    };
    auto poll = [&] {
        // With the GIL held: Python's signal handlers, then the progress callback.
        if (PyErr_CheckSignals() != 0) {
            raised.emplace();
            cancel.store(true);
            return;
        }
        if (progress.is_none()) return;
        std::optional<api::Progress> p;
        {
            std::lock_guard lock(mutex);
            p.swap(latest);
        }
        if (!p) return;
        try {
            progress(p->tiles_done, p->tiles_total);
        } catch (py::error_already_set& e) {
            raised.emplace(std::move(e));
            cancel.store(true);
        }
    };
    {
        py::gil_scoped_release release;
        std::thread worker([&] {
            auto r = api::render(scene, options);
            std::lock_guard lock(mutex);
            result.emplace(std::move(r));
            done = true;
            finished.notify_all();
        });
        for (;;) {
            {
                std::unique_lock lock(mutex);
                if (finished.wait_for(lock, std::chrono::milliseconds(50), [&] { return done; })) break;
            }
            if (raised) continue;  // cancelled: wait for the render to stop
            py::gil_scoped_acquire acquire;
            poll();
        }
        worker.join();
    }
    if (!raised && !progress.is_none()) poll();  // the last figures (100 %)
    if (raised) {
        raised->restore();
        throw py::error_already_set();
    }
    api::RenderResult out = take(std::move(*result));
    if (out.cancelled) throw py::value_error("the render was cancelled");
    return out;
}

api::Vec3 vec(const std::array<double, 3>& v) {
    return {v[0], v[1], v[2]};
}

api::Material material(const py::dict& m) {
    api::Material out;
    // As in a scene file: a colour is three numbers, or one number for a grey.
    auto get3 = [&](const char* key, api::Vec3& into) {
        if (!m.contains(key)) return;
        const py::handle value = m[key];
        try {
            if (py::isinstance<py::float_>(value) || py::isinstance<py::int_>(value)) {
                const double grey = value.cast<double>();
                into = {grey, grey, grey};
            } else {
                into = vec(value.cast<std::array<double, 3>>());
            }
        } catch (const py::cast_error&) {
            throw py::value_error(std::string("material: ") + key + " must be a number or three numbers, not " +
                                  py::repr(value).cast<std::string>());
        }
    };
    for (const auto& item : m) {
        const auto key = item.first.cast<std::string>();
        if (key != "ka" && key != "kd" && key != "ks" && key != "p" && key != "km")
            throw py::value_error("material: unknown key '" + key + "' (ka, kd, ks, p, km)");
    }
    get3("ka", out.ka);
    get3("kd", out.kd);
    get3("ks", out.ks);
    get3("km", out.km);
    if (m.contains("p")) {
        try {
            out.p = m["p"].cast<double>();
        } catch (const py::cast_error&) {
            throw py::value_error("material: p must be a number, not " + py::repr(m["p"]).cast<std::string>());
        }
    }
    return out;
}

}  // namespace

PYBIND11_MODULE(whitted, m) {
    m.doc() =
        "Whitted: an offline ray tracer for the lecture shading model, checked against POV-Ray 3.7 "
        "(docs/library.md)";
    m.attr("__version__") = api::version();
    m.def("version", &api::version, "The library's version (the same as whitted.__version__).");

    static py::exception<std::runtime_error> error_type(m, "Error",
                                                        PyExc_RuntimeError);  // docs/library.md: a RuntimeError
    g_error_type = error_type.ptr();
    py::setattr(error_type, "__doc__",
                py::str("A bad scene, option or file: str() is 'FILE:LINE:COL: message'; the attributes "
                        "message, file, line, column and kind ('bad_input' or 'failure') hold the parts."));

    py::class_<api::Scene>(m, "Scene", "A loaded, validated scene (whitted.load, whitted.loads, SceneBuilder)")
        .def_property_readonly("width", &api::Scene::width)
        .def_property_readonly("height", &api::Scene::height)
        .def_property_readonly("samples", &api::Scene::samples)
        .def_property_readonly("max_depth", &api::Scene::max_depth)
        .def_property_readonly("path", &api::Scene::path)
        .def_property_readonly("layers", &api::Scene::layers);

    m.def(
        "load",
        [](const std::string& path, std::optional<int> width, std::optional<int> height, std::optional<int> samples,
           std::optional<int> max_depth, std::optional<std::string> intersection) {
            return take(api::load_scene_file(path, {width, height, samples, max_depth, intersection}));
        },
        py::arg("path"), py::kw_only(), py::arg("width") = py::none(), py::arg("height") = py::none(),
        py::arg("samples") = py::none(), py::arg("max_depth") = py::none(), py::arg("intersection") = py::none(),
        "Read and validate a scene file (YAML/JSON scene format v1, a course .xml scene, an NFF scene). Raises "
        "whitted.Error naming FILE:LINE:COL. width, height, samples, max_depth and intersection ('exact' or "
        "'povray') replace the file's settings, as `whitted render --width ...` does (one side alone keeps the "
        "aspect ratio).");
    m.def(
        "loads",
        [](const std::string& text, const std::string& name, std::optional<int> width, std::optional<int> height,
           std::optional<int> samples, std::optional<int> max_depth, std::optional<std::string> intersection) {
            return take(api::load_scene_string(text, name, {width, height, samples, max_depth, intersection}));
        },
        py::arg("text"), py::arg("name") = "<string>", py::kw_only(), py::arg("width") = py::none(),
        py::arg("height") = py::none(), py::arg("samples") = py::none(), py::arg("max_depth") = py::none(),
        py::arg("intersection") = py::none(),
        "Read and validate a scene from a string (its format by `name`'s extension, else by its first line); "
        "`name` stands for the file in messages. Overrides as for load.");

    m.def(
        "render",
        [](const api::Scene& scene, int threads, const py::object& progress, const py::object& crop) {
            auto result = render_releasing_gil(scene, render_options(threads, {"none"}, crop), progress);
            auto image = std::make_shared<whitted::Image>(std::move(result.image));
            float* data = image->rgb.data();
            return array_of(std::move(image), data, 3);
        },
        py::arg("scene"), py::arg("threads") = 0, py::arg("progress") = py::none(), py::arg("crop") = py::none(),
        "Render the scene's beauty: a float32 NumPy array H x W x 3, linear (the pixels of the EXR "
        "`whitted render` writes, bit for bit), without a copy. progress(tiles_done, tiles_total) is called "
        "from this thread a few times a second; an exception it raises (or Ctrl-C) cancels the render and "
        "propagates. The GIL is released while rendering. crop=(x, y, width, height) renders only that window "
        "of the image (the same pixels as the whole render).");
    m.def(
        "render_layers",
        [](const api::Scene& scene, const std::vector<std::string>& layers, int threads, const py::object& progress,
           const py::object& crop) {
            auto result = render_releasing_gil(scene, render_options(threads, layers, crop), progress);
            auto image = std::make_shared<whitted::Image>(std::move(result.image));
            py::dict out;
            out["beauty"] = array_of(image, image->rgb.data(), 3);
            for (whitted::ImageLayer& layer : image->layers)
                out[py::str(layer.name)] = array_of(image, layer.values.data(), layer.channels.size());
            return out;
        },
        py::arg("scene"), py::arg("layers") = std::vector<std::string>{}, py::arg("threads") = 0,
        py::arg("progress") = py::none(), py::arg("crop") = py::none(),
        "Render with render layers (docs/layers.md; empty: the scene's render.layers): a dict of arrays, "
        "'beauty' and one per layer (H x W x channels). crop as for render.");

    m.def(
        "write_image",
        [](py::array_t<float, py::array::c_style | py::array::forcecast> rgb, const std::string& path, bool half,
           const std::string& exr_compression, int bit_depth, const std::string& ocio_config,
           const std::string& display, const std::string& view) {
            if (rgb.ndim() != 3 || rgb.shape(2) != 3) throw py::value_error("write_image: the array must be H x W x 3");
            if (rgb.shape(0) < 1 || rgb.shape(1) < 1 || rgb.shape(0) > 65536 || rgb.shape(1) > 65536)
                throw py::value_error("write_image: the image must be 1 to 65536 pixels on each side, got " +
                                      std::to_string(rgb.shape(1)) + " x " + std::to_string(rgb.shape(0)));
            whitted::Image image;
            image.height = int(rgb.shape(0));
            image.width = int(rgb.shape(1));
            image.rgb.assign(rgb.data(), rgb.data() + rgb.size());
            api::WriteOptions options;
            options.half = half;
            options.exr_compression = exr_compression;
            options.bit_depth = bit_depth;
            options.ocio_config = ocio_config;
            options.display = display;
            options.view = view;
            // The error is raised with the GIL held again: raising while it is released crashed.
            api::Expected<void> written = [&] {
                py::gil_scoped_release release;
                return api::write_image(image, path, options);
            }();
            take(std::move(written));
        },
        py::arg("image"), py::arg("path"), py::arg("half") = false, py::arg("exr_compression") = "",
        py::arg("bit_depth") = 0, py::arg("ocio_config") = "", py::arg("display") = "", py::arg("view") = "",
        "Write an H x W x 3 linear image as `whitted render` does: .exr linear, .png/.jpg/.tif through the "
        "OpenColorIO display transform.");

    m.def(
        "to_povray", [](const api::Scene& scene) { return take(api::to_povray(scene)); }, py::arg("scene"),
        "The scene as POV-Ray 3.7 SDL.");
    m.def(
        "write_povray",
        [](const api::Scene& scene, const std::string& path) { return take(api::write_povray(scene, path)); },
        py::arg("scene"), py::arg("path"), "Write the .pov file and its .ini; returns the .ini's path.");

    py::class_<api::CheckResult>(m, "CheckResult", "The outcome of whitted.check")
        .def_readonly("passed", &api::CheckResult::passed)
        .def_readonly("fraction_within", &api::CheckResult::fraction_within)
        .def_readonly("max_error_codes", &api::CheckResult::max_error_codes)
        .def_readonly("psnr", &api::CheckResult::psnr)
        .def_readonly("failures", &api::CheckResult::failures)
        .def_readonly("verdict", &api::CheckResult::verdict)
        .def("__bool__", [](const api::CheckResult& r) { return r.passed; })
        .def("__repr__", [](const api::CheckResult& r) { return "<whitted.CheckResult " + r.verdict + ">"; });
    m.def(
        "check",
        [](const std::string& path, int threads, double tolerance, double min_fraction, double max_error,
           const std::string& report_dir, bool quiet) {
            api::CheckOptions options;
            options.threads = checked_threads(threads);
            options.tolerance_codes = tolerance;
            options.min_fraction = min_fraction;
            options.max_error_codes = max_error;
            options.report_dir = report_dir;
            options.quiet = quiet;
            api::Expected<api::CheckResult> result = [&] {
                py::gil_scoped_release release;
                return api::check(path, options);
            }();
            return take(std::move(result));
        },
        py::arg("path"), py::arg("threads") = 0, py::arg("tolerance") = 2.0, py::arg("min_fraction") = 0.999,
        py::arg("max_error") = 64.0, py::arg("report_dir") = "", py::arg("quiet") = true,
        "`whitted check`: render the scene file with Whitted and with POV-Ray 3.7 and compare pixel by pixel "
        "(tolerances in 16-bit codes). Prints the verdict line; returns a CheckResult (truthy when passed).");

    py::class_<api::SceneBuilder>(m, "SceneBuilder", "A scene built in code; each method returns the builder")
        .def(py::init<>())
        .def(
            "image",
            [](api::SceneBuilder& b, int w, int h, int samples) -> api::SceneBuilder& {
                return b.image(w, h, samples);
            },
            py::arg("width"), py::arg("height"), py::arg("samples") = 1, py::return_value_policy::reference_internal)
        .def(
            "background",
            [](api::SceneBuilder& b, std::array<double, 3> c) -> api::SceneBuilder& { return b.background(vec(c)); },
            py::arg("color"), py::return_value_policy::reference_internal)
        .def(
            "camera",
            [](api::SceneBuilder& b, std::array<double, 3> eye, std::array<double, 3> look_at, std::array<double, 3> up,
               double fov) -> api::SceneBuilder& { return b.camera(vec(eye), vec(look_at), vec(up), fov); },
            py::arg("eye"), py::arg("look_at"), py::arg("up") = std::array<double, 3>{0, 1, 0}, py::arg("fov") = 45.0,
            py::return_value_policy::reference_internal)
        .def(
            "ambient",
            [](api::SceneBuilder& b, std::array<double, 3> c) -> api::SceneBuilder& { return b.ambient(vec(c)); },
            py::arg("intensity"), py::return_value_policy::reference_internal)
        .def(
            "max_depth", [](api::SceneBuilder& b, int d) -> api::SceneBuilder& { return b.max_depth(d); },
            py::arg("depth"), py::return_value_policy::reference_internal)
        .def(
            "point_light",
            [](api::SceneBuilder& b, std::array<double, 3> p, std::array<double, 3> i) -> api::SceneBuilder& {
                return b.point_light(vec(p), vec(i));
            },
            py::arg("position"), py::arg("intensity"), py::return_value_policy::reference_internal)
        .def(
            "directional_light",
            [](api::SceneBuilder& b, std::array<double, 3> d, std::array<double, 3> i) -> api::SceneBuilder& {
                return b.directional_light(vec(d), vec(i));
            },
            py::arg("direction"), py::arg("intensity"), py::return_value_policy::reference_internal)
        .def(
            "sphere",
            [](api::SceneBuilder& b, std::array<double, 3> c, double r, const py::dict& mat) -> api::SceneBuilder& {
                return b.sphere(vec(c), r, material(mat));
            },
            py::arg("center"), py::arg("radius"), py::arg("material"), py::return_value_policy::reference_internal)
        .def(
            "plane",
            [](api::SceneBuilder& b, std::array<double, 3> p, std::array<double, 3> n,
               const py::dict& mat) -> api::SceneBuilder& { return b.plane(vec(p), vec(n), material(mat)); },
            py::arg("point"), py::arg("normal"), py::arg("material"), py::return_value_policy::reference_internal)
        .def(
            "box",
            [](api::SceneBuilder& b, std::array<double, 3> lo, std::array<double, 3> hi,
               const py::dict& mat) -> api::SceneBuilder& { return b.box(vec(lo), vec(hi), material(mat)); },
            py::arg("min"), py::arg("max"), py::arg("material"), py::return_value_policy::reference_internal)
        .def(
            "triangle",
            [](api::SceneBuilder& b, std::array<double, 3> a, std::array<double, 3> b2, std::array<double, 3> c,
               const py::dict& mat) -> api::SceneBuilder& {
                return b.triangle(vec(a), vec(b2), vec(c), material(mat));
            },
            py::arg("a"), py::arg("b"), py::arg("c"), py::arg("material"), py::return_value_policy::reference_internal)
        .def(
            "build", [](const api::SceneBuilder& b) { return take(b.build()); },
            "Validate and return the Scene (raises whitted.Error naming '<SceneBuilder>:CALL').");
}
