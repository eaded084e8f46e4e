// SPDX-License-Identifier: MIT
// `whitted live` is a plug-in, lib/libwhitted_live.so, loaded only when it runs: its web server
// (cpp-httplib) links OpenSSL and Brotli, whose loading and relocation cost every other run
// about as much start-up as OpenColorIO does (docs/performance.md, "Start-up").
#include "live_command.h"

#include "core/plugin.h"

#include <cstdio>
#include <stdexcept>

namespace whitted {

int run_live(const LiveArguments& args) {
    using RunLive = int (*)(const LiveArguments&);
    RunLive run = nullptr;
    try {
        run = reinterpret_cast<RunLive>(
            plugin_symbol("libwhitted_live.so", "whitted_run_live", "the web server of `whitted live`"));
    } catch (const std::runtime_error& e) {
        std::fprintf(stderr, "whitted: error: %s\n", e.what());
        return 2;
    }
    return run(args);
}

}  // namespace whitted
