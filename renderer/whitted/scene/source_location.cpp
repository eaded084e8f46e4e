// SPDX-License-Identifier: MIT
#include "whitted/scene/source_location.h"

namespace whitted {

std::string SourceLocation::str() const {
    if (line <= 0) return file;
    return file + ":" + std::to_string(line) + ":" + std::to_string(column);
}

InputError::InputError(SourceLocation where, const std::string& message)
    : std::runtime_error(where.file.empty() ? message : where.str() + ": " + message),
      m_where(std::move(where)),
      m_message(message) {}

}  // namespace whitted
