// SPDX-License-Identifier: MIT
#pragma once

#include <atomic>
#include <filesystem>
#include <string>

namespace whitted::reference {

/// The povray program on PATH (or $WHITTED_POVRAY). Throws std::runtime_error saying how to
/// install it when there is none.
std::string find_povray();

/// A fresh directory (mkdtemp under $TMPDIR) removed with everything in it when destroyed.
class TemporaryDirectory {
public:
    explicit TemporaryDirectory(const std::string& prefix);
    ~TemporaryDirectory();
    TemporaryDirectory(const TemporaryDirectory&) = delete;
    TemporaryDirectory& operator=(const TemporaryDirectory&) = delete;
    const std::filesystem::path& path() const { return m_path; }

private:
    std::filesystem::path m_path;
};

/// What one POV-Ray run printed, and how long it took.
struct PovrayRun {
    std::string program;  ///< the povray that ran
    std::string log;      ///< its stdout and stderr, interleaved as written
    double seconds = 0;
};

/// Renders `ini_path` (which names its scene and output) with POV-Ray, from the ini's
/// directory, with a private writable $HOME. Nothing is printed: the output is captured and
/// returned, and also written to `log_path` when one is given (even when POV-Ray fails; the
/// file is replaced, never written through a symlink found there). Throws std::runtime_error
/// with the last lines of POV-Ray's output when it fails. When `cancel` becomes true POV-Ray
/// is ended (SIGTERM, then SIGKILL if it has not exited within 2 s) and Interrupted (check.h)
/// is thrown.
PovrayRun run_povray(const std::string& ini_path, const std::string& log_path = "",
                     const std::atomic<bool>* cancel = nullptr);

}  // namespace whitted::reference
