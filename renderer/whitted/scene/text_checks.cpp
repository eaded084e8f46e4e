// SPDX-License-Identifier: MIT
#include "whitted/scene/text_checks.h"

#include "whitted/scene/source_location.h"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <filesystem>

namespace whitted {

std::string read_text_file(const std::string& path, int64_t max_bytes, const std::string& what) {
    const MappedTextFile file(path, max_bytes, what);
    return std::string(file.text());
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
    m_length = size_t(info.st_size);
    if (m_length > 0) {
        m_address = ::mmap(nullptr, m_length, PROT_READ, MAP_PRIVATE, fd, 0);
        if (m_address == MAP_FAILED) {
            m_address = nullptr;
            const int mmap_errno = errno;
            ::close(fd);
            throw InputError({path}, "cannot read the " + what + ": " + std::strerror(mmap_errno));
        }
        ::madvise(m_address, m_length, MADV_WILLNEED);  // read ahead (the kernel's page cache)
        m_text = std::string_view(static_cast<const char*>(m_address), m_length);
    }
    ::close(fd);
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
    if (m_address) ::munmap(m_address, m_length);
}

}  // namespace whitted
