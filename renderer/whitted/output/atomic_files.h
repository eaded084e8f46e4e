// SPDX-License-Identifier: MIT
#pragma once

#include <filesystem>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace whitted {

/// Writes each (path, bytes) so that the files appear complete or not at all. The bytes go to
/// unnamed files in the targets' directories (O_TMPFILE), which vanish with the process if it
/// is interrupted or killed; only when every file is written are they given their names (a
/// link to temporary_path(NAME), then move_into_place). Where a filesystem cannot make
/// unnamed files, the named temporary is written directly (and removed on failure; a kill can
/// leave it). Throws std::runtime_error naming the file and the reason. Nothing is renamed
/// before every file is written; the renames come last, one after the other, all or nothing:
/// a target that is a directory is refused before any rename, and if a rename fails the files
/// already moved are put back (an existing regular file is restored; only a symlink or other
/// non-file replaced by a rename cannot be). The renames hold an flock on the directory, so two
/// processes writing the same set of files at once leave one's whole set, never a mix.
/// `.NAME.whitted-PID.tmp.EXT` beside `target`: where a file is finished before it is moved to
/// `target` (hidden, and marked as ours, by process). A process killed with SIGKILL in the
/// instant between naming and moving can leave one; the next move_into_place or
/// write_files_atomically to the same target removes those whose process no longer exists.
std::string temporary_path(const std::filesystem::path& target);

/// Moves a finished file to `target` in one step: an existing regular file is swapped out
/// atomically and then deleted, anything else renamed over. Throws std::runtime_error.
/// Throws std::runtime_error when `target` exists and is neither a regular file nor a directory
/// (a device such as /dev/full, a FIFO, a socket, or a link to one): an output never replaces it.
void refuse_special_target(const std::filesystem::path& target);
void move_into_place(const std::string& temporary, const std::filesystem::path& target);

void write_files_atomically(const std::vector<std::pair<std::filesystem::path, std::string_view>>& files);

}  // namespace whitted
