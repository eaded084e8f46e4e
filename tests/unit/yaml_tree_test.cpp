// SPDX-License-Identifier: MIT
// The scene file's value tree (yaml_tree.h): the fast scanner must read exactly what libyaml
// reads (every YAML and JSON file in the repository, and hand-written forms), the limits hold
// while reading, and the top-level objects are handed on and forgotten one by one.

#include "scene/yaml_tree.h"
#include "scene/description.h"
#include "scene/text_checks.h"

#include "test_support.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

namespace whitted::yaml_tree {
namespace {

using ::testing::HasSubstr;

/// The tree as text: kind, line:column, quotedness and value of every node, in order.
void dump(const Node& node, std::string& out, int depth = 0) {
    out += std::string(size_t(depth) * 2, ' ');
    const SourceLocation at = node.location();
    out += std::to_string(at.line) + ":" + std::to_string(at.column) + " ";
    switch (node.kind()) {
        case Kind::undefined:
            out += "undefined\n";
            return;
        case Kind::null:
            out += "null\n";
            return;
        case Kind::scalar:
            out += (node.IsQuoted() ? "quoted '" : "plain '") + node.Scalar() + "'\n";
            return;
        case Kind::sequence:
            out += node.IsStreamed() ? "streamed list\n" : "list\n";
            for (size_t i = 0; i < node.size(); ++i) dump(node[i], out, depth + 1);
            return;
        case Kind::map:
            out += "map\n";
            for (const Pair& pair : node.pairs()) {
                dump(pair.first, out, depth + 1);
                dump(pair.second, out, depth + 2);
            }
            return;
    }
}

/// Reads `text` with one reader; the dump of the tree and of every streamed object, or the
/// error message.
std::string read_with(const std::string& text, Reader reader) {
    Document document;
    std::string objects;
    const auto on_object = [&](const Node& item, size_t index) {
        objects += "object " + std::to_string(index) + "\n";
        dump(item, objects, 1);
    };
    try {
        document.read(text, "test.yaml", on_object, {}, &reader);
    } catch (const InputError& e) {
        return std::string("error: ") + e.what();
    }
    std::string out;
    dump(document.root(), out);
    return out + objects;
}

TEST(YamlTree, FastScannerReadsWhatLibyamlReadsInEveryRepositoryScene) {
    int fast = 0, left_to_libyaml = 0;
    for (const char* dir : {"examples", "tests", "bench", "docs"}) {
        const std::filesystem::path root = std::filesystem::path(WHITTED_SOURCE_DIR) / dir;
        if (!std::filesystem::exists(root)) continue;
        for (const auto& entry : std::filesystem::recursive_directory_iterator(root)) {
            const std::string ext = entry.path().extension().string();
            if (!entry.is_regular_file() || (ext != ".yaml" && ext != ".json")) continue;
            std::ifstream in(entry.path(), std::ios::binary);
            std::stringstream buffer;
            buffer << in.rdbuf();
            const std::string text = buffer.str();
            try {
                check_text_is_readable(text, "test.yaml");
            } catch (const InputError&) {
                continue;  // refused before either reader sees it
            }
            std::string fast_tree;
            try {
                fast_tree = read_with(text, Reader::fast);
            } catch (const NotForTheFastScanner&) {
                ++left_to_libyaml;
                continue;
            }
            ++fast;
            EXPECT_EQ(fast_tree, read_with(text, Reader::libyaml)) << entry.path();
        }
    }
    RecordProperty("fast", fast);
    RecordProperty("libyaml", left_to_libyaml);
    // Most scenes are plain YAML or JSON: the fast scanner must be the one that reads them.
    EXPECT_GT(fast, 150);
    EXPECT_GT(fast, 3 * left_to_libyaml);
}

TEST(YamlTree, FastScannerReadsTheUsualFormsLikeLibyaml) {
    const std::vector<std::string> texts = {
        "a: 1\nb: [1, 2.5, -3e-2]\nc: {x: y, 'q': \"z w\"}\n",
        "# comment\n\nkey:   # after a key\n  - one\n  - two  # after a value\nother: ~\n",
        "list:\n- a\n- b\nnext: null\n",
        "outer:\n  inner:\n    deep: [[1, 2], [3], []]\n  empty: {}\nlast:\n",
        "- - a\n  - b\n- key: v\n  key2: w\n-\n- {}\n",
        "{\"camera\": {\"eye\": [0, 6, 14], \"fov\": 60},\n \"objects\": [\n  {\"type\": \"sphere\"},\n  {\"type\": "
        "\"box\"}\n]}\n",
        "objects:\n  - {type: sphere, center: [0, 0, 0]}\n  - type: group\n    objects:\n      - {type: box}\n",
        "name with spaces: a b c\npath: models/x.obj\nnum: +1.5\ndot: .5\nnulls: [~, null, Null, NULL]\n",
        "quoted: ''\nq2: \"\"\nplainnull:\n",
    };
    for (const std::string& text : texts) {
        std::string fast_tree;
        ASSERT_NO_THROW(fast_tree = read_with(text, Reader::fast)) << text;
        EXPECT_EQ(fast_tree, read_with(text, Reader::libyaml)) << text;
    }
}

TEST(YamlTree, WhatTheFastScannerDoesNotReadGoesToLibyaml) {
    const std::vector<std::string> texts = {
        "a: &x [1, 2]\nb: *x\n", "a: !!str 1\n", "a: |\n  block\n", "a: \"esc\\tape\"\n",
        "a: multi\n  line\n",    "---\na: 1\n",  "a:\tb\n",         "{\"a\":1}",
        "a: [1,\n  2]\n",        "a: x:y\n",     "a: 'it''s'\n",    "a: caf\xc3\xa9\n",
    };
    for (const std::string& text : texts) {
        EXPECT_THROW(read_with(text, Reader::fast), NotForTheFastScanner) << text;
        Document document;
        document.read(text, "test.yaml");  // the default: the scanner, then libyaml
        EXPECT_EQ(document.reader(), Reader::libyaml) << text;
        EXPECT_TRUE(document.root().IsMap()) << text;
    }
}

TEST(YamlTree, StringTagAndQuotesMakeStrings) {
    Document document;
    document.read("a: !!str 1\nb: '2'\nc: 3\nd: ! 4\n", "test.yaml");
    EXPECT_TRUE(document.root()["a"].IsQuoted());
    EXPECT_TRUE(document.root()["b"].IsQuoted());
    EXPECT_FALSE(document.root()["c"].IsQuoted());
    EXPECT_TRUE(document.root()["d"].IsQuoted());
    EXPECT_EQ(document.root()["a"].Scalar(), "1");
}

TEST(YamlTree, ASecondDocumentIsAnError) {
    for (const char* text : {"a: 1\n---\nb: 2\n", "a: 1\n...\n---\nb: 2\n", "--- {a: 1}\n--- {b: 2}\n"}) {
        Document document;
        try {
            document.read(text, "test.yaml");
            ADD_FAILURE() << "accepted " << text;
        } catch (const InputError& e) {
            EXPECT_THAT(e.message(), HasSubstr("a second YAML document")) << text;
            EXPECT_GT(e.where().line, 1) << text;
        }
    }
}

TEST(YamlTree, NestingIsLimitedWhileReading) {
    for (const Reader reader : {Reader::fast, Reader::libyaml}) {
        const std::string text = "a: " + std::string(600, '[') + std::string(600, ']') + "\n";
        EXPECT_THAT(read_with(text, reader), HasSubstr("nested more than 512 levels deep"));
    }
}

TEST(YamlTree, ValuesHeldAtOnceAreLimitedButStreamedObjectsAreForgotten) {
    // 5000 objects of 7 values each with room for 1000 values at once: each object is handed on
    // and forgotten before the next is read.
    std::string text = "camera: {eye: [0, 0, 5]}\nobjects:\n";
    for (int i = 0; i < 5000; ++i) text += "  - {type: sphere, center: [0, 0, " + std::to_string(i) + "]}\n";
    Limits limits;
    limits.max_nodes_at_once = 1000;
    for (const Reader reader : {Reader::fast, Reader::libyaml}) {
        Document document;
        size_t objects = 0;
        std::string last;
        document.read(
            text, "test.yaml",
            [&](const Node& item, size_t) {
                ++objects;
                last = item["center"][2].Scalar();
            },
            limits, &reader);
        EXPECT_EQ(objects, 5000u);
        EXPECT_EQ(last, "4999");
        EXPECT_TRUE(document.root()["objects"].IsStreamed());
        EXPECT_EQ(document.root()["objects"].size(), 0u);
        // Without streaming the same text passes the limit, with the line and column of the
        // value that did.
        try {
            document.read(text, "test.yaml", {}, limits, &reader);
            ADD_FAILURE() << "no limit";
        } catch (const InputError& e) {
            EXPECT_THAT(e.message(), HasSubstr("more than 1000 values at once"));
            EXPECT_GT(e.where().line, 2);
        }
    }
}

TEST(YamlTree, AnAliasIsSharedNotCopied) {
    Document document;
    document.read("m: &m {kd: 0.5}\nobjects:\n  - {material: *m}\n  - {material: *m}\n", "test.yaml",
                  [&](const Node& item, size_t) { EXPECT_EQ(item["material"]["kd"].Scalar(), "0.5"); });
    EXPECT_EQ(document.root()["m"]["kd"].location().line, 1);
}

}  // namespace
}  // namespace whitted::yaml_tree

namespace whitted {
namespace {

TEST(ParseMessages, AHugeNameIsShortenedInTheMessage) {
    const std::string name(10 << 20, 'x');
    const auto error = test::scene_error(
        "camera: {eye: [0, 0, 5], look_at: [0, 0, 0]}\nimage: {width: 8, height: 6}\n" + name + ": 1\n");
    ASSERT_TRUE(error);
    EXPECT_THAT(error->message(), ::testing::HasSubstr("unknown key 'xxxx"));
    EXPECT_THAT(error->message(), ::testing::HasSubstr("(10485760 bytes)"));
    EXPECT_LT(std::string(error->what()).size(), 400u);
    EXPECT_EQ(error->where().line, 3);
}

TEST(ParseMessages, ControlCharactersInANameAreEscaped) {
    const auto error = test::scene_error(
        "camera: {eye: [0, 0, 5], look_at: [0, 0, 0]}\nimage: {width: 8, height: 6}\n\"\\e]0;x\\a\": 1\n");
    ASSERT_TRUE(error);
    EXPECT_THAT(error->message(), ::testing::HasSubstr("unknown key '\\x1b]0;x\\x07'"));
    for (const char c : std::string(error->what())) EXPECT_GE(static_cast<unsigned char>(c), 0x20);
}

}  // namespace
}  // namespace whitted

// Large scene files are let go of behind the reader (MappedTextFile::reader_at), so that the file
// does not add its size to the peak memory; what is read must not change.
namespace whitted {
namespace {

/// The process's resident pages of mapped files, in KiB (/proc/self/status, RssFile).
long resident_file_kib() {
    std::ifstream status("/proc/self/status");
    std::string line;
    while (std::getline(status, line))
        if (line.rfind("RssFile:", 0) == 0) return std::stol(line.substr(8));
    ADD_FAILURE() << "no RssFile in /proc/self/status";
    return -1;
}

/// A scene of `spheres` one-line spheres, each at its own place (so that a wrong byte shows).
std::string many_spheres(int spheres) {
    std::string text =
        "image: { width: 64, height: 48 }\ncamera: { eye: [0, 6, 14], look_at: [0, 0, 0] }\n"
        "materials:\n  ball: { kd: 0.5 }\nobjects:\n";
    for (int i = 0; i < spheres; ++i)
        text += "  - { type: sphere, center: [" + std::to_string(i % 1000) + ".25, " + std::to_string(i / 1000) +
                ".5, -" + std::to_string(i) + "], radius: 0.125, material: ball }\n";
    return text;
}

TEST(MappedTextFile, PagesLetGoLeaveTheProcessButTheTextStaysTheSame) {
    const test::ScratchDirectory dir;
    std::string bytes(size_t(24) << 20, '\0');
    for (size_t i = 0; i < bytes.size(); ++i) bytes[i] = char('a' + (i * 7919 % 26));
    const std::string path = dir.write("big.txt", bytes);
    MappedTextFile file(path, int64_t(1) << 30, "test file");
    ASSERT_EQ(file.text(), bytes);  // every page read, so resident
    const long before = resident_file_kib();
    file.reader_at(file.text().size());  // done with all of it
    const long after = resident_file_kib();
    EXPECT_GE(before - after, 20 * 1024) << "RssFile " << before << " KiB -> " << after << " KiB";
    EXPECT_EQ(file.text(), bytes);  // read again: the same bytes, from the page cache
    // A reader going through again from the start is told of smaller offsets: it lets go again.
    file.reader_at(0);
    file.reader_at(file.text().size());
    EXPECT_LE(resident_file_kib(), after + 4 * 1024);
    EXPECT_EQ(file.text(), bytes);
}

// A mapped file truncated by another program while it is read: the reader reads zeros where the
// cut pages were (never SIGBUS), and read() says the file changed, naming it.
TEST(MappedTextFile, AFileTruncatedWhileReadIsAnErrorNamingItNeverSigbus) {
    const test::ScratchDirectory dir;
    const std::string path = dir.write("cut.obj", std::string(size_t(4) << 20, 'v'));
    const MappedTextFile file(path, int64_t(1) << 30, "mesh file");
    ASSERT_FALSE(file.changed());
    ASSERT_EQ(::truncate(path.c_str(), 1000), 0);
    std::atomic<size_t> seen{0};
    try {
        // Four threads at once, as the OBJ reader reads its parts; each meets cut pages.
        file.read([&] {
            std::vector<std::thread> threads;
            const std::string_view text = file.text();
            for (size_t part = 0; part < 4; ++part)
                threads.emplace_back([&, part] {
                    const std::string_view mine = text.substr(part * text.size() / 4, text.size() / 4);
                    seen += size_t(std::count(mine.begin(), mine.end(), 'v'));
                });
            for (std::thread& thread : threads) thread.join();
            return 0;
        });
        ADD_FAILURE() << "read() returned for a file truncated while it was read";
    } catch (const FileChangedWhileRead& e) {
        EXPECT_THAT(e.what(), ::testing::HasSubstr("the mesh file '" + path + "' changed while it was read"));
        EXPECT_THAT(e.what(), ::testing::HasSubstr("4194304 bytes when opened, 1000 bytes now"));
    }
    EXPECT_EQ(seen.load(), 1000u);  // the rest read as zeros
    EXPECT_TRUE(file.changed());
}

// An error the reader throws because of the zeros it met is the file's change, not bad input.
TEST(MappedTextFile, AnErrorFromTheZerosOfACutFileBecomesTheChange) {
    const test::ScratchDirectory dir;
    const std::string path = dir.write("cut.yaml", std::string(size_t(1) << 20, 'a'));
    const MappedTextFile file(path, int64_t(1) << 30, "scene file");
    ASSERT_EQ(::truncate(path.c_str(), 10), 0);
    EXPECT_THROW(file.read([&] {
        check_text_is_readable(file.text(), path);  // a NUL byte at 1:11
        return 0;
    }),
                 FileChangedWhileRead);
}

// The handler mends only its own mappings: any other SIGBUS still ends the process by it.
TEST(MappedTextFileDeathTest, AnotherSigbusIsStillFatal) {
    const test::ScratchDirectory dir;
    const std::string path = dir.write("whole.yaml", "a: 1\n");
#if defined(__SANITIZE_ADDRESS__)
    // AddressSanitizer handles SIGBUS itself: it reports the signal and exits with status 1.
    const auto ends_the_process = ::testing::ExitedWithCode(1);
    const char* const message = "SEGV|BUS|DEADLYSIGNAL";
#else
    const auto ends_the_process = ::testing::KilledBySignal(SIGBUS);
    const char* const message = "";
#endif
    EXPECT_EXIT(
        {
            const MappedTextFile file(path, 1 << 20, "scene file");
            ::raise(SIGBUS);
        },
        ends_the_process, message);
}

TEST(YamlTree, TheFastScannerSaysWhereItIsAsItGoes) {
    const std::string text = many_spheres(250000);  // about 20 MB
    ASSERT_GT(text.size(), 2 * MappedTextFile::reader_stride);
    for (const yaml_tree::Reader reader : {yaml_tree::Reader::fast, yaml_tree::Reader::libyaml}) {
        std::vector<size_t> told;
        yaml_tree::Document document;
        size_t objects = 0;
        document.read(
            text, "many.yaml", [&](const yaml_tree::Node&, size_t) { ++objects; }, {}, &reader,
            [&](size_t offset) { told.push_back(offset); });
        EXPECT_EQ(objects, 250000u);
        if (reader == yaml_tree::Reader::libyaml) {
            EXPECT_TRUE(told.empty());  // libyaml's own buffers: nothing to say
            continue;
        }
        ASSERT_GE(told.size(), 3u);
        EXPECT_EQ(told.front(), 0u);
        for (size_t i = 1; i < told.size(); ++i) {
            EXPECT_GE(told[i] - told[i - 1], MappedTextFile::reader_stride);
            EXPECT_LT(told[i], text.size());
        }
    }
}

TEST(Load, ALargeSceneFileGivesTheSceneItsTextGives) {
    const test::ScratchDirectory dir;
    const std::string text = many_spheres(250000);
    const std::string path = dir.write("many.yaml", text);
    for (const bool one_pass : {false, true}) {
        const Scene from_file = one_pass ? load_scene_file(path) : validate_scene(parse_scene_file(path));
        const Scene from_text = one_pass ? load_scene_text(text, path) : validate_scene(parse_scene_text(text, path));
        ASSERT_EQ(from_file.spheres.size(), 250000u);
        ASSERT_EQ(from_text.spheres.size(), 250000u);
        for (size_t i = 0; i < from_file.spheres.size(); i += 997) {
            EXPECT_EQ(from_file.spheres[i].center.x, from_text.spheres[i].center.x);
            EXPECT_EQ(from_file.spheres[i].center.z, from_text.spheres[i].center.z);
            EXPECT_EQ(from_file.spheres[i].center.z, -double(i));
        }
        EXPECT_EQ(from_file.spheres.back().center.y, from_text.spheres.back().center.y);
    }
}

}  // namespace
}  // namespace whitted
