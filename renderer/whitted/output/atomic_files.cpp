// SPDX-License-Identifier: MIT
#include "whitted/output/atomic_files.h"

#include <fcntl.h>
#include <unistd.h>

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

std::string temporary_name(const std::filesystem::path& target) {
    const std::filesystem::path directory = target.parent_path().empty() ? "." : target.parent_path();
    return (directory / ("." + target.filename().string() + ".whitted-" + std::to_string(::getpid()) + ".tmp"))
        .string();
}

[[noreturn]] void fail(const std::filesystem::path& target, const std::string& what) {
    throw std::runtime_error("cannot write '" + target.string() + "': " + what + ": " + std::strerror(errno));
}

void open_file(Pending& file) {
    const std::filesystem::path directory = file.target.parent_path().empty() ? "." : file.target.parent_path();
    file.fd = ::open(directory.c_str(), O_TMPFILE | O_WRONLY | O_CLOEXEC, 0644);
    if (file.fd >= 0) return;
    // No unnamed files here (an older kernel, or a filesystem such as NFS): a named one.
    file.temporary = temporary_name(file.target);
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
    const std::string name = temporary_name(file.target);
    const std::string self = "/proc/self/fd/" + std::to_string(file.fd);
    if (::linkat(AT_FDCWD, self.c_str(), AT_FDCWD, name.c_str(), AT_SYMLINK_FOLLOW) != 0 &&
        ::linkat(file.fd, "", AT_FDCWD, name.c_str(), AT_EMPTY_PATH) != 0)
        fail(file.target, "cannot name the finished file");
    file.temporary = name;
}

}  // namespace

void write_files_atomically(const std::vector<std::pair<std::filesystem::path, std::string_view>>& files) {
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
        for (Pending& file : pending) {
            if (std::rename(file.temporary.c_str(), file.target.c_str()) != 0)
                fail(file.target, "cannot move the finished file into place");
            file.temporary.clear();
        }
    } catch (...) {
        for (Pending& file : pending) {
            if (file.fd >= 0) ::close(file.fd);
            if (!file.temporary.empty()) ::unlink(file.temporary.c_str());
        }
        throw;
    }
}

}  // namespace whitted
