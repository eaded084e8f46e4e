// SPDX-License-Identifier: MIT
#include "reference/povray.h"

#include <stdexcept>

namespace whitted::reference {
std::string find_povray() {
    throw std::runtime_error("whitted check: not implemented yet");
}
void run_povray(const std::string&) {
    throw std::runtime_error("whitted check: not implemented yet");
}
}  // namespace whitted::reference
