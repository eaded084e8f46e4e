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

/// The usage checks of an output path, made before any work; each throws std::invalid_argument
/// naming `target`: its directory exists and a file can be made in it (a file is made there and
/// removed: a read-only, immutable or full directory is found now, not after minutes of work),
/// `target` is not a directory, and not a device, FIFO or socket (refuse_special_target).
void check_can_write(const std::filesystem::path& target);

/// A usage error (std::invalid_argument) when `target` is a symbolic link. An output replaces a
/// regular file by renaming over it, which would replace the link itself, not what it names;
/// writing through it instead could reach anything (`/proc/self/fd/1` names whatever the
/// standard output is). So neither: the user names the file itself.
void refuse_symlink_target(const std::filesystem::path& target);
void move_into_place(const std::string& temporary, const std::filesystem::path& target);

void write_files_atomically(const std::vector<std::pair<std::filesystem::path, std::string_view>>& files);

}  // namespace whitted
