// SPDX-License-Identifier: MIT
// `whitted check`: one scene rendered by Whitted and, converted, by POV-Ray 3.7, compared
// pixel by pixel (docs/validation.md explains the method and the tolerance).

#include "reference/check.h"

#include "converters/pov_writer.h"
#include "output/atomic_files.h"
#include "reference/povray.h"
#include "render/accelerator.h"
#include "render/renderer.h"
#include "scene/description.h"
#include "scene/scene.h"
#include "scene/text_checks.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <stdexcept>

namespace whitted::reference {
namespace {

namespace fs = std::filesystem;

// Fixed names inside the work directory: the scene's own name may hold characters that a
// POV-Ray .ini cannot, and a report directory then always looks the same.
constexpr const char* pov_name = "scene.pov";
constexpr const char* ini_name = "scene.ini";
constexpr const char* povray_image_name = "povray-16bit.png";

/// POV-Ray clipped values above 1 into code 65535; this many times at most it is run again at
/// half the exposure before the comparison is made anyway (and then shows the clipping).
constexpr int max_exposure_retries = 8;

double max_value(const Image& image) {
    double m = 0;
    for (const float v : image.rgb)
        if (double(v) > m) m = v;  // NaN compares false and is left to the comparison to report
    return m;
}

/// The largest power of two ≤ 1 that brings `m` into [0, 1]: a power of two scales every float
/// exactly, so ours×exposure carries no rounding of its own.
double exposure_for(double m) {
    // An infinite value is a bug the comparison will show; it must not darken POV-Ray to black.
    if (!std::isfinite(m)) return 1.0;
    return m > 1 ? std::exp2(-std::ceil(std::log2(m))) : 1.0;
}

Image scaled(const Image& image, double factor) {
    Image out = image;
    if (factor != 1)
        for (float& v : out.rgb) v = float(double(v) * factor);
    return out;
}

/// Whether POV-Ray's 16-bit PNG clipped a value that is not 1 in our image: a code of 65535
/// under a pixel where ours (at this exposure) is clearly below 1. With image.samples > 1 a
/// single sub-sample may exceed 1 while the block average does not, so this is checked on
/// POV-Ray's full-resolution image.
bool povray_clipped(const Image& full, const Image& ours, int n, double exposure, double tolerance) {
    for (int y = 0; y < full.height; ++y)
        for (int x = 0; x < full.width; ++x) {
            const float* p = full.pixel(x, y);
            const float* o = ours.pixel(x / n, y / n);
            for (int ch = 0; ch < 3; ++ch)
                if (p[ch] >= 1.0f && double(o[ch]) * exposure < 1.0 - tolerance) return true;
        }
    return false;
}

std::string rgb_text(const float* v) {
    return fmt::format("{:.6f} {:.6f} {:.6f}", v[0], v[1], v[2]);
}

std::string rgb_codes(const float* v) {
    return fmt::format("{:.1f} {:.1f} {:.1f}", double(v[0]) * 65535.0, double(v[1]) * 65535.0, double(v[2]) * 65535.0);
}

void print_table(const std::string& scene_path, const CheckRecord& r, const CheckRun& options) {
    const ImageComparison& c = r.comparison;
    const PassRule& rule = options.rule;
    std::string out;
    out +=
        fmt::format("whitted check {}: {}x{}, {} sample(s)/pixel, compared at exposure {:g}{}\n", scene_path, c.width,
                    c.height, r.samples * r.samples, r.exposure, r.exposure != 1 ? " (scene values above 1)" : "");
    if (!options.povray_image.empty())
        out += fmt::format("  Whitted {:.3f}s, POV-Ray not run (stored image {}, exposure given)\n", r.whitted_seconds,
                           options.povray_image);
    else
        out += fmt::format("  Whitted {:.3f}s, POV-Ray {:.2f}s ({} run{}, {})\n", r.whitted_seconds, r.povray_seconds,
                           r.povray_runs, r.povray_runs == 1 ? "" : "s", r.povray_program);
    out += fmt::format("  max error    {:.3e}  ({} codes of 65535; cap {:g})\n", c.max_error, format_codes(c.max_error),
                       rule.max_error * 65535);
    out +=
        fmt::format("  mean error   {:.3e}  ({} codes)\n", c.mean_error, fmt::format("{:.3f}", c.mean_error * 65535));
    out += fmt::format("  RMS error    {:.3e}  ({} codes)\n", c.rms_error, fmt::format("{:.3f}", c.rms_error * 65535));
    out += std::isinf(c.psnr) ? std::string("  PSNR         inf (identical)\n")
                              : fmt::format("  PSNR         {:.1f} dB (peak 1)\n", c.psnr);
    out += fmt::format("  within {:g}/65535: {} ({} of {} pixels; {:g}% required)\n", rule.tolerance * 65535,
                       format_percent(c), c.pixels_within, c.pixels, rule.required_fraction * 100);
    if (c.nonfinite_ours + c.nonfinite_theirs > 0)
        out += fmt::format("  NaN/Inf      {} value(s) in Whitted's image, {} in POV-Ray's\n", c.nonfinite_ours,
                           c.nonfinite_theirs);
    if (!c.worst.empty()) {
        const PixelError& w = c.worst.front();
        out += fmt::format("  worst pixel  ({}, {}): Whitted {}  POV-Ray {}\n", w.x, w.y, rgb_text(w.ours),
                           rgb_text(w.theirs));
        out += fmt::format("               in codes: Whitted {}  POV-Ray {}\n", rgb_codes(w.ours), rgb_codes(w.theirs));
    }
    if (!options.report_dir.empty())
        out += "  report       " + (fs::path(options.report_dir) / "report.html").string() + "\n";
    std::fputs(out.c_str(), stdout);
}

void throw_if_cancelled(const CheckRun& options) {
    if (options.cancel && options.cancel->load()) throw Interrupted();
}

}  // namespace

std::string verdict_line(const std::string& scene_path, const CheckRecord& r, const CheckRun& options) {
    // No figures when the images could not be compared at all (their sizes differ).
    const bool compared = r.comparison.pixels > 0;
    return verdict_text(scene_path, compared ? verdict_figures(r.comparison, options.rule) : std::string(), r.failures);
}

namespace {

/// A report directory that cannot be one (a file, or under one) is a usage error found before
/// the scene is read and rendered, not after (it took 28-38 s on a large scene).
void check_report_dir(const CheckRun& options) {
    if (options.report_dir.empty()) return;
    std::error_code error;
    for (fs::path at = fs::absolute(options.report_dir, error); !error && !at.empty(); at = at.parent_path()) {
        const fs::file_status status = fs::status(at, error);
        if (error) {
            error.clear();  // not there (yet): its parent decides
        } else if (fs::exists(status)) {
            if (!fs::is_directory(status))
                throw std::invalid_argument("cannot create the report directory '" + options.report_dir + "': '" +
                                            at.string() + "' is not a directory");
            return;
        }
        if (at == at.parent_path()) return;
    }
}

/// Every file `check --report` may write in the report directory.
constexpr const char* report_files[] = {pov_name,   ini_name,       povray_image_name, "povray.log",
                                        "ours.exr", "povray.exr",   "ours.png",        "povray.png",
                                        "diff.png", "metrics.json", "report-data.js",  "report.html"};

/// A report file that is one of the check's inputs (the scene, a mesh or MTL file, by any name:
/// a scene copied to `r/metrics.json`) is a usage error before the render: the report would
/// replace it.
void refuse_report_over_inputs(const CheckRun& options) {
    if (options.report_dir.empty()) return;
    for (const char* name : report_files) {
        const fs::path target = fs::path(options.report_dir) / name;
        if (const std::string input = input_file_at(target.string()); !input.empty())
            throw std::invalid_argument("cannot write the report file '" + target.string() + "': it is " + input +
                                        ", an input of the same check");
    }
}

}  // namespace

CheckRecord run_check(const std::string& scene_path, const CheckRun& options) {
    check_report_dir(options);
    const InputFilesNoted inputs;  // for refuse_report_over_inputs
    return run_check(parse_scene_file(scene_path), scene_path, options);
}

CheckRecord run_check(const SceneDescription& description, const std::string& scene_path, const CheckRun& options) {
    check_report_dir(options);
    CheckRecord result;

    // 1. Whitted, as `whitted render` does it, with POV-Ray's intersection decisions
    //    (render.intersection: povray), so that the two can agree pixel by pixel where an exact
    //    answer and POV-Ray's differ (at an edge, a graze, a tie).
    Scene scene = validate_scene(description);  // reads the meshes
    refuse_report_over_inputs(options);
    scene.intersection = Intersection::povray;
    Image ours;
    {
        const Accelerator accelerator(scene, options.threads);
        RenderJob render_options;
        render_options.threads = options.threads;
        render_options.layers = options.layers;
        RenderedTiles rendered = render(scene, accelerator, render_options);
        result.whitted_seconds = rendered.seconds;
        ours = std::move(rendered.image);
    }
    result.samples = scene.samples;
    const int n = scene.samples;

    // From here on there are directories and files to remove or finish: a signal only asks
    // for the check to stop (POV-Ray ended, temporaries removed), it no longer exits at once.
    if (options.exit_at_once) options.exit_at_once->store(false);
    throw_if_cancelled(options);

    // 2. Where POV-Ray's files go: the report directory (kept), else a temporary one. With a
    // stored POV-Ray image there are none; only a report is written.
    const bool stored = !options.povray_image.empty();
    std::optional<TemporaryDirectory> temporary;
    fs::path work;
    if (!options.report_dir.empty()) {
        work = options.report_dir;
        std::error_code error;
        fs::create_directories(work, error);
        if (error || !fs::is_directory(work))
            throw std::runtime_error("cannot create the report directory '" + work.string() +
                                     "': " + (error ? error.message() : "not a directory"));
    } else if (!stored) {
        temporary.emplace("whitted-check-");
        work = temporary->path();
    }
    result.pov_file = pov_name;
    result.ini_file = ini_name;
    result.povray_image = povray_image_name;

    // 3. POV-Ray, always into a linear 16-bit PNG (1/65535 steps): scenes brighter than 1 are
    // darkened by a power of two (lights, ambient light and background; the image is linear in
    // them) instead of using POV-Ray's half-float EXR, whose steps are 2^-11 relative.
    double exposure = stored ? options.exposure : exposure_for(max_value(ours));
    Image theirs_full;
    bool stored_clipped = false;
    if (stored) {
        // The same size, channels and clipping rules as for a live POV-Ray. Clipping here means
        // the reference was made at another exposure than the one given (or ours got brighter):
        // a failure, since the clipped pixels cannot be compared.
        result.pov_file = result.ini_file = "";
        result.povray_image = options.povray_image;
        result.povray_program = "none: stored image " + options.povray_image;
        const ImageShape shape = read_image_shape(options.povray_image);
        result.failures = shape_mismatches({ours.width * n, ours.height * n, 3}, shape, ChannelRule::exact);
        theirs_full = read_linear_image(options.povray_image);
        stored_clipped =
            result.failures.empty() && povray_clipped(theirs_full, ours, n, exposure, options.rule.tolerance);
    }
    for (int attempt = 0; !stored; ++attempt) {
        pov::ConvertOptions convert;
        convert.exposure = exposure;
        convert.hdr_output = false;
        const std::string sdl = pov::scene_to_sdl(description, scene, convert);
        const std::string ini = pov::ini_for(description, pov_name, povray_image_name, convert);
        write_files_atomically({{work / pov_name, sdl}, {work / ini_name, ini}});
        std::error_code ignored;
        fs::remove(work / povray_image_name, ignored);  // never read a previous run's image

        const PovrayRun run =
            run_povray((work / ini_name).string(),
                       options.report_dir.empty() ? std::string() : (work / "povray.log").string(), options.cancel);
        result.povray_program = run.program;
        result.povray_seconds += run.seconds;
        ++result.povray_runs;
        if (!fs::exists(work / povray_image_name))
            throw std::runtime_error("POV-Ray finished but wrote no '" + (work / povray_image_name).string() +
                                     "'; its last words:\n" +
                                     run.log.substr(run.log.size() > 2000 ? run.log.size() - 2000 : 0));
        // The size and channels rules: POV-Ray must have written RGB at n·W × n·H. Anything
        // else is a failed comparison, reported as such, not an error of the check.
        const ImageShape shape = read_image_shape((work / povray_image_name).string());
        result.failures = shape_mismatches({ours.width * n, ours.height * n, 3}, shape, ChannelRule::exact);
        theirs_full = read_linear_image((work / povray_image_name).string());
        if (!result.failures.empty()) break;
        if (attempt == max_exposure_retries || !povray_clipped(theirs_full, ours, n, exposure, options.rule.tolerance))
            break;
        exposure *= 0.5;
    }
    result.exposure = exposure;

    // 4. The comparison, at the exposure POV-Ray rendered with.
    const Image ours_exposed = scaled(ours, exposure);
    Image theirs = theirs_full;
    if (result.failures.empty()) {
        theirs = downsample_box(theirs_full, n);
        result.comparison = compare_images(ours_exposed, theirs, options.rule.tolerance, options.worst_count);
        result.failures = failed_rules(result.comparison, options.rule, "Whitted's image", "POV-Ray's");
        if (stored_clipped)
            result.failures.push_back(fmt::format(
                "clipped (the stored POV-Ray image is 65535 where Whitted's is below 1 at exposure {:g})", exposure));
    }
    result.passed = result.failures.empty();
    throw_if_cancelled(options);

    if (!options.quiet && result.comparison.pixels > 0) print_table(scene_path, result, options);
    if (!options.report_dir.empty())
        write_report(options.report_dir, scene_path, ours_exposed, theirs, result, options);
    std::printf("%s\n", verdict_line(scene_path, result, options).c_str());
    std::fflush(stdout);
    return result;
}

namespace {

template <class F>
void for_each_material(std::vector<ObjectDescription>& objects, F&& f) {
    for_each_object(objects, [&](ObjectDescription& object) {
        if (object.material && object.material->inline_) f(*object.material->inline_);
        const auto* mesh = std::get_if<MeshShape>(&object.shape);
        if (mesh && mesh->file.given && !object.material)
            throw InputError(object.where, "check --terms: this mesh takes its materials from the MTL file of '" +
                                               mesh->file.value +
                                               "', which --terms cannot isolate; give it a 'material'");
    });
}

/// Applies f to every material of the scene, named or inline.
template <class F>
void for_each_material(SceneDescription& scene, F&& f) {
    for (MaterialDescription& material : scene.materials) f(material);
    for_each_material(scene.objects, f);
}

}  // namespace

std::vector<TermScene> term_scenes(const SceneDescription& description) {
    SceneDescription probe = description;
    bool any_ka = false, any_kd = false, any_ks = false;
    for_each_material(probe, [&](MaterialDescription& m) {
        any_ka |= !is_zero(m.ka.value);
        any_kd |= !is_zero(m.kd.value);
        any_ks |= !is_zero(m.ks.value);
    });
    const auto keep_only = [&](bool ka, bool kd, bool ks) {
        SceneDescription variant = description;
        for_each_material(variant, [&](MaterialDescription& m) {
            if (!ka) m.ka.value = Color(0.0);
            if (!kd) m.kd.value = Color(0.0);
            if (!ks) m.ks.value = Color(0.0);
            m.km.value = Color(0.0);
        });
        return variant;
    };
    std::vector<TermScene> terms;
    if (any_ka && !is_zero(description.ambient.value)) terms.push_back({"ambient", keep_only(true, false, false)});
    const bool lit = !description.lights.empty();
    if (lit && any_kd) terms.push_back({"diffuse", keep_only(false, true, false)});
    if (lit && any_ks) terms.push_back({"specular", keep_only(false, false, true)});
    if (description.lights.size() > 1 && (any_kd || any_ks))
        for (size_t k = 0; k < description.lights.size(); ++k) {
            TermScene light{"light " + std::to_string(k + 1), keep_only(false, true, true)};
            light.description.lights = {description.lights[k]};
            terms.push_back(std::move(light));
        }
    return terms;
}

std::string run_check_terms(const std::string& scene_path, const CheckRun& options, std::vector<std::string>& failed) {
    const InputFilesNoted inputs;  // for refuse_report_over_inputs
    const SceneDescription description = parse_scene_file(scene_path);
    const std::vector<TermScene> terms = term_scenes(description);
    if (terms.empty()) throw InputError({scene_path}, "check --terms: the scene has no term to isolate");
    failed.clear();
    std::vector<std::string> passed;
    for (const TermScene& term : terms) {
        CheckRun one = options;
        one.terms = false;
        if (!options.report_dir.empty()) {
            std::string folder = term.term;
            std::replace(folder.begin(), folder.end(), ' ', '_');
            one.report_dir = (fs::path(options.report_dir) / folder).string();
        }
        std::printf("term '%s':\n", term.term.c_str());
        std::fflush(stdout);
        const CheckRecord result = run_check(term.description, scene_path + " [" + term.term + " only]", one);
        (result.passed ? passed : failed).push_back(term.term);
    }
    const auto list = [](const std::vector<std::string>& names) {
        std::string text;
        for (const std::string& name : names) text += (text.empty() ? "" : ", ") + name;
        return text;
    };
    const std::string verdict = failed.empty() ? "whitted check --terms " + scene_path +
                                                     ": PASS: every term agrees with POV-Ray (" + list(passed) + ")"
                                               : "whitted check --terms " + scene_path + ": FAIL: " + list(failed) +
                                                     " disagree" + (failed.size() == 1 ? "s" : "") + " with POV-Ray" +
                                                     (passed.empty() ? "" : " (" + list(passed) + " agree)");
    std::printf("%s\n", verdict.c_str());
    std::fflush(stdout);
    return verdict;
}

}  // namespace whitted::reference
