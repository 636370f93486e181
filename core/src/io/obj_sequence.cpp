#include "deformkit/io/obj_sequence.h"

#include <algorithm>
#include <charconv>
#include <cstdlib>
#include <span>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>

#include "deformkit/error.h"

namespace deformkit::io {
namespace fs = std::filesystem;

namespace {

constexpr std::string_view kPatternForm =
    "one frame token in the file name, as in name.####.obj or name.%04d.obj";
constexpr int kMaxPadding = 32;

struct FrameToken {
    size_t position = 0;
    size_t length = 0;
    int padding = 0;  // digits; 0 for %d
};

// Finds the frame tokens of a file name: runs of '#' and printf's %d / %0Nd. Returns how many there are
// and the first in `first`.
int findTokens(std::string_view name, FrameToken& first) {
    int count = 0;
    for (size_t i = 0; i < name.size();) {
        FrameToken token;
        if (name[i] == '#') {
            size_t j = i;
            while (j < name.size() && name[j] == '#')
                ++j;
            token = {i, j - i, static_cast<int>(std::min<size_t>(j - i, kMaxPadding + 1))};
        } else if (name[i] == '%') {
            size_t j = i + 1;
            int padding = 0;
            if (j < name.size() && name[j] == '0') {
                ++j;
                const size_t digits = j;
                while (j < name.size() && name[j] >= '0' && name[j] <= '9')
                    ++j;
                const auto parsed = std::from_chars(name.data() + digits, name.data() + j, padding);
                if (parsed.ec == std::errc::result_out_of_range || padding > kMaxPadding)
                    padding = kMaxPadding + 1;
            }
            if (j >= name.size() || name[j] != 'd') {
                i = j;
                continue;
            }
            token = {i, j + 1 - i, padding};
        } else {
            ++i;
            continue;
        }
        if (count == 0) first = token;
        ++count;
        i = token.position + token.length;
    }
    return count;
}

std::string fileNameOf(const std::string& pattern) {
    const size_t slash = pattern.find_last_of('/');
    return slash == std::string::npos ? pattern : pattern.substr(slash + 1);
}

std::string describeFace(std::span<const int32_t> vertices) {
    std::string text = std::to_string(vertices.size()) + " vertices (";
    const size_t shown = std::min<size_t>(vertices.size(), 8);
    for (size_t k = 0; k < shown; ++k)
        text += (k ? " " : "") + std::to_string(vertices[k]);
    return text + (shown < vertices.size() ? " ...)" : ")");
}

}  // namespace

namespace {

// Why `pattern` is not a sequence's, and what is expected instead; an empty problem when it is one (its
// token then in `token`).
std::pair<std::string, std::string_view> patternFault(const std::string& pattern, FrameToken& token) {
    const int count = findTokens(fileNameOf(pattern), token);
    if (count == 0) return {"has no frame token in its file name", kPatternForm};
    if (count > 1) return {"has " + std::to_string(count) + " frame tokens in its file name", kPatternForm};
    if (token.padding > kMaxPadding)
        return {"asks for more than 32 digits of padding", "a padding of 1 to 32 digits"};
    return {};
}

}  // namespace

std::string ObjSequence::patternProblem(const std::string& pattern) {
    FrameToken token;
    return patternFault(pattern, token).first;
}

ObjSequence::ObjSequence(fs::path pattern) : pattern_(std::move(pattern)) {
    const std::string name = pattern_.filename().string();
    FrameToken token;
    if (const auto [problem, expected] = patternFault(pattern_.string(), token); !problem.empty())
        throw InvalidInput(formatError(pattern_.string(), "", problem, expected));
    prefix_ = name.substr(0, token.position);
    suffix_ = name.substr(token.position + token.length);
    padding_ = token.padding;
}

bool ObjSequence::isPattern(const std::string& pattern) {
    return patternProblem(pattern).empty();
}

fs::path ObjSequence::framePath(int frame) const {
    std::string digits = std::to_string(std::abs(static_cast<int64_t>(frame)));
    if (digits.size() < static_cast<size_t>(padding_)) digits.insert(0, padding_ - digits.size(), '0');
    return pattern_.parent_path() / (prefix_ + (frame < 0 ? "-" : "") + digits + suffix_);
}

std::vector<int> ObjSequence::frames() const {
    const fs::path folder = pattern_.parent_path().empty() ? fs::path(".") : pattern_.parent_path();
    std::error_code ec;
    if (!fs::is_directory(folder, ec)) {
        throw IoError(formatError(pattern_.string(), "", "folder '" + folder.string() + "' does not exist",
                                  "an existing folder holding the sequence"));
    }
    std::vector<int> found;
    fs::directory_iterator it(folder, ec), end;
    for (; !ec && it != end; it.increment(ec)) {
        const std::string name = it->path().filename().string();
        if (name.size() <= prefix_.size() + suffix_.size() || !name.starts_with(prefix_) ||
            !name.ends_with(suffix_)) {
            continue;
        }
        const std::string_view middle =
            std::string_view(name).substr(prefix_.size(), name.size() - prefix_.size() - suffix_.size());
        int frame = 0;
        const auto [ptr, parsed] = std::from_chars(middle.data(), middle.data() + middle.size(), frame);
        if (parsed != std::errc() || ptr != middle.data() + middle.size()) continue;
        // Only the spelling framePath() gives counts: no other padding, no "+" or "-0".
        if (framePath(frame).filename().string() != name) continue;
        std::error_code typeError;
        if (!it->is_regular_file(typeError)) continue;
        found.push_back(frame);
    }
    if (ec) {
        throw IoError(formatError(pattern_.string(), "",
                                  "cannot list folder '" + folder.string() + "': " + ec.message(),
                                  "a readable folder"));
    }
    std::sort(found.begin(), found.end());
    return found;
}

ObjContent ObjSequence::read(int frame) {
    const fs::path path = framePath(frame);
    std::error_code ec;
    if (!fs::exists(path, ec)) {
        throw IoError(formatError(path.string(), "frame " + std::to_string(frame), "is missing",
                                  "a file for every frame of '" + pattern_.string() + "'"));
    }
    ObjContent content = readObj(path);
    const geom::Mesh& mesh = content.mesh;
    if (!haveReference_) {
        setReference(mesh, path);
        referenceIsFrame_ = true;
        return content;
    }
    const std::string expected =
        (referenceIsFrame_ ? "the topology of the first frame read, '" : "the topology of '") +
        referencePath_.string() + "'";
    if (mesh.numVertices() != referenceVertices_) {
        throw InvalidInput(formatError(path.string(), "",
                                       "has " + std::to_string(mesh.numVertices()) + " vertices instead of " +
                                           std::to_string(referenceVertices_),
                                       expected));
    }
    const auto counts = mesh.faceCounts();
    const auto indices = mesh.faceIndices();
    if (counts.size() != referenceCounts_.size()) {
        throw InvalidInput(formatError(path.string(), "",
                                       "has " + std::to_string(counts.size()) + " faces instead of " +
                                           std::to_string(referenceCounts_.size()),
                                       expected));
    }
    size_t offset = 0;
    for (size_t f = 0; f < counts.size(); ++f) {
        const auto size = static_cast<size_t>(counts[f]);
        const auto mine = indices.subspan(offset, size);
        const bool sameCount = counts[f] == referenceCounts_[f];
        if (!sameCount || !std::equal(mine.begin(), mine.end(), referenceIndices_.begin() + offset)) {
            const auto theirs =
                std::span<const int32_t>(referenceIndices_)
                    .subspan(std::min(offset, referenceIndices_.size()),
                             std::min<size_t>(referenceCounts_[f], referenceIndices_.size() - offset));
            throw InvalidInput(formatError(path.string(), "face " + std::to_string(f),
                                           "has " + describeFace(mine) + " where " +
                                               (referenceIsFrame_ ? std::string("the first frame")
                                                                  : referencePath_.filename().string()) +
                                               " has " + describeFace(theirs),
                                           expected));
        }
        offset += size;
    }
    return content;
}

void ObjSequence::setReference(const geom::Mesh& mesh, const fs::path& path) {
    referencePath_ = path;
    referenceIsFrame_ = false;
    referenceVertices_ = mesh.numVertices();
    referenceCounts_.assign(mesh.faceCounts().begin(), mesh.faceCounts().end());
    referenceIndices_.assign(mesh.faceIndices().begin(), mesh.faceIndices().end());
    haveReference_ = true;
}

}  // namespace deformkit::io
