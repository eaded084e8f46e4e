// SPDX-License-Identifier: MIT
// The report of `whitted check --report DIR`: the two images, a difference heat map, the
// figures as JSON and one HTML page to explore them (docs/validation.md, "The report"). The page
// needs nothing but the files next to it (no server, no network, no web fonts), so a CI
// artefact opens from file:// anywhere. From file:// a browser lets a page neither fetch its
// sibling files nor read back the pixels of an <img> it drew, so the values its pixel probe
// shows come from report-data.js, loaded by a <script> tag: the compared float values
// themselves, not the PNGs.

#include "reference/check.h"

#include "output/atomic_files.h"
#include "output/image_output.h"

#include "report_viewer_js.h"

#include <OpenImageIO/imageio.h>
#include <fmt/format.h>
#include <zlib.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <limits>
#include <stdexcept>

namespace whitted::reference {
namespace {

namespace fs = std::filesystem;

std::string html_escape(const std::string& text) {
    std::string out;
    for (const char c : text) {
        switch (c) {
            case '&':
                out += "&amp;";
                break;
            case '<':
                out += "&lt;";
                break;
            case '>':
                out += "&gt;";
                break;
            case '"':
                out += "&quot;";
                break;
            case '\'':
                out += "&#39;";
                break;
            default:
                out += c;
        }
    }
    return out;
}

/// Quotes a word for a POSIX shell, so the reproduce commands can be pasted as they are.
std::string shell_quote(const std::string& word) {
    if (!word.empty() &&
        word.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_-./+=:,@") ==
            std::string::npos)
        return word;
    std::string out = "'";
    for (const char c : word) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return out + "'";
}

/// Heat-map colour of one pixel's largest channel difference. Full scale is twice the
/// tolerance, so the tolerance sits at mid-scale: within it black → blue, beyond it a jump to
/// yellow → red (saturating at 2× the tolerance). A failing pixel can never look like a passing one.
void heat_colour(double difference, double tolerance, unsigned char* rgb) {
    const double t = tolerance > 0 ? tolerance : 1.0 / 65535.0;
    double r, g, b;
    if (!(difference > t) && !std::isnan(difference)) {
        const double u = difference / t;
        r = 0.25 * u, g = 0.55 * u, b = 1.0 * u;
    } else {
        const double u = std::isnan(difference) ? 1.0 : std::min((difference - t) / t, 1.0);
        r = 1.0, g = 0.85 * (1 - u), b = 0.0;
    }
    rgb[0] = static_cast<unsigned char>(std::lround(r * 255));
    rgb[1] = static_cast<unsigned char>(std::lround(g * 255));
    rgb[2] = static_cast<unsigned char>(std::lround(b * 255));
}

/// Writes display-ready 8-bit pixels unchanged: the heat map's colours are already what should
/// be seen, so no display transform may touch them.
/// Written to a temporary beside `path` and moved into place: never through a symlink planted
/// at `path`, and never half-written.
void write_raw_png(const std::vector<unsigned char>& pixels, int width, int height, const fs::path& path) {
    auto out = OIIO::ImageOutput::create(path.string());
    if (!out) throw std::runtime_error("cannot write '" + path.string() + "': " + OIIO::geterror());
    OIIO::ImageSpec spec(width, height, 3, OIIO::TypeDesc::UINT8);
    spec.attribute("Software", "Whitted (whitted check)");
    const std::string temporary = temporary_path(path);
    if (!out->open(temporary, spec) || !out->write_image(OIIO::TypeDesc::UINT8, pixels.data()) || !out->close()) {
        std::remove(temporary.c_str());
        throw std::runtime_error("cannot write '" + path.string() + "': " + out->geterror());
    }
    try {
        move_into_place(temporary, path);
    } catch (...) {
        std::remove(temporary.c_str());
        throw;
    }
}

Image absolute_difference(const Image& a, const Image& b) {
    Image d = a;
    for (size_t i = 0; i < d.rgb.size(); ++i) d.rgb[i] = std::abs(a.rgb[i] - b.rgb[i]);
    return d;
}

Image divided(const Image& image, double exposure) {
    Image out = image;
    for (float& v : out.rgb) v = float(double(v) / exposure);  // a power of two: exact
    return out;
}

nlohmann::json rgb_json(const float* v) {
    return nlohmann::json::array({double(v[0]), double(v[1]), double(v[2])});
}

/// Standard base64 (RFC 4648, with padding), what the page's atob() reads.
std::string base64(const std::vector<unsigned char>& bytes) {
    static const char alphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    out.reserve((bytes.size() + 2) / 3 * 4);
    for (size_t i = 0; i < bytes.size(); i += 3) {
        const uint32_t n = uint32_t(bytes[i]) << 16 | (i + 1 < bytes.size() ? uint32_t(bytes[i + 1]) << 8 : 0) |
                           (i + 2 < bytes.size() ? uint32_t(bytes[i + 2]) : 0);
        out += alphabet[(n >> 18) & 63];
        out += alphabet[(n >> 12) & 63];
        out += i + 1 < bytes.size() ? alphabet[(n >> 6) & 63] : '=';
        out += i + 2 < bytes.size() ? alphabet[n & 63] : '=';
    }
    return out;
}

/// The image's words (the bits of its floats, or its 16-bit codes), channel by channel, each
/// replaced by its difference from the gradient prediction left + up − upper-left (modulo the
/// word size; the first row predicts from the left, the first column from above), folded to an
/// unsigned number (zig-zag: 0, −1, 1, −2, ... → 0, 1, 2, 3, ...), its bytes regrouped into planes
/// (every word's lowest byte first, then every second byte, ...), deflated in zlib format (what
/// the browser's DecompressionStream("deflate") reads), base64-encoded. Rendered images are
/// smooth almost everywhere, so the differences are small numbers whose high bytes are zero:
/// the planes deflate to a fraction of the raw floats (report_viewer.js, decode_words, undoes it).
template <typename Word>
std::string encode_words(const std::vector<Word>& words, int width, int height) {
    constexpr int channels = 3;
    constexpr size_t bytes = sizeof(Word);
    const size_t n = words.size();
    if (n != size_t(width) * size_t(height) * channels) throw std::logic_error("encode_words: wrong pixel count");
    std::vector<unsigned char> planes(bytes * n);
    size_t i = 0;
    for (int c = 0; c < channels; ++c)
        for (int y = 0; y < height; ++y)
            for (int x = 0; x < width; ++x, ++i) {
                const auto at = [&](int px, int py) {
                    return words[(size_t(py) * size_t(width) + size_t(px)) * channels + size_t(c)];
                };
                const Word predicted = x > 0 && y > 0 ? Word(at(x - 1, y) + at(x, y - 1) - at(x - 1, y - 1))
                                       : x > 0        ? at(x - 1, y)
                                       : y > 0        ? at(x, y - 1)
                                                      : Word(0);
                const Word r = Word(at(x, y) - predicted);
                const Word folded = Word(Word(r << 1) ^ Word(0u - (r >> (8 * bytes - 1))));
                for (size_t k = 0; k < bytes; ++k) planes[k * n + i] = static_cast<unsigned char>(folded >> (8 * k));
            }
    uLongf size = compressBound(uLong(planes.size()));
    std::vector<unsigned char> deflated(size);
    if (compress2(deflated.data(), &size, planes.data(), uLong(planes.size()), 9) != Z_OK)
        throw std::runtime_error("cannot compress the report's pixel data");
    deflated.resize(size);
    return base64(deflated);
}

/// 1/65535 in binary32: OpenImageIO reads a 16-bit code c as float(c) × this.
constexpr float code_step = 1.0f / 65535.0f;

/// One image of report-data.js: its values exactly, as 16-bit codes when every value is one
/// (POV-Ray's PNG read as float, unless image.samples averaged it: a quarter of the bytes),
/// otherwise as the bits of the floats.
nlohmann::json encoded_image(const std::vector<float>& values, int width, int height) {
    std::vector<uint16_t> codes(values.size());
    bool all_codes = true;
    for (size_t i = 0; i < values.size() && all_codes; ++i) {
        const float v = values[i];
        if (!(v >= 0 && v <= 1)) {
            all_codes = false;
            break;
        }
        codes[i] = static_cast<uint16_t>(std::lround(double(v) * 65535));
        all_codes = std::bit_cast<uint32_t>(float(codes[i]) * code_step) == std::bit_cast<uint32_t>(v);
    }
    if (all_codes)
        return {
            {"encoding", "codes16"}, {"code_step", double(code_step)}, {"data", encode_words(codes, width, height)}};
    std::vector<uint32_t> bits(values.size());
    for (size_t i = 0; i < values.size(); ++i) bits[i] = std::bit_cast<uint32_t>(values[i]);
    return {{"encoding", "float32"}, {"data", encode_words(bits, width, height)}};
}

/// report-data.js: what the page's viewer shows and probes, as one JavaScript assignment. The
/// images are those compared (at the compared exposure); the colour render layers (when the
/// check rendered with --layers) are multiplied by the same exposure, so that they add up to
/// Whitted's compared image as the EXR's layers add up to its R, G, B.
std::string report_data_js(const std::string& scene_path, const Image& ours, const Image& theirs, const CheckRecord& r,
                           const CheckRun& options) {
    const ImageComparison& c = r.comparison;
    nlohmann::json j;
    j["format"] = 2;
    j["scene"] = scene_path;
    j["passed"] = r.passed;
    j["verdict"] = verdict_line(scene_path, r, options);
    j["width"] = c.width;
    j["height"] = c.height;
    j["exposure"] = r.exposure;
    j["tolerance_codes"] = options.rule.tolerance * 65535;
    j["encoding"] =
        "per channel, gradient-predicted words (float32 bits or 16-bit codes x code_step), zig-zag, byte planes, "
        "zlib deflate, base64 (report_viewer.js, decode_image); values as compared (x 65535 = 16-bit codes)";
    j["whitted"] = encoded_image(ours.rgb, c.width, c.height);
    j["povray"] = encoded_image(theirs.rgb, c.width, c.height);
    nlohmann::json layers = nlohmann::json::array();
    for (const ImageLayer& layer : ours.layers) {
        if (layer.data || layer.channels.size() != 3) continue;  // normals, depth, ids: not terms of L
        std::vector<float> exposed = layer.values;
        if (r.exposure != 1)
            for (float& v : exposed) v = float(double(v) * r.exposure);  // a power of two: exact
        layers.push_back({{"name", layer.name}, {"values", encoded_image(exposed, c.width, c.height)}});
    }
    j["layers"] = layers;
    nlohmann::json worst = nlohmann::json::array();
    for (const PixelError& w : c.worst) worst.push_back({{"x", w.x}, {"y", w.y}, {"error_codes", w.error * 65535}});
    j["worst_pixels"] = worst;
    return "// Written by whitted check: the data report.html shows (docs/validation.md, \"The report\").\n"
           "window.WHITTED_REPORT = " +
           j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace) + ";\n";
}

nlohmann::json metrics_json(const std::string& scene_path, const CheckRecord& r, const CheckRun& options) {
    const ImageComparison& c = r.comparison;
    nlohmann::json j;
    j["scene"] = fs::absolute(scene_path).string();
    j["passed"] = r.passed;
    j["width"] = c.width;
    j["height"] = c.height;
    j["samples"] = r.samples;
    j["exposure"] = r.exposure;
    j["failures"] = r.failures;
    nlohmann::json rules = nlohmann::json::array();
    for (const std::string& failure : r.failures) rules.push_back(failure.substr(0, failure.find(' ')));
    j["failed_rules"] = rules;
    j["tolerance"] = options.rule.tolerance;
    j["tolerance_codes"] = options.rule.tolerance * 65535;
    j["required_fraction"] = options.rule.required_fraction;
    j["max_error_cap"] = options.rule.max_error;
    j["max_error_cap_codes"] = options.rule.max_error * 65535;
    j["compared"] = c.pixels > 0;
    // An infinite error (NaN/Inf values) is written as null: JSON has no infinity.
    j["max_error"] = c.max_error;
    j["max_error_codes"] = c.max_error * 65535;
    j["mean_error"] = c.mean_error;
    j["rms_error"] = c.rms_error;
    // JSON has no infinity: identical images give null and "identical": true.
    j["psnr_db"] = std::isinf(c.psnr) ? nlohmann::json(nullptr) : nlohmann::json(c.psnr);
    j["identical"] = c.max_error == 0;
    j["pixels"] = c.pixels;
    j["pixels_within"] = c.pixels_within;
    j["fraction_within"] = c.fraction_within();
    j["nonfinite_whitted"] = c.nonfinite_ours;
    j["nonfinite_povray"] = c.nonfinite_theirs;
    nlohmann::json worst = nlohmann::json::array();
    for (const PixelError& w : c.worst)
        worst.push_back({{"x", w.x},
                         {"y", w.y},
                         {"error", w.error},
                         {"error_codes", w.error * 65535},
                         {"whitted", rgb_json(w.ours)},
                         {"povray", rgb_json(w.theirs)}});
    j["worst_pixels"] = worst;  // largest error first, at most CheckRun::worst_count
    j["whitted_seconds"] = r.whitted_seconds;
    // The intersection rules Whitted rendered with (docs/scene-format.md, render.intersection).
    j["whitted_intersection"] = "povray";
    j["povray_seconds"] = r.povray_seconds;
    j["povray_runs"] = r.povray_runs;
    j["povray_program"] = r.povray_program;
    j["files"] = {{"pov", r.pov_file},          {"ini", r.ini_file},          {"povray_output", r.povray_image},
                  {"whitted_exr", "ours.exr"},  {"povray_exr", "povray.exr"}, {"whitted_png", "ours.png"},
                  {"povray_png", "povray.png"}, {"heat_map_png", "diff.png"}, {"report_data_js", "report-data.js"}};
    return j;
}

std::string code_cells(const float* v) {
    return fmt::format("<td>{:.1f}</td><td>{:.1f}</td><td>{:.1f}</td>", double(v[0]) * 65535.0, double(v[1]) * 65535.0,
                       double(v[2]) * 65535.0);
}

/// One image of the side-by-side row, drawn with visible pixels and a box on each of the worst
/// pixels (the worst one solid, the others dashed). The figure is at most `scale` × the image's
/// size and shrinks so that the three fit side by side; the boxes are placed in percent of the
/// image so that they stay on their pixels at any size.
std::string figure(const std::string& file, const std::string& caption, const ImageComparison& c, int scale) {
    std::string boxes;
    for (size_t i = 0; i < c.worst.size(); ++i)
        boxes += fmt::format(
            "<div class=\"worst{}\" style=\"left:{:.4f}%;top:{:.4f}%;width:{:.4f}%;height:{:.4f}%\" title=\"#{} ({}, "
            "{})\"></div>",
            i == 0 ? "" : " other", 100.0 * c.worst[i].x / c.width, 100.0 * c.worst[i].y / c.height, 100.0 / c.width,
            100.0 / c.height, i + 1, c.worst[i].x, c.worst[i].y);
    return fmt::format(
        "<figure style=\"max-width:{w}px\"><div class=\"frame\">"
        "<a href=\"{f}\"><img src=\"{f}\" width=\"{w}\" height=\"{h}\" alt=\"{cap}\"></a>{b}"
        "</div><figcaption>{cap}</figcaption></figure>\n",
        fmt::arg("w", c.width * scale), fmt::arg("h", c.height * scale), fmt::arg("f", file), fmt::arg("cap", caption),
        fmt::arg("b", boxes));
}

/// The interactive viewer: one canvas showing two of Whitted / POV-Ray / difference split by a
/// wipe, zoomed by whole factors; a pixel probe; the difference's threshold. Filled in by
/// report_viewer.js from report-data.js; the verdict, the figures and the images above it are
/// plain HTML, so the page says what it has to say before any script runs or without scripts.
std::string explore_section(const ImageComparison& c, double tolerance_codes) {
    const auto source_options = [](const char* selected) {
        std::string o;
        for (const auto& [value, label] :
             {std::pair{"whitted", "Whitted"}, {"povray", "POV-Ray"}, {"diff", "difference"}})
            o += fmt::format("<option value=\"{}\"{}>{}</option>", value,
                             std::string(value) == selected ? " selected" : "", label);
        return o;
    };
    std::string h = "<h2>Explore</h2>\n<div id=\"viewer\" hidden>\n<div class=\"controls\">\n";
    h += "<label>left <select id=\"left\">" + source_options("whitted") + "</select></label>\n";
    h += fmt::format(
        "<label>wipe <input id=\"wipe\" type=\"range\" min=\"0\" max=\"{0}\" step=\"1\" value=\"{1}\"> "
        "<output id=\"wipe-value\">{1}</output></label>\n",
        c.width, c.width / 2);
    h += "<label>right <select id=\"right\">" + source_options("povray") + "</select></label>\n";
    h += "<span class=\"zoom\">zoom <button id=\"zoom-out\" type=\"button\" title=\"zoom out (-)\">&minus;</button>"
         "<output id=\"zoom-value\">1&times;</output><button id=\"zoom-in\" type=\"button\" title=\"zoom in "
         "(+)\">+</button><button id=\"zoom-fit\" type=\"button\" title=\"fit (0)\">fit</button></span>\n";
    h += fmt::format(
        "<label>threshold <input id=\"threshold\" type=\"range\" min=\"0\" max=\"{0:g}\" step=\"any\" "
        "value=\"{1:g}\"> <input id=\"threshold-value\" type=\"number\" min=\"0\" step=\"any\" value=\"{1:g}\"> "
        "codes</label> <span id=\"above\"></span>\n",
        std::max(8 * tolerance_codes, 16.0), tolerance_codes);
    h += "</div>\n<div class=\"stage\"><canvas id=\"view\" tabindex=\"0\" width=\"640\" height=\"480\" "
         "aria-label=\"image viewer: drag to pan, wheel to zoom, click to probe a pixel\"></canvas>\n"
         "<div id=\"probe\"><h3>Pixel probe</h3>\n"
         "<p><label>x <input id=\"probe-x\" type=\"number\" min=\"0\" step=\"1\"></label> "
         "<label>y <input id=\"probe-y\" type=\"number\" min=\"0\" step=\"1\"></label></p>\n"
         "<div id=\"probe-values\"></div></div></div>\n";
    h += "<p class=\"help\">Drag to pan, mouse wheel or <kbd>+</kbd>/<kbd>-</kbd> to zoom (whole factors, so every "
         "pixel is a square of equal size), <kbd>0</kbd> to fit; click a pixel to probe it, or move the probe with "
         "the arrow keys (with <kbd>Shift</kbd>: pan); <kbd>[</kbd>/<kbd>]</kbd> move the wipe, <kbd>1</kbd> "
         "Whitted | POV-Ray, <kbd>2</kbd> Whitted | difference, <kbd>3</kbd> POV-Ray | difference. Values are those "
         "compared, in 16-bit codes (× 65535), linear, at the compared exposure; the images are shown with the "
         "sRGB curve, as ours.png and povray.png. The difference colours pixels by their largest channel "
         "difference against the threshold as the heat map below does against the tolerance.</p>\n</div>\n";
    h += "<p id=\"viewer-missing\">The interactive viewer (wipe, zoom, pixel probe) appears here when JavaScript runs; "
         "it reads <code>report-data.js</code> next to this page. The verdict, the figures and the images above need "
         "neither.</p>\n";
    return h;
}

std::string report_html(const std::string& dir, const std::string& scene_path, const CheckRecord& r,
                        const CheckRun& options) {
    const ImageComparison& c = r.comparison;
    const std::string verdict = verdict_line(scene_path, r, options);
    const double tolerance_codes = options.rule.tolerance * 65535;
    // Small test images are enlarged by a whole factor so single pixels can be seen.
    const int scale = std::clamp(320 / std::max({c.width, c.height, 1}), 1, 16);
    const std::string scene_abs = fs::absolute(scene_path).string();
    const std::string dir_abs = fs::absolute(dir).string();
    const std::string exposure_note =
        r.exposure == 1 ? std::string("1 (all values of the scene are at most 1)")
                        : fmt::format(
                              "{:g} = 2<sup>{:g}</sup>: the scene has values above 1, so POV-Ray rendered it "
                              "with every light, the ambient light and the background multiplied by this, and "
                              "Whitted's image was multiplied by the same (exact: a power of two)",
                              r.exposure, std::log2(r.exposure));

    std::string h;
    h += "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n";
    h += "<title>" + html_escape((r.passed ? "PASS " : "FAIL ") + fs::path(scene_path).filename().string()) +
         " - whitted check</title>\n";
    h += R"(<style>
body { font: 14px/1.45 system-ui, sans-serif; margin: 1.5em; color: #222; max-width: 1400px; }
h1 { font-size: 1.3em; } h2 { font-size: 1.1em; margin-top: 1.6em; }
.verdict { display: inline-block; padding: .2em .6em; border-radius: 4px; color: #fff; font-weight: bold; }
.pass { background: #1a7f37; } .fail { background: #cf222e; }
.row { display: flex; gap: 1.2em; align-items: flex-start; }
figure { margin: 0; } .row figure { flex: 1 1 0; min-width: 0; }
figcaption { font-size: .9em; color: #444; margin-top: .3em; max-width: 420px; }
.frame { position: relative; background: #888; }
.frame img { display: block; width: 100%; height: auto; image-rendering: pixelated; image-rendering: crisp-edges; }
.worst { position: absolute; border: 2px solid #ff00ff; box-sizing: content-box; margin: -2px; pointer-events: none; }
.worst.other { border-style: dashed; border-color: #ff00ffa0; }
table { border-collapse: collapse; margin-top: .4em; }
td, th { border: 1px solid #ccc; padding: .2em .6em; text-align: right; font-variant-numeric: tabular-nums; }
th { background: #f3f3f3; text-align: left; }
.legend { width: 320px; height: 14px; border: 1px solid #999;
          background: linear-gradient(to right, #000 0%, #408cff 50%, #ffd900 50%, #ff0000 100%); }
.legend-labels { display: flex; justify-content: space-between; width: 322px; font-size: .8em; }
pre { background: #f6f8fa; padding: .6em; overflow-x: auto; }
code { font-size: .95em; }
.controls { display: flex; flex-wrap: wrap; gap: .4em 1.2em; align-items: center; margin-bottom: .5em; }
.controls input[type=number] { width: 5em; }
.stage { display: flex; flex-wrap: wrap; gap: 1.2em; align-items: flex-start; }
#view { image-rendering: pixelated; background: #777; cursor: crosshair; outline: 1px solid #999; }
#probe { flex: 1 1 380px; min-width: 0; max-width: 520px; } #probe h3 { font-size: 1em; margin: 0 0 .3em; }
#probe input { width: 5em; } #probe td.within { color: #1a7f37; } #probe td.beyond { color: #cf222e; font-weight: bold; }
.help { font-size: .9em; color: #444; max-width: 1100px; }
kbd { border: 1px solid #bbb; border-radius: 3px; padding: 0 .25em; font-size: .9em; background: #f6f6f6; }
</style>
</head>
<body>
)";
    h += "<h1>whitted check: " + html_escape(scene_path) + "</h1>\n";
    h += "<p><span id=\"verdict\" class=\"verdict " + std::string(r.passed ? "pass" : "fail") + "\">" +
         (r.passed ? "PASS" : "FAIL") + "</span> <code>" + html_escape(verdict) + "</code></p>\n";

    if (!r.failures.empty()) {
        h += "<p>Rules broken:</p>\n<ul>\n";
        for (const std::string& failure : r.failures) h += "<li><code>" + html_escape(failure) + "</code></li>\n";
        h += "</ul>\n";
    }
    if (c.pixels == 0) {
        // Nothing to show side by side: the images could not be compared (their sizes differ).
        h += "<p>The images were not compared. <a href=\"ours.exr\">ours.exr</a> and <a "
             "href=\"povray.exr\">povray.exr</a> hold them as they are.</p>\n</body>\n</html>\n";
        return h;
    }
    h += "<h2>Figures</h2>\n<table>\n";
    auto row = [&](const std::string& name, const std::string& value) {
        h += "<tr><th>" + name + "</th><td>" + value + "</td></tr>\n";
    };
    // data-metric: the numbers a test reads without scripts and compares with metrics.json.
    const auto metric = [](const char* key, const std::string& text) {
        return fmt::format("<span data-metric=\"{}\">{}</span>", key, text);
    };
    row(fmt::format("pixels within {:g}/65535", tolerance_codes),
        fmt::format("{} ({} of {}; {:g}% required)", metric("fraction_within", format_percent(c)),
                    metric("pixels_within", std::to_string(c.pixels_within)),
                    metric("pixels", std::to_string(c.pixels)), 100 * options.rule.required_fraction));
    row("max error", fmt::format("{:.3e} ({} codes; cap {:g})", c.max_error,
                                 metric("max_error_codes", format_codes(c.max_error)), options.rule.max_error * 65535));
    if (!c.worst.empty())
        row("worst pixel", fmt::format("({}, {}): {} codes (the solid box in the images)",
                                       metric("worst_x", std::to_string(c.worst[0].x)),
                                       metric("worst_y", std::to_string(c.worst[0].y)),
                                       metric("worst_error_codes", format_codes(c.worst[0].error))));
    row("mean error", fmt::format("{:.3e} ({} codes)", c.mean_error,
                                  metric("mean_error_codes", fmt::format("{:.3f}", c.mean_error * 65535))));
    row("RMS error", fmt::format("{:.3e} ({:.3f} codes)", c.rms_error, c.rms_error * 65535));
    row("PSNR (peak 1)", std::isinf(c.psnr) ? std::string("∞ (identical)") : fmt::format("{:.1f} dB", c.psnr));
    row("NaN/Inf values", fmt::format("{} in Whitted's image, {} in POV-Ray's", c.nonfinite_ours, c.nonfinite_theirs));
    row("image",
        fmt::format("{}×{}, image.samples = {}{}", c.width, c.height, r.samples,
                    r.samples > 1 ? fmt::format(" (POV-Ray rendered {}×{} and each {}×{} block was averaged)",
                                                c.width * r.samples, c.height * r.samples, r.samples, r.samples)
                                  : std::string()));
    row("exposure", exposure_note);
    row("render time", fmt::format("Whitted {:.3f} s; POV-Ray {:.2f} s ({} run{})", r.whitted_seconds, r.povray_seconds,
                                   r.povray_runs, r.povray_runs == 1 ? "" : "s"));
    row("POV-Ray", "<code>" + html_escape(r.povray_program) + "</code>");
    row("Whitted's intersection",
        "<code>render.intersection: povray</code> (POV-Ray's decisions at edges, grazes and ties)");
    h += "</table>\n";

    h += "<h2>Images</h2>\n<div class=\"row\">\n";
    h += figure("ours.png", "Whitted (display sRGB of the linear image)", c, scale);
    h += figure("povray.png", "POV-Ray 3.7 (same display transform)", c, scale);
    h += figure("diff.png",
                fmt::format("Difference: largest |Whitted − POV-Ray| over R, G, B; full scale = 2 × tolerance "
                            "= {:g} codes",
                            2 * tolerance_codes),
                c, scale);
    h += "</div>\n";
    h += fmt::format(
        "<p>Heat map scale (per pixel, the largest channel difference in 16-bit codes of 1/65535):</p>\n"
        "<div class=\"legend\"></div>\n<div class=\"legend-labels\"><span>0</span><span>{0:g} = tolerance</span>"
        "<span>≥ {1:g}</span></div>\n"
        "<p>Black to blue: within the tolerance (blue = exactly at it). Yellow to red: outside it (red = twice the "
        "tolerance or more). The solid magenta box marks the worst pixel, dashed boxes the next worst ones "
        "(listed below). Images shown {2}× enlarged (smaller when the window is too narrow for the three)"
        "{3}; click one for the file.</p>\n",
        tolerance_codes, 2 * tolerance_codes, scale,
        r.exposure != 1 ? fmt::format(", at exposure {:g}", r.exposure) : std::string());

    h += explore_section(c, tolerance_codes);

    h += fmt::format("<h2>The {} worst pixels</h2>\n", c.worst.size());
    h += "<p>Column from the left, row from the top; values are linear, at the compared exposure, in 16-bit codes "
         "(× 65535). Error: the largest |Whitted − POV-Ray| of the three channels.</p>\n";
    h += "<table>\n<tr><th>#</th><th>x</th><th>y</th><th>error (codes)</th><th>Whitted R</th><th>G</th><th>B</th>"
         "<th>POV-Ray R</th><th>G</th><th>B</th></tr>\n";
    for (size_t i = 0; i < c.worst.size(); ++i) {
        const PixelError& w = c.worst[i];
        // data-x, data-y: a click probes the pixel in the viewer above.
        h += fmt::format("<tr data-x=\"{1}\" data-y=\"{2}\"><td>{0}</td><td>{1}</td><td>{2}</td><td>{3}</td>", i + 1,
                         w.x, w.y, format_codes(w.error)) +
             code_cells(w.ours) + code_cells(w.theirs) + "</tr>\n";
    }
    h += "</table>\n";

    h += "<h2>Files</h2>\n<ul>\n";
    const std::pair<const char*, const char*> files[] = {
        {"ours.exr",
         "Whitted, linear float, at the scene's own scale (what <code>whitted render -o x.exr</code> writes)"},
        {"povray.exr", "POV-Ray, linear float, divided by the exposure back to the scene's scale"},
        {"povray-16bit.png", "POV-Ray's own output: linear 16-bit PNG (gAMA 1.0)"},
        {"scene.pov", "the converted scene"},
        {"scene.ini", "POV-Ray's options (size, no antialiasing, 16-bit linear PNG)"},
        {"povray.log", "what POV-Ray printed"},
        {"metrics.json", "the figures above, machine-readable"},
        {"report-data.js", "the compared values (and colour render layers) the viewer above shows and probes"}};
    for (const auto& [file, what] : files)
        h += fmt::format("<li><a href=\"{0}\"><code>{0}</code></a>: {1}</li>\n", file, what);
    h += "</ul>\n";

    h += "<h2>Reproduce</h2>\n<pre>";
    h += html_escape("whitted render " + shell_quote(scene_abs) + " -o ours.exr\n");
    // With a stored POV-Ray image (check --povray-image) there is no .ini here to run POV-Ray on.
    const std::string stored = options.povray_image.empty()
                                   ? std::string()
                                   : fmt::format(" --povray-image {} --exposure {:g}",
                                                 shell_quote(fs::absolute(options.povray_image).string()), r.exposure);
    if (stored.empty())
        h += html_escape("cd " + shell_quote(dir_abs) + " && HOME=$(mktemp -d) povray " + r.ini_file + "\n");
    h += html_escape("whitted check " + shell_quote(scene_abs) + " --report " + shell_quote(dir_abs) + stored +
                     fmt::format(" --tolerance {:g} --min-fraction {:g} --max-error {:g}", tolerance_codes,
                                 options.rule.required_fraction, options.rule.max_error * 65535) +
                     "\n");
    h += "</pre>\n<p>See <code>docs/validation.md</code> for the mapping, the conventions and the tolerance.</p>\n";
    h += "<script src=\"report-data.js\"></script>\n<script>\n";
    h += report_viewer_js;
    h += "</script>\n</body>\n</html>\n";
    return h;
}

}  // namespace

void write_report(const std::string& dir, const std::string& scene_path, const Image& ours, const Image& theirs,
                  const CheckRecord& result, const CheckRun& options) {
    const fs::path d(dir);
    std::error_code error;
    fs::create_directories(d, error);
    if (!fs::is_directory(d)) throw std::runtime_error("cannot create the report directory '" + dir + "'");

    // Lossless compression, the smaller of the two for each (a 640x480 render: 3.69 MB raw):
    // PIZ for Whitted's floats (2.6 MB; ZIP 2.8), ZIP for POV-Ray's, 16-bit codes as floats
    // (1.0 MB; PIZ 2.1). The difference is not written as an EXR: it is exactly
    // exposure × |ours.exr − povray.exr| (docs/validation.md), and the page and diff.png show it.
    OutputOptions linear;
    linear.metadata = {{"whitted:scene", fs::absolute(scene_path).string()}};
    linear.exr_compression = "piz";
    write_image(divided(ours, result.exposure), (d / "ours.exr").string(), linear);
    linear.exr_compression = "zip";
    write_image(divided(theirs, result.exposure), (d / "povray.exr").string(), linear);
    // The default display transform (sRGB), the same for both so they look alike exactly when
    // they are alike.
    write_image(ours, (d / "ours.png").string(), {});
    write_image(theirs, (d / "povray.png").string(), {});

    if (result.comparison.pixels > 0) {
        const Image difference = absolute_difference(ours, theirs);
        std::vector<unsigned char> heat(size_t(difference.width) * size_t(difference.height) * 3);
        for (size_t i = 0; i < heat.size() / 3; ++i) {
            const float* p = &difference.rgb[3 * i];
            const double worst = std::isnan(p[0]) || std::isnan(p[1]) || std::isnan(p[2])
                                     ? std::numeric_limits<double>::quiet_NaN()
                                     : double(std::max({p[0], p[1], p[2]}));
            heat_colour(worst, options.rule.tolerance, &heat[3 * i]);
        }
        write_raw_png(heat, difference.width, difference.height, d / "diff.png");
    }

    // A scene's file name may hold bytes that are not UTF-8: written as U+FFFD, so that the
    // report is JSON whatever the name.
    const std::string metrics =
        metrics_json(scene_path, result, options).dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
    const std::string html = report_html(dir, scene_path, result, options);
    if (result.comparison.pixels > 0)
        write_files_atomically({{d / "metrics.json", metrics},
                                {d / "report-data.js", report_data_js(scene_path, ours, theirs, result, options)},
                                {d / "report.html", html}});
    else
        write_files_atomically({{d / "metrics.json", metrics}, {d / "report.html", html}});
}

}  // namespace whitted::reference
