// SPDX-License-Identifier: MIT
#pragma once

// Shared by the libFuzzer harnesses and their replay executables: a private scratch directory
// (the loaders read files, so inputs are written there) holding small valid mesh fixtures, so
// that corpus scenes which name `octahedron.obj` or `shapes.mtl` reach the mesh code.

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

namespace whitted::fuzz {

inline const char* const octahedron_obj =
    "mtllib shapes.mtl\nv 1 0 0\nv -1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nv 0 0 -1\nusemtl steel\n"
    "f 1 3 5\nf 3 2 5\nf 2 4 5\nf 4 1 5\nf 3 1 6\nf 2 3 6\nf 4 2 6\nf 1 4 6\n";
inline const char* const shapes_mtl =
    "newmtl glaze\nKa 0.03 0.016 0.005\nKd 0.6 0.3 0.08\nKs 0.3 0.3 0.3\nNs 80\nillum 2\n"
    "newmtl steel\nKa 0.02 0.02 0.02\nKd 0.15 0.16 0.18\nKs 0.4 0.4 0.4\nNs 120\nillum 3\n";

inline void write_file(const std::filesystem::path& path, const std::string& text) {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out << text;
}

/// The scratch directory, made once per process (RAM-backed where possible: written per input)
/// and removed at exit.
inline const std::filesystem::path& scratch_directory() {
    static const std::filesystem::path directory = [] {
        const std::filesystem::path base = std::filesystem::is_directory("/dev/shm") ? "/dev/shm" : "/tmp";
        std::filesystem::path dir = base / ("whitted-fuzz-" + std::to_string(::getpid()));
        std::filesystem::create_directories(dir);
        write_file(dir / "octahedron.obj", octahedron_obj);
        write_file(dir / "icosphere.obj", octahedron_obj);
        write_file(dir / "shapes.mtl", shapes_mtl);
        static std::string to_remove = dir.string();
        std::atexit([] {
            std::error_code ignored;
            std::filesystem::remove_all(to_remove, ignored);
        });
        return dir;
    }();
    return directory;
}

}  // namespace whitted::fuzz
