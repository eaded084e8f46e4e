// SPDX-License-Identifier: MIT
#pragma once

// Helpers shared by the unit tests: scenes from YAML text, expected input errors, and
// scratch directories. Kept header-only so each test executable stays self-contained.

#include "scene/description.h"
#include "scene/scene.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

namespace whitted::test {

/// Joins lines with '\n', so that a test can say "line k" as index k − 1 of its vector and
/// compute a column as `lines[k - 1].find(word) + 1`.
inline std::string join_lines(const std::vector<std::string>& lines) {
    std::string text;
    for (const auto& line : lines) text += line + "\n";
    return text;
}

/// 1-based column of `word` in `line` (fails the test when the word is absent, rather than
/// comparing against npos + 1).
inline int column_of(const std::string& line, const std::string& word) {
    const size_t at = line.find(word);
    EXPECT_NE(at, std::string::npos) << "'" << word << "' not in '" << line << "'";
    return at == std::string::npos ? -1 : static_cast<int>(at) + 1;
}

/// Runs `f` and returns the InputError it throws; a test fails if nothing (or something
/// else) is thrown.
template <class F>
std::optional<InputError> input_error_from(F&& f) {
    try {
        f();
    } catch (const InputError& e) {
        return e;
    } catch (const std::exception& e) {
        ADD_FAILURE() << "expected an InputError, got another exception: " << e.what();
        return std::nullopt;
    }
    ADD_FAILURE() << "expected an InputError, nothing was thrown";
    return std::nullopt;
}

/// The error that parsing (and then validating) `text` gives. The one-pass reader the program
/// uses (load_scene_text) must give the same one, at the same place: every error test checks both.
inline std::optional<InputError> scene_error(const std::string& text, const std::string& path = "scene.yaml") {
    std::optional<InputError> two_pass = input_error_from([&] { (void)validate_scene(parse_scene_text(text, path)); });
    std::optional<InputError> one_pass = input_error_from([&] { (void)load_scene_text(text, path); });
    if (two_pass && one_pass) {
        EXPECT_EQ(std::string(one_pass->what()), std::string(two_pass->what()))
            << "load_scene_text and validate_scene(parse_scene_text) disagree";
    }
    return two_pass;
}

/// The validated scene for `text`.
inline Scene scene_from(const std::string& text, const std::string& path = "scene.yaml") {
    return validate_scene(parse_scene_text(text, path));
}

/// A fresh directory under the system temp dir, removed with the object.
class ScratchDirectory {
public:
    ScratchDirectory() {
        static std::atomic<int> counter{0};
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        const std::string name = std::string("whitted_unit_") + (info ? info->name() : "test") + "_" +
                                 std::to_string(::getpid()) + "_" + std::to_string(counter++);
        m_path = std::filesystem::temp_directory_path() / name;
        std::filesystem::remove_all(m_path);
        std::filesystem::create_directories(m_path);
    }
    ~ScratchDirectory() {
        std::error_code ignored;
        std::filesystem::remove_all(m_path, ignored);
    }
    ScratchDirectory(const ScratchDirectory&) = delete;
    ScratchDirectory& operator=(const ScratchDirectory&) = delete;

    const std::filesystem::path& path() const { return m_path; }

    /// Writes `text` to `name` inside the directory and returns its full path.
    std::string write(const std::string& name, const std::string& text) const {
        const auto file = m_path / name;
        std::ofstream out(file, std::ios::binary);
        out << text;
        EXPECT_TRUE(out.good()) << "cannot write " << file;
        return file.string();
    }

private:
    std::filesystem::path m_path;
};

}  // namespace whitted::test
