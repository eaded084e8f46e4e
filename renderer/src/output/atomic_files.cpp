// SPDX-License-Identifier: MIT
#include "output/atomic_files.h"

#include <dirent.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <string>

namespace whitted {
namespace {

/// One file being written: its descriptor, and its temporary name once it has one.
struct Pending {
    std::filesystem::path target;
    int fd = -1;
    std::string temporary;  ///< empty while the file is unnamed
};

[[noreturn]] void fail(const std::filesystem::path& target, const std::string& what) {
    throw std::runtime_error("cannot write '" + target.string() + "': " + what + ": " + std::strerror(errno));
}

void open_file(Pending& file) {
    const std::filesystem::path directory = file.target.parent_path().empty() ? "." : file.target.parent_path();
    file.fd = ::open(directory.c_str(), O_TMPFILE | O_WRONLY | O_CLOEXEC, 0644);
    if (file.fd >= 0) return;
    // No unnamed files here (an older kernel, or a filesystem such as NFS): a named one.
    file.temporary = temporary_path(file.target);
    file.fd = ::open(file.temporary.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (file.fd < 0) {
        file.temporary.clear();
        fail(file.target, "cannot create a temporary file");
    }
}

void write_all(const Pending& file, std::string_view bytes) {
    while (!bytes.empty()) {
        const ssize_t written = ::write(file.fd, bytes.data(), bytes.size());
        if (written < 0 && errno == EINTR) continue;
        if (written <= 0) fail(file.target, "write failed");
        bytes.remove_prefix(size_t(written));
    }
}

/// Gives an unnamed file its temporary name.
void name_file(Pending& file) {
    if (!file.temporary.empty()) return;
    const std::string name = temporary_path(file.target);
    const std::string self = "/proc/self/fd/" + std::to_string(file.fd);
    if (::linkat(AT_FDCWD, self.c_str(), AT_FDCWD, name.c_str(), AT_SYMLINK_FOLLOW) != 0 &&
        ::linkat(file.fd, "", AT_FDCWD, name.c_str(), AT_EMPTY_PATH) != 0)
        fail(file.target, "cannot name the finished file");
    file.temporary = name;
}

/// Holds an exclusive flock on each directory given (in sorted order, so two writers never wait
/// for each other crosswise) until destroyed. Every writer of a set of files takes it for its
/// renames, so two of them can never interleave: `whitted convert` run twice at once to the
/// same name leaves one run's .pov and .ini, never one of each. A lock on the directory itself
/// leaves no lock file behind. Where flock is unsupported the writers are simply not serialised.
class DirectoryLocks {
public:
    explicit DirectoryLocks(std::vector<std::filesystem::path> directories) {
        std::sort(directories.begin(), directories.end());
        directories.erase(std::unique(directories.begin(), directories.end()), directories.end());
        for (const auto& directory : directories) {
            const int fd = ::open(directory.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
            if (fd < 0) continue;  // the rename will then fail with its own, clearer, reason
            while (::flock(fd, LOCK_EX) != 0 && errno == EINTR) {
            }
            m_fds.push_back(fd);
        }
    }
    ~DirectoryLocks() {
        for (const int fd : m_fds) ::close(fd);  // closing releases the lock
    }
    DirectoryLocks(const DirectoryLocks&) = delete;
    DirectoryLocks& operator=(const DirectoryLocks&) = delete;

private:
    std::vector<int> m_fds;
};

std::filesystem::path directory_of(const std::filesystem::path& target) {
    return target.parent_path().empty() ? "." : target.parent_path();
}

/// The mode a new file takes from the one it replaces: its permission bits (a private 0600
/// output stays private), never set-user-ID, set-group-ID or sticky (an image is no program).
mode_t kept_mode(mode_t replaced) {
    return replaced & 0777;
}

/// A finished file moved to its target, and how to take that back.
struct Moved {
    std::filesystem::path target;
    std::string temporary;    ///< after an exchange: the previous file, under the temporary name
    bool exchanged = false;   ///< the previous file is at `temporary`
    bool was_absent = false;  ///< nothing was at `target` before (undo: remove it)
};

Moved move_keeping_previous(const std::string& temporary, const std::filesystem::path& target) {
    Moved moved{target, temporary};
    struct stat existing {};
    const bool exists = ::lstat(target.c_str(), &existing) == 0;
    if (exists && S_ISREG(existing.st_mode)) ::chmod(temporary.c_str(), kept_mode(existing.st_mode));
    if (exists && S_ISREG(existing.st_mode) &&
        ::renameat2(AT_FDCWD, temporary.c_str(), AT_FDCWD, target.c_str(), RENAME_EXCHANGE) == 0) {
        moved.exchanged = true;
        return moved;
    }
    if (std::rename(temporary.c_str(), target.c_str()) != 0)
        throw std::runtime_error("cannot move the finished file to '" + target.string() + "': " + std::strerror(errno));
    moved.was_absent = !exists;
    return moved;
}

/// Puts back what was at a target before (best effort: this runs while an error is on its way).
void undo(const Moved& moved) {
    if (moved.exchanged) {
        if (::renameat2(AT_FDCWD, moved.temporary.c_str(), AT_FDCWD, moved.target.c_str(), RENAME_EXCHANGE) == 0)
            ::unlink(moved.temporary.c_str());  // the new file
    } else if (moved.was_absent) {
        ::unlink(moved.target.c_str());
    }
    // Else a symlink or other non-file was replaced by a rename: it cannot be brought back.
}

/// The temporary name temporary_path gives `target` in process `pid`.
std::string temporary_name(const std::filesystem::path& target, long pid) {
    const std::string suffix = ".whitted-" + std::to_string(pid) + ".tmp" + target.extension().string();
    std::string name = target.filename().string();
    // A legal name near the 255-byte limit must not fail on the longer temporary one after
    // the render: the name is cut short (its start is kept; the suffix still marks the file).
    constexpr size_t most = 255;
    if (1 + name.size() + suffix.size() > most) name.resize(most - 1 - std::min(suffix.size(), most - 1));
    return "." + name + suffix;
}

/// SIGKILL cannot be caught, and between naming a finished file and moving it into place (or
/// between swapping the previous file out and deleting it) a killed process leaves its
/// temporary behind. The next write of the same target removes those whose process is gone,
/// so they never pile up; a live process's are left alone, as is anything that merely looks
/// similar (the name must be exactly what temporary_path gave that process).
void remove_abandoned_temporaries(const std::filesystem::path& target) {
    const std::filesystem::path directory = target.parent_path().empty() ? "." : target.parent_path();
    const std::string marker = ".whitted-";
    DIR* listing = ::opendir(directory.c_str());
    if (!listing) return;
    while (const dirent* entry = ::readdir(listing)) {
        const std::string name = entry->d_name;
        const size_t at = name.rfind(marker);
        if (name.empty() || name[0] != '.' || at == std::string::npos) continue;
        char* end = nullptr;
        const long pid = std::strtol(name.c_str() + at + marker.size(), &end, 10);
        if (pid <= 0 || pid == ::getpid() || name != temporary_name(target, pid)) continue;
        if (::kill(pid_t(pid), 0) == 0 || errno != ESRCH) continue;  // still running (or not ours to ask)
        ::unlinkat(::dirfd(listing), name.c_str(), 0);
    }
    ::closedir(listing);
}

}  // namespace

std::string temporary_path(const std::filesystem::path& target) {
    const std::filesystem::path directory = target.parent_path().empty() ? "." : target.parent_path();
    return (directory / temporary_name(target, ::getpid())).string();
}

void refuse_special_target(const std::filesystem::path& target) {
    struct stat existing {};
    if (::stat(target.c_str(), &existing) == 0 && !S_ISREG(existing.st_mode) && !S_ISDIR(existing.st_mode))
        throw std::runtime_error("cannot write '" + target.string() +
                                 "': it is not a regular file (a device, FIFO or socket); Whitted writes only "
                                 "regular files and never replaces anything else");
}

void check_can_write(const std::filesystem::path& target) {
    const std::filesystem::path directory = directory_of(target);
    std::error_code error;
    if (!std::filesystem::is_directory(directory, error))
        throw std::invalid_argument("cannot write '" + target.string() + "': directory '" + directory.string() +
                                    "' does not exist");
    if (std::filesystem::is_directory(target, error))
        throw std::invalid_argument("cannot write '" + target.string() + "': it is a directory");
    try {
        refuse_special_target(target);
    } catch (const std::runtime_error& e) {
        throw std::invalid_argument(e.what());
    }
    // A file made and dropped where the output will go. access(W_OK) is not enough: root passes
    // it in an immutable (chattr +i) or read-only-mounted directory, where the write would fail.
    const auto refuse = [&](int error_number) {
        throw std::invalid_argument("cannot write '" + target.string() + "': cannot create a file in directory '" +
                                    directory.string() + "': " + std::strerror(error_number));
    };
    int fd = ::open(directory.c_str(), O_TMPFILE | O_WRONLY | O_CLOEXEC, 0600);
    if (fd >= 0) {
        ::close(fd);  // unnamed: gone with its descriptor
        return;
    }
    if (errno != EOPNOTSUPP && errno != EISDIR && errno != EINVAL) refuse(errno);
    // No unnamed files on this filesystem: a named one, removed at once.
    const std::string probe = temporary_path(target);
    fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
    if (fd < 0) refuse(errno);
    ::close(fd);
    ::unlink(probe.c_str());
}

void refuse_symlink_target(const std::filesystem::path& target) {
    struct stat existing {};
    if (::lstat(target.c_str(), &existing) != 0 || !S_ISLNK(existing.st_mode)) return;
    std::error_code error;
    const std::filesystem::path points_to = std::filesystem::read_symlink(target, error);
    throw std::invalid_argument("cannot write '" + target.string() + "': it is a symbolic link" +
                                (error ? std::string() : " to '" + points_to.string() + "'") +
                                "; Whitted neither writes through a link nor replaces it: name the file itself");
}

void move_into_place(const std::string& temporary, const std::filesystem::path& target) {
    refuse_special_target(target);
    remove_abandoned_temporaries(target);
    // An existing file is swapped out atomically (RENAME_EXCHANGE) and then deleted under the
    // temporary name: a rename over it made ext4 start writing the new file to disk before
    // returning (its "auto_da_alloc" for replace-by-rename), 10 ms for a 1280x960 float EXR
    // against under 1 ms this way. Anything but a regular file there (nothing, a link, a
    // directory), or a filesystem that cannot exchange: a plain rename, with its refusals.
    struct stat existing {};
    const bool regular = ::lstat(target.c_str(), &existing) == 0 && S_ISREG(existing.st_mode);
    if (regular) ::chmod(temporary.c_str(), kept_mode(existing.st_mode));
    if (regular && ::renameat2(AT_FDCWD, temporary.c_str(), AT_FDCWD, target.c_str(), RENAME_EXCHANGE) == 0) {
        std::remove(temporary.c_str());  // the old file
        return;
    }
    if (std::rename(temporary.c_str(), target.c_str()) != 0)
        throw std::runtime_error("cannot move the finished file to '" + target.string() + "': " + std::strerror(errno));
}

void write_files_atomically(const std::vector<std::pair<std::filesystem::path, std::string_view>>& files) {
    for (const auto& [target, bytes] : files) refuse_special_target(target);  // before a byte is written
    std::vector<Pending> pending(files.size());
    try {
        for (size_t i = 0; i < files.size(); ++i) {
            pending[i].target = files[i].first;
            open_file(pending[i]);
            write_all(pending[i], files[i].second);
        }
        for (Pending& file : pending) {
            name_file(file);  // an unnamed file must be linked while it is still open
            const int fd = file.fd;
            file.fd = -1;
            if (::close(fd) != 0 && errno != EINTR) fail(file.target, "write failed");  // e.g. NFS quota
        }
        // Refused before anything is renamed: a directory in the way would fail its rename
        // after the files before it had already replaced theirs.
        for (const Pending& file : pending) {
            struct stat existing {};
            if (::lstat(file.target.c_str(), &existing) == 0 && S_ISDIR(existing.st_mode)) {
                throw std::runtime_error("cannot write '" + file.target.string() + "': it is a directory");
            }
        }
        for (const Pending& file : pending) remove_abandoned_temporaries(file.target);
        std::vector<Moved> moved;
        {
            std::vector<std::filesystem::path> directories;
            for (const Pending& file : pending) directories.push_back(directory_of(file.target));
            const DirectoryLocks locks(directories);
            try {
                for (Pending& file : pending) {
                    moved.push_back(move_keeping_previous(file.temporary, file.target));
                    file.temporary.clear();
                }
            } catch (...) {
                // All or nothing: the files already moved give their places back.
                for (auto it = moved.rbegin(); it != moved.rend(); ++it) undo(*it);
                throw;
            }
        }
        for (const Moved& file : moved)
            if (file.exchanged) ::unlink(file.temporary.c_str());  // the previous file
    } catch (...) {
        for (Pending& file : pending) {
            if (file.fd >= 0) ::close(file.fd);
            if (!file.temporary.empty()) ::unlink(file.temporary.c_str());
        }
        throw;
    }
}

}  // namespace whitted
