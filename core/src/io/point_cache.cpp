#include "deformkit/io/point_cache.h"

#include <algorithm>
#include <bit>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>

#include "deformkit/error.h"
#include "deformkit/io/atomic_file.h"

namespace deformkit::io {
namespace fs = std::filesystem;

namespace {

constexpr char kPc2Magic[12] = {'P', 'O', 'I', 'N', 'T', 'C', 'A', 'C', 'H', 'E', '2', '\0'};
constexpr std::uintmax_t kPc2Header = 32;
constexpr std::uintmax_t kBytesPerVertex = 12;
// How close a sample's frame must be to a whole frame to be that frame (PC2 sampling such as 0.1).
constexpr double kFrameTolerance = 1.0e-4;

// A PC2 stores its sampling (frames per sample) as a 32-bit float: 1/3 as 0.33333334, 0.1 as 0.100000001.
// Multiplied by a sample's index that rounding drifts past kFrameTolerance after about 10^4 samples, and
// whole frames inside the cache go missing. The value the writer meant: 1/n when the float is 1/n rounded,
// else the shortest decimal that rounds to the float (0.4, 2.5).
double intendedSampling(float sampling) {
    const double n = std::round(1.0 / static_cast<double>(sampling));
    if (n >= 1.0 && static_cast<float>(1.0 / n) == sampling) return 1.0 / n;
    char text[32];
    const auto written = std::to_chars(text, text + sizeof text, sampling);
    double meant = sampling;
    if (written.ec == std::errc()) (void)std::from_chars(text, written.ptr, meant);
    return meant;
}

// 4-byte words in a file's byte order (PC2 little-endian, MDD big-endian), whatever the machine's.
uint32_t loadWord(const char* bytes, bool bigEndian) {
    uint32_t v = 0;
    for (int k = 0; k < 4; ++k) {
        const auto byte = static_cast<uint32_t>(static_cast<unsigned char>(bytes[bigEndian ? k : 3 - k]));
        v = (v << 8) | byte;
    }
    return v;
}

void storeWord(char* bytes, uint32_t v, bool bigEndian) {
    for (int k = 0; k < 4; ++k)
        bytes[bigEndian ? 3 - k : k] = static_cast<char>((v >> (8 * k)) & 0xffu);
}

int32_t loadInt(const char* bytes, bool bigEndian) {
    return std::bit_cast<int32_t>(loadWord(bytes, bigEndian));
}
float loadFloat(const char* bytes, bool bigEndian) {
    return std::bit_cast<float>(loadWord(bytes, bigEndian));
}

std::string frameText(double frame) {
    return "frame " + numberText(frame);
}

}  // namespace

std::optional<PointCacheFormat> pointCacheFormat(const fs::path& path) {
    std::string extension = path.extension().string();
    for (char& c : extension)
        c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    if (extension == ".pc2") return PointCacheFormat::Pc2;
    if (extension == ".mdd") return PointCacheFormat::Mdd;
    return std::nullopt;
}

const char* formatName(PointCacheFormat format) {
    return format == PointCacheFormat::Pc2 ? "PC2" : "MDD";
}

PointCache::PointCache(fs::path path, std::optional<double> firstFrame) : path_(std::move(path)) {
    const std::string name = path_.string();
    const std::optional<PointCacheFormat> format = pointCacheFormat(path_);
    if (!format) {
        throw InvalidInput(
            formatError(name, "", "is not a point cache", "a file name ending in .pc2 or .mdd"));
    }
    format_ = *format;
    const char* kind = formatName(format_);
    std::error_code ec;
    const fs::file_status status = fs::status(path_, ec);
    if (!fs::exists(status)) {
        throw IoError(formatError(name, "", "does not exist", std::string("an existing ") + kind + " file"));
    }
    if (!fs::is_regular_file(status)) {
        throw IoError(formatError(name, "", "is not a regular file", std::string("a ") + kind + " file"));
    }
    const std::uintmax_t size = fs::file_size(path_, ec);
    in_.open(path_, std::ios::binary);
    if (!in_ || ec) {
        throw IoError(formatError(name, "", std::string("cannot be read: ") + std::strerror(errno),
                                  std::string("a readable ") + kind + " file"));
    }
    auto readBytes = [&](char* out, std::uintmax_t count, const std::string& what) {
        in_.read(out, static_cast<std::streamsize>(count));
        if (!in_) {
            throw InvalidInput(formatError(name, what,
                                           "is cut short: the file has " + std::to_string(size) + " bytes",
                                           std::string("a whole ") + kind + " header"));
        }
    };
    if (format_ == PointCacheFormat::Pc2) {
        char header[kPc2Header];
        readBytes(header, kPc2Header, "header");
        if (std::memcmp(header, kPc2Magic, sizeof kPc2Magic) != 0) {
            throw InvalidInput(formatError(name, "header", "does not start with POINTCACHE2",
                                           "a PC2 file (\"POINTCACHE2\\0\", version 1, ...)"));
        }
        const int32_t version = loadInt(header + 12, false);
        if (version != 1) {
            // Version 1 read in the other byte order: a big-endian writer's file.
            const bool swapped = loadInt(header + 12, true) == 1;
            throw InvalidInput(formatError(
                name, "header",
                "has version " + std::to_string(version) +
                    (swapped ? ", which is version 1 in big-endian byte order" : ""),
                swapped
                    ? "PC2 version 1 in little-endian byte order, as Blender, 3ds Max and Houdini write it"
                    : "PC2 version 1"));
        }
        vertices_ = loadInt(header + 16, false);
        const float start = loadFloat(header + 20, false);
        const float sampling = loadFloat(header + 24, false);
        samples_ = loadInt(header + 28, false);
        if (!std::isfinite(start)) {
            throw InvalidInput(formatError(name, "header", "has the start frame " + numberText(start),
                                           "a finite start frame"));
        }
        if (!(sampling > 0.0f) || !std::isfinite(sampling)) {
            throw InvalidInput(formatError(name, "header", "has the sampling " + numberText(sampling),
                                           "a positive number of frames per sample"));
        }
        first_ = start;
        sampling_ = intendedSampling(sampling);
        dataOffset_ = kPc2Header;
    } else {
        char header[8];
        readBytes(header, 8, "header");
        samples_ = loadInt(header, true);
        vertices_ = loadInt(header + 4, true);
        first_ = 1.0;
        // A header whose counts give the file's size only when read little-endian: a little-endian writer's
        // file, which would otherwise be reported as cut short by billions of frames.
        const auto fits = [size](int32_t frames, int32_t vertices) {
            if (frames <= 0 || vertices <= 0) return false;
            const auto f = static_cast<std::uintmax_t>(frames), v = static_cast<std::uintmax_t>(vertices);
            if (size < 8 + 4 * f) return false;
            const std::uintmax_t data =
                size - 8 - 4 * f;  // f * v * 12 without overflow: compared by division
            return data % (12 * v) == 0 && data / (12 * v) == f;
        };
        const int32_t littleSamples = loadInt(header, false), littleVertices = loadInt(header + 4, false);
        if (!fits(samples_, vertices_) && fits(littleSamples, littleVertices)) {
            throw InvalidInput(formatError(
                name, "header",
                "reads as " + std::to_string(littleSamples) + " frames of " + std::to_string(littleVertices) +
                    " vertices, as the file's size says, only in little-endian byte order",
                "MDD's big-endian byte order, as LightWave, Blender and Houdini write it"));
        }
    }
    if (vertices_ <= 0 || samples_ <= 0) {
        throw InvalidInput(formatError(
            name, "header",
            "has " + std::to_string(vertices_) + " vertices and " + std::to_string(samples_) + " frames",
            "at least one vertex and one frame"));
    }
    if (format_ == PointCacheFormat::Mdd) {
        if (size < 8 + 4 * static_cast<std::uintmax_t>(samples_)) {
            throw InvalidInput(formatError(name, "frame times",
                                           "are cut short: the file has " + std::to_string(size) + " bytes",
                                           std::to_string(samples_) + " times after the header"));
        }
        std::vector<char> bytes(4 * static_cast<size_t>(samples_));
        readBytes(bytes.data(), bytes.size(), "frame times");
        times_.resize(static_cast<size_t>(samples_));
        for (int32_t i = 0; i < samples_; ++i) {
            times_[static_cast<size_t>(i)] = loadFloat(bytes.data() + 4 * static_cast<size_t>(i), true);
            const float t = times_[static_cast<size_t>(i)];
            if (!std::isfinite(t) || (i > 0 && !(t > times_[static_cast<size_t>(i) - 1]))) {
                throw InvalidInput(
                    formatError(name, "frame time " + std::to_string(i),
                                "is " + numberText(t) + (i > 0 ? " after " + numberText(times_[i - 1]) : ""),
                                "finite times in seconds, increasing"));
            }
        }
        dataOffset_ = 8 + 4 * static_cast<std::uintmax_t>(samples_);
    }
    if (firstFrame) {
        if (!std::isfinite(*firstFrame)) {
            throw InvalidInput(
                formatError(name, "first frame", "is " + numberText(*firstFrame), "a finite frame"));
        }
        first_ = *firstFrame;
    }
    // The frames' bytes, counted without overflow: 2^31 vertices by 2^31 samples pass 2^64, and a product
    // wrapped around it could equal a small file's size.
    const std::uintmax_t frameBytes = static_cast<std::uintmax_t>(vertices_) * kBytesPerVertex;
    const auto samples = static_cast<std::uintmax_t>(samples_);
    const std::uintmax_t whole = (size - dataOffset_) / frameBytes;  // size >= dataOffset_: the header read
    const bool countable =
        samples == 0 || frameBytes <= (std::numeric_limits<std::uintmax_t>::max() - dataOffset_) / samples;
    const std::string expected =
        (countable ? std::to_string(dataOffset_ + frameBytes * samples) : std::string("more than 2^64")) +
        " bytes for " + std::to_string(samples_) + " frames of " + std::to_string(vertices_) + " vertices";
    if (whole < samples) {
        throw InvalidInput(formatError(name, frameText(sampleFrame(static_cast<int32_t>(whole))),
                                       "is cut short: the file has " + std::to_string(size) + " bytes, " +
                                           std::to_string(whole) + " whole frames",
                                       expected));
    }
    const std::uintmax_t extra = size - dataOffset_ - frameBytes * samples;  // whole >= samples: no overflow
    if (extra > 0) {
        throw InvalidInput(
            formatError(name, "", "has " + std::to_string(extra) + " bytes after its last frame", expected));
    }
}

std::vector<int> PointCache::frames() const {
    std::vector<int> out;
    for (int32_t i = 0; i < samples_; ++i) {
        const double f = sampleFrame(i);
        const double whole = std::round(f);
        // Samples closer together than the tolerance can share a whole frame (they come in order): listed
        // once, sampleOf picks the nearest.
        if (std::abs(f - whole) <= kFrameTolerance && std::abs(whole) < 1.0e9 &&
            (out.empty() || out.back() != static_cast<int>(whole)))
            out.push_back(static_cast<int>(whole));
    }
    return out;
}

std::optional<int32_t> PointCache::sampleOf(int frame) const {
    if (samples_ == 0) return std::nullopt;
    // The nearest sample inside the cache: with samples closer than the tolerance, the nearest one counted
    // from the start can lie past either end while an end sample is within the tolerance (frames()).
    const double index = std::clamp(std::round((frame - first_) / sampling_), 0.0, samples_ - 1.0);
    const auto sample = static_cast<int32_t>(index);
    if (std::abs(sampleFrame(sample) - frame) > kFrameTolerance) return std::nullopt;
    return sample;
}

std::string PointCache::rangeText() const {
    if (sampleCount() == 0) return "no frames";
    const std::string first = numberText(sampleFrame(0));
    if (sampleCount() == 1) return "frame " + first;
    std::string text = "frames " + first + " to " + numberText(sampleFrame(sampleCount() - 1));
    if (sampling() != 1.0) text += " every " + numberText(sampling());
    return text;
}

std::string PointCache::frameName(int frame) const {
    return path_.string() + " frame " + std::to_string(frame);
}

void PointCache::read(int frame, std::vector<glm::vec3>& points) {
    const std::optional<int32_t> sample = sampleOf(frame);
    if (!sample) {
        throw InvalidInput(formatError(path_.string(), frameText(frame), "is not in the cache",
                                       "one of its " + rangeText()));
    }
    const size_t bytes = static_cast<size_t>(vertices_) * kBytesPerVertex;
    const std::lock_guard<std::mutex> lock(readMutex_);
    buffer_.resize(bytes);
    in_.clear();
    in_.seekg(static_cast<std::streamoff>(dataOffset_ + static_cast<std::uintmax_t>(*sample) * bytes));
    in_.read(buffer_.data(), static_cast<std::streamsize>(bytes));
    if (!in_) {
        throw IoError(formatError(path_.string(), frameText(frame), "cannot be read (the file changed?)",
                                  "a readable point cache"));
    }
    const bool big = format_ == PointCacheFormat::Mdd;
    points.resize(static_cast<size_t>(vertices_));
    for (size_t v = 0; v < points.size(); ++v) {
        const char* p = buffer_.data() + v * kBytesPerVertex;
        const glm::vec3 q(loadFloat(p, big), loadFloat(p + 4, big), loadFloat(p + 8, big));
        if (!std::isfinite(q.x) || !std::isfinite(q.y) || !std::isfinite(q.z)) {
            throw InvalidInput(
                formatError(path_.string(), frameText(frame) + ": vertex " + std::to_string(v),
                            "is (" + numberText(q.x) + ", " + numberText(q.y) + ", " + numberText(q.z) + ")",
                            "finite coordinates"));
        }
        points[v] = q;
    }
}

// ---------------------------------------------------------------------------------------------------------

PointCacheWriter::PointCacheWriter(fs::path path, int32_t vertices, int32_t frames, int firstFrame,
                                   double fps)
    : path_(std::move(path)), vertices_(vertices), frames_(frames), firstFrame_(firstFrame) {
    requireExtension(path_, {".pc2", ".mdd"}, "a point cache");
    format_ = *pointCacheFormat(path_);
    if (vertices <= 0 || frames <= 0) {
        throw InvalidInput(formatError(
            path_.string(), "",
            "would hold " + std::to_string(frames) + " frames of " + std::to_string(vertices) + " vertices",
            "at least one frame and one vertex"));
    }
    if (!(fps > 0.0) || !std::isfinite(fps)) {
        throw InvalidInput(
            formatError(path_.string(), "frame rate", "is " + numberText(fps), "frames per second > 0"));
    }
    // A PC2 stores its start frame as a 32-bit float: whole numbers are exact up to 2^24.
    constexpr int kMaxExactStart = 1 << 24;
    if (format_ == PointCacheFormat::Pc2 && (firstFrame > kMaxExactStart || firstFrame < -kMaxExactStart)) {
        throw InvalidInput(formatError(path_.string(), "first frame", "is " + std::to_string(firstFrame),
                                       "a frame from -16777216 to 16777216 (a PC2 stores it as a float)"));
    }
    const fs::path folder = path_.parent_path().empty() ? fs::path(".") : path_.parent_path();
    staging_ = folder / ("." + path_.filename().string() + ".partial-" + uniqueToken());
    out_.open(staging_, std::ios::binary | std::ios::trunc);
    if (!out_) {
        throw IoError(formatError(path_.string(), "",
                                  std::string("cannot be written: ") + std::strerror(errno),
                                  "an existing, writable folder"));
    }
    const bool big = format_ == PointCacheFormat::Mdd;
    std::vector<char> header;
    if (format_ == PointCacheFormat::Pc2) {
        header.resize(kPc2Header);
        std::memcpy(header.data(), kPc2Magic, sizeof kPc2Magic);
        storeWord(header.data() + 12, 1u, big);
        storeWord(header.data() + 16, static_cast<uint32_t>(vertices), big);
        storeWord(header.data() + 20, std::bit_cast<uint32_t>(static_cast<float>(firstFrame)), big);
        storeWord(header.data() + 24, std::bit_cast<uint32_t>(1.0f), big);
        storeWord(header.data() + 28, static_cast<uint32_t>(frames), big);
    } else {
        header.resize(8 + 4 * static_cast<size_t>(frames));
        storeWord(header.data(), static_cast<uint32_t>(frames), big);
        storeWord(header.data() + 4, static_cast<uint32_t>(vertices), big);
        for (int32_t i = 0; i < frames; ++i) {
            const auto t = static_cast<float>(i / fps);
            storeWord(header.data() + 8 + 4 * static_cast<size_t>(i), std::bit_cast<uint32_t>(t), big);
        }
    }
    out_.write(header.data(), static_cast<std::streamsize>(header.size()));
}

PointCacheWriter::~PointCacheWriter() {
    if (finished_) return;
    out_.close();
    std::error_code ec;
    fs::remove(staging_, ec);
}

void PointCacheWriter::append(std::span<const glm::vec3> points) {
    const std::string name = path_.string();
    const std::string frame = frameText(firstFrame_ + written_);
    if (written_ == frames_) {
        throw InvalidInput(formatError(name, frame, "is one frame more than announced",
                                       std::to_string(frames_) + " frames"));
    }
    if (points.size() != static_cast<size_t>(vertices_)) {
        throw InvalidInput(formatError(name, frame, "has " + std::to_string(points.size()) + " vertices",
                                       std::to_string(vertices_) + " vertices, as every frame of the cache"));
    }
    const bool big = format_ == PointCacheFormat::Mdd;
    buffer_.resize(points.size() * kBytesPerVertex);
    for (size_t v = 0; v < points.size(); ++v) {
        const glm::vec3 q = points[v];
        if (!std::isfinite(q.x) || !std::isfinite(q.y) || !std::isfinite(q.z)) {
            throw InvalidInput(formatError(name, frame + ": vertex " + std::to_string(v), "is not finite",
                                           "finite coordinates"));
        }
        for (int c = 0; c < 3; ++c)
            storeWord(buffer_.data() + v * kBytesPerVertex + 4 * c, std::bit_cast<uint32_t>(q[c]), big);
    }
    out_.write(buffer_.data(), static_cast<std::streamsize>(buffer_.size()));
    if (!out_)
        throw StorageError(formatError(name, frame, "write failed (disk full?)", "enough space to write"));
    ++written_;
}

void PointCacheWriter::finish() {
    if (finished_) return;
    if (written_ != frames_) {
        throw InvalidInput(
            formatError(path_.string(), "",
                        "has " + std::to_string(written_) + " of its " + std::to_string(frames_) + " frames",
                        "every announced frame appended before finish()"));
    }
    out_.close();
    if (!out_)
        throw StorageError(
            formatError(path_.string(), "", "write failed (disk full?)", "enough space to write"));
    writeAtomically(path_, [this](const fs::path& tmp) {
        std::error_code ec;
        fs::rename(staging_, tmp, ec);
        if (ec) {
            throw IoError(formatError(path_.string(), "", "cannot be moved into place: " + ec.message(),
                                      "a writable folder"));
        }
    });
    finished_ = true;
}

}  // namespace deformkit::io
