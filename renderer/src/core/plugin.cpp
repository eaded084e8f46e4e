// SPDX-License-Identifier: MIT
#include "core/plugin.h"

#include <dlfcn.h>

#include <cstdlib>
#include <filesystem>
#include <map>
#include <mutex>
#include <stdexcept>
#include <vector>

namespace whitted {
namespace {

void* open_plugin(const std::vector<std::filesystem::path>& candidates, const char* plugin_file,
                  const char* needed_for);

void* load_plugin(const char* plugin_file, const char* needed_for) {
    std::vector<std::filesystem::path> candidates;
    std::error_code error;
    // $WHITTED_PLUGIN_DIR, when set, is the only place: one set of plug-ins, not a mix.
    if (const char* dir = std::getenv("WHITTED_PLUGIN_DIR"); dir && *dir)
        return open_plugin({dir}, plugin_file, needed_for);
    const auto exe = std::filesystem::read_symlink("/proc/self/exe", error);
    if (!error) candidates.push_back(exe.parent_path().parent_path() / "lib");
#ifdef WHITTED_INSTALL_LIBDIR
    // An installed program: PREFIX/bin/whitted finds PREFIX/<libdir>/libwhitted_oiio.so.
    if (!error) candidates.push_back(exe.parent_path().parent_path() / WHITTED_INSTALL_LIBDIR);
#endif
    // The library (libwhitted.so, the Python module) in a program that is not ours, e.g.
    // /usr/bin/python3: the plug-in is installed (and built) beside libwhitted.so.
    Dl_info self{};
    if (dladdr(reinterpret_cast<void*>(&load_plugin), &self) && self.dli_fname) {
        const auto object = std::filesystem::weakly_canonical(self.dli_fname, error);
        if (!error) candidates.push_back(object.parent_path());
    }
#ifdef WHITTED_BUILD_PLUGIN_DIR
    candidates.emplace_back(WHITTED_BUILD_PLUGIN_DIR);
#endif
    return open_plugin(candidates, plugin_file, needed_for);
}

void* open_plugin(const std::vector<std::filesystem::path>& candidates, const char* plugin_file,
                  const char* needed_for) {
    std::error_code error;
    std::string tried;
    for (const auto& dir : candidates) {
        const std::filesystem::path path = dir / plugin_file;
        if (!std::filesystem::exists(path, error)) {
            tried += "\n  " + path.string() + " (not found)";
            continue;
        }
        if (void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL)) return handle;
        tried += "\n  " + path.string() + " (" + dlerror() + ")";
    }
    throw std::runtime_error(std::string("cannot load the plug-in ") + plugin_file + " (" + needed_for +
                             "); tried:" + tried);
}

}  // namespace

void* plugin_symbol(const char* file, const char* name, const char* needed_for) {
    struct Loaded {
        void* handle = nullptr;
        std::string error;
    };
    static std::mutex mutex;
    static std::map<std::string, Loaded> loaded;
    void* handle;
    {
        std::lock_guard lock(mutex);
        auto [it, first] = loaded.try_emplace(file);
        if (first) {
            try {
                it->second.handle = load_plugin(file, needed_for);
            } catch (const std::exception& e) {
                it->second.error = e.what();
            }
        }
        if (!it->second.handle) throw std::runtime_error(it->second.error);
        handle = it->second.handle;
    }
    void* symbol = dlsym(handle, name);
    if (!symbol) throw std::runtime_error(std::string("the plug-in ") + file + " has no '" + name + "'");
    return symbol;
}

void* image_io_plugin_symbol(const char* name) {
    return plugin_symbol("libwhitted_oiio.so", name,
                         "the OpenImageIO plug-in, needed for `whitted check` and "
                         "`whitted compare`");
}

}  // namespace whitted
