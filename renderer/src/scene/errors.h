// SPDX-License-Identifier: MIT
#pragma once

// The one mapping from what the private libraries throw to an api::Error (whose exit status
// api::exit_status gives). The library (api.cpp; api::error_of_current_exception for the program's
// own code) and the OpenImageIO plug-in (reference/plugin.cpp) use it, so a kind of mistake means
// the same status everywhere.
// Inline: the plug-in is a module of its own and does not link the API library. It lives with the
// scene, where InputError and FileChangedWhileRead are defined, below both the API and the
// reference tools that use it.

#include "scene/source_location.h"
#include "scene/text_checks.h"
#include "whitted/whitted.h"

#include <cstdio>
#include <exception>
#include <new>
#include <stdexcept>
#include <string>
#include <utility>

namespace whitted::api {

/// What the work was, for the exceptions that do not say so themselves.
struct ErrorContext {
    ErrorContext(std::string doing_, std::string file_ = {}, Error::Kind otherwise_ = Error::Kind::failure)
        : doing(std::move(doing_)), file(std::move(file_)), otherwise(otherwise_) {}

    /// Finishes "out of memory while ...", e.g. "rendering s.yaml".
    std::string doing;
    /// Named before the message of an exception that carries no place (a filesystem error, say);
    /// empty: the message alone.
    std::string file;
    /// What any other std::exception is: bad_input where the work is reading the caller's
    /// files (an unreadable file), failure where it is working on input already accepted.
    Error::Kind otherwise = Error::Kind::failure;
};

/// The exception being handled, as an Error; call only inside a catch block. InputError keeps its
/// FILE:LINE:COL, std::invalid_argument (a usage or option mistake, whose message is complete) is
/// bad input, running out of memory and a file changed under its reader are failures, anything
/// else is `context.otherwise`. What is not a std::exception is thrown on.
inline Error current_error(const ErrorContext& context) {
    Error error;
    try {
        throw;
    } catch (const InputError& e) {
        error.message = e.message();
        error.file = e.where().file.str();
        error.line = e.where().line;
        error.column = e.where().column;
        error.kind = Error::Kind::bad_input;
        return error;
    } catch (const std::invalid_argument& e) {
        error.message = e.what();
        error.kind = Error::Kind::bad_input;
        return error;
    } catch (const std::bad_alloc&) {
        // A scene, mesh or image too large for this machine's memory: an error, never an abort.
        error.message = "out of memory while " + context.doing;
        error.kind = Error::Kind::failure;
    } catch (const FileChangedWhileRead& e) {
        // Not the input's fault: another program changed it under the reader.
        error.message = e.what();
        error.kind = Error::Kind::failure;
    } catch (const std::exception& e) {
        error.message = e.what();
        error.kind = context.otherwise;
    }
    error.file = context.file;
    return error;
}

}  // namespace whitted::api
