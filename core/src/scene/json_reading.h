#pragma once

// The one set of JSON reading helpers of the library (scenes, weights files, feature-line files, farm
// plans), over nlohmann/json, which stays private to the library.

#include <algorithm>
#include <initializer_list>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "deformkit/error.h"

namespace deformkit::scene::detail {

using nlohmann::json;

// What a value is, for messages: "a number", "an array of 3", "an object".
inline std::string jsonKind(const json& v) {
    if (v.is_null()) return "null";
    if (v.is_boolean()) return "a boolean";
    if (v.is_number()) return "a number";
    if (v.is_string()) return "a string";
    if (v.is_array()) return "an array of " + std::to_string(v.size());
    return "an object";
}

// Throws InvalidInput naming `source` and the key (under `path`) when `object` has a key outside `known`: a
// typo would otherwise be ignored silently.
inline void requireKnownKeys(const json& object, const std::string& source, const std::string& path,
                             std::initializer_list<const char*> known) {
    for (const auto& item : object.items()) {
        std::string list;
        bool found = false;
        for (const char* k : known) {
            found = found || item.key() == k;
            list += (list.empty() ? "" : ", ") + std::string(k);
        }
        if (!found) {
            throw InvalidInput(formatError(source, path.empty() ? item.key() : path + "." + item.key(),
                                           "is not a known key", "one of: " + list));
        }
    }
}

// "path[i]" and "path.key" (key alone at the top level).
inline std::string jsonIndex(const std::string& path, size_t i) {
    return path + "[" + std::to_string(i) + "]";
}
inline std::string jsonMember(const std::string& path, std::string_view key) {
    return path.empty() ? std::string(key) : path + "." + std::string(key);
}

// nlohmann's DOM builder with a check of every object's keys: the first key given twice in one object is
// kept by its full path ("objects[1].stack[0].label"). A SAX handler, not a parse callback: nlohmann's
// callback parser scans the enclosing array at the end of every object, so reading a plan took time
// quadratic in its tasks (a task of a 240,000-task plan: 10.5 s instead of 2).
class DuplicateKeyDom {
  public:
    explicit DuplicateKeyDom(json& root) : dom_(root) {}

    bool null() { return element() && dom_.null(); }
    bool boolean(bool v) { return element() && dom_.boolean(v); }
    bool number_integer(json::number_integer_t v) { return element() && dom_.number_integer(v); }
    bool number_unsigned(json::number_unsigned_t v) { return element() && dom_.number_unsigned(v); }
    bool number_float(json::number_float_t v, const json::string_t& s) {
        return element() && dom_.number_float(v, s);
    }
    bool string(json::string_t& v) {
        element();
        if (v.find('\0') != std::string::npos && nul_.empty()) nul_ = where(open_.size());
        return dom_.string(v);
    }
    bool binary(json::binary_t& v) { return element() && dom_.binary(v); }
    bool start_object(std::size_t n) {
        element();
        open_.push_back(Open{false, {}, {}, -1});
        return dom_.start_object(n);
    }
    bool key(json::string_t& k) {
        if (k.find('\0') != std::string::npos && nul_.empty()) {
            std::string shown;  // the key as the file spells it
            for (const char c : k)
                shown += c == '\0' ? std::string("\\u0000") : std::string(1, c);
            nul_ = jsonMember(where(open_.size() - 1), shown);
        }
        if (!open_.back().keys.insert(k).second && duplicate_.empty())
            duplicate_ = jsonMember(where(open_.size() - 1), k);
        open_.back().key = k;
        return dom_.key(k);
    }
    bool end_object() {
        open_.pop_back();
        return dom_.end_object();
    }
    bool start_array(std::size_t n) {
        element();
        open_.push_back(Open{true, {}, {}, -1});
        return dom_.start_array(n);
    }
    bool end_array() {
        open_.pop_back();
        return dom_.end_array();
    }
    bool parse_error(std::size_t position, const std::string& token, const nlohmann::detail::exception& e) {
        return dom_.parse_error(position, token, e);
    }

    // The first key given twice, by its path; empty when none was.
    [[nodiscard]] const std::string& duplicate() const { return duplicate_; }
    // The first string or key holding a NUL character (\u0000), by its path (a key by its own, spelt with
    // \u0000); empty when none did. Paths and names are C strings to the system: the text after it would
    // be cut off there.
    [[nodiscard]] const std::string& nul() const { return nul_; }

  private:
    // Per open container: an object's keys so far and the key being read, or an array's element index.
    struct Open {
        bool array = false;
        std::set<std::string> keys;
        std::string key;
        int64_t index = -1;
    };
    // A value, an object or an array starting inside an array is its next element.
    bool element() {
        if (!open_.empty() && open_.back().array) ++open_.back().index;
        return true;
    }
    [[nodiscard]] std::string where(size_t depth) const {
        std::string path;
        for (size_t d = 0; d < depth; ++d)
            path = open_[d].array ? jsonIndex(path, static_cast<size_t>(open_[d].index))
                                  : jsonMember(path, open_[d].key);
        return path;
    }

    nlohmann::detail::json_sax_dom_parser<json> dom_;
    std::vector<Open> open_;
    std::string duplicate_, nul_;
};

// Parses `text`; ParseError naming `source`, the line and column and what the file should be (`expected`).
// A key given twice in one object is an InvalidInput naming it by its full path
// ("objects[1].stack[0].label"): the text is JSON, but JSON readers keep one of the two silently (nlohmann
// the last), so a value the user wrote would be ignored.
inline json parseJson(std::string_view text, const std::string& source, const std::string& expected) {
    // nlohmann ends its input at a NUL byte: the text after one would be ignored.
    if (const size_t nul = text.find('\0'); nul != std::string_view::npos) {
        const auto line = 1 + std::count(text.begin(), text.begin() + static_cast<ptrdiff_t>(nul), '\n');
        const size_t lineStart = text.rfind('\n', nul == 0 ? 0 : nul - 1);
        const size_t column = lineStart == std::string_view::npos || nul == 0 ? nul + 1 : nul - lineStart;
        throw ParseError(formatError(
            source, "",
            "holds a NUL byte at line " + std::to_string(line) + ", column " + std::to_string(column),
            expected + ", without NUL bytes"));
    }
    try {
        json root;
        DuplicateKeyDom dom(root);
        json::sax_parse(text.begin(), text.end(), &dom);
        if (!dom.duplicate().empty()) {
            throw InvalidInput(
                formatError(source, dom.duplicate(), "is given twice in one object", "each key once"));
        }
        if (!dom.nul().empty()) {
            throw InvalidInput(formatError(source, dom.nul(), "holds a NUL character (\\u0000)",
                                           "text without NUL characters (names and paths end at one)"));
        }
        return root;
    } catch (const json::exception& e) {
        // nlohmann reports "[json.exception.parse_error.101] parse error at line L, column C: ..." (or
        // out_of_range for a number too large): keep the part after the bracketed id.
        const std::string what = e.what();
        const size_t at = what.find("] ");
        throw ParseError(
            formatError(source, "", at == std::string::npos ? what : what.substr(at + 2), expected));
    }
}

}  // namespace deformkit::scene::detail
