// SPDX-License-Identifier: MIT
// Runs POV-Ray as a child process. No shell is involved: the scene's directory may hold any
// character, and a shell would reinterpret them. POV-Ray's chatter goes to a log file (never
// to our terminal) and is shown only when it fails.

#include "reference/povray.h"

#include "output/atomic_files.h"
#include "reference/check.h"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <thread>
#include <vector>

extern char** environ;

namespace whitted::reference {
namespace {

namespace fs = std::filesystem;

constexpr const char* install_hint =
    "POV-Ray 3.7 is needed for `whitted check`: apt-get install povray "
    "(or set WHITTED_POVRAY to the povray program)";

bool is_executable_file(const fs::path& path) {
    std::error_code error;
    return fs::is_regular_file(path, error) && ::access(path.c_str(), X_OK) == 0;
}

/// Frees posix_spawn's file actions on every path out.
class SpawnActions {
public:
    SpawnActions() { ::posix_spawn_file_actions_init(&m_actions); }
    ~SpawnActions() { ::posix_spawn_file_actions_destroy(&m_actions); }
    SpawnActions(const SpawnActions&) = delete;
    SpawnActions& operator=(const SpawnActions&) = delete;
    posix_spawn_file_actions_t* get() { return &m_actions; }

private:
    posix_spawn_file_actions_t m_actions;
};

std::string read_text(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
}

std::string last_lines(const std::string& text, int count) {
    size_t start = text.size();
    // Skip trailing newlines so that "the last lines" are lines with text.
    while (start > 0 && (text[start - 1] == '\n' || text[start - 1] == '\r')) --start;
    const size_t end = start;
    for (int found = 0; start > 0; --start) {
        if (text[start - 1] == '\n' && ++found == count) break;
    }
    return text.substr(start, end - start);
}

/// Waits for `pid` for at most `limit`; true once it is reaped.
bool reap(pid_t pid, int& status, std::chrono::milliseconds limit) {
    const auto until = std::chrono::steady_clock::now() + limit;
    for (;;) {
        const pid_t done = ::waitpid(pid, &status, WNOHANG);
        if (done == pid) return true;
        if (done < 0 && errno != EINTR)
            throw std::runtime_error("lost track of POV-Ray: " + std::string(std::strerror(errno)));
        if (std::chrono::steady_clock::now() >= until) return false;
        // Polled rather than blocked in waitpid so that a cancel request is seen within 10 ms.
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
}

/// Ends POV-Ray and whatever it started: SIGTERM to its process group lets it exit by itself,
/// SIGKILL to the group follows if it does not within 2 s, and once more after it is reaped, for
/// what outlives it (the POV-Ray a wrapper script runs as its child: SIGTERM to the script alone
/// left that child rendering). The group's id cannot be reused while a member lives.
void stop(pid_t pid) {
    int status = 0;
    ::kill(-pid, SIGTERM);
    if (!reap(pid, status, std::chrono::milliseconds(2000))) {
        ::kill(-pid, SIGKILL);
        while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
        }
    }
    ::kill(-pid, SIGKILL);
}

/// posix_spawn's attributes, freed on every path out: POV-Ray in a process group of its own.
class SpawnGroup {
public:
    SpawnGroup() {
        ::posix_spawnattr_init(&m_attributes);
        // No signal blocked or ignored: a caller that blocks SIGTERM for a thread of its own to
        // take (`whitted live`) would pass the mask on, and POV-Ray would then not end at stop()'s
        // SIGTERM but only at the SIGKILL 2 s later.
        sigset_t none, stop_signals;
        sigemptyset(&none);
        sigemptyset(&stop_signals);
        sigaddset(&stop_signals, SIGINT);
        sigaddset(&stop_signals, SIGTERM);
        m_ready = ::posix_spawnattr_setflags(
                      &m_attributes, POSIX_SPAWN_SETPGROUP | POSIX_SPAWN_SETSIGMASK | POSIX_SPAWN_SETSIGDEF) == 0 &&
                  ::posix_spawnattr_setpgroup(&m_attributes, 0) == 0 &&
                  ::posix_spawnattr_setsigmask(&m_attributes, &none) == 0 &&
                  ::posix_spawnattr_setsigdefault(&m_attributes, &stop_signals) == 0;
    }
    ~SpawnGroup() { ::posix_spawnattr_destroy(&m_attributes); }
    SpawnGroup(const SpawnGroup&) = delete;
    SpawnGroup& operator=(const SpawnGroup&) = delete;
    const posix_spawnattr_t* get() const { return &m_attributes; }
    bool ready() const { return m_ready; }

private:
    posix_spawnattr_t m_attributes;
    bool m_ready = false;
};

}  // namespace

TemporaryDirectory::TemporaryDirectory(const std::string& prefix) {
    std::error_code error;
    fs::path base = fs::temp_directory_path(error);
    if (error) base = "/tmp";
    std::string pattern = (base / (prefix + "XXXXXX")).string();
    if (!::mkdtemp(pattern.data()))
        throw std::runtime_error("cannot create a temporary directory in '" + base.string() +
                                 "': " + std::strerror(errno));
    m_path = pattern;
}

TemporaryDirectory::~TemporaryDirectory() {
    std::error_code error;
    fs::remove_all(m_path, error);  // best effort: a destructor must not throw
}

std::string find_povray() {
    const char* given = std::getenv("WHITTED_POVRAY");
    const std::string name = given && *given ? given : "povray";
    if (name.find('/') != std::string::npos) {
        if (!is_executable_file(name))
            throw std::runtime_error("WHITTED_POVRAY='" + name + "' is not an executable file. " + install_hint);
        return name;
    }
    const char* path_env = std::getenv("PATH");
    std::stringstream entries(path_env ? path_env : "/usr/local/bin:/usr/bin:/bin");
    std::string dir;
    while (std::getline(entries, dir, ':')) {
        const fs::path candidate = fs::path(dir.empty() ? "." : dir) / name;
        if (is_executable_file(candidate)) return candidate.string();
    }
    throw std::runtime_error("'" + name + "' was not found on PATH. " + install_hint);
}

PovrayRun run_povray(const std::string& ini_path, const std::string& log_path, const std::atomic<bool>* cancel) {
    PovrayRun run;
    run.program = find_povray();
    const fs::path ini = fs::absolute(ini_path);
    if (!fs::is_regular_file(ini)) throw std::runtime_error("POV-Ray options file '" + ini.string() + "' is missing");

    // POV-Ray wants a writable $HOME for its user settings; a private empty one also keeps the
    // user's own ~/.povray/3.7/povray.ini out of a reference render.
    const TemporaryDirectory home("whitted-povray-home-");
    const fs::path log = home.path() / "povray.log";

    std::vector<std::string> environment;
    for (char** entry = environ; entry && *entry; ++entry) {
        const std::string text = *entry;
        // POVINI would add a second options file behind our back.
        if (text.rfind("HOME=", 0) == 0 || text.rfind("POVINI=", 0) == 0) continue;
        environment.push_back(text);
    }
    environment.push_back("HOME=" + home.path().string());
    std::vector<char*> envp;
    for (auto& text : environment) envp.push_back(text.data());
    envp.push_back(nullptr);

    // "./" keeps a name starting with '+' or '-' from being read as an option.
    std::string program = run.program, ini_argument = "./" + ini.filename().string();
    std::vector<char*> argv{program.data(), ini_argument.data(), nullptr};

    SpawnActions actions;
    const std::string directory = ini.parent_path().string();
    if (::posix_spawn_file_actions_addchdir_np(actions.get(), directory.c_str()) != 0 ||
        ::posix_spawn_file_actions_addopen(actions.get(), STDIN_FILENO, "/dev/null", O_RDONLY, 0) != 0 ||
        ::posix_spawn_file_actions_addopen(actions.get(), STDOUT_FILENO, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC,
                                           0600) != 0 ||
        ::posix_spawn_file_actions_adddup2(actions.get(), STDOUT_FILENO, STDERR_FILENO) != 0)
        throw std::runtime_error("cannot prepare to run POV-Ray: " + std::string(std::strerror(errno)));

    // Its own process group, so that stop() ends everything it started. Ctrl-C in a terminal
    // then reaches whitted alone, which stops POV-Ray the same way.
    const SpawnGroup group;
    if (!group.ready()) throw std::runtime_error("cannot prepare to run POV-Ray: " + std::string(std::strerror(errno)));
    const auto start = std::chrono::steady_clock::now();
    pid_t pid = 0;
    if (const int error = ::posix_spawn(&pid, program.c_str(), actions.get(), group.get(), argv.data(), envp.data()))
        throw std::runtime_error("cannot run '" + program + "': " + std::strerror(error));
    int status = 0;
    while (!reap(pid, status, std::chrono::milliseconds(50))) {
        if (cancel && cancel->load()) {
            stop(pid);
            throw Interrupted();  // `home` (POV-Ray's $HOME and log) is removed on the way out
        }
    }
    // A signal that came as POV-Ray ended by itself.
    if (cancel && cancel->load()) throw Interrupted();
    run.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    run.log = read_text(log);
    // Replaced as a whole (a symlink planted there is replaced, not followed).
    if (!log_path.empty()) write_files_atomically({{log_path, run.log}});

    if (WIFEXITED(status) && WEXITSTATUS(status) == 0) return run;
    const std::string how = WIFEXITED(status)     ? "exit status " + std::to_string(WEXITSTATUS(status))
                            : WIFSIGNALED(status) ? "killed by signal " + std::to_string(WTERMSIG(status))
                                                  : "status " + std::to_string(status);
    // The log can be empty when the spawned process could not even start (chdir failed).
    throw std::runtime_error("POV-Ray failed (" + how + ") on '" + ini.string() + "'" +
                             (run.log.empty() ? std::string(" without any output") : ":\n" + last_lines(run.log, 20)));
}

}  // namespace whitted::reference
