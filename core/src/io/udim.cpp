#include "deformkit/io/udim.h"

#include <algorithm>
#include <array>
#include <optional>
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

bool allDigits(std::string_view text) {
    return !text.empty() &&
           std::all_of(text.begin(), text.end(), [](char c) { return c >= '0' && c <= '9'; });
}

int digitsValue(std::string_view digits) {  // at most four digits: no overflow
    int value = 0;
    for (const char c : digits)
        value = 10 * value + (c - '0');
    return value;
}

constexpr int kNoTile = 0;        // no token read yet
constexpr int kInvalidTile = -1;  // the first token spells no UDIM tile

// The tile of a file name matched against a pattern: the first token proposes a tile (four digits for the
// numeric tokens, u<1-2 digits>_v<1-4 digits> for <UVTILE>), and a name is accepted when expanding the
// pattern with that tile gives it back exactly, which rejects leading zeros, out-of-range indices and tokens
// that disagree with each other. Every way of splitting the name between the tokens is tried (a pattern
// has one or two tokens, so there are at most a few dozen).
class TileMatcher {
  public:
    explicit TileMatcher(const std::vector<Segment>& segments) : segments_(segments) {}

    std::optional<int> match(std::string_view name) const { return visit(0, name, kNoTile, name); }

  private:
    // Matches segments_[seg...] against `rest`; `tile` is what the first token spelled (kNoTile before it).
    std::optional<int> visit(size_t seg, std::string_view rest, int tile, std::string_view name) const {
        if (seg == segments_.size()) {
            if (rest.empty() && isValidTile(tile) && expandSegments(segments_, tile) == name) return tile;
            return std::nullopt;
        }
        const Segment& s = segments_[seg];
        if (!s.token) {
            if (!rest.starts_with(s.literal)) return std::nullopt;
            return visit(seg + 1, rest.substr(s.literal.size()), tile, name);
        }
        if (*s.token != Token::UvTile) {
            if (rest.size() < 4 || !allDigits(rest.substr(0, 4))) return std::nullopt;
            return visit(seg + 1, rest.substr(4), tile == kNoTile ? digitsValue(rest.substr(0, 4)) : tile,
                         name);
        }
        if (!rest.starts_with('u')) return std::nullopt;
        for (size_t uLength = 1; uLength <= 2; ++uLength) {
            if (rest.size() < 1 + uLength || !allDigits(rest.substr(1, uLength))) break;
            const std::string_view afterU = rest.substr(1 + uLength);
            if (!afterU.starts_with("_v")) continue;
            const int u = digitsValue(rest.substr(1, uLength));
            for (size_t vLength = 1; vLength <= 4; ++vLength) {
                if (afterU.size() < 2 + vLength || !allDigits(afterU.substr(2, vLength))) break;
                const int v = digitsValue(afterU.substr(2, vLength));
                const int spelled =
                    (u < 1 || u > 10 || v < 1) ? kInvalidTile : kFirstTile + (u - 1) + 10 * (v - 1);
                const std::optional<int> found =
                    visit(seg + 1, afterU.substr(2 + vLength), tile == kNoTile ? spelled : tile, name);
                if (found) return found;
            }
        }
        return std::nullopt;
    }

    const std::vector<Segment>& segments_;
};

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

    const TileMatcher matcher(segments);
    std::vector<UdimFile> files;
    fs::directory_iterator it(folder, ec);
    for (; !ec && it != fs::directory_iterator(); it.increment(ec)) {
        const std::string candidate = it->path().filename().string();
        const std::optional<int> tile = matcher.match(candidate);
        if (!tile) continue;
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
