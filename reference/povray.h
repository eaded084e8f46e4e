// SPDX-License-Identifier: MIT
#pragma once

#include <string>

namespace whitted::reference {

/// The povray program on PATH (or $WHITTED_POVRAY). Throws std::runtime_error saying how to
/// install it when there is none.
std::string find_povray();

/// Renders `ini_path` (which names its scene and output) with POV-Ray, from the ini's
/// directory, with a private writable $HOME. Throws std::runtime_error with POV-Ray's own
/// messages when it fails.
void run_povray(const std::string& ini_path);

}  // namespace whitted::reference
