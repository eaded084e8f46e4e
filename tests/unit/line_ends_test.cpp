// SPDX-License-Identifier: MIT
// Every text format Whitted reads counts CR, LF and CRLF as line ends (YAML 1.2's line breaks):
// a mistake on line 3 is named at line 3 whichever the file uses, and in OBJ and MTL files a lone
// CR also ends a statement (docs/robustness.md).

#include "scene/course_xml.h"
#include "scene/mesh_file.h"
#include "scene/msh_file.h"
#include "scene/nff_file.h"
#include "scene/scene.h"

#include "test_support.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace whitted {
namespace {

using ::testing::HasSubstr;

/// The lines joined with `end` after each.
std::string with_ends(const std::vector<std::string>& lines, const std::string& end) {
    std::string text;
    for (const std::string& line : lines) text += line + end;
    return text;
}

const std::vector<std::string> line_ends = {"\n", "\r\n", "\r"};

std::string name_of(const std::string& end) {
    return end == "\n" ? "LF" : end == "\r\n" ? "CRLF" : "CR";
}

/// `where` of the error, which must name `path` at line:column.
void expect_at(const std::optional<InputError>& error, const std::string& path, int line, int column,
               const std::string& message, const std::string& end) {
    ASSERT_TRUE(error) << name_of(end);
    EXPECT_EQ(error->where().file.str(), path) << name_of(end);
    EXPECT_EQ(error->where().line, line) << name_of(end) << ": " << error->what();
    EXPECT_EQ(error->where().column, column) << name_of(end) << ": " << error->what();
    EXPECT_THAT(error->message(), HasSubstr(message)) << name_of(end);
}

// The auditor's file: a NUL byte at line 3, column 20 was named 1:79 with CR line ends.
TEST(LineEnds, YamlNulByteIsNamedAtItsLine) {
    for (const std::string& end : line_ends) {
        const std::string text = with_ends({"version: 1", "camera: { eye: [0, 0, 5], look_at: [0, 0, 0] }",
                                            std::string("image: { width: 16, \0height: 12 }", 33)},
                                           end);
        expect_at(test::input_error_from([&] { (void)load_scene_text(text, "cr.yaml"); }), "cr.yaml", 3, 21, "NUL byte",
                  end);
    }
}

TEST(LineEnds, YamlBadUtf8IsNamedAtItsLine) {
    for (const std::string& end : line_ends) {
        const std::string text =
            with_ends({"version: 1", "# a comment", "image: { width: 16, height: 12 } # caf\xE9"}, end);
        expect_at(test::input_error_from([&] { (void)load_scene_text(text, "cr.yaml"); }), "cr.yaml", 3, 39,
                  "not valid UTF-8", end);
    }
}

// An error found after parsing (libyaml's marks), and a comment that must end at a lone CR
// (the fast scanner once read a comment to the next LF, swallowing every CR-ended line after it).
TEST(LineEnds, YamlKeyErrorIsNamedAtItsLine) {
    for (const std::string& end : line_ends) {
        const std::string text =
            with_ends({"version: 1  # the format", "camera: { eye: [0, 0, 5], look_at: [0, 0, 0] }",
                       "image: { width: 16, heigth: 12 }"},
                      end);
        expect_at(test::scene_error(text, "cr.yaml"), "cr.yaml", 3, 21, "unknown key 'heigth'", end);
    }
}

TEST(LineEnds, NffErrorIsNamedAtItsLine) {
    for (const std::string& end : line_ends) {
        const std::string text = with_ends({"v", "from 0 0 5", "at 0 0 x"}, end);
        expect_at(test::input_error_from([&] { (void)parse_nff_text(text, "cr.nff"); }), "cr.nff", 3, 8, "", end);
    }
}

TEST(LineEnds, CourseXmlErrorIsNamedAtItsLine) {
    for (const std::string& end : line_ends) {
        const std::string text =
            with_ends({"<?xml version=\"1.0\" encoding=\"UTF-8\" ?>", "<scene>", "  <sphear/>", "</scene>"}, end);
        expect_at(test::input_error_from([&] { (void)parse_course_xml_text(text, "cr.xml"); }), "cr.xml", 3, 3,
                  "unknown element <sphear>", end);
    }
}

// A word in an element's text is placed by counting the text's own line ends.
TEST(LineEnds, CourseXmlWordIsNamedAtItsLine) {
    for (const std::string& end : line_ends) {
        const std::string text = with_ends({"<?xml version=\"1.0\" encoding=\"UTF-8\" ?>",
                                            "<scene><camera><viewPoint>0 0 5</viewPoint><viewWidth>2</viewWidth>",
                                            "<viewHeight>2</viewHeight></camera><image>8", " x</image></scene>"},
                                           end);
        expect_at(test::input_error_from([&] { (void)parse_course_xml_text(text, "cr.xml"); }), "cr.xml", 4, 2, "'x'",
                  end);
    }
}

TEST(LineEnds, MshErrorIsNamedAtItsLine) {
    for (const std::string& end : line_ends) {
        const test::ScratchDirectory directory;
        const std::string path =
            directory.write("cr.msh", with_ends({"3", "1", "vertices 0 0 0 1 0 x 0 1 0", "triangles", "0 1 2"}, end));
        expect_at(test::input_error_from([&] {
                      (void)load_msh_mesh(path, {"scene.xml", 7, 11});
                  }),
                  path, 3, 20, "'x'", end);
    }
}

TEST(LineEnds, ObjErrorIsNamedAtItsLine) {
    for (const std::string& end : line_ends) {
        const test::ScratchDirectory directory;
        const std::string path =
            directory.write("cr.obj", with_ends({"v 0 0 0", "v 1 0 0", "v 0 1 x", "f 1 2 3"}, end));
        expect_at(test::input_error_from([&] {
                      (void)load_obj_mesh(path, {"scene.yaml", 4, 11});
                  }),
                  path, 3, 7, "vertex coordinate", end);
    }
}

// With CR line ends the statements are still separate: the same mesh as with LF.
TEST(LineEnds, ObjStatementsEndAtALoneCr) {
    const std::vector<std::string> lines = {"# a quad", "v 0 0 0", "v 1 0 0", "v 1 1 0", "v 0 1 0", "f 1 2 3 4"};
    const test::ScratchDirectory directory;
    const MeshData lf = load_obj_mesh(directory.write("lf.obj", with_ends(lines, "\n")), {});
    ASSERT_EQ(lf.indices.size(), 6u);
    for (const std::string& end : {std::string("\r\n"), std::string("\r")}) {
        const MeshData mesh = load_obj_mesh(directory.write("cr.obj", with_ends(lines, end)), {});
        EXPECT_EQ(mesh.positions, lf.positions) << name_of(end);
        EXPECT_EQ(mesh.indices, lf.indices) << name_of(end);
    }
}

TEST(LineEnds, MtlErrorIsNamedAtItsLine) {
    for (const std::string& end : line_ends) {
        const test::ScratchDirectory directory;
        const std::string mtl = directory.write("cr.mtl", with_ends({"newmtl red", "Kd 1 0 0", "Ks 0 y 0"}, end));
        const std::string obj = directory.write(
            "cr.obj", with_ends({"mtllib cr.mtl", "v 0 0 0", "v 1 0 0", "v 0 1 0", "usemtl red", "f 1 2 3"}, end));
        expect_at(test::input_error_from([&] {
                      (void)load_obj_mesh(obj, {"scene.yaml", 4, 11});
                  }),
                  mtl, 3, 6, "'y'", end);
    }
}

// A control byte is named at its line whatever the line ends, in a comment too.
TEST(LineEnds, ObjControlByteIsNamedAtItsLine) {
    for (const std::string& end : line_ends) {
        const test::ScratchDirectory directory;
        const std::string path = directory.write(
            "cr.obj", with_ends({"v 0 0 0", "v 1 0 0", "# an \x1B[2J escape", "v 0 1 0", "f 1 2 3"}, end));
        expect_at(test::input_error_from([&] {
                      (void)load_obj_mesh(path, {"scene.yaml", 4, 11});
                  }),
                  path, 3, 6, "control byte 0x1B", end);
    }
}

}  // namespace
}  // namespace whitted
