// SPDX-License-Identifier: MIT
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace whitted {

/// Reads a whole file, refusing files larger than `max_bytes`, directories, devices, FIFOs and
/// other files that are not regular, and unreadable paths, with an InputError naming the file
/// (`what` says what the file was meant to be).
std::string read_text_file(const std::string& path, int64_t max_bytes, const std::string& what);

/// True when every byte is ASCII and none is NUL: such text needs no closer look.
bool is_plain_ascii(std::string_view text);

/// Refuses text a YAML parser should never see: NUL bytes (binary files) and invalid UTF-8,
/// reported at the line and column of the first bad byte.
void check_text_is_readable(std::string_view text, const std::string& path);

/// A file mapped into memory, read-only (mesh files are tens of megabytes: no copy, no zeroed
/// buffer). Throws InputError like read_text_file.
class MappedTextFile {
public:
    MappedTextFile(const std::string& path, int64_t max_bytes, const std::string& what);
    ~MappedTextFile();
    MappedTextFile(const MappedTextFile&) = delete;
    MappedTextFile& operator=(const MappedTextFile&) = delete;
    std::string_view text() const { return m_text; }

private:
    std::string_view m_text;
    void* m_address = nullptr;
    size_t m_length = 0;
};

/// `text` made safe to print in a message: control characters (ESC, BEL, ...) written as \xNN
/// escapes, so a scene cannot drive the terminal, and at most `max_characters` characters, the
/// rest replaced by "... (N bytes)". `text` must be valid UTF-8 (as a checked scene is).
std::string printable(std::string_view text, size_t max_characters = 60);

/// " (did you mean 'x'?)" for the closest candidate within a small edit distance, else "".
std::string did_you_mean(const std::string& word, const std::vector<std::string>& candidates);

}  // namespace whitted
