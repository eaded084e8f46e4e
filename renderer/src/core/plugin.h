// SPDX-License-Identifier: MIT
#pragma once

#include <string>

namespace whitted {

/// Code that needs OpenImageIO (reading images: `whitted check` and `whitted compare`) lives in
/// a plug-in, lib/libwhitted_oiio.so, loaded on first use. Linking OpenImageIO into the program
/// would cost every run about 0.2 s of start-up (it pulls in ~250 shared libraries), most of a
/// small render's time; a render never loads it.
///
/// Returns the address of `name` in the plug-in, loading it from $WHITTED_PLUGIN_DIR (when set,
/// the only place looked), else from
/// ../lib (and ../<install libdir>) beside the running program, else from the directory of the
/// shared object holding this code (libwhitted.so, for a program that links the library), else
/// from the build tree. Throws std::runtime_error
/// saying where it looked when the plug-in cannot be loaded.
void* image_io_plugin_symbol(const char* name);

/// The same for any of our plug-ins (lib/`file`, e.g. libwhitted_mpi.so); `needed_for` ends
/// the message when it cannot be loaded.
void* plugin_symbol(const char* file, const char* name, const char* needed_for);

}  // namespace whitted
