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

// Parses `text`; ParseError naming `source`, the line and column and what the file should be (`expected`).
// A key given twice in one object is an InvalidInput naming it by its full path
// ("objects[1].stack[0].label"): the text is JSON, but JSON readers keep one of the two silently (nlohmann
// the last), so a value the user wrote would be ignored.
inline json parseJson(std::string_view text, const std::string& source, const std::string& expected) {
    // Per open container: an object's keys so far and the key being read, or an array's element index.
    struct Open {
        bool array = false;
        std::set<std::string> keys;
        std::string key;
        int64_t index = -1;
    };
    std::vector<Open> open;
    std::string duplicate;
    const auto where = [&](size_t depth) {
        std::string path;
        for (size_t d = 0; d < depth; ++d)
            path = open[d].array ? jsonIndex(path, static_cast<size_t>(open[d].index))
                                 : jsonMember(path, open[d].key);
        return path;
    };
    const json::parser_callback_t check = [&](int, json::parse_event_t event, json& parsed) {
        using Event = json::parse_event_t;
        // A value, an object or an array starting inside an array is its next element.
        const bool starts =
            event == Event::value || event == Event::object_start || event == Event::array_start;
        if (starts && !open.empty() && open.back().array) ++open.back().index;
        if (event == Event::object_start || event == Event::array_start) {
            open.push_back(Open{event == Event::array_start, {}, {}, -1});
        } else if ((event == Event::object_end || event == Event::array_end) && !open.empty()) {
            open.pop_back();
        } else if (event == Event::key && !open.empty()) {
            const std::string key = parsed.get<std::string>();
            if (!open.back().keys.insert(key).second && duplicate.empty())
                duplicate = jsonMember(where(open.size() - 1), key);
            open.back().key = key;
        }
        return true;
    };
    try {
        json root = json::parse(text.begin(), text.end(), check);
        if (!duplicate.empty()) {
            throw InvalidInput(
                formatError(source, duplicate, "is given twice in one object", "each key once"));
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
