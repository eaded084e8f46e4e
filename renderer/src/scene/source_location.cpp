// SPDX-License-Identifier: MIT
#include "scene/source_location.h"

#include <mutex>
#include <ostream>
#include <unordered_set>

namespace whitted {

FileName::FileName(const std::string& name) {
    // Node-based: an element never moves, so the pointer stays valid for the whole run. Few
    // names are ever kept (the scene file, its mesh files).
    static std::mutex mutex;
    static std::unordered_set<std::string> names;
    const std::lock_guard<std::mutex> lock(mutex);
    m_name = &*names.insert(name).first;
}

const std::string& FileName::empty_name() {
    static const std::string empty;
    return empty;
}

std::ostream& operator<<(std::ostream& out, const FileName& name) {
    return out << name.str();
}

std::string SourceLocation::str() const {
    if (line <= 0) return file.str();
    return file.str() + ":" + std::to_string(line) + ":" + std::to_string(column);
}

InputError::InputError(SourceLocation where, const std::string& message)
    : std::runtime_error(where.file.empty() ? message : where.str() + ": " + message),
      m_where(std::move(where)),
      m_message(message) {}

}  // namespace whitted
