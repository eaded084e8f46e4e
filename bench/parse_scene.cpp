// SPDX-License-Identifier: MIT
// Times reading scene files (docs/performance.md, "Reading large scenes"): for each file, the
// fast scanner and libyaml building the value tree alone (every object forgotten as it is read,
// as parse.cpp does), the whole parse_scene_file, and load_scene_file (parse and validate in one
// pass, as `whitted render` reads a scene). Best of --runs, wall and CPU seconds.
//   whitted_parse_bench [--runs N] [--parse-only] FILE...

#include "scene/description.h"
#include "scene/scene.h"
#include "scene/text_checks.h"
#include "scene/yaml_tree.h"

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <functional>
#include <string>
#include <vector>

namespace {

struct Seconds {
    double wall, cpu;
};

double now(clockid_t clock) {
    timespec t{};
    clock_gettime(clock, &t);
    return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

Seconds best_of(int runs, const std::function<void()>& work) {
    Seconds best{1e30, 1e30};
    for (int i = 0; i < runs; ++i) {
        const double w = now(CLOCK_MONOTONIC), c = now(CLOCK_PROCESS_CPUTIME_ID);
        work();
        best.wall = std::min(best.wall, now(CLOCK_MONOTONIC) - w);
        best.cpu = std::min(best.cpu, now(CLOCK_PROCESS_CPUTIME_ID) - c);
    }
    return best;
}

}  // namespace

int main(int argc, char** argv) {
    int runs = 3;
    bool parse_only = false;
    std::vector<std::string> files;
    for (int i = 1; i < argc; ++i) {
        if (std::strcmp(argv[i], "--help") == 0 || std::strcmp(argv[i], "-h") == 0) {
            std::printf("usage: whitted_parse_bench [--runs N] [--parse-only] FILE...\n");
            return 0;
        }
        if (std::strcmp(argv[i], "--runs") == 0 && i + 1 < argc)
            runs = std::atoi(argv[++i]);
        else if (std::strcmp(argv[i], "--parse-only") == 0)
            parse_only = true;
        else
            files.emplace_back(argv[i]);
    }
    if (files.empty()) {
        std::fprintf(stderr, "usage: whitted_parse_bench [--runs N] [--parse-only] FILE...\n");
        return 2;
    }
    std::printf("%-28s %9s %-20s %10s %10s\n", "file", "MB", "stage", "wall s", "cpu s");
    for (const std::string& path : files) {
        try {
            const whitted::MappedTextFile file(path, whitted::limits::max_scene_file_bytes, "scene file");
            const std::string name = path.substr(path.find_last_of('/') + 1);
            const double mb = double(file.text().size()) / 1e6;
            size_t objects = 0;
            const auto count = [&](const whitted::yaml_tree::Node&, size_t) { ++objects; };
            // The value tree is YAML's (and JSON's); an NFF or course XML file has none.
            const bool yaml = whitted::scene_format(path, file.text()) == whitted::SceneFormat::yaml;
            for (const auto reader : {whitted::yaml_tree::Reader::fast, whitted::yaml_tree::Reader::libyaml}) {
                if (parse_only || !yaml) break;
                const char* stage =
                    reader == whitted::yaml_tree::Reader::fast ? "tree (fast scanner)" : "tree (libyaml)";
                try {
                    const Seconds s = best_of(runs, [&] {
                        whitted::yaml_tree::Document document;
                        document.read(file.text(), path, count, {}, &reader);
                    });
                    std::printf("%-28s %9.1f %-20s %10.3f %10.3f\n", name.c_str(), mb, stage, s.wall, s.cpu);
                } catch (const whitted::yaml_tree::NotForTheFastScanner&) {
                    // YAML the fast scanner leaves to libyaml (a render reads it with libyaml).
                    std::printf("%-28s %9.1f %-20s %21s\n", name.c_str(), mb, stage, "(left to libyaml)");
                }
            }
            size_t parsed = 0;
            const Seconds s = best_of(runs, [&] { parsed = whitted::parse_scene_file(path).objects.size(); });
            std::printf("%-28s %9.1f %-20s %10.3f %10.3f   (%zu objects)\n", name.c_str(), mb, "parse_scene_file",
                        s.wall, s.cpu, parsed);
            // What `whitted render` does: parse and validate in one pass (scene.h).
            const Seconds l = best_of(runs, [&] { parsed = whitted::load_scene_file(path).objects.size(); });
            std::printf("%-28s %9.1f %-20s %10.3f %10.3f   (%zu objects)\n", name.c_str(), mb, "load_scene_file",
                        l.wall, l.cpu, parsed);
        } catch (const std::exception& e) {
            std::fprintf(stderr, "whitted_parse_bench: %s\n", e.what());
            return 1;
        }
    }
    return 0;
}
