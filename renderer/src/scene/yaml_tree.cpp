// SPDX-License-Identifier: MIT
#include "scene/yaml_tree.h"

#include "scene/text_checks.h"

#include <yaml.h>

#include <algorithm>
#include <memory>
#include <unordered_map>

namespace whitted::yaml_tree {

enum : uint8_t { flag_quoted = 1, flag_streamed = 2 };

// ---------------------------------------------------------------------------------------------
// Node

const NodeData* Node::data() const {
    if (!m_doc || m_index == UINT32_MAX) return nullptr;
    return &m_doc->m_nodes[m_index];
}
Kind Node::kind() const {
    const NodeData* d = data();
    return d ? d->kind : Kind::undefined;
}
bool Node::IsQuoted() const {
    const NodeData* d = data();
    return d && (d->flags & flag_quoted);
}
bool Node::IsStreamed() const {
    const NodeData* d = data();
    return d && (d->flags & flag_streamed);
}
std::string_view Node::scalar_view() const {
    const NodeData* d = data();
    if (!d || d->kind != Kind::scalar) return {};
    return std::string_view(m_doc->m_arena).substr(d->begin, d->count);
}
size_t Node::size() const {
    const NodeData* d = data();
    if (!d) return 0;
    if (d->kind == Kind::sequence) return d->count;
    if (d->kind == Kind::map) return d->count / 2;
    return 0;
}
Node Node::operator[](size_t i) const {
    const NodeData* d = data();
    if (!d || d->kind != Kind::sequence || i >= d->count) return {};
    return Node(m_doc, m_doc->m_children[d->begin + i]);
}
Node Node::operator[](std::string_view key) const {
    const NodeData* d = data();
    if (!d || d->kind != Kind::map) return {};
    for (uint32_t i = 0; i < d->count; i += 2) {
        const Node k(m_doc, m_doc->m_children[d->begin + i]);
        if (k.IsScalar() && k.scalar_view() == key) return Node(m_doc, m_doc->m_children[d->begin + i + 1]);
    }
    return {};
}
Pair Node::pair(size_t i) const {
    const NodeData* d = data();
    if (!d || d->kind != Kind::map || 2 * i >= d->count) return {};
    return {Node(m_doc, m_doc->m_children[d->begin + 2 * i]), Node(m_doc, m_doc->m_children[d->begin + 2 * i + 1])};
}
SourceLocation Node::location() const {
    const NodeData* d = data();
    if (!m_doc) return {};
    if (!d || d->line == 0) return {m_doc->m_file, 0, 0};
    return {m_doc->m_file, int(d->line), int(d->column)};
}

// ---------------------------------------------------------------------------------------------
// Builder: both readers send it the same events; it keeps the limits and hands on `objects` items.

class Builder {
public:
    Builder(Document& doc, const Document::ObjectCallback& on_object, const Limits& limits)
        : m_doc(doc), m_on_object(on_object), m_limits(limits) {}

    [[noreturn]] void fail(uint32_t line, uint32_t column, const std::string& message) const {
        throw InputError({m_doc.m_file, int(line), int(column)}, message);
    }

    void document_start(uint32_t line, uint32_t column) {
        if (++m_documents > 1)
            fail(line, column,
                 "a second YAML document starts here; a scene file holds one document (remove the '---' "
                 "or '...' line, or split the file)");
    }

    void scalar(std::string_view text, uint32_t line, uint32_t column, bool quoted, std::string_view anchor) {
        begin_value();
        NodeData node;
        node.line = line, node.column = column;
        node.flags = quoted ? flag_quoted : 0;
        if (!quoted && (text.empty() || text == "~" || text == "null" || text == "Null" || text == "NULL")) {
            node.kind = Kind::null;
        } else {
            node.kind = Kind::scalar;
            node.begin = uint32_t(m_doc.m_arena.size());
            node.count = uint32_t(text.size());
            m_doc.m_arena.append(text);
        }
        const uint32_t index = push(node);
        if (!anchor.empty()) anchor_at(anchor, index, {index, 1, 0});
        complete(index, 1, 0);
    }

    void start(Kind kind, uint32_t line, uint32_t column, std::string_view anchor) {
        if (m_open.size() + 1 > m_limits.max_depth)
            fail(line, column, "values nested more than " + std::to_string(m_limits.max_depth) + " levels deep");
        begin_value();
        // The top-level map's `objects` list: its items go to the caller one at a time.
        const bool streamed = kind == Kind::sequence && m_on_object && m_open.size() == 1 &&
                              m_open[0].kind == Kind::map && m_documents <= 1 &&
                              (m_pending.size() - m_open[0].pending_begin) % 2 == 1 &&
                              is_key(m_pending.back(), "objects");
        NodeData node;
        node.kind = kind;
        node.line = line, node.column = column;
        node.flags = streamed ? flag_streamed : 0;
        const uint32_t index = push(node);
        if (!anchor.empty()) anchor_at(anchor, index, {index, 0, 0});  // sizes known at its end
        m_open.push_back({index, uint32_t(m_pending.size()), kind, streamed, !anchor.empty(), 0, 0, 0});
    }

    void end() {
        const Open open = m_open.back();
        m_open.pop_back();
        NodeData& node = m_doc.m_nodes[open.node];
        node.begin = uint32_t(m_doc.m_children.size());
        node.count = open.streamed ? 0 : uint32_t(m_pending.size() - open.pending_begin);
        m_doc.m_children.insert(m_doc.m_children.end(), m_pending.begin() + open.pending_begin, m_pending.end());
        m_pending.resize(open.pending_begin);
        if (open.anchored)
            for (auto& [name, anchored] : m_anchors)
                if (anchored.node == open.node) anchored.values = 1 + open.values, anchored.height = 1 + open.height;
        complete(open.node, 1 + open.values, 1 + open.height);
    }

    /// An alias is the anchored value itself, shared (the tree becomes a graph without cycles);
    /// the values it stands for are counted against max_alias_values, so that nested aliases
    /// cannot make parse.cpp walk billions of values.
    void alias(std::string_view anchor, uint32_t line, uint32_t column) {
        const auto found = m_anchors.find(std::string(anchor));
        if (found == m_anchors.end()) fail(line, column, "unknown alias '*" + std::string(anchor) + "'");
        const Anchored anchored = found->second;
        if (anchored.values == 0)
            fail(line, column, "alias '*" + std::string(anchor) + "' refers to a value that contains it");
        m_alias_values += anchored.values;
        if (m_alias_values > m_limits.max_alias_values)
            fail(line, column,
                 "the document expands to more than " + std::to_string(m_limits.max_alias_values) +
                     " values (nested aliases?); refusing to read it");
        if (m_open.size() + anchored.height > m_limits.max_depth)
            fail(line, column, "values nested more than " + std::to_string(m_limits.max_depth) + " levels deep");
        begin_value();
        complete(anchored.node, anchored.values, anchored.height);
    }

    uint32_t root() const { return m_root; }
    uint32_t streamed() const { return m_streamed; }

private:
    struct Open {
        uint32_t node;
        uint32_t pending_begin;
        Kind kind;
        bool streamed;
        bool anchored;
        size_t items;
        uint64_t values;  ///< inside it so far, aliases expanded
        uint32_t height;  ///< of its deepest child so far
    };
    struct Anchored {
        uint32_t node;
        uint64_t values;  ///< 0 while it is still open
        uint32_t height;
    };

    void anchor_at(std::string_view name, uint32_t index, Anchored anchored) {
        m_anchors[std::string(name)] = anchored;
        m_last_anchored = std::max(m_last_anchored, int64_t(index));
    }

    bool is_key(uint32_t index, std::string_view word) const {
        const NodeData& key = m_doc.m_nodes[index];
        return key.kind == Kind::scalar && std::string_view(m_doc.m_arena).substr(key.begin, key.count) == word;
    }

    /// A value begins: note where an `objects` item's nodes and text start, to forget them after.
    void begin_value() {
        if (!m_open.empty() && m_open.back().streamed) {
            m_item_nodes = uint32_t(m_doc.m_nodes.size());
            m_item_arena = uint32_t(m_doc.m_arena.size());
            m_item_children = uint32_t(m_doc.m_children.size());
        }
    }

    uint32_t push(const NodeData& node) {
        if (m_doc.m_nodes.size() >= m_limits.max_nodes_at_once)
            fail(node.line, node.column,
                 "the scene holds more than " + std::to_string(m_limits.max_nodes_at_once) +
                     " values at once; refusing to read it (a large mesh belongs in an OBJ file)");
        m_doc.m_nodes.push_back(node);
        return uint32_t(m_doc.m_nodes.size() - 1);
    }

    /// A value is complete: it becomes its parent's child, the root, or is handed on.
    void complete(uint32_t index, uint64_t values, uint32_t height) {
        if (m_open.empty()) {
            if (m_root == UINT32_MAX) m_root = index;
            return;
        }
        Open& parent = m_open.back();
        parent.values += values;
        parent.height = std::max(parent.height, height);
        if (!parent.streamed) {
            m_pending.push_back(index);
            return;
        }
        m_streamed = parent.node;
        m_on_object(Node(&m_doc, index), parent.items++);
        // Forget the item, unless an anchor inside it may still be named by a later alias.
        if (m_last_anchored < int64_t(m_item_nodes)) {
            m_doc.m_nodes.resize(m_item_nodes);
            m_doc.m_arena.resize(m_item_arena);
            // Children lists of the item's containers were appended after its first node.
            m_doc.m_children.resize(m_item_children);
        }
    }

    Document& m_doc;
    const Document::ObjectCallback& m_on_object;
    Limits m_limits;
    std::vector<Open> m_open;
    std::vector<uint32_t> m_pending;  ///< children of the open containers, innermost last
    std::unordered_map<std::string, Anchored> m_anchors;
    int64_t m_last_anchored = -1;
    uint64_t m_alias_values = 0;
    uint32_t m_root = UINT32_MAX;
    uint32_t m_streamed = UINT32_MAX;
    uint32_t m_item_nodes = 0, m_item_arena = 0, m_item_children = 0;
    int m_documents = 0;
};

// ---------------------------------------------------------------------------------------------
// libyaml: the whole of YAML 1.1, and the messages for syntax errors.

namespace {

struct LibyamlParser {
    yaml_parser_t parser;
    LibyamlParser() { yaml_parser_initialize(&parser); }
    ~LibyamlParser() { yaml_parser_delete(&parser); }
};

struct LibyamlEvent {
    yaml_event_t event;
    ~LibyamlEvent() { yaml_event_delete(&event); }
};

/// Line and column (1-based) of a byte offset, for libyaml's reader errors.
std::pair<uint32_t, uint32_t> position_of(std::string_view text, size_t offset) {
    uint32_t line = 1, column = 1;
    for (size_t i = 0; i < offset && i < text.size(); ++i) {
        if (ends_line(text, i))
            ++line, column = 1;
        else if ((static_cast<unsigned char>(text[i]) & 0xC0) != 0x80)
            ++column;
    }
    return {line, column};
}

/// What usually causes a syntax error that libyaml describes tersely.
std::string syntax_hint(std::string_view text, size_t line) {
    size_t begin = 0;
    for (size_t l = 1; l < line && begin < text.size(); ++begin)
        if (ends_line(text, begin)) ++l;
    for (size_t i = begin; i < text.size() && (text[i] == ' ' || text[i] == '\t'); ++i)
        if (text[i] == '\t') return " (a tab in the indentation: YAML indents with spaces only)";
    return "";
}

bool is_string_tag(const yaml_char_t* tag) {
    if (!tag) return false;
    const std::string_view t(reinterpret_cast<const char*>(tag));
    return t == "tag:yaml.org,2002:str" || t == "!";
}

std::string_view text_of(const yaml_char_t* s) {
    return s ? std::string_view(reinterpret_cast<const char*>(s)) : std::string_view();
}

void read_with_libyaml(std::string_view text, Builder& builder) {
    LibyamlParser p;
    yaml_parser_set_input_string(&p.parser, reinterpret_cast<const unsigned char*>(text.data()), text.size());
    for (;;) {
        LibyamlEvent e;
        if (!yaml_parser_parse(&p.parser, &e.event)) {
            const yaml_parser_t& parser = p.parser;
            uint32_t line = uint32_t(parser.problem_mark.line + 1), column = uint32_t(parser.problem_mark.column + 1);
            if (parser.error == YAML_READER_ERROR) std::tie(line, column) = position_of(text, parser.problem_offset);
            std::string message = "syntax error: ";
            message += parser.problem ? parser.problem : "cannot read the scene";
            if (parser.context) {
                message += std::string(" (") + parser.context;
                if (parser.context_mark.line != parser.problem_mark.line ||
                    parser.context_mark.column != parser.problem_mark.column)
                    message += " that starts at " + std::to_string(parser.context_mark.line + 1) + ":" +
                               std::to_string(parser.context_mark.column + 1);
                message += ")";
            }
            if (parser.error == YAML_MEMORY_ERROR) throw std::bad_alloc();
            builder.fail(line, column, message + syntax_hint(text, line));
        }
        const yaml_event_t& event = e.event;
        const uint32_t line = uint32_t(event.start_mark.line + 1), column = uint32_t(event.start_mark.column + 1);
        switch (event.type) {
            case YAML_STREAM_END_EVENT:
                return;
            case YAML_DOCUMENT_START_EVENT:
                builder.document_start(line, column);
                break;
            case YAML_ALIAS_EVENT:
                builder.alias(text_of(event.data.alias.anchor), line, column);
                break;
            case YAML_SCALAR_EVENT: {
                const auto& s = event.data.scalar;
                const bool quoted = s.style != YAML_PLAIN_SCALAR_STYLE || is_string_tag(s.tag);
                builder.scalar(std::string_view(reinterpret_cast<const char*>(s.value), s.length), line, column, quoted,
                               text_of(s.anchor));
                break;
            }
            case YAML_SEQUENCE_START_EVENT:
                builder.start(Kind::sequence, line, column, text_of(event.data.sequence_start.anchor));
                break;
            case YAML_MAPPING_START_EVENT:
                builder.start(Kind::map, line, column, text_of(event.data.mapping_start.anchor));
                break;
            case YAML_SEQUENCE_END_EVENT:
            case YAML_MAPPING_END_EVENT:
                builder.end();
                break;
            default:
                break;
        }
    }
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// The fast scanner: the YAML that scene files are made of, in one pass over the bytes. It reads
// block maps and lists (spaces only), flow maps and lists on one line (or spanning lines when the
// whole document is one flow value, as JSON is), plain scalars of letters, digits, spaces and
// _ . + - / ~, quoted scalars without escapes, comments. At anything else it gives up
// (NotForTheFastScanner) and libyaml reads the text from the start, so what it reads it must read
// exactly as libyaml does (tests/unit/yaml_tree_test.cpp compares the two on every scene in the
// repository).

namespace {

class FastScanner {
public:
    FastScanner(std::string_view text, Builder& builder, const std::function<void(size_t)>& done_before)
        : m_text(text), m_builder(builder), m_done_before(done_before) {}

    void read() {
        if (m_done_before) m_done_before(0);
        skip_blank_lines();
        if (at_end()) return;  // no document at all
        m_builder.document_start(line(), column());
        if (peek() == '{' || peek() == '[') {
            m_flow_document = true;
            flow_value();
            skip_flow_space();
            if (!at_end()) give_up();
            return;
        }
        if (column() != 1) give_up();
        block_node(0);
        skip_blank_lines();
        if (!at_end()) give_up();
    }

private:
    [[noreturn]] static void give_up() { throw NotForTheFastScanner(); }

    /// A map or list ends: every `done_every` bytes, the reader is told that the text before
    /// here is done with. (It is not read again, but if it were, a mapped file's bytes would
    /// come back the same: MappedTextFile::reader_at.) By position, not by line: a JSON file
    /// may be one line.
    void end() {
        m_builder.end();
        if (m_done_before && m_p >= m_next_done) {
            m_done_before(m_p);
            m_next_done = m_p + done_every;
        }
    }
    static constexpr size_t done_every = MappedTextFile::reader_stride;

    bool at_end() const { return m_p >= m_text.size(); }
    char peek(size_t ahead = 0) const { return m_p + ahead < m_text.size() ? m_text[m_p + ahead] : '\0'; }
    uint32_t line() const { return m_line; }
    uint32_t column() const { return uint32_t(m_p - m_line_start + 1); }
    bool blank_or_end(size_t ahead) const {
        const char c = peek(ahead);
        return c == ' ' || c == '\n' || c == '\0';
    }

    void newline() {
        ++m_p;
        ++m_line;
        m_line_start = m_p;
    }
    void skip_spaces() {
        while (peek() == ' ') ++m_p;
    }
    void skip_comment() {
        // A CR ends a comment too (a lone CR is a line break); the scanner then gives up on it
        // and libyaml reads the file.
        while (!at_end() && m_text[m_p] != '\n' && m_text[m_p] != '\r') ++m_p;
    }
    /// After a value: spaces, an optional comment, the end of the line.
    void end_of_line() {
        skip_spaces();
        if (peek() == '#') skip_comment();
        if (at_end()) return;
        if (peek() != '\n') give_up();
        newline();
    }
    /// Skips empty and comment-only lines; leaves m_p at the first content of a line (or the end)
    /// and returns its indentation.
    uint32_t skip_blank_lines() {
        for (;;) {
            skip_spaces();
            if (at_end()) return 0;
            const char c = peek();
            if (c == '#') {
                skip_comment();
                continue;
            }
            if (c == '\n') {
                newline();
                continue;
            }
            if (c == '\t' || c == '\r') give_up();
            if (m_p == m_line_start && (c == '-' || c == '.') && peek(1) == c && peek(2) == c) give_up();  // --- ...
            if (m_p == m_line_start && c == '%') give_up();
            return column() - 1;
        }
    }

    static bool plain_char(char c) {
        return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '.' ||
               c == '+' || c == '-' || c == '/' || c == '~';
    }

    /// A plain scalar at m_p: plain characters and single inner spaces; ends before a space,
    /// ':', ',', ']', '}', '#' or the end of the line. Gives up at anything else.
    std::string_view plain() {
        const size_t begin = m_p;
        const char first = peek();
        if (!plain_char(first) || (first == '-' && !plain_char(peek(1)))) give_up();
        size_t end = m_p;
        for (;;) {
            while (plain_char(peek())) ++m_p;
            end = m_p;
            if (peek() == ' ' && plain_char(peek(1)) && !(peek(1) == '-' && blank_or_end(2))) {
                ++m_p;
                continue;
            }
            break;
        }
        const char next = peek();
        if (!(next == ' ' || next == '\n' || next == '\0' || next == ':' || next == ',' || next == ']' || next == '}'))
            give_up();
        return m_text.substr(begin, end - begin);
    }

    /// A quoted scalar without escapes on one line; m_p is at the quote.
    std::string_view quoted() {
        const char quote = peek();
        const size_t begin = ++m_p;
        for (;; ++m_p) {
            const char c = peek();
            if (c == quote) break;
            if (c == '\0' || c == '\n' || c == '\\' || c == '\t' || c == '\r' || (static_cast<unsigned char>(c) & 0x80))
                give_up();
        }
        const std::string_view value = m_text.substr(begin, m_p - begin);
        ++m_p;
        if (quote == '\'' && peek() == '\'') give_up();  // '' inside a single-quoted scalar
        return value;
    }

    /// A scalar, as a key or a value; returns whether it was quoted.
    bool scalar(std::string_view& value) {
        const char c = peek();
        if (c == '"' || c == '\'') {
            value = quoted();
            return true;
        }
        value = plain();
        return false;
    }

    void skip_flow_space() {
        for (;;) {
            const char c = peek();
            if (c == ' ') {
                ++m_p;
            } else if (c == '\n' && m_flow_document) {
                newline();
            } else if (c == '#' && m_flow_document &&
                       (m_p == m_line_start || m_text[m_p - 1] == ' ' || m_text[m_p - 1] == '\n')) {
                skip_comment();
            } else {
                return;
            }
        }
    }

    /// ':' then a space (or the end of the line): a key's indicator.
    bool value_indicator() const { return peek() == ':' && blank_or_end(1); }

    void flow_value() {
        const uint32_t l = line(), c = column();
        const char first = peek();
        if (first == '{') {
            ++m_p;
            m_builder.start(Kind::map, l, c, {});
            skip_flow_space();
            if (peek() == '}') {
                ++m_p;
                return end();
            }
            for (;;) {
                std::string_view key;
                const uint32_t kl = line(), kc = column();
                if (peek() == '{' || peek() == '[') give_up();
                const bool quoted_key = scalar(key);
                m_builder.scalar(key, kl, kc, quoted_key, {});
                skip_spaces();
                if (!value_indicator()) give_up();
                ++m_p;
                skip_flow_space();
                if (peek() == ',' || peek() == '}') give_up();  // an empty value
                flow_value();
                skip_flow_space();
                if (peek() == ',') {
                    ++m_p;
                    skip_flow_space();
                    if (peek() == '}') give_up();
                    continue;
                }
                if (peek() != '}') give_up();
                ++m_p;
                return end();
            }
        }
        if (first == '[') {
            ++m_p;
            m_builder.start(Kind::sequence, l, c, {});
            skip_flow_space();
            if (peek() == ']') {
                ++m_p;
                return end();
            }
            for (;;) {
                flow_value();
                skip_flow_space();
                if (peek() == ',') {
                    ++m_p;
                    skip_flow_space();
                    if (peek() == ']') give_up();
                    continue;
                }
                if (peek() != ']') give_up();
                ++m_p;
                return end();
            }
        }
        std::string_view value;
        const bool is_quoted = scalar(value);
        skip_spaces();
        if (peek() == ':') give_up();  // a single-pair map inside a list, or a plain scalar with ':'
        m_builder.scalar(value, l, c, is_quoted, {});
    }

    /// A value after "key: " or "- " on the same line: a flow collection closed on this line or a
    /// scalar, then the end of the line.
    void inline_value() {
        const uint32_t l = line(), c = column();
        const char first = peek();
        if (first == '{' || first == '[') {
            flow_value();
        } else {
            std::string_view value;
            const bool is_quoted = scalar(value);
            skip_spaces();
            if (peek() == ':') give_up();  // "a: b: c", or a map where a scalar was expected
            m_builder.scalar(value, l, c, is_quoted, {});
        }
        end_of_line();
    }

    /// Does a "key:" start at m_p (a scalar on this line followed by ': ' or ':' at the end)?
    bool key_ahead() {
        const size_t saved = m_p;
        std::string_view key;
        const char c = peek();
        bool is_key = false;
        if (c != '{' && c != '[' && !(c == '-' && blank_or_end(1))) {
            scalar(key);
            skip_spaces();
            is_key = value_indicator();
        }
        m_p = saved;
        return is_key;
    }

    /// A node starting at m_p in block context, whose first line is indented by `indent`.
    void block_node(uint32_t indent) {
        if (peek() == '-' && blank_or_end(1)) return block_sequence(indent);
        if (key_ahead()) return block_map(indent);
        inline_value();
    }

    /// The value of "key:" or "- " that is not on the same line: indented more than `parent`, or
    /// (for a map's value) a list at the same indentation; an empty value is null.
    void value_on_next_lines(uint32_t parent, bool list_at_same_indent, uint32_t l, uint32_t c) {
        const uint32_t indent = skip_blank_lines();
        if (!at_end() &&
            (indent > parent || (list_at_same_indent && indent == parent && peek() == '-' && blank_or_end(1)))) {
            // Only lists and maps start on a line of their own here; a scalar alone on the next
            // line (possibly continued on more lines) is left to libyaml.
            if (!(peek() == '-' && blank_or_end(1)) && !key_ahead()) give_up();
            return block_node(indent);
        }
        m_builder.scalar({}, l, c, false, {});
    }

    void block_map(uint32_t indent) {
        m_builder.start(Kind::map, line(), column(), {});
        for (;;) {
            std::string_view key;
            const uint32_t kl = line(), kc = column();
            if (peek() == '{' || peek() == '[' || peek() == '?') give_up();
            const bool quoted_key = scalar(key);
            m_builder.scalar(key, kl, kc, quoted_key, {});
            skip_spaces();
            if (!value_indicator()) give_up();
            ++m_p;
            const uint32_t after_l = line(), after_c = column();
            skip_spaces();
            if (at_end() || peek() == '\n' || peek() == '#') {
                end_of_line();
                value_on_next_lines(indent, true, after_l, after_c);
            } else {
                if (peek() == '-' && blank_or_end(1)) give_up();  // "key: - x"
                if (std::string_view("&*!|>%@`").find(peek()) != std::string_view::npos) give_up();
                inline_value();
            }
            const uint32_t next = skip_blank_lines();
            if (at_end() || next < indent) break;
            if (next > indent) give_up();
            if (peek() == '-' && blank_or_end(1)) give_up();
        }
        end();
    }

    void block_sequence(uint32_t indent) {
        m_builder.start(Kind::sequence, line(), column(), {});
        for (;;) {
            ++m_p;  // '-'
            const uint32_t after_l = line(), after_c = column();
            skip_spaces();
            if (at_end() || peek() == '\n' || peek() == '#') {
                end_of_line();
                value_on_next_lines(indent, false, after_l, after_c);
            } else {
                if (std::string_view("&*!|>%@`?").find(peek()) != std::string_view::npos) give_up();
                const uint32_t inner = column() - 1;
                block_node(inner);
            }
            const uint32_t next = skip_blank_lines();
            if (at_end() || next < indent) break;
            if (next > indent) give_up();
            if (!(peek() == '-' && blank_or_end(1))) break;  // the next key of a map at this indentation
        }
        end();
    }

    std::string_view m_text;
    Builder& m_builder;
    const std::function<void(size_t)>& m_done_before;
    size_t m_next_done = done_every;
    size_t m_p = 0;
    size_t m_line_start = 0;
    uint32_t m_line = 1;
    bool m_flow_document = false;
};

}  // namespace

void read_fast(std::string_view text, Builder& builder, const std::function<void(size_t)>& done_before) {
    FastScanner(text, builder, done_before).read();
}

void Document::read(std::string_view text, FileName file, const ObjectCallback& on_object, const Limits& limits,
                    const Reader* force, const std::function<void(size_t)>& done_before) {
    m_file = file;
    const auto attempt = [&](Reader reader) {
        m_nodes.clear(), m_children.clear(), m_arena.clear();
        m_root = m_streamed = UINT32_MAX;
        m_reader = reader;
        Builder builder(*this, on_object, limits);
        if (reader == Reader::fast)
            read_fast(text, builder, done_before);
        else
            read_with_libyaml(text, builder);
        m_root = builder.root();
        m_streamed = builder.streamed();
        m_nodes.shrink_to_fit();
    };
    if (force) return attempt(*force);
    try {
        attempt(Reader::fast);
    } catch (const NotForTheFastScanner&) {
        attempt(Reader::libyaml);
    }
}

}  // namespace whitted::yaml_tree
