// SPDX-License-Identifier: MIT
#include "reference/check.h"

#include <stdexcept>

namespace whitted::reference {
CheckResult run_check(const std::string&, const CheckOptions&) {
    throw std::runtime_error("whitted check: not implemented yet");
}
}  // namespace whitted::reference
