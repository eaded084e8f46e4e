// SPDX-License-Identifier: MIT
#include "scene/text_checks.h"

#include "scene/source_location.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <mutex>
#include <string>
#include <vector>

namespace whitted {
namespace {

/// The mappings of MappedTextFile that the SIGBUS handler may mend: [begin, end) in whole pages.
/// Lock-free atomics only, so that the handler can read them at any moment.
struct GuardedMapping {
    std::atomic<bool> taken{false};
    std::atomic<uintptr_t> begin{0}, end{0};  ///< begin 0: no mapping
    std::atomic<bool> cut{false};             ///< a page of it was past the file's end
};
constexpr int guarded_mappings = 64;  // files mapped at once; more are read with read() instead
GuardedMapping g_guarded[guarded_mappings];
struct sigaction g_previous_sigbus {};
uintptr_t g_page_size = 4096;

/// A read of a mapped file's page that the file no longer has (it was truncated) raises SIGBUS.
/// When the page is one of ours, zeros are mapped from it to the mapping's end and the read
/// goes on; the reader learns of the cut through MappedTextFile::changed(). mmap is a plain
/// system call, safe here though POSIX does not list it. Any other SIGBUS: the handler that was
/// there before is put back and the fault happens again (or the signal is raised again) under it.
void on_sigbus(int, siginfo_t* info, void*) {
    const auto address = reinterpret_cast<uintptr_t>(info->si_addr);
    if (info->si_code > 0) {  // a fault, not a signal someone sent
        for (GuardedMapping& mapping : g_guarded) {
            const uintptr_t begin = mapping.begin.load(std::memory_order_acquire);
            const uintptr_t end = mapping.end.load(std::memory_order_acquire);
            if (begin == 0 || address < begin || address >= end) continue;
            const uintptr_t page = address & ~(g_page_size - 1);
            if (::mmap(reinterpret_cast<void*>(page), end - page, PROT_READ, MAP_PRIVATE | MAP_ANONYMOUS | MAP_FIXED,
                       -1, 0) == MAP_FAILED)
                break;
            mapping.cut.store(true, std::memory_order_release);
            return;
        }
    }
    ::sigaction(SIGBUS, &g_previous_sigbus, nullptr);
    if (info->si_code <= 0) ::raise(SIGBUS);
}

/// A slot for a mapping of `length` bytes at `address`, or -1 when all are taken.
int guard_mapping(void* address, size_t length) {
    static std::once_flag installed;
    std::call_once(installed, [] {
        g_page_size = uintptr_t(::sysconf(_SC_PAGESIZE));
        struct sigaction action {};
        action.sa_sigaction = on_sigbus;
        action.sa_flags = SA_SIGINFO | SA_RESTART;
        sigemptyset(&action.sa_mask);
        ::sigaction(SIGBUS, &action, &g_previous_sigbus);
    });
    for (int slot = 0; slot < guarded_mappings; ++slot) {
        if (g_guarded[slot].taken.exchange(true)) continue;
        const auto begin = reinterpret_cast<uintptr_t>(address);
        g_guarded[slot].cut.store(false);
        g_guarded[slot].end.store((begin + length + g_page_size - 1) & ~(g_page_size - 1), std::memory_order_release);
        g_guarded[slot].begin.store(begin, std::memory_order_release);
        return slot;
    }
    return -1;
}

void release_mapping(int slot) {
    g_guarded[slot].begin.store(0, std::memory_order_release);
    g_guarded[slot].end.store(0, std::memory_order_release);
    g_guarded[slot].taken.store(false);
}

/// The files read while an InputFilesNoted lives.
std::mutex g_noted_mutex;
int g_noting = 0;
std::vector<NotedInput> g_noted;

void note_input(const struct stat& info, const std::string& path, const std::string& what) {
    const std::lock_guard<std::mutex> lock(g_noted_mutex);
    if (g_noting > 0)
        g_noted.push_back({uint64_t(info.st_dev), uint64_t(info.st_ino), "the " + what + " '" + path + "'"});
}

}  // namespace

InputFilesNoted::InputFilesNoted() {
    const std::lock_guard<std::mutex> lock(g_noted_mutex);
    ++g_noting;
    m_first = g_noted.size();  // the list is cleared only when no InputFilesNoted lives
}

InputFilesNoted::~InputFilesNoted() {
    const std::lock_guard<std::mutex> lock(g_noted_mutex);
    if (--g_noting == 0) g_noted.clear();
}

std::vector<NotedInput> InputFilesNoted::noted() const {
    const std::lock_guard<std::mutex> lock(g_noted_mutex);
    return {g_noted.begin() + std::ptrdiff_t(m_first), g_noted.end()};
}

std::string input_file_at(const std::string& target, const std::vector<NotedInput>& inputs) {
    struct stat info {};
    if (::stat(target.c_str(), &info) != 0) return {};
    for (const NotedInput& input : inputs)
        if (input.device == uint64_t(info.st_dev) && input.inode == uint64_t(info.st_ino)) return input.what;
    return {};
}

std::string input_file_at(const std::string& target) {
    const std::lock_guard<std::mutex> lock(g_noted_mutex);
    return input_file_at(target, g_noted);
}

std::string read_text_file(const std::string& path, int64_t max_bytes, const std::string& what) {
    const MappedTextFile file(path, max_bytes, what);
    return file.read([&] { return std::string(file.text()); });
}

bool is_plain_ascii(std::string_view text) {
    const auto* bytes = reinterpret_cast<const unsigned char*>(text.data());
    const size_t n = text.size();
    // 8 bytes at a time while they are all ASCII and none is NUL (mesh files are tens of
    // megabytes), then the tail byte by byte.
    size_t clean = 0;
    for (; clean + 8 <= n; clean += 8) {
        uint64_t word;
        std::memcpy(&word, bytes + clean, 8);
        constexpr uint64_t high = 0x8080808080808080ull, ones = 0x0101010101010101ull;
        if ((word & high) || ((word - ones) & ~word & high)) return false;
    }
    for (size_t i = clean; i < n; ++i)
        if (bytes[i] == 0 || bytes[i] >= 0x80) return false;
    return true;
}

void check_text_is_readable(std::string_view text, const std::string& path, const DoneBefore& done_before) {
    // Only text with something other than plain ASCII in it is looked at byte by byte. In parts,
    // so that each can be let go once checked; the scanner brings the pages back as it reads.
    constexpr size_t part = MappedTextFile::reader_stride;
    bool plain = true;
    for (size_t begin = 0; begin < text.size() && plain; begin += part) {
        if (done_before) done_before(begin);
        plain = is_plain_ascii(text.substr(begin, part));
    }
    if (plain) return;
    const auto* bytes = reinterpret_cast<const unsigned char*>(text.data());
    const size_t n = text.size();
    int line = 1, column = 1;
    for (size_t i = 0; i < n;) {
        const unsigned char c = bytes[i];
        if (c == 0) throw InputError({path, line, column}, "the file contains a NUL byte: is it a binary file?");
        size_t extra = 0;
        if (c < 0x80)
            extra = 0;
        else if ((c & 0xE0) == 0xC0 && c >= 0xC2)
            extra = 1;
        else if ((c & 0xF0) == 0xE0)
            extra = 2;
        else if ((c & 0xF8) == 0xF0 && c <= 0xF4)
            extra = 3;
        else
            throw InputError({path, line, column}, "the file is not valid UTF-8 text");
        if (i + extra >= n + (extra == 0 ? 1 : 0) && extra > 0 && i + extra >= n)
            throw InputError({path, line, column}, "the file is not valid UTF-8 text (truncated character)");
        for (size_t k = 1; k <= extra; ++k)
            if ((bytes[i + k] & 0xC0) != 0x80)
                throw InputError({path, line, column}, "the file is not valid UTF-8 text");
        // Overlong forms and UTF-16 surrogates (ED A0..BF ..) are not characters either.
        if (extra >= 2) {
            const unsigned char second = bytes[i + 1];
            if ((c == 0xE0 && second < 0xA0) || (c == 0xED && second > 0x9F) || (c == 0xF0 && second < 0x90) ||
                (c == 0xF4 && second > 0x8F))
                throw InputError({path, line, column}, "the file is not valid UTF-8 text");
        }
        if (ends_line(text, i))
            line += 1, column = 1;
        else
            column += 1;
        i += extra + 1;
    }
}

std::string printable(std::string_view text, size_t max_characters) {
    static constexpr char hex[] = "0123456789abcdef";
    std::string out;
    size_t characters = 0, i = 0;
    for (; i < text.size() && characters < max_characters; ++characters) {
        const auto c = static_cast<unsigned char>(text[i]);
        if (c < 0x20 || c == 0x7F) {
            out += c == '\n' ? "\\n" : c == '\t' ? "\\t" : std::string{'\\', 'x', hex[c >> 4], hex[c & 15]};
            ++i;
            continue;
        }
        // One UTF-8 character, or a byte that does not start one (Latin-1 text, say), escaped. C1
        // controls (U+0080 to U+009F: U+009B is a terminal's CSI) are escaped as the C0 ones are.
        const size_t length = c < 0x80             ? 1
                              : (c & 0xE0) == 0xC0 ? 2
                              : (c & 0xF0) == 0xE0 ? 3
                              : (c & 0xF8) == 0xF0 ? 4
                                                   : 0;
        bool valid = length > 0 && i + length <= text.size();
        for (size_t k = 1; valid && k < length; ++k) valid = (static_cast<unsigned char>(text[i + k]) & 0xC0) == 0x80;
        const bool c1 = valid && length == 2 && c == 0xC2 && static_cast<unsigned char>(text[i + 1]) < 0xA0;
        if (!valid || c1) {
            const auto shown = c1 ? static_cast<unsigned char>(text[i + 1]) : c;
            out += std::string{'\\', 'x', hex[shown >> 4], hex[shown & 15]};
            i += c1 ? 2 : 1;
            continue;
        }
        out.append(text.substr(i, length));
        i += length;
    }
    if (i < text.size()) out += "... (" + std::to_string(text.size()) + " bytes)";
    return out;
}

MappedTextFile::MappedTextFile(const std::string& path, int64_t max_bytes, const std::string& what) {
    std::error_code error;
    const auto status = std::filesystem::status(path, error);
    if (error || !std::filesystem::exists(status)) throw InputError({path}, what + " not found");
    if (std::filesystem::is_directory(status)) throw InputError({path}, what + " is a directory, not a file");
    // Only regular files: a device (/dev/urandom, /dev/zero) has no end to check a limit against,
    // and opening a FIFO blocks until a writer comes, so a render would hang before any message.
    // Checked before the open and again on the open descriptor (the path may change in between);
    // O_NONBLOCK keeps that open from waiting on a FIFO put there meanwhile.
    if (!std::filesystem::is_regular_file(status)) throw InputError({path}, what + " is not a regular file");
    const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
    if (fd < 0) throw InputError({path}, "cannot open the " + what + ": " + std::strerror(errno));
    struct stat info {};
    if (::fstat(fd, &info) != 0 || !S_ISREG(info.st_mode)) {
        ::close(fd);
        throw InputError({path}, what + " is not a regular file");
    }
    if (info.st_size > max_bytes) {
        ::close(fd);
        throw InputError(
            {path}, what + " is " + std::to_string(info.st_size) + " bytes; the limit is " + std::to_string(max_bytes));
    }
    note_input(info, path, what);
    m_path = path;
    m_what = what;
    m_fd = fd;
    m_length = size_t(info.st_size);
    if (m_length > 0) {
        m_address = ::mmap(nullptr, m_length, PROT_READ, MAP_PRIVATE, fd, 0);
        if (m_address == MAP_FAILED) {
            m_address = nullptr;
            const int mmap_errno = errno;
            ::close(fd);
            throw InputError({path}, "cannot read the " + what + ": " + std::strerror(mmap_errno));
        }
        m_guard = guard_mapping(m_address, m_length);
        if (m_guard < 0) {
            // Every slot taken (64 files mapped at once): this one is copied instead.
            ::munmap(m_address, m_length);
            m_address = nullptr;
            m_copy.resize(m_length);
            size_t done = 0;
            while (done < m_length) {
                const ssize_t got = ::pread(fd, m_copy.data() + done, m_length - done, off_t(done));
                if (got < 0 && errno == EINTR) continue;
                if (got < 0) {
                    const int read_errno = errno;
                    ::close(fd);
                    throw InputError({path}, "cannot read the " + what + ": " + std::strerror(read_errno));
                }
                if (got == 0) {
                    ::close(fd);
                    m_fd = -1;
                    throw_changed();
                }
                done += size_t(got);
            }
            m_text = m_copy;
            return;
        }
        ::madvise(m_address, m_length, MADV_WILLNEED);  // read ahead (the kernel's page cache)
        m_text = std::string_view(static_cast<const char*>(m_address), m_length);
    }
}

bool MappedTextFile::changed() const {
    if (m_guard >= 0 && g_guarded[m_guard].cut.load(std::memory_order_acquire)) return true;
    struct stat info {};
    return m_fd >= 0 && ::fstat(m_fd, &info) == 0 && size_t(info.st_size) != m_length;
}

void MappedTextFile::throw_changed() const {
    struct stat info {};
    const std::string now = m_fd >= 0 && ::fstat(m_fd, &info) == 0 ? std::to_string(info.st_size) + " bytes" : "?";
    throw FileChangedWhileRead("the " + m_what + " '" + m_path + "' changed while it was read (" +
                               std::to_string(m_length) + " bytes when opened, " + now +
                               " now): another program is writing or truncating it; nothing from it was used");
}

void MappedTextFile::reader_at(size_t offset) {
    static const size_t page = size_t(::sysconf(_SC_PAGESIZE));
    if (!m_address) return;
    offset = std::min(offset, m_length);
    const size_t behind = offset / page * page;
    if (behind < m_let_go) m_let_go = 0;  // a reader going through again (the scanner after the check)
    // A private, read-only file mapping never written: MADV_DONTNEED drops the page table
    // entries only, and a later read faults the same bytes back in from the page cache.
    if (behind > m_let_go) ::madvise(static_cast<char*>(m_address) + m_let_go, behind - m_let_go, MADV_DONTNEED);
    m_let_go = behind;
    // The part ahead, mapped in one call (Linux 5.14 on; older kernels refuse the advice and
    // the reader's page faults do it, as they did before).
    const size_t ahead_end = std::min(m_length, behind + reader_stride + page);
    if (ahead_end > behind) ::madvise(static_cast<char*>(m_address) + behind, ahead_end - behind, MADV_POPULATE_READ);
}

MappedTextFile::~MappedTextFile() {
    if (m_guard >= 0) release_mapping(m_guard);
    if (m_address) ::munmap(m_address, m_length);
    if (m_fd >= 0) ::close(m_fd);
}

}  // namespace whitted
