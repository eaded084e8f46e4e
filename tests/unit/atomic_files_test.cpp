// SPDX-License-Identifier: MIT
// Files written so that they appear complete or not at all (`whitted convert`'s .pov and .ini):
// the bytes land exactly, existing files are replaced, and a failure leaves no temporary file.

#include "output/atomic_files.h"

#include "test_support.h"

#include <gtest/gtest.h>

#include <fcntl.h>
#include <sys/file.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace whitted {
namespace {

std::string bytes_of(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream bytes;
    bytes << in.rdbuf();
    return bytes.str();
}

std::vector<std::string> entries(const std::filesystem::path& directory) {
    std::vector<std::string> names;
    for (const auto& entry : std::filesystem::directory_iterator(directory))
        names.push_back(entry.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
}

TEST(AtomicFiles, WritesEveryByteAndNothingElse) {
    const test::ScratchDirectory directory;
    std::string big(3 << 20, '\0');  // larger than one write() may take
    for (size_t i = 0; i < big.size(); ++i) big[i] = char(i * 131 % 251);
    write_files_atomically({{directory.path() / "a.pov", "camera {}\n"}, {directory.path() / "a.ini", big}});
    EXPECT_EQ(bytes_of(directory.path() / "a.pov"), "camera {}\n");
    EXPECT_EQ(bytes_of(directory.path() / "a.ini"), big);
    EXPECT_EQ(entries(directory.path()), (std::vector<std::string>{"a.ini", "a.pov"}));
}

TEST(AtomicFiles, ReplacesExistingFiles) {
    const test::ScratchDirectory directory;
    write_files_atomically({{directory.path() / "s.pov", "old"}});
    write_files_atomically({{directory.path() / "s.pov", "new, longer"}});
    EXPECT_EQ(bytes_of(directory.path() / "s.pov"), "new, longer");
    EXPECT_EQ(entries(directory.path()), std::vector<std::string>{"s.pov"});
}

TEST(AtomicFiles, MissingDirectoryThrowsAndWritesNothing) {
    const test::ScratchDirectory directory;
    EXPECT_THROW(write_files_atomically({{directory.path() / "a.pov", "x"}, {directory.path() / "no/b.ini", "y"}}),
                 std::runtime_error);
    EXPECT_TRUE(entries(directory.path()).empty()) << "a.pov must not appear when b.ini cannot be written";
}

TEST(AtomicFiles, FailedRenameLeavesNoTemporaryFile) {
    const test::ScratchDirectory directory;
    std::filesystem::create_directory(directory.path() / "taken.ini");  // a directory: the rename fails
    try {
        write_files_atomically({{directory.path() / "taken.ini", "x"}});
        ADD_FAILURE() << "a directory was replaced by a file";
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("taken.ini"), std::string::npos) << e.what();
    }
    EXPECT_EQ(entries(directory.path()), std::vector<std::string>{"taken.ini"});
}

// `whitted convert`'s case: x.ini is a directory. Without the check before the renames, x.pov
// was replaced and then the .ini's rename failed, leaving the new .pov beside no .ini.
TEST(AtomicFiles, DirectoryInTheWayLeavesEveryOtherFileAsItWas) {
    const test::ScratchDirectory directory;
    write_files_atomically({{directory.path() / "x.pov", "old scene"}});
    std::filesystem::create_directory(directory.path() / "x.ini");
    try {
        write_files_atomically({{directory.path() / "x.pov", "new scene"}, {directory.path() / "x.ini", "new ini"}});
        ADD_FAILURE() << "a directory was replaced by a file";
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("x.ini': it is a directory"), std::string::npos) << e.what();
    }
    EXPECT_EQ(bytes_of(directory.path() / "x.pov"), "old scene");
    EXPECT_EQ(entries(directory.path()), (std::vector<std::string>{"x.ini", "x.pov"}));
}

// Two writers of the same files must not interleave their renames: each holds an flock on the
// directory while it renames. Here the test holds it, so the writer must wait for it.
TEST(AtomicFiles, RenamesWaitForTheDirectoryLock) {
    const test::ScratchDirectory directory;
    write_files_atomically({{directory.path() / "s.pov", "old"}, {directory.path() / "s.ini", "old"}});
    const int lock = ::open(directory.path().c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    ASSERT_GE(lock, 0);
    ASSERT_EQ(::flock(lock, LOCK_EX), 0);
    std::atomic<bool> done{false};
    std::thread writer([&] {
        write_files_atomically({{directory.path() / "s.pov", "new"}, {directory.path() / "s.ini", "new"}});
        done = true;
    });
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    EXPECT_FALSE(done.load()) << "the files were renamed while another writer held the directory";
    EXPECT_EQ(bytes_of(directory.path() / "s.pov"), "old");
    EXPECT_EQ(bytes_of(directory.path() / "s.ini"), "old");
    ::close(lock);  // releases the lock
    writer.join();
    EXPECT_TRUE(done.load());
    EXPECT_EQ(bytes_of(directory.path() / "s.pov"), "new");
    EXPECT_EQ(bytes_of(directory.path() / "s.ini"), "new");
    EXPECT_EQ(entries(directory.path()), (std::vector<std::string>{"s.ini", "s.pov"}));
}

// A legal 255-byte name must have a legal temporary name too, kept in the same directory.
TEST(AtomicFiles, TemporaryNameOfALongNameFits) {
    const test::ScratchDirectory directory;
    const std::filesystem::path target = directory.path() / (std::string(251, 'x') + ".png");
    const std::filesystem::path temporary = temporary_path(target);
    EXPECT_LE(temporary.filename().string().size(), 255u);
    EXPECT_EQ(temporary.parent_path(), directory.path());
    EXPECT_EQ(temporary.extension(), ".png");
    write_files_atomically({{target, "bytes"}});
    EXPECT_EQ(bytes_of(target), "bytes");
    EXPECT_EQ(entries(directory.path()), std::vector<std::string>{target.filename().string()});
}

// A run killed with SIGKILL between naming its finished file and moving it leaves
// `.NAME.whitted-PID.tmp.EXT`; the next write of NAME removes it when PID is gone, and leaves a
// live process's (pid 1 here) and lookalikes alone.
TEST(AtomicFiles, NextWriteRemovesAKilledRunsTemporary) {
    const test::ScratchDirectory directory;
    const pid_t child = ::fork();
    if (child == 0) ::_exit(0);
    ASSERT_GT(child, 0);
    int status = 0;
    ASSERT_EQ(::waitpid(child, &status, 0), child);  // reaped: no process has this pid now
    const std::string dead = ".x.pov.whitted-" + std::to_string(child) + ".tmp.pov";
    const std::string live = ".x.pov.whitted-1.tmp.pov";
    const std::string lookalike = ".x.pov.whitted-" + std::to_string(child) + ".tmp.pov.bak";
    for (const std::string& name : {dead, live, lookalike}) write_files_atomically({{directory.path() / name, "left"}});
    write_files_atomically({{directory.path() / "x.pov", "new"}});
    EXPECT_EQ(bytes_of(directory.path() / "x.pov"), "new");
    std::vector<std::string> expected{live, lookalike, "x.pov"};
    std::sort(expected.begin(), expected.end());
    EXPECT_EQ(entries(directory.path()), expected);
}

}  // namespace
}  // namespace whitted
