// SPDX-License-Identifier: MIT
#pragma once

#include <cstdint>
#include <functional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace whitted {

/// True when the byte at `i` ends a line: a LF, or a CR that no LF follows. Every text format
/// (YAML, NFF, OBJ, MTL, course XML, .msh) counts lines this way, as YAML 1.2 does (a line break
/// is CR, LF or CRLF), so that a file saved with CR-only line ends (classic Mac OS) gets the same
/// LINE:COL in a message as the same file with LF or CRLF ends.
inline bool ends_line(std::string_view text, size_t i) {
    return text[i] == '\n' || (text[i] == '\r' && (i + 1 == text.size() || text[i + 1] != '\n'));
}

/// Reads a whole file, refusing files larger than `max_bytes`, directories, devices, FIFOs and
/// other files that are not regular, and unreadable paths, with an InputError naming the file
/// (`what` says what the file was meant to be).
std::string read_text_file(const std::string& path, int64_t max_bytes, const std::string& what);

/// True when every byte is ASCII and none is NUL: such text needs no closer look.
bool is_plain_ascii(std::string_view text);

/// Told an offset into a text by a reader that goes through it once: the reader is done with
/// what lies before it and about to read what follows (MappedTextFile::reader_at).
using DoneBefore = std::function<void(size_t offset)>;

/// Refuses text a YAML parser should never see: NUL bytes (binary files) and invalid UTF-8,
/// reported at the line and column of the first bad byte. `done_before`, if given, is told where
/// the check is, every MappedTextFile::reader_stride bytes of plain ASCII text.
void check_text_is_readable(std::string_view text, const std::string& path, const DoneBefore& done_before = {});

/// An input file that was cut short (truncated) or grown while it was read: whatever was read
/// from it is not the file. Not an InputError: the file may be fine; it changed under the reader
/// (a failure, exit 1). The message names the file.
class FileChangedWhileRead : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

/// A file mapped into memory, read-only (mesh files are tens of megabytes: no copy, no zeroed
/// buffer). Throws InputError like read_text_file.
///
/// A mapped file that another process truncates would kill the reader with SIGBUS at the first
/// byte past the new end. A SIGBUS handler knows every mapping made here: it puts zeros where
/// the cut pages were (the read goes on, reading zeros) and notes the cut; read() then throws
/// FileChangedWhileRead instead of returning what was read. A SIGBUS anywhere else is handled
/// as it was before. Every reader of text() must go through read().
class MappedTextFile {
public:
    MappedTextFile(const std::string& path, int64_t max_bytes, const std::string& what);
    ~MappedTextFile();
    MappedTextFile(const MappedTextFile&) = delete;
    MappedTextFile& operator=(const MappedTextFile&) = delete;
    std::string_view text() const { return m_text; }
    /// True when the file was cut while mapped (its pages read as zeros since) or is no longer
    /// the size it was when mapped.
    bool changed() const;
    /// Runs `reader` (which reads text()) and returns what it returns, unless the file changed
    /// meanwhile: then FileChangedWhileRead, also in place of an error the reader threw (the
    /// zeros it met, say, are not the file's fault).
    template <class Reader>
    auto read(Reader&& reader) const -> decltype(reader()) {
        try {
            auto result = reader();
            if (changed()) throw_changed();
            return result;
        } catch (const FileChangedWhileRead&) {
            throw;
        } catch (...) {
            if (changed()) throw_changed();
            throw;
        }
    }
    /// A reader going through the text once is at `offset`: the whole pages before it leave
    /// this process's memory, and the next `reader_stride` bytes are mapped in, in one call
    /// rather than a page fault every few pages. The text stays the same: the pages let go are
    /// still in the kernel's page cache and come back from there if read again. So a large
    /// file does not add its whole size to the peak memory (a million spheres written as
    /// indented JSON take 157 MB). An offset smaller than the one before means that a reader is
    /// going through the text again (the scanner, after the UTF-8 check).
    void reader_at(size_t offset);
    /// How far apart a reader's reader_at calls should be.
    static constexpr size_t reader_stride = size_t(8) << 20;

private:
    [[noreturn]] void throw_changed() const;
    std::string m_path, m_what;
    std::string_view m_text;
    void* m_address = nullptr;
    size_t m_length = 0;
    int m_fd = -1;        ///< kept open: the size is checked on it after the read
    int m_guard = -1;     ///< the SIGBUS handler's slot for this mapping
    std::string m_copy;   ///< the text, read with read(), when every slot is taken
    size_t m_let_go = 0;  ///< bytes from the start let go by the latest reader (whole pages)
};

/// A file read while an InputFilesNoted lived, by its identity (device and inode).
struct NotedInput {
    uint64_t device = 0, inode = 0;
    std::string what;  ///< "the mesh file 'm.obj'"
};

/// While one lives, every file opened by MappedTextFile (read_text_file too: scenes, meshes, MTL
/// and NFF files) is noted by its identity (device and inode), so that a command about to write
/// can ask whether an output is one of its own inputs under another name (input_file_at). A
/// command (`check`) makes one; so does loading an api::Scene, which keeps what it read (noted())
/// for `render` and `convert` to ask the same of their outputs.
class InputFilesNoted {
public:
    InputFilesNoted();
    ~InputFilesNoted();
    InputFilesNoted(const InputFilesNoted&) = delete;
    InputFilesNoted& operator=(const InputFilesNoted&) = delete;

    /// The files read (by any thread) since this one was made.
    std::vector<NotedInput> noted() const;

private:
    size_t m_first = 0;
};

/// What `target` is among the files read while an InputFilesNoted lives ("the mesh file
/// 'm.obj'"), or "" when it is none of them or does not exist.
std::string input_file_at(const std::string& target);
/// The same among `inputs`.
std::string input_file_at(const std::string& target, const std::vector<NotedInput>& inputs);

/// `text` made safe to print in a message: control characters (C0 such as ESC and BEL, DEL, and
/// C1 such as U+009B) and bytes that are not UTF-8 (Latin-1 names) written as \xNN escapes, so a
/// scene cannot drive the terminal, and at most `max_characters` characters, the rest replaced
/// by "... (N bytes)".
std::string printable(std::string_view text, size_t max_characters = 60);

/// " (did you mean 'x'?)" for the closest candidate within a small edit distance, else "".
std::string did_you_mean(const std::string& word, const std::vector<std::string>& candidates);

}  // namespace whitted
