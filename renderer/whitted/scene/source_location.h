// SPDX-License-Identifier: MIT
#pragma once

#include <stdexcept>
#include <string>

namespace whitted {

/// Where a value came from: a file and a 1-based line and column (0 when unknown).
struct SourceLocation {
    std::string file;
    int line = 0;
    int column = 0;

    /// "file:line:col" (or "file" alone when the position is unknown).
    std::string str() const;
};

/// Anything wrong with the user's input (scene, mesh, command line). The program reports it as
/// "FILE:LINE:COL: message" and exits with status 2.
class InputError : public std::runtime_error {
public:
    InputError(SourceLocation where, const std::string& message);
    const SourceLocation& where() const { return m_where; }
    const std::string& message() const { return m_message; }

private:
    SourceLocation m_where;
    std::string m_message;
};

}  // namespace whitted
