// SPDX-License-Identifier: MIT
#include "explain_command.h"

#include "scene/errors.h"
#include "whitted/whitted.h"

#include <fmt/format.h>

#include <cstdio>
#include <stdexcept>
#include <string>

namespace whitted {

namespace {

using api::exit_ok;

/// "X,Y" → two non-negative integers; throws std::invalid_argument saying what is wrong.
void parse_pixel(const std::string& text, int& x, int& y) {
    const size_t comma = text.find(',');
    const auto number = [&](const std::string& part, const char* axis) {
        if (part.empty() || part.find_first_not_of("0123456789") != std::string::npos || part.size() > 9)
            throw std::invalid_argument("--pixel '" + text + "': " + axis +
                                        " must be a whole number >= 0; write --pixel X,Y, e.g. --pixel 320,240");
        return std::stoi(part);
    };
    if (comma == std::string::npos)
        throw std::invalid_argument("--pixel '" + text +
                                    "': expected X,Y (column, row from the top-left), e.g. "
                                    "--pixel 320,240");
    x = number(text.substr(0, comma), "X");
    y = number(text.substr(comma + 1), "Y");
}

}  // namespace

int run_explain(const std::string& scene_path, const std::string& pixel, bool json, bool summary, int threads) {
    int x = 0, y = 0;
    try {
        parse_pixel(pixel, x, y);  // usage first: nothing here reads the scene
    } catch (...) {
        return api::report(api::current_error({"reading the scene", scene_path, api::Error::Kind::bad_input}));
    }
    const api::Expected<api::Scene> scene = api::load_scene_file(scene_path, {}, api::SceneUse::render_only);
    if (!scene) return api::report(scene.error());
    if (x >= scene->width() || y >= scene->height())
        return api::report(
            api::Error{fmt::format("--pixel {},{} is outside the {}x{} image (X 0..{}, Y 0..{})", x, y, scene->width(),
                                   scene->height(), scene->width() - 1, scene->height() - 1)});
    api::ExplainOptions options;
    options.format = json ? api::ExplainFormat::json : summary ? api::ExplainFormat::summary : api::ExplainFormat::text;
    options.threads = threads;
    const api::Expected<std::string> text = api::explain(*scene, x, y, options);
    if (!text) return api::report(text.error());
    std::fputs(text->c_str(), stdout);
    return exit_ok;
}

}  // namespace whitted
