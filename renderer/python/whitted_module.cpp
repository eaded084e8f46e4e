// SPDX-License-Identifier: MIT
// The Python module `whitted` over the public C++ API (whitted/whitted.h); docs/library.md.
//
// A render or a check runs on a thread of its own with the GIL released, while the calling (main)
// thread waits in slices of 50 ms: after each it takes the GIL to run Python's signal handlers
// (PyErr_CheckSignals: Ctrl-C raises KeyboardInterrupt there, and only in the main thread) and
// the progress callback. Either raising cancels the work (a render stops within a tile, a check
// ends POV-Ray and removes its files), and the exception propagates to the caller. Every failure
// of the library is raised as whitted.Error with the library's message (FILE:LINE:COL); an
// argument the library cannot be given (a thread count, a share out of range, a path with a NUL)
// is a ValueError, and one of the wrong type pybind11's TypeError.

#include "whitted/whitted.h"

#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <array>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <exception>
#include <functional>
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

/// Runs `work` on a thread of its own with the GIL released, while this (calling) thread takes
/// the GIL every 50 ms to run Python's signal handlers (Ctrl-C raises KeyboardInterrupt there, and
/// only in the main thread) and then `poll`, if given. A Python exception from either sets
/// `cancel`, and is rethrown once `work` has returned (work heeds `cancel` and stops soon).
void run_releasing_gil(const std::function<void()>& work, std::atomic<bool>& cancel,
                       const std::function<void()>& poll = {}) {
    std::mutex mutex;
    std::condition_variable finished;
    bool done = false;
    std::exception_ptr failed;  // a C++ exception from `work` (out of memory), rethrown here
    std::optional<py::error_already_set> raised;
    {
        py::gil_scoped_release release;
        std::thread worker([&] {
            try {
                work();
            } catch (...) {
                failed = std::current_exception();
            }
            std::lock_guard lock(mutex);
            done = true;
            finished.notify_all();
        });
        for (;;) {
            {
                std::unique_lock lock(mutex);
                if (finished.wait_for(lock, std::chrono::milliseconds(50), [&] { return done; })) break;
            }
            if (raised) continue;  // cancelled: wait for the work to stop
            py::gil_scoped_acquire acquire;
            try {
                if (PyErr_CheckSignals() != 0) throw py::error_already_set();
                if (poll) poll();
            } catch (py::error_already_set& e) {
                raised.emplace(std::move(e));
                cancel.store(true);
            }
        }
        worker.join();
    }
    if (raised) {
        raised->restore();
        throw py::error_already_set();
    }
    if (failed) std::rethrow_exception(failed);
}

/// api::render with run_releasing_gil: `progress(tiles_done, tiles_total)` is called from this
/// thread with the latest figures, and once more at the end.
api::RenderResult render_releasing_gil(const api::Scene& scene, api::RenderOptions options,
                                       const py::object& progress) {
    std::atomic<bool> cancel{false};
    std::mutex mutex;
    std::optional<api::Progress> latest;
    std::optional<api::Expected<api::RenderResult>> result;

    options.cancel = &cancel;
    options.on_progress = [&](const api::Progress& p) {
        std::lock_guard lock(mutex);
        latest = p;
        return true;
    };
    auto report = [&] {  // with the GIL held
        if (progress.is_none()) return;
        std::optional<api::Progress> p;
        {
            std::lock_guard lock(mutex);
            p.swap(latest);
        }
        if (p) progress(p->tiles_done, p->tiles_total);
    };
    run_releasing_gil([&] { result.emplace(api::render(scene, options)); }, cancel, report);
    report();  // the last figures (100 %)
    api::RenderResult out = take(std::move(*result));
    if (out.cancelled) throw py::value_error("the render was cancelled");
    return out;
}

/// `f()` with the GIL released: for a call that reads or writes files. Its Expected is raised
/// (take) by the caller, with the GIL held again: raising while it is released crashed.
template <class F>
auto without_gil(F&& f) {
    py::gil_scoped_release release;
    return f();
}

/// A path from Python: a NUL byte would end it early in the C library (writing another file
/// than the one named), so it is refused as Python's own open() refuses it.
const std::string& checked_path(const std::string& path, const char* what) {
    if (path.find('\0') != std::string::npos)
        throw py::value_error(std::string(what) + ": embedded null character in the path");
    return path;
}

/// The pass rule (docs/validation.md) from the module's arguments, refused as `whitted compare`
/// and `whitted check` refuse them: tolerances of at least 0, a share in [0, 1] (NaN is neither).
api::PassRule pass_rule(double tolerance, double min_fraction, double max_error) {
    if (!(tolerance >= 0))
        throw py::value_error("tolerance: must be a number >= 0 (16-bit codes), not " +
                              py::repr(py::float_(tolerance)).cast<std::string>());
    if (!(min_fraction >= 0 && min_fraction <= 1))
        throw py::value_error("min_fraction: must be in [0, 1], not " +
                              py::repr(py::float_(min_fraction)).cast<std::string>());
    if (!(max_error >= 0))
        throw py::value_error("max_error: must be a number >= 0 (16-bit codes), not " +
                              py::repr(py::float_(max_error)).cast<std::string>());
    return {tolerance, min_fraction, max_error};
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
            return take(
                api::load_scene_file(checked_path(path, "path"), {width, height, samples, max_depth, intersection}));
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
            checked_path(path, "path");
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
        "display transform (the built-in config's, or the OpenColorIO config's).");

    m.def(
        "to_povray", [](const api::Scene& scene) { return take(api::to_povray(scene)); }, py::arg("scene"),
        "The scene as POV-Ray 3.7 SDL.");
    m.def(
        "write_povray",
        [](const api::Scene& scene, const std::string& path) {
            return take(api::write_povray(scene, checked_path(path, "path")));
        },
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
           const std::string& report_dir, bool quiet, const std::vector<std::string>& layers, bool terms,
           const std::string& povray_image, double exposure) {
            const api::PassRule rule = pass_rule(tolerance, min_fraction, max_error);
            if (!(exposure > 0 && exposure <= 1))
                throw py::value_error("exposure: must be in (0, 1] (a power of two), not " +
                                      py::repr(py::float_(exposure)).cast<std::string>());
            api::CheckOptions options;
            options.threads = checked_threads(threads);
            options.tolerance_codes = rule.tolerance_codes;
            options.min_fraction = rule.min_fraction;
            options.max_error_codes = rule.max_error_codes;
            options.report_dir = checked_path(report_dir, "report_dir");
            options.quiet = quiet;
            options.layers = layers;
            options.terms = terms;
            options.povray_image = checked_path(povray_image, "povray_image");
            options.exposure = exposure;
            std::atomic<bool> cancel{false};
            options.cancel = &cancel;
            std::optional<api::Expected<api::CheckResult>> result;
            checked_path(path, "path");
            run_releasing_gil([&] { result.emplace(api::check(path, options)); }, cancel);
            return take(std::move(*result));
        },
        py::arg("path"), py::arg("threads") = 0, py::arg("tolerance") = 2.0, py::arg("min_fraction") = 0.999,
        py::arg("max_error") = 64.0, py::arg("report_dir") = "", py::arg("quiet") = true, py::kw_only(),
        py::arg("layers") = std::vector<std::string>{}, py::arg("terms") = false, py::arg("povray_image") = "",
        py::arg("exposure") = 1.0,
        R"(`whitted check`: render the scene file with Whitted and, converted, with POV-Ray 3.7 ($WHITTED_POVRAY
or `povray`) and compare them pixel by pixel (docs/validation.md).

Parameter ``path`` (str): the scene file.
Parameter ``threads`` (int): Whitted's worker threads, 0 (all cores) to 4096.
Parameter ``tolerance``, ``min_fraction``, ``max_error`` (float): the pass rule, as for compare_image_files.
Parameter ``report_dir`` (str): write images, a heat map, metrics.json and report.html here; empty: none.
Parameter ``quiet`` (bool): print only the verdict line (False: the figures too), on standard output.
Parameter ``layers`` (list[str]): render Whitted's image with these render layers (docs/layers.md) and
compare its beauty, then the float sum of the colour layers.
Parameter ``terms`` (bool): check term by term (only ambient, only diffuse, only specular, each light
alone); the result's failures name the terms that disagree.
Parameter ``povray_image`` (str): compare with this stored POV-Ray 16-bit PNG of the converted scene
instead of running POV-Ray; ``exposure`` (float, a power of two <= 1) is the one it was made at.
Returns CheckResult (truthy when passed): a failed comparison is a result, not an exception.
Raises whitted.Error (kind 'bad_input') for a scene or option it cannot check with; Ctrl-C
(KeyboardInterrupt) ends POV-Ray, removes the temporary files and propagates. The GIL is released.)");

    py::class_<api::Comparison>(m, "Comparison", "The outcome of whitted.compare_image_files; truthy when passed")
        .def_readonly("passed", &api::Comparison::passed)
        .def_readonly("first_meaning", &api::Comparison::first_meaning,
                      "What the first file was read as, e.g. 'linear Rec.709 (EXR)'")
        .def_readonly("second_meaning", &api::Comparison::second_meaning)
        .def_readonly("fraction_within", &api::Comparison::fraction_within, "Share of pixels within tolerance")
        .def_readonly("max_error_codes", &api::Comparison::max_error_codes,
                      "Largest error of any channel, 16-bit codes (inf with NaN/Inf values)")
        .def_readonly("rms_error", &api::Comparison::rms_error, "Root mean square error, linear units")
        .def_readonly("failures", &api::Comparison::failures, "The rules broken, e.g. 'cap (max 1000.0 codes > 64)'")
        .def_readonly("verdict", &api::Comparison::verdict, "'PASS A vs B: ...' or 'FAIL ...', as `whitted compare`")
        .def("__bool__", [](const api::Comparison& c) { return c.passed; })
        .def("__repr__", [](const api::Comparison& c) { return "<whitted.Comparison " + c.verdict + ">"; });
    m.def(
        "compare_image_files",
        [](const std::string& first, const std::string& second, double tolerance, double min_fraction, double max_error,
           bool clip) {
            const api::PassRule rule = pass_rule(tolerance, min_fraction, max_error);
            checked_path(first, "first");
            checked_path(second, "second");
            return take(without_gil([&] { return api::compare_image_files(first, second, rule, clip); }));
        },
        py::arg("first"), py::arg("second"), py::arg("tolerance") = 2.0, py::arg("min_fraction") = 0.999,
        py::arg("max_error") = 64.0, py::arg("clip") = false,
        R"(`whitted compare A B`: two image files (EXR, PNG, JPEG, TIFF, ...), each turned into linear
Rec.709 from its colour metadata, compared channel by channel (docs/validation.md).

Parameter ``tolerance`` (float): per-channel tolerance in 16-bit codes (1/65535), >= 0.
Parameter ``min_fraction`` (float): share of pixels that must be within it, in [0, 1].
Parameter ``max_error`` (float): hard cap: no channel of any pixel may differ by more, 16-bit codes.
Parameter ``clip`` (bool): clip both to [0, 1] first (a float EXR against a PNG, which clips).
Returns Comparison (truthy when passed): images that differ, in values or size, are a result.
Raises whitted.Error (kind 'bad_input') for a file that cannot be read or whose colour is not
known; ValueError for a rule out of range. The GIL is released.)");

    m.def(
        "explain",
        [](const api::Scene& scene, int x, int y, int threads) {
            api::ExplainOptions options;
            options.format = api::ExplainFormat::json;
            options.threads = checked_threads(threads);
            const std::string text = take(without_gil([&] { return api::explain(scene, x, y, options); }));
            return py::module_::import("json").attr("loads")(text);
        },
        py::arg("scene"), py::arg("x"), py::arg("y"), py::arg("threads") = 0,
        R"(`whitted explain SCENE --pixel X,Y --json`: every term of pixel (x, y)'s equation, traced as
the render traces it (the same numbers, bit for bit).

Parameter ``x``, ``y`` (int): column and row from the top-left corner, 0-based.
Parameter ``threads`` (int): threads for building the BVH, if no render has built it yet (0: all cores).
Returns dict: the document docs/explain.schema.json describes (json.loads of the program's output).
Raises whitted.Error (kind 'bad_input') for a pixel outside the image.)");
    m.def(
        "explain_text",
        [](const api::Scene& scene, int x, int y, bool summary, int threads) {
            api::ExplainOptions options;
            options.format = summary ? api::ExplainFormat::summary : api::ExplainFormat::text;
            options.threads = checked_threads(threads);
            return take(without_gil([&] { return api::explain(scene, x, y, options); }));
        },
        py::arg("scene"), py::arg("x"), py::arg("y"), py::arg("summary") = false, py::arg("threads") = 0,
        R"(`whitted explain SCENE --pixel X,Y` (``summary``: ``--summary``): pixel (x, y)'s equation as the
text the program prints: every sample, segment, light and term with its numbers, or a dozen lines (the
first hit, each term averaged over the samples, the pixel). Raises as explain does.)");

    m.def(
        "describe_colour_config",
        [](const std::string& ocio_config) {
            checked_path(ocio_config, "ocio_config");
            return take(without_gil([&] { return api::describe_colour_config(ocio_config); }));
        },
        py::arg("ocio_config") = "",
        R"(`whitted colour --list`: each display and view of the OpenColorIO config (empty: $OCIO, else the
built-in one), the colour space it writes and what that means; the text the program prints.
Raises whitted.Error for a config that cannot be read.)");
    m.def(
        "write_colour_config",
        [](const std::string& path) {
            checked_path(path, "path");
            take(without_gil([&] { return api::write_colour_config(path); }));
        },
        py::arg("path"),
        R"(`whitted colour --write-config PATH`: write the built-in OpenColorIO config (the one write_image
uses without $OCIO) for other programs. The file appears complete or not at all; an existing file is
replaced only by a complete one. Raises whitted.Error for a folder that does not exist, a symbolic link
(never written through), a device or a folder that cannot be written.)");

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
