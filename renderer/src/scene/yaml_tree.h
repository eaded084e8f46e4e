// SPDX-License-Identifier: MIT
#pragma once

// The scene file as a tree of values, made for scenes of millions of objects: each value is a
// 20-byte node (its kind, line and column, and offsets into one string arena or one list of
// child indices), not a yaml-cpp node of several heap blocks. Text is read by a fast scanner for
// the YAML that programs and people usually write (block and flow maps and lists, plain and
// quoted scalars without escapes, JSON); anything else (anchors, tags, block scalars, escapes,
// multi-line scalars, and every syntax error) is read again by libyaml, whose messages and
// marks are then the ones reported. The items of the top-level `objects` list can be handed to
// the caller one by one as each is complete and then forgotten, so memory does not grow with
// the number of objects (`Document::read`).

#include "scene/source_location.h"

#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

namespace whitted::yaml_tree {

class Document;

enum class Kind : uint8_t { undefined, null, scalar, sequence, map };

struct NodeData {
    Kind kind = Kind::undefined;
    uint8_t flags = 0;
    uint32_t line = 0, column = 0;  ///< 1-based
    uint32_t begin = 0;             ///< scalar: offset into the arena; container: into the child list
    uint32_t count = 0;             ///< scalar: length; sequence: items; map: 2 × pairs (key, value, ...)
};

struct Pair;

/// A value in a Document (a handle: copy freely while the Document lives). A Node that is not
/// there (a missing key, an index past the end) is "undefined": `!node` is true.
class Node {
public:
    Node() = default;
    Node(const Document* doc, uint32_t index) : m_doc(doc), m_index(index) {}

    explicit operator bool() const { return kind() != Kind::undefined; }
    bool operator!() const { return kind() == Kind::undefined; }
    Kind kind() const;
    bool IsNull() const { return kind() == Kind::null; }
    bool IsScalar() const { return kind() == Kind::scalar; }
    bool IsSequence() const { return kind() == Kind::sequence; }
    bool IsMap() const { return kind() == Kind::map; }
    /// Written as a string: quoted, or tagged !!str or !. Such a scalar is never a number.
    bool IsQuoted() const;
    /// The value of a scalar (empty for anything else).
    std::string Scalar() const { return std::string(scalar_view()); }
    std::string_view scalar_view() const;
    /// Items of a sequence, pairs of a map, 0 otherwise.
    size_t size() const;
    /// Item `i` of a sequence (undefined past the end or for a non-sequence).
    Node operator[](size_t i) const;
    Node operator[](int i) const { return (*this)[size_t(i)]; }
    /// The value of `key` in a map (undefined when absent or for a non-map).
    Node operator[](std::string_view key) const;
    Node operator[](const char* key) const { return (*this)[std::string_view(key)]; }
    Node operator[](const std::string& key) const { return (*this)[std::string_view(key)]; }
    /// Pair `i` of a map.
    Pair pair(size_t i) const;
    /// Where the value starts.
    SourceLocation location() const;
    uint32_t index() const { return m_index; }
    /// This is the top-level `objects` list whose items were handed to the caller as they were
    /// read (Document::read's on_object): it holds no items any more.
    bool IsStreamed() const;

    /// `for (const Pair& entry : map.pairs())`.
    struct Pairs pairs() const;

private:
    const NodeData* data() const;
    const Document* m_doc = nullptr;
    uint32_t m_index = UINT32_MAX;
};

struct Pair {
    Node first, second;
};

class PairIterator {
public:
    PairIterator(Node map, size_t i) : m_map(map), m_i(i) {}
    Pair operator*() const { return m_map.pair(m_i); }
    PairIterator& operator++() { return ++m_i, *this; }
    bool operator!=(const PairIterator& other) const { return m_i != other.m_i; }

private:
    Node m_map;
    size_t m_i;
};

struct Pairs {
    Node map;
    PairIterator begin() const { return PairIterator(map, 0); }
    PairIterator end() const { return PairIterator(map, map.size()); }
};

inline Pairs Node::pairs() const {
    return {*this};
}

/// Limits checked while reading (docs/scene-format.md lists them).
struct Limits {
    uint64_t max_nodes_at_once = 10'000'000;  ///< values held at one time
    uint64_t max_alias_values = 10'000'000;   ///< values that aliases expand to ("billion laughs")
    uint32_t max_depth = 512;                 ///< lists and maps inside each other
};

/// How the text was read, for benchmarks and tests.
enum class Reader { fast, libyaml };

/// Thrown by a read forced to the fast scanner (Document::read's `force`) where the scanner
/// leaves the text to libyaml.
struct NotForTheFastScanner {};

class Document {
public:
    /// Called with each item of the top-level `objects` list (and its index) as soon as it is
    /// complete; the item is forgotten afterwards. An exception thrown here ends the reading.
    /// Where the fast scanner leaves the text to libyaml, libyaml reads it from the start and the
    /// items come again from index 0 (parse.cpp hands each to its caller once).
    using ObjectCallback = std::function<void(Node item, size_t index)>;

    /// Reads `text` (already checked to be UTF-8 without NUL bytes). Throws InputError with the
    /// file's line and column for a syntax error, a second document or a limit passed.
    /// `force` chooses the reader (tests compare the two); by default the fast scanner, and
    /// libyaml where the scanner stops.
    /// `done_before`, if given, is told where the fast scanner is: at the start, then every
    /// MappedTextFile::reader_stride bytes or so (MappedTextFile::reader_at).
    void read(std::string_view text, FileName file, const ObjectCallback& on_object = {}, const Limits& limits = {},
              const Reader* force = nullptr, const std::function<void(size_t)>& done_before = {});

    /// The document's top value (undefined for an empty stream, null for an empty document).
    Node root() const { return m_root == UINT32_MAX ? Node() : Node(this, m_root); }
    Reader reader() const { return m_reader; }
    FileName file() const { return m_file; }

private:
    friend class Node;
    friend class Builder;
    std::vector<NodeData> m_nodes;
    std::vector<uint32_t> m_children;
    std::string m_arena;
    uint32_t m_root = UINT32_MAX;
    uint32_t m_streamed = UINT32_MAX;
    FileName m_file;
    Reader m_reader = Reader::fast;
};

}  // namespace whitted::yaml_tree
