// SPDX-License-Identifier: MIT
#pragma once

#include <string>

namespace whitted {

struct LiveArguments {
    std::string scene;
    int port = 0;  ///< 0: a free port the system picks
    bool open_browser = true;
    int threads = 0;  ///< render threads, 0 = all cores
};

/// `whitted live SCENE`: serves a page on 127.0.0.1 that shows the scene rendered, with sliders
/// for each named material's and each light's parameters, re-rendered as they move and when the
/// file changes on disk (docs/live.md). Returns the exit status: 2 when the scene does not load
/// at the start or the port cannot be had, 130/143 when stopped by SIGINT/SIGTERM.
int run_live(const LiveArguments& args);

}  // namespace whitted
