// SPDX-License-Identifier: MIT
#pragma once

// The program's one way from an error to its exit status, for every command: the library's
// functions return an api::Error, and what the program's own code throws becomes one by the
// library's rules (api::error_of_current_exception).

#include "whitted/whitted.h"

#include <cstdio>
#include <string>

namespace whitted {

/// Prints the error as `whitted` prints every error ("whitted: error: FILE:LINE:COL: message")
/// and returns its exit status (api::exit_status: 2 bad input, 1 failure).
inline int report(const api::Error& error) {
    std::fprintf(stderr, "whitted: error: %s\n", error.what().c_str());
    return api::exit_status(error);
}

/// Runs `command` (returning an exit status); what it throws is reported, "out of memory while
/// `doing`" for instance, and its status returned.
template <class Command>
int run_reporting(const std::string& doing, Command&& command) {
    try {
        return command();
    } catch (...) {
        return report(api::error_of_current_exception(doing));
    }
}

}  // namespace whitted
