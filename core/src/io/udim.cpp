#include "deformkit/io/udim.h"

#include <algorithm>
#include <array>
#include <optional>
#include <regex>
#include <system_error>

#include "deformkit/error.h"

namespace deformkit::io {
namespace fs = std::filesystem;

namespace {

enum class Token { Udim, UvTile, Houdini, MapId };

struct TokenSpelling {
    Token token;
    std::string_view text;
};

constexpr std::array<TokenSpelling, 4> kTokens{{
    {Token::Udim, "<UDIM>"},
    {Token::UvTile, "<UVTILE>"},
    {Token::Houdini, "%(UDIM)d"},
    {Token::MapId, "_MAPID_"},
}};

constexpr int kFirstTile = 1001;
constexpr int kLastTile = 9999;

// A pattern cut into literal text and tokens, scanned left to right so that expansion and matching
// agree on where each token is.
struct Segment {
    std::string literal;
    std::optional<Token> token;
};

std::vector<Segment> splitPattern(std::string_view pattern) {
    std::vector<Segment> segments;
    std::string literal;
    size_t i = 0;
    while (i < pattern.size()) {
        const auto found = std::find_if(kTokens.begin(), kTokens.end(), [&](const TokenSpelling& t) {
            return pattern.substr(i, t.text.size()) == t.text;
        });
        if (found == kTokens.end()) {
            literal.push_back(pattern[i++]);
            continue;
        }
        if (!literal.empty()) segments.push_back({std::move(literal), std::nullopt});
        literal.clear();
        segments.push_back({{}, found->token});
        i += found->text.size();
    }
    if (!literal.empty()) segments.push_back({std::move(literal), std::nullopt});
    return segments;
}

bool hasToken(const std::vector<Segment>& segments) {
    return std::any_of(segments.begin(), segments.end(),
                       [](const Segment& s) { return s.token.has_value(); });
}

bool isValidTile(int tile) {
    return tile >= kFirstTile && tile <= kLastTile;
}

void requireValidTile(int tile, std::string_view source) {
    if (!isValidTile(tile)) {
        throw InvalidInput(
            formatError(source, "tile " + std::to_string(tile), "is not a UDIM tile", "1001 to 9999"));
    }
}

std::string spell(Token token, int tile) {
    if (token == Token::UvTile) {
        const TileOrigin o = udimOrigin(tile);
        std::string text =
            "u";  // appended, not chained with +: GCC 12 warns falsely (-Wrestrict) on the chain
        text += std::to_string(o.u + 1);
        text += "_v";
        text += std::to_string(o.v + 1);
        return text;
    }
    return std::to_string(tile);
}

std::string expandSegments(const std::vector<Segment>& segments, int tile) {
    std::string out;
    for (const Segment& s : segments)
        out += s.token ? spell(*s.token, tile) : s.literal;
    return out;
}

std::string escapeRegex(std::string_view text) {
    static constexpr std::string_view kSpecial = R"(\^$.|?*+()[]{})";
    std::string out;
    for (const char ch : text) {
        if (kSpecial.find(ch) != std::string_view::npos) out.push_back('\\');
        out.push_back(ch);
    }
    return out;
}

// One capture group per token: (tile) for the numeric tokens, (u)(v) for <UVTILE>. The captures only
// propose a tile; a name is accepted when expanding the pattern with that tile gives it back exactly,
// which rejects leading zeros, out-of-range indices and tokens that disagree with each other.
std::regex buildMatcher(const std::vector<Segment>& segments) {
    std::string re;
    for (const Segment& s : segments) {
        if (!s.token) {
            re += escapeRegex(s.literal);
        } else if (*s.token == Token::UvTile) {
            re += "u([0-9]{1,2})_v([0-9]{1,4})";
        } else {
            re += "([0-9]{4})";
        }
    }
    return std::regex(re, std::regex::ECMAScript | std::regex::optimize);
}

std::optional<int> proposedTile(const std::vector<Segment>& segments, const std::smatch& match) {
    const Segment& first =
        *std::find_if(segments.begin(), segments.end(), [](const Segment& s) { return s.token; });
    if (*first.token != Token::UvTile) return std::stoi(match[1].str());
    const int u = std::stoi(match[1].str()), v = std::stoi(match[2].str());
    if (u < 1 || u > 10 || v < 1) return std::nullopt;
    return kFirstTile + (u - 1) + 10 * (v - 1);
}

}  // namespace

bool hasUdimToken(std::string_view pattern) {
    return hasToken(splitPattern(pattern));
}

TileOrigin udimOrigin(int tile) {
    requireValidTile(tile, "UDIM");
    return {(tile - kFirstTile) % 10, (tile - kFirstTile) / 10};
}

std::string expandUdim(std::string_view pattern, int tile) {
    const std::vector<Segment> segments = splitPattern(pattern);
    if (!hasToken(segments)) {
        throw InvalidInput(
            formatError(pattern, "", "has no UDIM token", "<UDIM>, <UVTILE>, %(UDIM)d or _MAPID_"));
    }
    requireValidTile(tile, pattern);
    return expandSegments(segments, tile);
}

std::vector<UdimFile> findUdimFiles(const fs::path& pattern) {
    const std::string name = pattern.filename().string();
    const std::vector<Segment> segments = splitPattern(name);
    // Only the pattern's own folder is scanned, so a token must be in the file name.
    if (hasUdimToken(pattern.parent_path().string())) {
        throw InvalidInput(formatError(pattern.string(), "", "has a UDIM token in a folder name",
                                       "<UDIM>, <UVTILE>, %(UDIM)d or _MAPID_ in the file name only"));
    }
    if (!hasToken(segments)) {
        throw InvalidInput(formatError(pattern.string(), "", "has no UDIM token",
                                       "<UDIM>, <UVTILE>, %(UDIM)d or _MAPID_ in the file name"));
    }

    const fs::path folder = pattern.parent_path().empty() ? fs::path(".") : pattern.parent_path();
    std::error_code ec;
    if (!fs::is_directory(folder, ec)) {
        throw IoError(formatError(pattern.string(), "", "folder '" + folder.string() + "' does not exist",
                                  "an existing folder"));
    }

    const std::regex matcher = buildMatcher(segments);
    std::vector<UdimFile> files;
    fs::directory_iterator it(folder, ec);
    for (; !ec && it != fs::directory_iterator(); it.increment(ec)) {
        const std::string candidate = it->path().filename().string();
        std::smatch match;
        if (!std::regex_match(candidate, match, matcher)) continue;
        const std::optional<int> tile = proposedTile(segments, match);
        if (!tile || !isValidTile(*tile) || expandSegments(segments, *tile) != candidate) continue;
        std::error_code typeEc;
        if (!it->is_regular_file(typeEc)) continue;
        files.push_back({*tile, pattern.parent_path() / candidate});
    }
    if (ec) {
        throw IoError(formatError(pattern.string(), "",
                                  "cannot list folder '" + folder.string() + "': " + ec.message(),
                                  "a readable folder"));
    }
    if (files.empty()) {
        throw IoError(formatError(
            "", "", "UDIM pattern '" + pattern.string() + "' matches no file in '" + folder.string() + "'",
            "files such as '" + expandSegments(segments, kFirstTile) + "'"));
    }
    std::sort(files.begin(), files.end(),
              [](const UdimFile& a, const UdimFile& b) { return a.tile < b.tile; });
    return files;
}

}  // namespace deformkit::io
