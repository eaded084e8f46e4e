// SPDX-License-Identifier: MIT
#pragma once

#include <iosfwd>
#include <stdexcept>
#include <string>
#include <string_view>

namespace whitted {

/// A file name kept once for the whole run: every value of a scene (millions of them) records
/// where it was written, and a pointer to one shared copy of the name costs 8 bytes where a
/// std::string of its own cost 32 and often a heap block.
class FileName {
public:
    FileName() = default;
    FileName(const std::string& name);  // NOLINT: implicit, so `{path, line, column}` reads naturally
    FileName(const char* name) : FileName(std::string(name)) {}  // NOLINT
    const std::string& str() const { return m_name ? *m_name : empty_name(); }
    operator const std::string&() const { return str(); }  // NOLINT
    bool empty() const { return str().empty(); }

    friend bool operator==(const FileName& a, const FileName& b) { return a.str() == b.str(); }
    friend bool operator!=(const FileName& a, const FileName& b) { return !(a == b); }
    friend bool operator==(const FileName& a, const std::string& b) { return a.str() == b; }
    friend bool operator==(const FileName& a, std::string_view b) { return a.str() == b; }
    friend bool operator==(const FileName& a, const char* b) { return a.str() == b; }
    friend std::ostream& operator<<(std::ostream& out, const FileName& name);

private:
    static const std::string& empty_name();
    const std::string* m_name = nullptr;
};

/// Where a value came from: a file and a 1-based line and column (0 when unknown).
struct SourceLocation {
    FileName file;
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
