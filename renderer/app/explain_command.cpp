// SPDX-License-Identifier: MIT
#include "explain_command.h"

#include "report.h"
#include "whitted/whitted.h"

#include <fmt/format.h>

#include <cstdio>
#include <stdexcept>
#include <string>

namespace whitted {

namespace {

using api::exit_ok;

/// "X,Y" → two non-negative integers; an Error (bad input) says what is wrong.
api::Expected<void> parse_pixel(const std::string& text, int& x, int& y) {
    const size_t comma = text.find(',');
    if (comma == std::string::npos)
        return api::Error{"--pixel '" + text + "': expected X,Y (column, row from the top-left), e.g. --pixel 320,240"};
    const auto number = [&](const std::string& part, const char* axis, int& value) -> api::Expected<void> {
        if (part.empty() || part.find_first_not_of("0123456789") != std::string::npos || part.size() > 9)
            return api::Error{"--pixel '" + text + "': " + axis +
                              " must be a whole number >= 0; write --pixel X,Y, e.g. --pixel 320,240"};
        value = std::stoi(part);
        return {};
    };
    if (auto parsed = number(text.substr(0, comma), "X", x); !parsed) return parsed;
    return number(text.substr(comma + 1), "Y", y);
}

}  // namespace

int run_explain(const std::string& scene_path, const std::string& pixel, const api::SceneOverrides& overrides,
                bool json, bool summary, int threads) {
    int x = 0, y = 0;
    // Usage first: nothing here reads the scene.
    if (const api::Expected<void> parsed = parse_pixel(pixel, x, y); !parsed) return report(parsed.error());
    const api::Expected<api::Scene> scene = api::load_scene_file(scene_path, overrides, api::SceneUse::render_only);
    if (!scene) return report(scene.error());
    if (x >= scene->width() || y >= scene->height())
        return report(
            api::Error{fmt::format("--pixel {},{} is outside the {}x{} image (X 0..{}, Y 0..{})", x, y, scene->width(),
                                   scene->height(), scene->width() - 1, scene->height() - 1)});
    api::ExplainOptions options;
    options.format = json ? api::ExplainFormat::json : summary ? api::ExplainFormat::summary : api::ExplainFormat::text;
    options.threads = threads;
    const api::Expected<std::string> text = api::explain(*scene, x, y, options);
    if (!text) return report(text.error());
    std::fputs(text->c_str(), stdout);
    return exit_ok;
}

}  // namespace whitted
