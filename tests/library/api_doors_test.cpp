// SPDX-License-Identifier: MIT
// The doors of the public API that `whitted render`, `convert`, `compare`, `colour`, `check` and
// `explain` go through (docs/library.md), used as a caller does: only whitted/whitted.h, linked with libwhitted.so.
// Each function's result and each of its error paths.
// Usage: api_doors_test SOURCE_DIR WORK_DIR

#include "whitted/whitted.h"

#include <atomic>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <utility>
#include <vector>

namespace fs = std::filesystem;
using namespace whitted;

namespace {

int failures = 0;

#define EXPECT(condition)                                                             \
    do {                                                                              \
        if (!(condition)) {                                                           \
            std::fprintf(stderr, "FAIL %s:%d: %s\n", __FILE__, __LINE__, #condition); \
            ++failures;                                                               \
        }                                                                             \
    } while (0)

bool starts_with(const std::string& text, const std::string& prefix) {
    return text.compare(0, prefix.size(), prefix) == 0;
}

bool contains(const std::string& text, const std::string& part) {
    return text.find(part) != std::string::npos;
}

/// A small gradient, every value different, all in [0, 1].
Image gradient(int width, int height) {
    Image image;
    image.width = width;
    image.height = height;
    for (int i = 0; i < width * height * 3; ++i) image.rgb.push_back(float(i) / float(width * height * 3));
    return image;
}

std::string written(const Image& image, const fs::path& path) {
    const api::Expected<void> done = api::write_image(image, path.string());
    if (!done) std::fprintf(stderr, "write_image: %s\n", done.error().what().c_str());
    EXPECT(done.has_value());
    return path.string();
}

void compare_image_files(const fs::path& work) {
    const Image base = gradient(4, 3);
    const std::string a = written(base, work / "a.exr"), same = written(base, work / "same.exr");
    Image off = base;
    off.rgb[7] += 0.5f;  // one channel of one pixel of twelve, far beyond the cap
    const std::string b = written(off, work / "b.exr");

    const api::Expected<api::Comparison> equal = api::compare_image_files(a, same);
    EXPECT(equal && equal->passed && equal->failures.empty());
    EXPECT(equal && starts_with(equal->verdict, "PASS " + a + " vs " + same + ": 100.000% of pixels"));
    EXPECT(equal && equal->max_error_codes == 0 && equal->fraction_within == 1);
    EXPECT(equal && !equal->first_meaning.empty() && !equal->second_meaning.empty());

    const api::Expected<api::Comparison> different = api::compare_image_files(a, b);
    EXPECT(different && !different->passed);
    EXPECT(different && different->failures.size() == 2);  // share (11 of 12 pixels) and cap
    EXPECT(different && starts_with(different->verdict, "FAIL "));
    EXPECT(different && contains(different->verdict, "cap"));
    EXPECT(different && different->max_error_codes > 0.49 * 65535 && different->max_error_codes < 0.51 * 65535);

    // The rule is the caller's: a share of 11/12 and no cap to speak of let the same pixel pass.
    api::PassRule lenient;
    lenient.min_fraction = 0.9;
    lenient.max_error_codes = 65535;
    const api::Expected<api::Comparison> allowed = api::compare_image_files(a, b, lenient);
    EXPECT(allowed && allowed->passed && allowed->fraction_within < 1);

    // clip: a value of 2 is 1 once clipped, as a PNG would hold it.
    Image bright = base, unit = base;
    bright.rgb[0] = 2.0f;
    unit.rgb[0] = 1.0f;
    const std::string bright_file = written(bright, work / "bright.exr"), unit_file = written(unit, work / "unit.exr");
    const auto unclipped = api::compare_image_files(bright_file, unit_file);
    const auto clipped = api::compare_image_files(bright_file, unit_file, {}, true);
    EXPECT(unclipped && !unclipped->passed);
    EXPECT(clipped && clipped->passed);

    // Images that cannot be compared at all: a result, with no meanings read.
    const std::string wide = written(gradient(5, 3), work / "wide.exr");
    const api::Expected<api::Comparison> sizes = api::compare_image_files(a, wide);
    EXPECT(sizes && !sizes->passed && sizes->failures.size() == 1);
    EXPECT(sizes && starts_with(sizes->failures.front(), "size (4x3 vs 5x3)"));
    EXPECT(sizes && sizes->first_meaning.empty() && sizes->second_meaning.empty());

    // Files that are not images: the caller's input.
    const api::Expected<api::Comparison> missing = api::compare_image_files(a, (work / "missing.exr").string());
    EXPECT(!missing && missing.error().kind == api::Error::Kind::bad_input);
    EXPECT(!missing && contains(missing.error().what(), "missing.exr"));
    std::ofstream(work / "text.png") << "not a PNG\n";
    const api::Expected<api::Comparison> text = api::compare_image_files((work / "text.png").string(), a);
    EXPECT(!text && text.error().kind == api::Error::Kind::bad_input);
    EXPECT(!text && contains(text.error().what(), "text.png"));
}

void colour_config(const fs::path& work) {
    const api::Expected<std::string> builtin = api::describe_colour_config();
    EXPECT(builtin && contains(*builtin, "sRGB"));

    const fs::path config = work / "builtin.ocio";
    const api::Expected<void> wrote = api::write_colour_config(config.string());
    EXPECT(wrote.has_value());
    std::ifstream in(config);
    const std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
    EXPECT(starts_with(text, "ocio_profile_version"));
    // The file written is a config OpenColorIO reads, with the same displays as the built-in one.
    const api::Expected<std::string> reread = api::describe_colour_config(config.string());
    EXPECT(reread && contains(*reread, "sRGB"));

    const api::Expected<std::string> no_config = api::describe_colour_config((work / "none.ocio").string());
    EXPECT(!no_config && contains(no_config.error().what(), "none.ocio"));

    const api::Expected<void> no_folder = api::write_colour_config((work / "no" / "such" / "c.ocio").string());
    EXPECT(!no_folder && contains(no_folder.error().what(), "c.ocio"));
    // A symbolic link is not written through: its target keeps what it held.
    std::ofstream(work / "target.txt") << "kept\n";
    fs::remove(work / "link.ocio");
    fs::create_symlink(work / "target.txt", work / "link.ocio");
    const api::Expected<void> through_link = api::write_colour_config((work / "link.ocio").string());
    EXPECT(!through_link && through_link.error().kind == api::Error::Kind::bad_input);
    std::ifstream target(work / "target.txt");
    std::string kept;
    std::getline(target, kept);
    EXPECT(kept == "kept");
}

void check(const fs::path& source, const fs::path& work) {
    const std::string scene = (source / "tests/pov/three_coloured_lights.yaml").string();
    api::CheckOptions options;
    options.threads = 2;
    // POV-Ray's own render of the converted scene, stored (tests/image/README.md): no POV-Ray run.
    options.povray_image = (source / "tests/image/ref/three_coloured_lights.png").string();
    options.exposure = 1;
    const api::Expected<api::CheckResult> passed = api::check(scene, options);
    EXPECT(passed && passed->passed && passed->failures.empty() && passed->fraction_within >= 0.999);
    EXPECT(passed && starts_with(passed->verdict, "PASS " + scene + ": "));

    // Whitted's image with its colour layers: the beauty and their sum are compared.
    api::CheckOptions layered = options;
    layered.layers = {"diffuse", "specular", "ambient", "mirror", "transmission", "background"};
    const api::Expected<api::CheckResult> with_layers = api::check(scene, layered);
    EXPECT(with_layers && with_layers->passed);

    // A stored image at the wrong exposure: a failed check is a result, not an error.
    api::CheckOptions darker = options;
    darker.exposure = 0.5;
    const api::Expected<api::CheckResult> failed = api::check(scene, darker);
    EXPECT(failed && !failed->passed && !failed->failures.empty() && starts_with(failed->verdict, "FAIL "));

    const api::Expected<api::CheckResult> missing = api::check((work / "missing.yaml").string(), options);
    EXPECT(!missing && missing.error().kind == api::Error::Kind::bad_input);
    EXPECT(!missing && contains(missing.error().what(), "missing.yaml"));

    api::CheckOptions unknown_layer = options;
    unknown_layer.layers = {"difuse"};
    const api::Expected<api::CheckResult> bad_layer = api::check(scene, unknown_layer);
    EXPECT(!bad_layer && bad_layer.error().kind == api::Error::Kind::bad_input);
    EXPECT(!bad_layer && contains(bad_layer.error().what(), "difuse"));

    // Cancelled: an Error of kind cancelled, after it said it was about to create files.
    std::atomic<bool> cancel{true}, nothing_created_yet{true};
    api::CheckOptions cancelled = options;
    cancelled.cancel = &cancel;
    cancelled.nothing_created_yet = &nothing_created_yet;
    const api::Expected<api::CheckResult> stopped = api::check(scene, cancelled);
    EXPECT(!stopped && stopped.error().kind == api::Error::Kind::cancelled);
    EXPECT(!nothing_created_yet.load());
}

void explain(const fs::path& source) {
    const std::string path = (source / "tests/pov/three_coloured_lights.yaml").string();
    const api::Expected<api::Scene> scene = api::load_scene_file(path);
    EXPECT(scene.has_value());
    if (!scene) return;
    api::ExplainOptions options;
    options.threads = 2;
    const api::Expected<std::string> json = api::explain(*scene, 48, 36, options);
    EXPECT(json && starts_with(*json, "{") && json->size() > 2 && json->substr(json->size() - 2) == "}\n");
    EXPECT(json && contains(*json, "\"scene\": \"three_coloured_lights.yaml\"") && contains(*json, "\"samples\""));
    options.format = api::ExplainFormat::text;
    const api::Expected<std::string> text = api::explain(*scene, 48, 36, options);
    EXPECT(text && starts_with(*text, "pixel (48, 36) of " + path + ": 96x72"));
    EXPECT(text && contains(*text, "\npixel = sum(L) / 1 = "));
    options.format = api::ExplainFormat::summary;
    const api::Expected<std::string> summary = api::explain(*scene, 48, 36, options);
    EXPECT(summary && contains(*summary, "  first hit (sample 0): "));
    EXPECT(summary && summary->size() < text->size());

    for (const auto& [x, y] : {std::pair{96, 0}, std::pair{0, 72}, std::pair{-1, 0}, std::pair{0, -1}}) {
        const api::Expected<std::string> outside = api::explain(*scene, x, y);
        EXPECT(!outside && outside.error().kind == api::Error::Kind::bad_input);
        EXPECT(!outside && contains(outside.error().what(), "is outside the 96x72 image (X 0..95, Y 0..71)"));
    }
}

std::string read_file(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void write_file(const fs::path& path, const std::string& text) {
    std::ofstream(path, std::ios::binary) << text;
}

/// `whitted convert`: the scene as it was loaded, not as its file says later; the usage checks
/// before any work; an output that is one of the scene's own files refused.
void convert(const fs::path& work) {
    const std::string scene_text =
        "version: 1\nimage: {width: 8, height: 6}\ncamera: {eye: [0, 0, 5], look_at: [0, 0, 0], fov: 40}\n"
        "lights:\n  - {type: point, position: [2, 3, 4], intensity: [1, 1, 1]}\n"
        "objects:\n  - {type: sphere, center: [0, 0, 0], radius: 1.25, material: {kd: [0.5, 0.25, 0.125]}}\n";
    const fs::path path = work / "loaded.yaml";
    write_file(path, scene_text);
    const api::Expected<api::Scene> scene = api::load_scene_file(path.string());
    EXPECT(scene.has_value());
    if (!scene) return;
    // The file changes after loading: the conversion is still of the scene loaded (radius 1.25).
    std::string changed = scene_text;
    changed.replace(changed.find("radius: 1.25"), 12, "radius: 2.75");
    write_file(path, changed);
    const api::Expected<std::vector<std::string>> yaml = api::convert(*scene, (work / "out.yaml").string());
    EXPECT(yaml && yaml->size() == 1 && yaml->front() == (work / "out.yaml").string());
    const std::string yaml_text = read_file(work / "out.yaml");
    EXPECT(contains(yaml_text, "1.25") && !contains(yaml_text, "2.75"));
    const api::Expected<std::vector<std::string>> pov = api::convert(*scene, (work / "out.pov").string());
    EXPECT(pov && pov->size() == 2 && pov->back() == (work / "out.ini").string());
    const std::string sdl = read_file(work / "out.pov");
    EXPECT(contains(sdl, "1.25") && !contains(sdl, "2.75"));
    EXPECT(fs::exists(work / "out.ini"));
    const api::Expected<std::string> to_povray = api::to_povray(*scene);
    EXPECT(to_povray && *to_povray == sdl);

    // Refused: the scene file itself (under another name too), an unknown format, a .pov whose
    // .ini is the scene; all bad input, nothing written.
    const fs::path link = work / "link.yaml";
    fs::create_symlink(path, link);
    for (const fs::path& output : {path, link}) {
        const api::Expected<std::vector<std::string>> over = api::convert(*scene, output.string());
        EXPECT(!over && over.error().kind == api::Error::Kind::bad_input && contains(over.error().what(), "an input"));
    }
    EXPECT(read_file(path) == changed);
    const api::Expected<void> unknown = api::check_convert_output((work / "out.obj").string(), path.string());
    EXPECT(!unknown && unknown.error().kind == api::Error::Kind::bad_input &&
           contains(unknown.error().what(), "unknown format '.obj'"));
    const api::Expected<void> ini_over = api::check_convert_output((work / "loaded.pov").string(), path.string());
    EXPECT(ini_over.has_value());  // loaded.ini is not the scene
    const api::Expected<void> over_input = api::check_convert_output(path.string(), path.string());
    EXPECT(!over_input && contains(over_input.error().what(), "it is the input"));
    EXPECT(api::check_convert_output((work / "fine.yaml").string(), path.string()).has_value());
    EXPECT(!api::check_convert_output(link.string()).has_value());  // a symbolic link is not written through

    // A scene loaded for rendering only keeps no description to convert.
    const api::Expected<api::Scene> render_only = api::load_scene_file(path.string(), {}, api::SceneUse::render_only);
    const api::Expected<std::vector<std::string>> none = api::convert(*render_only, (work / "none.yaml").string());
    EXPECT(!none && !fs::exists(work / "none.yaml"));
}

/// `whitted render`'s checks before any work, and the scene's own files.
void render_checks(const fs::path& source, const fs::path& work) {
    const std::string scene_path = (source / "tests/pov/three_coloured_lights.yaml").string();
    EXPECT(api::check_image_output((work / "a.png").string(), {}).has_value());
    EXPECT(api::check_image_output((work / "a.exr").string(), {}, {"diffuse", "N"}, "--layers").has_value());
    const api::Expected<void> png_layers =
        api::check_image_output((work / "a.png").string(), {}, {"diffuse"}, "--layers");
    EXPECT(!png_layers && png_layers.error().kind == api::Error::Kind::bad_input &&
           contains(png_layers.error().what(), "render layers (--layers)"));
    EXPECT(api::check_image_output((work / "a.png").string(), {}, {"none"}, "--layers").has_value());
    const api::Expected<void> unknown_layer = api::check_image_output((work / "a.exr").string(), {}, {"difuse"});
    EXPECT(!unknown_layer && contains(unknown_layer.error().what(), "did you mean 'diffuse'"));
    api::WriteOptions half;
    half.half = true;
    EXPECT(!api::check_image_output((work / "a.png").string(), half).has_value());
    EXPECT(!api::check_image_output((work / "a.yaml").string(), {}).has_value());
    const fs::path copy = work / "scene.png";
    fs::copy_file(scene_path, copy);
    const api::Expected<void> over = api::check_image_output(copy.string(), {}, {}, {}, copy.string());
    EXPECT(!over && contains(over.error().what(), "it is the scene file"));

    const api::Expected<api::Scene> scene = api::load_scene_file(scene_path, {}, api::SceneUse::render_only);
    EXPECT(scene && contains(scene->input_file_at(scene_path), "three_coloured_lights.yaml"));
    EXPECT(scene && scene->input_file_at((work / "a.png").string()).empty());
    EXPECT(!api::layer_choices().empty() && contains(api::layer_choices(), "diffuse"));
    EXPECT(starts_with(api::printable("a\x1b"), "a\\x") && api::printable("a\x1b").find('\x1b') == std::string::npos);
    EXPECT(api::exit_status(api::Error{}) == api::exit_bad_input);
}

}  // namespace

int main(int argc, char** argv) {
    if (argc != 3) {
        std::fprintf(stderr, "usage: api_doors_test SOURCE_DIR WORK_DIR\n");
        return 2;
    }
    const fs::path source = argv[1], work = argv[2];
    fs::remove_all(work);
    fs::create_directories(work);
    compare_image_files(work);
    colour_config(work);
    check(source, work);
    explain(source);
    convert(work);
    render_checks(source, work);
    if (failures) return 1;
    std::printf(
        "PASS: compare_image_files, describe_colour_config, write_colour_config, check, explain, convert, render "
        "checks\n");
    return 0;
}
