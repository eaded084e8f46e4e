// SPDX-License-Identifier: MIT
#include "whitted/output/color_management.h"

#include <OpenColorIO/OpenColorIO.h>
#include <tbb/parallel_for.h>

#include <algorithm>

#include <cstdlib>
#include <sstream>
#include <stdexcept>

namespace OCIO = OCIO_NAMESPACE;

namespace whitted {
namespace {

OCIO::ConstConfigRcPtr make_builtin_config() {
    OCIO::ConfigRcPtr config = OCIO::Config::Create();
    config->setName("whitted-builtin");
    config->setDescription("Whitted's built-in config: linear Rec.709 scene, sRGB display.");

    OCIO::ColorSpaceRcPtr linear = OCIO::ColorSpace::Create();
    linear->setName("Linear Rec.709 (sRGB)");
    linear->setFamily("Scene-linear");
    linear->setDescription("Scene-referred linear light with Rec.709 / sRGB primaries: what Whitted renders.");
    linear->setEncoding("scene-linear");
    config->addColorSpace(linear);

    OCIO::ColorSpaceRcPtr srgb = OCIO::ColorSpace::Create(OCIO::REFERENCE_SPACE_SCENE);
    srgb->setName("sRGB - Display");
    srgb->setFamily("Display");
    srgb->setDescription("The sRGB piecewise curve (IEC 61966-2-1) on Rec.709 primaries.");
    srgb->setEncoding("sdr-video");
    OCIO::ExponentWithLinearTransformRcPtr curve = OCIO::ExponentWithLinearTransform::Create();
    curve->setGamma({2.4, 2.4, 2.4, 1.0});
    curve->setOffset({0.055, 0.055, 0.055, 0.0});
    // Forward decodes (display code → linear), so it is the colour space's "to reference".
    srgb->setTransform(curve, OCIO::COLORSPACE_DIR_TO_REFERENCE);
    config->addColorSpace(srgb);

    OCIO::ColorSpaceRcPtr raw = OCIO::ColorSpace::Create();
    raw->setName("Raw");
    raw->setFamily("Utility");
    raw->setDescription("No conversion: the linear values, clipped to the file's range.");
    raw->setIsData(true);
    config->addColorSpace(raw);

    config->setRole(OCIO::ROLE_SCENE_LINEAR, "Linear Rec.709 (sRGB)");
    config->setRole(OCIO::ROLE_DEFAULT, "Linear Rec.709 (sRGB)");
    config->setRole(OCIO::ROLE_REFERENCE, "Linear Rec.709 (sRGB)");
    config->setRole(OCIO::ROLE_DATA, "Raw");
    config->setRole("color_picking", "sRGB - Display");
    config->addDisplayView("sRGB", "Standard", "sRGB - Display", "");
    config->addDisplayView("sRGB", "Raw", "Raw", "");
    config->setActiveDisplays("sRGB");
    config->setActiveViews("Standard, Raw");
    config->validate();
    return config;
}

std::string list_displays(const OCIO::ConstConfigRcPtr& config) {
    std::string out;
    for (int i = 0; i < config->getNumDisplays(); ++i) out += std::string(i ? ", " : "") + config->getDisplay(i);
    return out;
}

std::string list_views(const OCIO::ConstConfigRcPtr& config, const char* display) {
    std::string out;
    for (int i = 0; i < config->getNumViews(display); ++i)
        out += std::string(i ? ", " : "") + config->getView(display, i);
    return out;
}

}  // namespace

struct DisplayTransform::Impl {
    OCIO::ConstCPUProcessorRcPtr cpu;
};

DisplayTransform::DisplayTransform(const std::string& config_path, const std::string& display, const std::string& view)
    : m_impl(std::make_unique<Impl>()) {
    OCIO::ConstConfigRcPtr config;
    try {
        const char* env = std::getenv("OCIO");
        if (!config_path.empty()) {
            config = OCIO::Config::CreateFromFile(config_path.c_str());
            m_source = config_path;
        } else if (env && *env) {
            config = OCIO::Config::CreateFromFile(env);
            m_source = std::string("$OCIO=") + env;
        } else {
            config = make_builtin_config();
            m_source = "built-in";
        }
    } catch (const OCIO::Exception& e) {
        throw std::runtime_error("cannot load the OpenColorIO config " +
                                 (config_path.empty() ? std::string("from $OCIO") : "'" + config_path + "'") + ": " +
                                 e.what());
    }
    m_display = display.empty() ? config->getDefaultDisplay() : display;
    bool display_known = false;
    for (int i = 0; i < config->getNumDisplays(); ++i) display_known |= m_display == config->getDisplay(i);
    if (!display_known)
        throw std::runtime_error("OpenColorIO display '" + m_display + "' is not in the config (" + m_source +
                                 "); displays: " + list_displays(config));
    m_view = view.empty() ? config->getDefaultView(m_display.c_str()) : view;
    bool view_known = false;
    for (int i = 0; i < config->getNumViews(m_display.c_str()); ++i)
        view_known |= m_view == config->getView(m_display.c_str(), i);
    if (!view_known)
        throw std::runtime_error("OpenColorIO view '" + m_view + "' is not a view of display '" + m_display +
                                 "'; views: " + list_views(config, m_display.c_str()));
    try {
        OCIO::ConstProcessorRcPtr processor = config->getProcessor(OCIO::ROLE_SCENE_LINEAR, m_display.c_str(),
                                                                   m_view.c_str(), OCIO::TRANSFORM_DIR_FORWARD);
        m_impl->cpu =
            processor->getOptimizedCPUProcessor(OCIO::BIT_DEPTH_F32, OCIO::BIT_DEPTH_F32, OCIO::OPTIMIZATION_DEFAULT);
    } catch (const OCIO::Exception& e) {
        throw std::runtime_error(std::string("OpenColorIO cannot build the display transform: ") + e.what());
    }
}

DisplayTransform::~DisplayTransform() = default;

void DisplayTransform::apply(float* rgb, size_t pixel_count) const {
    // OCIO's CPU processor may be applied from several threads at once: large buffers are cut
    // into chunks that run on all cores (its sRGB curve calls powf per value: ~13 ms of CPU for
    // a 1280x960 image); a small one stays on the calling thread.
    constexpr size_t chunk = 32768;
    tbb::parallel_for(size_t(0), (pixel_count + chunk - 1) / chunk, [&](size_t c) {
        const size_t first = c * chunk, count = std::min(chunk, pixel_count - first);
        OCIO::PackedImageDesc image(rgb + 3 * first, static_cast<long>(count), 1, 3);
        m_impl->cpu->apply(image);
    });
}

std::string DisplayTransform::builtin_config_text() {
    std::ostringstream out;
    make_builtin_config()->serialize(out);
    return out.str();
}

}  // namespace whitted
