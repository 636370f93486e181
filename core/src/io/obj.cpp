#include "deformkit/io/obj.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <limits>
#include <unordered_map>

#include "deformkit/error.h"
#include "deformkit/geom/finite.h"
#include "deformkit/io/atomic_file.h"
#include "deformkit/io/read_file.h"
#include "polygon_loops.h"

namespace deformkit::io {
namespace fs = std::filesystem;

namespace {

constexpr std::string_view kVertexForm = "v x y z, optionally followed by w or by r g b";
constexpr std::string_view kTexCoordForm = "vt u v, optionally followed by w";
constexpr std::string_view kCornerForm = "a face corner v, v/vt, v//vn or v/vt/vn with integer indices";

// Character classes for the scanner's hot loops.
enum CharClass : uint8_t { kBlank = 1, kStatementEnd = 2, kBackslash = 4 };
constexpr std::array<uint8_t, 256> kCharClass = [] {
    std::array<uint8_t, 256> table{};
    for (const char c : {' ', '\t', '\r', '\f', '\v'})
        table[static_cast<uint8_t>(c)] = kBlank;
    table['\n'] = table['#'] = kStatementEnd;
    table['\\'] = kBackslash;
    return table;
}();

bool isBlank(char c) {
    return kCharClass[static_cast<uint8_t>(c)] == kBlank;
}

// Statements of the OBJ specification that carry nothing a polygon mesh needs (normals are counted
// apart, so that v//vn corners can be checked).
bool isIgnoredStatement(std::string_view keyword) {
    static constexpr std::string_view kIgnored[] = {
        "vp",   "l",     "p",        "s",        "mg",         "usemtl",   "mtllib", "usemap", "maplib",
        "lod",  "bevel", "c_interp", "d_interp", "ctech",      "stech",    "cstype", "deg",    "bmat",
        "step", "curv",  "curv2",    "surf",     "parm",       "trim",     "hole",   "scrv",   "sp",
        "end",  "con",   "call",     "csh",      "shadow_obj", "trace_obj"};
    return std::find(std::begin(kIgnored), std::end(kIgnored), keyword) != std::end(kIgnored);
}

// Exporters add their own lower-case statements (vc, vw, ...); readers skip them as DCCs do. Anything
// else (an upper-case typo, binary bytes from a file that is not an OBJ) is an error.
bool isExtensionKeyword(std::string_view keyword) {
    if (keyword.empty() || !(keyword[0] >= 'a' && keyword[0] <= 'z')) return false;
    return std::all_of(keyword.begin(), keyword.end(),
                       [](char c) { return (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_'; });
}

// A token as shown in messages: at most 40 bytes, anything unprintable as \xNN.
std::string printable(std::string_view token) {
    static constexpr char kHex[] = "0123456789abcdef";
    std::string out = "'";
    const size_t shown = std::min<size_t>(token.size(), 40);
    for (size_t i = 0; i < shown; ++i) {
        const auto c = static_cast<unsigned char>(token[i]);
        if (c >= 0x20 && c < 0x7f) {
            out.push_back(static_cast<char>(c));
        } else {
            out += "\\x";
            out.push_back(kHex[c >> 4]);
            out.push_back(kHex[c & 15]);
        }
    }
    if (shown < token.size()) out += "...";
    out += "'";
    return out;
}

std::string lineLabel(int64_t line) {
    return "line " + std::to_string(line);
}

class ObjParser {
  public:
    ObjParser(std::string_view text, const std::string& source)
        : p_(text.data()), end_(text.data() + text.size()), source_(source) {}

    ObjContent parse() {
        while (p_ < end_) {
            skipBlanks();
            statementLine_ = line_;
            if (atStatementEnd()) {
                endStatement();
                continue;
            }
            const std::string_view keyword = nextToken();
            if (keyword == "v") {
                readVertex();
            } else if (keyword == "f") {
                readFace();
            } else if (keyword == "vt") {
                readTexCoord();
            } else if (keyword == "vn") {
                ++normalCount_;
                skipStatement();
            } else if (keyword == "g" || keyword == "o") {
                readGroupNames();
            } else if (isIgnoredStatement(keyword) || isExtensionKeyword(keyword)) {
                skipStatement();
            } else {
                fail<ParseError>(statementLine_, "unknown statement " + printable(keyword),
                                 "an OBJ statement such as v, vt, vn, f, g or o");
            }
        }
        return finish();
    }

  private:
    template <typename ErrorType>
    [[noreturn]] void fail(int64_t line, const std::string& problem, std::string_view expected) const {
        throw ErrorType(formatError(source_, lineLabel(line), problem, expected));
    }

    // A backslash that joins the next line: only blanks may follow it before the line break.
    bool continuationAt(const char* p) const {
        if (*p != '\\') return false;
        for (++p; p < end_ && isBlank(*p); ++p) {
        }
        return p == end_ || *p == '\n';
    }

    void skipBlanks() {
        while (p_ < end_) {
            if (isBlank(*p_)) {
                ++p_;
            } else if (*p_ == '\\' && continuationAt(p_)) {
                for (++p_; p_ < end_ && *p_ != '\n'; ++p_) {
                }
                if (p_ < end_) {
                    ++p_;
                    ++line_;
                }
            } else {
                return;
            }
        }
    }

    bool atStatementEnd() const { return p_ == end_ || *p_ == '\n' || *p_ == '#'; }

    bool atSeparator(const char* p) const {
        if (p == end_) return true;
        const uint8_t c = kCharClass[static_cast<uint8_t>(*p)];
        return c != 0 && (c != kBackslash || continuationAt(p));
    }

    // The token at the cursor (which must not be at a statement end); the cursor moves past it.
    std::string_view nextToken() {
        const char* begin = p_;
        while (!atSeparator(p_))
            ++p_;
        return {begin, static_cast<size_t>(p_ - begin)};
    }

    std::string_view tokenAt(const char* begin) const {
        const char* p = begin;
        while (!atSeparator(p))
            ++p;
        return {begin, static_cast<size_t>(p - begin)};
    }

    // Requires the statement to be over, then moves past its comment and line break.
    void endStatement(std::string_view expected = {}) {
        skipBlanks();
        if (!atStatementEnd()) {
            fail<ParseError>(line_, "unexpected " + printable(tokenAt(p_)), expected);
        }
        if (p_ < end_ && *p_ == '#') {
            while (p_ < end_ && *p_ != '\n')
                ++p_;
        }
        if (p_ < end_) {
            ++p_;
            ++line_;
        }
    }

    void skipStatement() {
        for (skipBlanks(); !atStatementEnd(); skipBlanks())
            nextToken();
        endStatement();
    }

    // "1.#QNAN", "-1.#IND00", "1.#INF": how old Microsoft runtimes print NaN and infinity. Read as a number,
    // the '#' would start a comment and leave 1 (`after` is where the digits "1." end).
    bool isMicrosoftNonFinite(const char* after) const {
        if (after == p_ || after[-1] != '.' || after >= end_ || *after != '#') return false;
        std::string word;
        for (const char* q = after + 1;
             q < end_ && std::isalpha(static_cast<unsigned char>(*q)) && word.size() < 4; ++q)
            word.push_back(static_cast<char>(std::toupper(static_cast<unsigned char>(*q))));
        return word == "QNAN" || word == "SNAN" || word.starts_with("IND") || word.starts_with("INF");
    }

    // Reads a number into `value`; false at the end of the statement. `finite` rejects NaN and inf.
    bool readFloat(float& value, std::string_view expected, bool finite = true) {
        skipBlanks();
        if (atStatementEnd()) return false;
        const char* first = p_;
        // from_chars takes no leading '+'.
        if (*first == '+' && first + 1 < end_ && first[1] != '+' && first[1] != '-') ++first;
        auto [ptr, ec] = std::from_chars(first, end_, value);
        if (ec == std::errc::result_out_of_range) {
            // Underflow (a tiny value) is fine: it rounds to zero or a subnormal. Beyond double's range too
            // (1e-400): read in long double, which holds it, and narrowed to 0.
            long double wide = 0.0L;
            const auto r = std::from_chars(first, end_, wide);
            auto narrowed = static_cast<float>(wide);
            if (r.ec == std::errc() && !std::isfinite(narrowed) && !finite)
                narrowed = 0.0f;  // ignored anyway
            if (r.ec != std::errc() || !std::isfinite(narrowed)) {
                fail<InvalidInput>(
                    line_, "number " + printable(tokenAt(p_)) + " is out of the range of a 32-bit float",
                    "a finite number");
            }
            value = narrowed;
            ptr = r.ptr;
            ec = std::errc();
        }
        if (ec == std::errc() && isMicrosoftNonFinite(ptr)) {
            const char* last = ptr;
            while (last < end_ && !isBlank(*last) && *last != '\n')
                ++last;
            const std::string_view token(p_, static_cast<size_t>(last - p_));
            if (finite)
                fail<InvalidInput>(line_, "coordinate " + printable(token) + " is NaN or infinite",
                                   "finite coordinates");
            fail<ParseError>(line_, "malformed number " + printable(token), expected);
        }
        if (ec != std::errc() || !atSeparator(ptr)) {
            fail<ParseError>(line_, "malformed number " + printable(tokenAt(p_)), expected);
        }
        if (finite && !std::isfinite(value)) {
            fail<InvalidInput>(line_, "coordinate " + printable(tokenAt(p_)) + " is NaN or infinite",
                               "finite coordinates");
        }
        p_ = ptr;
        return true;
    }

    void readVertex() {
        glm::vec3 point;
        for (int k = 0; k < 3; ++k) {
            if (!readFloat(point[k], kVertexForm)) {
                fail<ParseError>(statementLine_, "vertex has " + std::to_string(k) + " coordinates",
                                 kVertexForm);
            }
        }
        float ignored = 0.0f;
        for (int extra = 0; extra < 4 && readFloat(ignored, kVertexForm, false); ++extra) {
        }
        endStatement(kVertexForm);
        data_.points.push_back(point);
    }

    void readTexCoord() {
        glm::vec2 uv;
        for (int k = 0; k < 2; ++k) {
            if (!readFloat(uv[k], kTexCoordForm)) {
                fail<ParseError>(statementLine_, "texture coordinate has " + std::to_string(k) + " values",
                                 kTexCoordForm);
            }
        }
        float ignored = 0.0f;
        readFloat(ignored, kTexCoordForm, false);
        endStatement(kTexCoordForm);
        data_.uvs.push_back(uv);
    }

    struct Index {
        int64_t value = 0;
        std::string_view text;  // as written, for messages
    };

    // Parses an integer at `p` (optional sign, digits), moving `p` past it. Values beyond 10^18 saturate:
    // they are out of range of any index anyway.
    static bool parseInteger(const char*& p, const char* end, Index& index) {
        constexpr int64_t kSaturated = std::numeric_limits<int64_t>::max();
        const char* q = p;
        const bool negative = q < end && *q == '-';
        if (q < end && (*q == '-' || *q == '+')) ++q;
        const char* digits = q;
        int64_t value = 0;
        for (; q < end && static_cast<unsigned>(*q - '0') < 10; ++q) {
            value = value >= 100'000'000'000'000'000 ? kSaturated : value * 10 + (*q - '0');
        }
        if (q == digits) return false;
        index.value = negative ? -value : value;
        index.text = std::string_view(p, static_cast<size_t>(q - p));
        p = q;
        return true;
    }

    struct Kind {
        std::string_view one, many;
    };
    static constexpr Kind kVertex{"vertex", "vertices"},
        kTexCoord{"texture coordinate", "texture coordinates"}, kNormal{"normal", "normals"};

    // Turns a 1-based or negative (relative) OBJ index into a 0-based one.
    int32_t resolveIndex(const Index& index, size_t count, const Kind& kind) const {
        const auto n = static_cast<int64_t>(count);
        if (index.value > 0 && index.value <= n) return static_cast<int32_t>(index.value - 1);
        if (index.value < 0 && index.value >= -n) return static_cast<int32_t>(n + index.value);
        failIndex(index, n, kind);
    }

    [[noreturn]] void failIndex(const Index& index, int64_t count, const Kind& kind) const {
        const std::string range =
            count == 0 ? "a " + std::string(kind.one) + " defined before it (none is yet)"
                       : "an index in 1.." + std::to_string(count) + " or -" + std::to_string(count) + "..-1";
        const std::string written = std::string(index.text.substr(0, 40));
        if (index.value == 0) {
            fail<InvalidInput>(
                line_, std::string(kind.one) + " index " + written + " is not valid (OBJ indices start at 1)",
                range);
        }
        fail<InvalidInput>(line_,
                           std::string(kind.one) + " index " + written +
                               " is out of range: " + std::to_string(count) + " " +
                               std::string(count == 1 ? kind.one : kind.many) + " defined so far",
                           range);
    }

    void readFace() {
        int32_t corners = 0;
        bool faceHasUVs = false;
        while (true) {
            skipBlanks();
            if (atStatementEnd()) break;
            const char* p = p_;
            Index v, t, n;
            bool hasT = false, hasN = false, ok = parseInteger(p, end_, v);
            if (ok && p < end_ && *p == '/') {
                ++p;
                if (p < end_ && *p == '/') {
                    ++p;
                    ok = hasN = parseInteger(p, end_, n);
                } else {
                    ok = hasT = parseInteger(p, end_, t);
                    if (ok && p < end_ && *p == '/') {
                        ++p;
                        ok = hasN = parseInteger(p, end_, n);
                    }
                }
            }
            if (!ok || !atSeparator(p))
                fail<ParseError>(line_, "malformed face corner " + printable(tokenAt(p_)), kCornerForm);
            const int32_t vertex = resolveIndex(v, data_.points.size(), kVertex);
            const int32_t uv = hasT ? resolveIndex(t, data_.uvs.size(), kTexCoord) : -1;
            if (hasN) resolveIndex(n, normalCount_, kNormal);
            if (corners == 0) {
                faceHasUVs = hasT;
            } else if (hasT != faceHasUVs) {
                fail<InvalidInput>(line_,
                                   "face corner " + std::to_string(corners + 1) + " " +
                                       printable(tokenAt(p_)) + (hasT ? " has" : " has no") +
                                       " texture coordinate, unlike corner 1",
                                   "texture coordinates on every corner of a face or on none");
            }
            p_ = p;
            data_.faceIndices.push_back(vertex);
            data_.uvIndices.push_back(uv);  // -1: no UVs (cleared at the end when no face has any)
            ++corners;
        }
        endStatement();
        if (corners < 3) {
            fail<InvalidInput>(statementLine_, "face has " + std::to_string(corners) + " vertices",
                               "at least 3 vertices per face");
        }
        int64_t& firstLine = faceHasUVs ? firstLineWithUVs_ : firstLineWithoutUVs_;
        if (firstLine == 0) firstLine = statementLine_;
        faceCorners_.clear();
        if (hasRepeat(corners)) {
            splitRepeats(corners);
        } else {
            faceCorners_.push_back(corners);
        }
        for (const int32_t count : faceCorners_) {
            if (data_.faceCounts.size() >= static_cast<size_t>(std::numeric_limits<int32_t>::max())) {
                fail<InvalidInput>(statementLine_, "too many faces", "fewer than 2^31 faces");
            }
            const auto face = static_cast<int32_t>(data_.faceCounts.size());
            data_.faceCounts.push_back(count);
            addToCurrentGroups(face);
        }
    }

    // A polygon that visits a vertex twice becomes the loops it is made of (polygon_loops.h); the count is
    // reported (ObjContent::repairedFaces). Replaces the polygon's last `corners` entries; faceCorners_ gets
    // the corner counts of the faces it becomes.
    void splitRepeats(int32_t corners) {
        const size_t n = static_cast<size_t>(corners);
        const std::vector<int32_t> v(data_.faceIndices.end() - static_cast<ptrdiff_t>(n),
                                     data_.faceIndices.end());
        const std::vector<int32_t> t(data_.uvIndices.end() - static_cast<ptrdiff_t>(n),
                                     data_.uvIndices.end());
        data_.faceIndices.resize(data_.faceIndices.size() - n);
        data_.uvIndices.resize(data_.uvIndices.size() - n);
        for (const std::vector<size_t>& loop : polygonLoops(v)) {
            for (const size_t k : loop) {
                data_.faceIndices.push_back(v[k]);
                data_.uvIndices.push_back(t[k]);
            }
            faceCorners_.push_back(static_cast<int32_t>(loop.size()));
        }
        if (faceCorners_.empty()) {
            fail<InvalidInput>(statementLine_, "face has fewer than 3 distinct vertices",
                               "at least 3 distinct vertices per face");
        }
        ++repairedFaces_;
        if (firstRepairedLine_ == 0) firstRepairedLine_ = statementLine_;
    }

    bool hasRepeat(int32_t corners) {
        const auto face = std::span<const int32_t>(data_.faceIndices).last(static_cast<size_t>(corners));
        if (corners <= 16) {
            for (int32_t k = 1; k < corners; ++k) {
                for (int32_t j = 0; j < k; ++j)
                    if (face[j] == face[k]) return true;
            }
            return false;
        }
        scratch_.assign(face.begin(), face.end());
        std::sort(scratch_.begin(), scratch_.end());
        return std::adjacent_find(scratch_.begin(), scratch_.end()) != scratch_.end();
    }

    void readGroupNames() {
        currentNames_.clear();
        currentGroups_.clear();
        namesResolved_ = false;
        for (skipBlanks(); !atStatementEnd(); skipBlanks()) {
            const std::string_view name = nextToken();
            // Written back, such a name would end its line and read as a continuation.
            if (name.back() == '\\') {
                fail<ParseError>(line_, "group name " + printable(name) + " ends in a backslash",
                                 "a name that does not end in '\\'");
            }
            currentNames_.push_back(name);
        }
        endStatement();
    }

    // Groups are created when their first face appears, so a `g` naming no faces (Maya's leading
    // `g default`) adds no group and group order is the order of first faces.
    void addToCurrentGroups(int32_t face) {
        if (!namesResolved_) {
            for (const std::string_view name : currentNames_) {
                auto [it, inserted] =
                    groupByName_.try_emplace(std::string(name), static_cast<int32_t>(groups_.size()));
                if (inserted) groups_.push_back(FaceGroup{std::string(name), {}});
                if (std::find(currentGroups_.begin(), currentGroups_.end(), it->second) ==
                    currentGroups_.end()) {
                    currentGroups_.push_back(it->second);
                }
            }
            namesResolved_ = true;
        }
        for (const int32_t g : currentGroups_)
            groups_[g].faces.push_back(face);
    }

    ObjContent finish() {
        if (data_.faceCounts.empty()) {
            throw ParseError(formatError(source_, "",
                                         "contains no faces (" + std::to_string(line_) + " lines, " +
                                             std::to_string(data_.points.size()) + " vertices)",
                                         "at least one 'f' statement"));
        }
        if (data_.points.size() > static_cast<size_t>(std::numeric_limits<int32_t>::max()) ||
            data_.uvs.size() > static_cast<size_t>(std::numeric_limits<int32_t>::max())) {
            throw InvalidInput(formatError(source_, "", "has too many vertices", "fewer than 2^31"));
        }
        // Without a face with UVs the mesh has none: texture coordinates no face uses are dropped.
        if (firstLineWithUVs_ == 0) {
            data_.uvIndices = {};  // released, not kept as capacity in the mesh
            data_.uvs = {};
        }
        ObjContent content;
        content.mesh = geom::Mesh(std::move(data_), source_);
        content.groups = std::move(groups_);
        content.repairedFaces = repairedFaces_;
        content.facesWithoutUVs = content.mesh.numFacesWithoutUVs();
        content.firstLineWithoutUVs = content.facesWithoutUVs > 0 ? firstLineWithoutUVs_ : 0;
        content.firstRepairedLine = firstRepairedLine_;
        return content;
    }

    const char* p_;
    const char* end_;
    const std::string& source_;
    int64_t line_ = 1;
    int64_t statementLine_ = 1;
    int64_t firstLineWithUVs_ = 0;  // 0: none seen yet
    int64_t firstLineWithoutUVs_ = 0;
    size_t normalCount_ = 0;
    geom::Mesh::Data data_;
    std::vector<FaceGroup> groups_;
    std::unordered_map<std::string, int32_t> groupByName_;
    std::vector<std::string_view> currentNames_;
    std::vector<int32_t> currentGroups_;
    bool namesResolved_ = true;
    std::vector<int32_t> scratch_;
    std::vector<int32_t>
        faceCorners_;  // the faces one `f` statement becomes (one, unless it repeats a vertex)
    int64_t repairedFaces_ = 0;
    int64_t firstRepairedLine_ = 0;
};

// Text output without iostreams: numbers through to_chars.
class ObjText {
  public:
    explicit ObjText(int precision) : precision_(precision) {}

    void reserve(size_t bytes) { text_.reserve(bytes); }
    void append(std::string_view s) { text_.append(s); }
    void append(char c) { text_.push_back(c); }
    void number(float value) {
        char buffer[64];
        const auto r =
            std::to_chars(buffer, buffer + sizeof buffer, value, std::chars_format::general, precision_);
        text_.append(buffer, r.ptr);
    }
    void number(int64_t value) {
        char buffer[24];
        const auto r = std::to_chars(buffer, buffer + sizeof buffer, value);
        text_.append(buffer, r.ptr);
    }
    std::string take() { return std::move(text_); }

  private:
    std::string text_;
    int precision_;
};

void checkGroupName(const std::string& name, std::string_view target) {
    const bool unwritable =
        name.empty() || name.back() == '\\' ||
        std::any_of(name.begin(), name.end(), [](char c) { return isBlank(c) || c == '\n' || c == '#'; });
    if (unwritable) {
        throw InvalidInput(formatError(target, "group " + printable(name),
                                       "cannot be written as an OBJ group name",
                                       "a non-empty name without blanks or '#' that does not end in '\\'"));
    }
}

// formatObj, with `target` (the file written, or a label) named in errors.
std::string formatObjText(const geom::Mesh& mesh, const std::vector<FaceGroup>& groups,
                          const ObjWriteOptions& options, std::string_view target);

}  // namespace

ObjContent parseObj(std::string_view text, const std::string& source) {
    // A UTF-16 file (byte order mark, or a NUL in its first bytes) would fail as an unknown statement.
    const bool bom =
        text.size() >= 2 &&
        ((static_cast<unsigned char>(text[0]) == 0xFE && static_cast<unsigned char>(text[1]) == 0xFF) ||
         (static_cast<unsigned char>(text[0]) == 0xFF && static_cast<unsigned char>(text[1]) == 0xFE));
    if (bom || text.substr(0, 64).find('\0') != std::string_view::npos) {
        throw ParseError(formatError(source, "", "is UTF-16 text, which is not supported",
                                     "UTF-8 or ASCII text: save the file as UTF-8"));
    }
    // UTF-8 with a byte order mark (what Windows editors write as "UTF-8") is UTF-8: the mark is skipped,
    // line numbers stay.
    if (text.starts_with("\xEF\xBB\xBF")) text.remove_prefix(3);
    // A CR alone ends a line (classic Mac OS editors and exporters, or files pasted together from both): read
    // as a blank, it would join two statements and drop the second. CR LF stays one line end.
    // CRs before an LF (CR LF, or CR CR LF from a file converted twice) are blanks of that one line end.
    auto loneCr = [&](size_t i) {
        if (text[i] != '\r') return false;
        size_t next = i + 1;
        while (next < text.size() && text[next] == '\r')
            ++next;
        return next == text.size() || text[next] != '\n';
    };
    for (size_t i = text.find('\r'); i != std::string_view::npos; i = text.find('\r', i + 1)) {
        if (!loneCr(i)) continue;
        std::string lines(text);
        for (size_t j = i; j < lines.size(); ++j)
            if (loneCr(j)) lines[j] = '\n';
        return ObjParser(lines, source).parse();
    }
    return ObjParser(text, source).parse();
}

ObjContent readObj(const fs::path& path) {
    const std::string bytes = readFile(path, "OBJ file");
    return parseObj(bytes, path.string());
}

std::string formatObj(const geom::Mesh& mesh, const std::vector<FaceGroup>& groups,
                      const ObjWriteOptions& options) {
    return formatObjText(mesh, groups, options, "OBJ output");
}

void writeObj(const fs::path& path, const geom::Mesh& mesh, const std::vector<FaceGroup>& groups,
              const ObjWriteOptions& options) {
    requireExtension(path, {".obj"}, "an OBJ mesh");
    writeFileAtomically(path, formatObjText(mesh, groups, options, path.string()));
}

namespace {

std::string formatObjText(const geom::Mesh& mesh, const std::vector<FaceGroup>& groups,
                          const ObjWriteOptions& options, std::string_view target) {
    if (mesh.numFaces() == 0) {
        // The reader rejects such a file: refuse to write what cannot be read back.
        throw InvalidInput(formatError(target, "", "the mesh has no faces", "at least one face"));
    }
    if (options.precision < 1 || options.precision > 17) {
        throw InvalidInput(formatError(target, "precision", "is " + std::to_string(options.precision),
                                       "1 to 17 significant digits"));
    }
    // The reader refuses NaN and infinite coordinates: a mesh whose points were changed after it was made
    // (Python's writable Mesh.points) must not write them.
    const std::span<const glm::vec3> points = mesh.points();
    if (const size_t bad = geom::firstNonFinite(points); bad < points.size()) {
        const glm::vec3& p = points[bad];
        throw InvalidInput(
            formatError(target, "vertex " + std::to_string(bad),
                        "is (" + numberText(p.x) + ", " + numberText(p.y) + ", " + numberText(p.z) + ")",
                        "finite coordinates"));
    }
    for (size_t t = 0; t < mesh.uvs().size(); ++t) {
        const glm::vec2& uv = mesh.uvs()[t];
        if (!std::isfinite(uv.x) || !std::isfinite(uv.y)) {
            throw InvalidInput(formatError(target, "texture coordinate " + std::to_string(t),
                                           "is (" + numberText(uv.x) + ", " + numberText(uv.y) + ")",
                                           "finite coordinates"));
        }
    }
    const int32_t numFaces = mesh.numFaces();
    // Each face's groups, as offsets into `members` (a face may belong to several groups).
    std::vector<int32_t> memberOffsets(static_cast<size_t>(numFaces) + 1, 0);
    std::vector<int32_t> members;
    if (!groups.empty()) {
        for (size_t g = 0; g < groups.size(); ++g) {
            checkGroupName(groups[g].name, target);
            for (const int32_t f : groups[g].faces) {
                if (f < 0 || f >= numFaces) {
                    throw InvalidInput(formatError(target, "group " + printable(groups[g].name),
                                                   "face index " + std::to_string(f) + " is out of range",
                                                   "an index in [0, " + std::to_string(numFaces) + ")"));
                }
                ++memberOffsets[f + 1];
            }
        }
        for (int32_t f = 0; f < numFaces; ++f)
            memberOffsets[f + 1] += memberOffsets[f];
        members.resize(memberOffsets.back());
        std::vector<int32_t> fill(memberOffsets.begin(), memberOffsets.end() - 1);
        for (size_t g = 0; g < groups.size(); ++g) {
            for (const int32_t f : groups[g].faces)
                members[fill[f]++] = static_cast<int32_t>(g);
        }
        for (int32_t f = 0; f < numFaces; ++f) {
            const auto first = members.begin() + memberOffsets[f],
                       last = members.begin() + memberOffsets[f + 1];
            std::sort(first, last);
            const auto unique = std::unique(first, last);
            std::fill(unique, last, -1);
        }
    }

    ObjText out(options.precision);
    out.reserve(static_cast<size_t>(mesh.numVertices()) * 40 + static_cast<size_t>(mesh.numUVs()) * 28 +
                static_cast<size_t>(mesh.numCorners()) * 16 + static_cast<size_t>(numFaces) * 4 + 64);
    out.append("# DeformKit OBJ: ");
    out.number(int64_t{mesh.numVertices()});
    out.append(" vertices, ");
    out.number(int64_t{numFaces});
    out.append(" faces\n");
    for (const glm::vec3& p : mesh.points()) {
        out.append("v ");
        out.number(p.x);
        out.append(' ');
        out.number(p.y);
        out.append(' ');
        out.number(p.z);
        out.append('\n');
    }
    const bool withUVs = mesh.hasUVs();
    if (withUVs) {
        for (const glm::vec2& t : mesh.uvs()) {
            out.append("vt ");
            out.number(t.x);
            out.append(' ');
            out.number(t.y);
            out.append('\n');
        }
    }
    std::span<const int32_t> previous;
    for (int32_t f = 0; f < numFaces; ++f) {
        if (!groups.empty()) {
            auto current = std::span<const int32_t>(members).subspan(memberOffsets[f],
                                                                     memberOffsets[f + 1] - memberOffsets[f]);
            while (!current.empty() && current.back() < 0)
                current = current.first(current.size() - 1);
            if (f == 0 ? !current.empty()
                       : !std::equal(current.begin(), current.end(), previous.begin(), previous.end())) {
                // A bare `g` puts the following faces in no group.
                out.append('g');
                for (const int32_t g : current) {
                    out.append(' ');
                    out.append(groups[g].name);
                }
                out.append('\n');
            }
            previous = current;
        }
        out.append('f');
        const auto vertices = mesh.face(f);
        const auto uvs = mesh.faceUVIndices(f);  // empty for a face without UVs
        for (size_t k = 0; k < vertices.size(); ++k) {
            out.append(' ');
            out.number(int64_t{vertices[k]} + 1);
            if (!uvs.empty()) {
                out.append('/');
                out.number(int64_t{uvs[k]} + 1);
            }
        }
        out.append('\n');
    }
    return out.take();
}

}  // namespace

}  // namespace deformkit::io
