// SPDX-License-Identifier: MIT
// The OpenColorIO side of DisplayTransform: the plug-in lib/libwhitted_ocio.so
// (output/ocio_plugin.h says why it is one).
#include "output/builtin_config.h"
#include "output/chromaticities.h"
#include "output/color_management.h"
#include "output/ocio_plugin.h"

#include <OpenColorIO/OpenColorIO.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace OCIO = OCIO_NAMESPACE;

namespace whitted {
namespace {

/// A display colour space of the built-in config: `decode` (display code → display-linear
/// light, the colour space's "to reference" direction) and, for other primaries than Rec.709,
/// the matrix from them to Rec.709.
OCIO::ColorSpaceRcPtr display_space(const char* name, const char* description, OCIO::ConstTransformRcPtr decode,
                                    const Chromaticities* primaries) {
    OCIO::ColorSpaceRcPtr space = OCIO::ColorSpace::Create(OCIO::REFERENCE_SPACE_SCENE);
    space->setName(name);
    space->setFamily("Display");
    space->setDescription(description);
    space->setEncoding("sdr-video");
    if (!primaries) {
        space->setTransform(decode, OCIO::COLORSPACE_DIR_TO_REFERENCE);
        return space;
    }
    const Matrix3 to_rec709 = multiply(inverse(rgb_to_xyz(rec709_chromaticities)), rgb_to_xyz(*primaries));
    double m44[16] = {};
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) m44[4 * i + j] = to_rec709[size_t(i)][size_t(j)];
    m44[15] = 1.0;
    OCIO::MatrixTransformRcPtr matrix = OCIO::MatrixTransform::Create();
    matrix->setMatrix(m44);
    OCIO::GroupTransformRcPtr group = OCIO::GroupTransform::Create();
    group->appendTransform(decode->createEditableCopy());
    group->appendTransform(matrix);
    space->setTransform(group, OCIO::COLORSPACE_DIR_TO_REFERENCE);
    return space;
}

OCIO::ConstTransformRcPtr srgb_curve() {
    OCIO::ExponentWithLinearTransformRcPtr curve = OCIO::ExponentWithLinearTransform::Create();
    curve->setGamma({2.4, 2.4, 2.4, 1.0});
    curve->setOffset({0.055, 0.055, 0.055, 0.0});
    return curve;
}

OCIO::ConstTransformRcPtr power_curve(double gamma) {
    OCIO::ExponentTransformRcPtr curve = OCIO::ExponentTransform::Create();
    curve->setValue({gamma, gamma, gamma, 1.0});
    // Negative display-linear values have no code: clamp (the default), as a file would.
    return curve;
}

/// The built-in config (builtin_config.h) as an OpenColorIO config.
OCIO::ConstConfigRcPtr make_builtin_config() {
    OCIO::ConfigRcPtr config = OCIO::Config::Create();
    config->setName(builtin_config_name);
    config->setDescription(builtin_config_description);

    OCIO::ColorSpaceRcPtr linear = OCIO::ColorSpace::Create();
    linear->setName(builtin_scene_linear);
    linear->setFamily("Scene-linear");
    linear->setDescription("Scene-referred linear light with Rec.709 / sRGB primaries, D65: what Whitted renders.");
    linear->setEncoding("scene-linear");
    config->addColorSpace(linear);

    for (const BuiltinDisplay& display : builtin_displays) {
        const OCIO::ConstTransformRcPtr curve = display.transfer == DisplayEncoding::Transfer::srgb ? srgb_curve()
                                                : display.transfer == DisplayEncoding::Transfer::gamma22
                                                    ? power_curve(2.2)
                                                    : power_curve(2.4);
        config->addColorSpace(display_space(
            display.colorspace, display.description, curve,
            display.primaries == DisplayEncoding::Primaries::display_p3 ? &display_p3_chromaticities : nullptr));
    }

    OCIO::ColorSpaceRcPtr raw = OCIO::ColorSpace::Create();
    raw->setName(builtin_raw);
    raw->setFamily("Utility");
    raw->setDescription(builtin_raw_description);
    raw->setIsData(true);
    config->addColorSpace(raw);

    config->setRole(OCIO::ROLE_SCENE_LINEAR, builtin_scene_linear);
    config->setRole(OCIO::ROLE_DEFAULT, builtin_scene_linear);
    config->setRole(OCIO::ROLE_REFERENCE, builtin_scene_linear);
    config->setRole(OCIO::ROLE_DATA, builtin_raw);
    config->setRole("color_picking", builtin_displays[0].colorspace);
    for (const BuiltinDisplay& display : builtin_displays) {
        config->addDisplayView(display.name, builtin_views[0], display.colorspace, "");
        config->addDisplayView(display.name, builtin_views[1], builtin_raw, "");
    }
    config->setActiveDisplays(builtin_display_list().c_str());
    config->setActiveViews(builtin_view_list().c_str());
    config->validate();
    return config;
}

std::string join(const std::vector<std::string>& names) {
    std::string out;
    for (const std::string& name : names) out += (out.empty() ? "" : ", ") + name;
    return out;
}

std::vector<std::string> displays_of(const OCIO::ConstConfigRcPtr& config) {
    std::vector<std::string> names;
    for (int i = 0; i < config->getNumDisplays(); ++i) names.emplace_back(config->getDisplay(i));
    return names;
}

std::vector<std::string> views_of(const OCIO::ConstConfigRcPtr& config, const std::string& display) {
    std::vector<std::string> names;
    for (int i = 0; i < config->getNumViews(display.c_str()); ++i)
        names.emplace_back(config->getView(display.c_str(), i));
    return names;
}

/// The file a FileTransform's `src` names, found as OpenColorIO finds it: an absolute path as it
/// is, else the first search path (context variables expanded, relative to the config's folder)
/// that holds it; empty when none does (OpenColorIO then reports it missing itself).
std::filesystem::path file_transform_source(const OCIO::ConstConfigRcPtr& config, const char* src) {
    const OCIO::ConstContextRcPtr context = config->getCurrentContext();
    const std::filesystem::path name = context->resolveStringVar(src);
    std::error_code error;
    if (name.is_absolute()) return name;
    for (int i = 0; i < config->getNumSearchPaths(); ++i) {
        std::filesystem::path folder = context->resolveStringVar(config->getSearchPath(i));
        if (folder.is_relative()) folder = std::filesystem::path(config->getWorkingDir()) / folder;
        if (std::filesystem::exists(folder / name, error)) return folder / name;
    }
    return {};
}

/// Every FileTransform of the config, in its colour spaces, looks and view transforms (inside
/// groups too), must name a regular file: OpenColorIO would wait forever on a FIFO and read a
/// device such as /dev/zero without end when the transform is built.
void refuse_file_transforms_from_special_files(const OCIO::ConstConfigRcPtr& config) {
    std::function<void(const OCIO::ConstTransformRcPtr&)> walk = [&](const OCIO::ConstTransformRcPtr& transform) {
        if (!transform) return;
        if (const auto group = OCIO::DynamicPtrCast<const OCIO::GroupTransform>(transform)) {
            for (int i = 0; i < group->getNumTransforms(); ++i) walk(group->getTransform(i));
        } else if (const auto file = OCIO::DynamicPtrCast<const OCIO::FileTransform>(transform)) {
            const std::filesystem::path path = file_transform_source(config, file->getSrc());
            std::error_code error;
            const auto status = std::filesystem::status(path, error);
            if (!path.empty() && std::filesystem::exists(status) && !std::filesystem::is_regular_file(status))
                throw std::runtime_error("its FileTransform source '" + std::string(file->getSrc()) + "' ('" +
                                         path.string() +
                                         "') is not a regular file (a FIFO, socket, device or directory)");
        }
    };
    for (int i = 0; i < config->getNumColorSpaces(OCIO::SEARCH_REFERENCE_SPACE_ALL, OCIO::COLORSPACE_ALL); ++i) {
        const OCIO::ConstColorSpaceRcPtr space = config->getColorSpace(
            config->getColorSpaceNameByIndex(OCIO::SEARCH_REFERENCE_SPACE_ALL, OCIO::COLORSPACE_ALL, i));
        if (!space) continue;
        walk(space->getTransform(OCIO::COLORSPACE_DIR_TO_REFERENCE));
        walk(space->getTransform(OCIO::COLORSPACE_DIR_FROM_REFERENCE));
    }
    for (int i = 0; i < config->getNumLooks(); ++i) {
        const OCIO::ConstLookRcPtr look = config->getLook(config->getLookNameByIndex(i));
        if (!look) continue;
        walk(look->getTransform());
        walk(look->getInverseTransform());
    }
    for (int i = 0; i < config->getNumViewTransforms(); ++i) {
        const OCIO::ConstViewTransformRcPtr view = config->getViewTransform(config->getViewTransformNameByIndex(i));
        if (!view) continue;
        walk(view->getTransform(OCIO::VIEWTRANSFORM_DIR_TO_REFERENCE));
        walk(view->getTransform(OCIO::VIEWTRANSFORM_DIR_FROM_REFERENCE));
    }
}

/// The config `config_path` names, else $OCIO's, else the built-in one; `source` says which.
OCIO::ConstConfigRcPtr load_config(const std::string& config_path, std::string& source) {
    const char* env = std::getenv("OCIO");
    // OCIO reads a directory or a file that is no config as an empty YAML document and then says
    // little, and it would wait forever on a FIFO (or read /dev/zero without end): only a regular
    // file (or a link to one) is handed to it.
    const auto check_file = [](const std::string& path) {
        std::error_code error;
        const auto status = std::filesystem::status(path, error);
        if (!std::filesystem::exists(status)) throw std::runtime_error("no such file");
        if (std::filesystem::is_directory(status)) throw std::runtime_error("it is a directory");
        if (!std::filesystem::is_regular_file(status))
            throw std::runtime_error("it is not a regular file (a FIFO, socket or device)");
    };
    const auto from_file = [&](const std::string& path) {
        check_file(path);
        const OCIO::ConstConfigRcPtr config = OCIO::Config::CreateFromFile(path.c_str());
        refuse_file_transforms_from_special_files(config);
        return config;
    };
    try {
        if (!config_path.empty()) {
            source = config_path;
            return from_file(config_path);
        }
        if (env && *env) {
            source = std::string("$OCIO=") + env;
            return from_file(env);
        }
    } catch (const std::exception& e) {
        throw std::invalid_argument(
            "cannot load the OpenColorIO config " +
            (config_path.empty() ? "from $OCIO='" + std::string(env) + "'" : "'" + config_path + "'") + ": " +
            e.what());
    }
    source = "built-in";
    return make_builtin_config();
}

OCIO::ConstCPUProcessorRcPtr make_processor(const OCIO::ConstConfigRcPtr& config, const std::string& display,
                                            const std::string& view) {
    try {
        const OCIO::ConstProcessorRcPtr processor =
            config->getProcessor(OCIO::ROLE_SCENE_LINEAR, display.c_str(), view.c_str(), OCIO::TRANSFORM_DIR_FORWARD);
        return processor->getOptimizedCPUProcessor(OCIO::BIT_DEPTH_F32, OCIO::BIT_DEPTH_F32,
                                                   OCIO::OPTIMIZATION_DEFAULT);
    } catch (const OCIO::Exception& e) {
        throw std::runtime_error(std::string("OpenColorIO cannot build the display transform: ") + e.what());
    }
}

/// Runs the transform on greys and on each primary and recognises the result: the transfer
/// function whose codes the greys get (to 5e-4, a tenth of an 8-bit code's width and far less
/// than the nearest two candidates differ by), then the primaries the decoded primaries are in
/// (to 2e-3). Anything else (a filmic tone curve, a look, other primaries) is "unknown", and the
/// file then records only the names.
DisplayEncoding probe(const OCIO::ConstCPUProcessorRcPtr& cpu) {
    const std::array<float, 6> greys = {0.001f, 0.01f, 0.05f, 0.18f, 0.5f, 0.9f};
    std::vector<float> rgb;
    for (const float v : greys) rgb.insert(rgb.end(), {v, v, v});
    for (int c = 0; c < 3; ++c)
        for (int k = 0; k < 3; ++k) rgb.push_back(c == k ? 0.5f : 0.0f);
    OCIO::PackedImageDesc image(rgb.data(), long(rgb.size() / 3), 1, 3);
    cpu->apply(image);

    DisplayEncoding encoding;
    using T = DisplayEncoding::Transfer;
    for (const T transfer : {T::linear, T::srgb, T::gamma22, T::gamma24}) {
        bool matches = true;
        for (size_t i = 0; i < greys.size(); ++i)
            for (size_t k = 0; k < 3; ++k)
                matches &= std::abs(double(rgb[3 * i + k]) - encode(transfer, double(greys[i]))) < 5e-4;
        if (matches) {
            encoding.transfer = transfer;
            break;
        }
    }
    if (encoding.transfer == T::unknown) return encoding;
    Matrix3 measured{};
    for (size_t c = 0; c < 3; ++c)
        for (size_t k = 0; k < 3; ++k)
            measured[k][c] = decode(encoding.transfer, rgb[3 * (greys.size() + c) + k]) / 0.5;
    const auto near = [&](const Matrix3& expected) {
        for (size_t i = 0; i < 3; ++i)
            for (size_t j = 0; j < 3; ++j)
                if (std::abs(measured[i][j] - expected[i][j]) > 2e-3) return false;
        return true;
    };
    const Matrix3 identity{{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
    const Matrix3 to_p3 = multiply(inverse(rgb_to_xyz(display_p3_chromaticities)), rgb_to_xyz(rec709_chromaticities));
    if (near(identity))
        encoding.primaries = DisplayEncoding::Primaries::rec709;
    else if (near(to_p3))
        encoding.primaries = DisplayEncoding::Primaries::display_p3;
    return encoding;
}

}  // namespace

void make_display_transform(const std::string& config_path, const std::string& display, const std::string& view,
                            DisplayTransformParts& parts) {
    const OCIO::ConstConfigRcPtr config = load_config(config_path, parts.source);
    parts.config_name = config->getName() ? config->getName() : "";
    parts.display = display.empty() ? config->getDefaultDisplay() : display;
    const std::vector<std::string> displays = displays_of(config);
    if (std::find(displays.begin(), displays.end(), parts.display) == displays.end())
        throw std::invalid_argument("OpenColorIO display '" + parts.display + "' is not in the config (" +
                                    parts.source + "); displays: " + join(displays));
    parts.view = view.empty() ? config->getDefaultView(parts.display.c_str()) : view;
    const std::vector<std::string> views = views_of(config, parts.display);
    if (std::find(views.begin(), views.end(), parts.view) == views.end())
        throw std::invalid_argument("OpenColorIO view '" + parts.view + "' is not a view of display '" + parts.display +
                                    "'; views: " + join(views));
    parts.colorspace = config->getDisplayViewColorSpaceName(parts.display.c_str(), parts.view.c_str());
    const OCIO::ConstCPUProcessorRcPtr cpu = make_processor(config, parts.display, parts.view);
    parts.encoding = probe(cpu);
    parts.apply = [cpu](float* rgb, size_t pixel_count) {
        // OCIO's CPU processor may be applied from several threads at once: large buffers are
        // cut into chunks that run on all cores (its sRGB curve calls powf per value: ~13 ms of
        // CPU for a 1280x960 image); a small one stays on the calling thread.
        constexpr size_t chunk = 32768;
        tbb::parallel_for(size_t(0), (pixel_count + chunk - 1) / chunk, [&](size_t c) {
            const size_t first = c * chunk, count = std::min(chunk, pixel_count - first);
            OCIO::PackedImageDesc image(rgb + 3 * first, static_cast<long>(count), 1, 3);
            cpu->apply(image);
        });
    };
}

std::string builtin_config_text() {
    std::ostringstream out;
    make_builtin_config()->serialize(out);
    return out.str();
}

std::string describe_config(const std::string& config_path) {
    std::string source;
    const OCIO::ConstConfigRcPtr config = load_config(config_path, source);
    std::ostringstream out;
    out << "OpenColorIO config: " << source;
    if (config->getName() && *config->getName()) out << " (" << config->getName() << ")";
    out << "\nscene_linear: "
        << config->getColorSpaceNameByIndex(config->getIndexForColorSpace(OCIO::ROLE_SCENE_LINEAR))
        << "\ndefault: --display '" << config->getDefaultDisplay() << "' --view '"
        << config->getDefaultView(config->getDefaultDisplay()) << "'\n";
    for (const std::string& display : displays_of(config)) {
        out << "display '" << display << "'\n";
        for (const std::string& view : views_of(config, display)) {
            const char* space = config->getDisplayViewColorSpaceName(display.c_str(), view.c_str());
            std::string meaning;
            try {
                meaning = probe(make_processor(config, display, view)).description();
            } catch (const std::exception& e) {
                meaning = e.what();
            }
            out << "  view '" << view << "': colour space '" << space << "': " << meaning << "\n";
        }
    }
    return out.str();
}

}  // namespace whitted

extern "C" WHITTED_PLUGIN_EXPORT void whitted_ocio_display_transform(const std::string& config_path,
                                                                     const std::string& display,
                                                                     const std::string& view,
                                                                     whitted::DisplayTransformParts& parts) {
    whitted::make_display_transform(config_path, display, view, parts);
}

extern "C" WHITTED_PLUGIN_EXPORT void whitted_ocio_builtin_config_text(std::string& text) {
    text = whitted::builtin_config_text();
}

extern "C" WHITTED_PLUGIN_EXPORT void whitted_ocio_describe_config(const std::string& config_path, std::string& text) {
    text = whitted::describe_config(config_path);
}
