// SPDX-License-Identifier: MIT
#pragma once

#include <filesystem>
#include <string_view>
#include <utility>
#include <vector>

namespace whitted {

/// Writes each (path, bytes) so that the files appear complete or not at all. The bytes go to
/// unnamed files in the targets' directories (O_TMPFILE), which vanish with the process if it
/// is interrupted or killed; only when every file is written are they given their names (a
/// link to `.NAME.whitted-PID.tmp`, then a rename over NAME). Where a filesystem cannot make
/// unnamed files, the named temporary is written directly (and removed on failure; a kill can
/// leave it). Throws std::runtime_error naming the file and the reason. Nothing is renamed
/// before every file is written; the renames come last, one after the other.
void write_files_atomically(const std::vector<std::pair<std::filesystem::path, std::string_view>>& files);

}  // namespace whitted
