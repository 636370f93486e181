#include "deformkit/io/image.h"

#include <unistd.h>

#include <zlib.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cstring>
#include <fstream>
#include <functional>
#include <iterator>
#include <memory>
#include <new>
#include <string>
#include <string_view>
#include <system_error>

#include "deformkit/error.h"
#include "deformkit/io/atomic_file.h"
#include "io/image_codec.h"

namespace deformkit::io {
namespace fs = std::filesystem;

namespace {

// OpenImageIO keeps a per-thread global error and appends to it; a message left by an earlier failure
// would otherwise be reported with the next one.
void discardPendingOiioErrors(const codec::Codec& oiio) {
    (void)oiio.takeGlobalError();
}

// OpenImageIO messages may span lines (libpng adds its own); errors are reported on one line.
std::string oneLine(std::string message) {
    std::string out;
    out.reserve(message.size());
    for (const char ch : message) {
        if (ch == '\n' || ch == '\r') {
            if (!out.empty() && out.back() != ' ') out.append("; ");
        } else {
            out.push_back(ch);
        }
    }
    while (!out.empty() && (out.back() == ' ' || out.back() == ';'))
        out.pop_back();
    return out.empty() ? std::string("unknown OpenImageIO error") : out;
}

std::string oiioError(const codec::Codec& oiio, const std::string& objectError = {}) {
    std::string message = objectError;
    const std::string global = oiio.takeGlobalError();
    if (!global.empty()) message += (message.empty() ? "" : "\n") + global;
    return oneLine(message);
}

void requireReadableFile(const fs::path& path) {
    std::error_code ec;
    const fs::file_status status = fs::status(path, ec);
    if (status.type() == fs::file_type::not_found) {
        throw IoError(formatError(path.string(), "", "no such file", "an existing image file"));
    }
    if (ec) {
        throw IoError(
            formatError(path.string(), "", "cannot read: " + ec.message(), "a readable image file"));
    }
    if (fs::is_directory(status)) {
        throw IoError(formatError(path.string(), "", "is a folder", "an image file"));
    }
    if (::access(path.c_str(), R_OK) != 0) {
        throw IoError(
            formatError(path.string(), "", "cannot read: permission denied", "a readable image file"));
    }
}

// The caller has checked the file is there and readable (requireReadableFile).
std::unique_ptr<codec::Reader> openInput(const codec::Codec& oiio, const fs::path& path) {
    discardPendingOiioErrors(oiio);
    // Keep colour and alpha as stored: a 4-channel data map must not come back premultiplied.
    auto in = oiio.openReader(path.string(), true);
    if (!in) {
        throw ParseError(formatError(path.string(), "", "cannot read the image: " + oiioError(oiio),
                                     "a complete image file in a format OpenImageIO reads"));
    }
    const codec::Spec& spec = in->spec();
    if (spec.deep) throw InvalidInput(formatError(path.string(), "", "is a deep image", "a flat image"));
    if (spec.width < 1 || spec.height < 1 || spec.depth > 1 || spec.channels < 1) {
        throw ParseError(formatError(path.string(), "header",
                                     "declares " + std::to_string(spec.width) + "x" +
                                         std::to_string(spec.height) + "x" + std::to_string(spec.depth) +
                                         " pixels with " + std::to_string(spec.channels) + " channels",
                                     "a 2D image with at least one pixel and one channel"));
    }
    // A crop or an overscan: its pixels would be read as the whole image, stretched over the tile a map
    // covers. Refused, naming both windows.
    if (spec.x != spec.fullX || spec.y != spec.fullY || spec.width != spec.fullWidth ||
        spec.height != spec.fullHeight) {
        const auto window = [](int32_t w, int32_t h, int32_t x, int32_t y) {
            return std::to_string(w) + "x" + std::to_string(h) + " at (" + std::to_string(x) + ", " +
                   std::to_string(y) + ")";
        };
        throw InvalidInput(formatError(
            path.string(), "header",
            "holds pixels " + window(spec.width, spec.height, spec.x, spec.y) +
                " (its data window) of an image " +
                window(spec.fullWidth, spec.fullHeight, spec.fullX, spec.fullY) + " (its display window)",
            "pixels for the whole image, as `oiiotool in.exr --croptofull -o out.exr` writes them"));
    }
    return in;
}

// The fewest bytes a TIFF file can hold the declared pixels in, by its compression's largest ratio: the
// pixels at 1 bit each (a bilevel image's; a palette index or subsampled colour takes at least that) over 1
// uncompressed, 64 for PackBits (2 bytes repeat one byte at most 128 times), 4096 for LZW (a 12-bit code
// stands for fewer than 4096 bytes) and 1032 for Deflate (zlib's). Fax coding (CCITT) spends at least one
// bit a row, however blank. 0 for other compressions (JPEG's arithmetic coding has no such bound).
uint64_t fewestTiffBytes(const codec::Spec& spec) {
    const auto pixels = static_cast<uint64_t>(spec.width) * static_cast<uint64_t>(spec.height);
    for (const auto& [name, value] : spec.stringAttributes) {
        if (name != "compression") continue;
        uint64_t ratio = 0;
        if (value == "none") ratio = 1;
        if (value == "packbits") ratio = 64;
        if (value == "lzw") ratio = 4096;
        if (value == "zip" || value == "deflate") ratio = 1032;
        if (ratio > 0) return (pixels + 8 * ratio - 1) / (8 * ratio);
        if (value.rfind("ccitt", 0) == 0) return (static_cast<uint64_t>(spec.height) + 7) / 8;
    }
    return 0;
}

// The fewest bytes a file can hold the declared pixels in, so that a header declaring more (a few hundred
// bytes claiming gigapixels) is refused before its pixels are allocated. OpenEXR: an 8-byte offset and a
// chunk header of at least 8 bytes per chunk (scanline chunks of 1 to 256 lines by compression, or tiles),
// whatever the pixels hold. TIFF: fewestTiffBytes. 0 for other formats: a PNG's image data is inflated and
// measured before its pixels are (requireCompletePng).
uint64_t fewestFileBytes(const codec::Spec& spec, std::string_view format) {
    if (format == "tiff") return fewestTiffBytes(spec);
    if (format != "openexr") return 0;
    const auto w = static_cast<uint64_t>(spec.width), h = static_cast<uint64_t>(spec.height);
    uint64_t chunks = 0;
    if (spec.tileWidth > 0 && spec.tileHeight > 0) {
        chunks = ((w + static_cast<uint64_t>(spec.tileWidth) - 1) / static_cast<uint64_t>(spec.tileWidth)) *
                 ((h + static_cast<uint64_t>(spec.tileHeight) - 1) / static_cast<uint64_t>(spec.tileHeight));
    } else {
        uint64_t lines = 256;  // DWAB's, the most; an unknown compression gets it too
        for (const auto& [name, value] : spec.stringAttributes) {
            if (name != "compression") continue;
            if (value == "none" || value == "rle" || value == "zips") lines = 1;
            if (value == "zip" || value == "pxr24") lines = 16;
            if (value == "piz" || value == "b44" || value == "b44a" || value.rfind("dwaa", 0) == 0)
                lines = 32;
        }
        chunks = (h + lines - 1) / lines;
    }
    return chunks * 16;
}

uint32_t bigEndian32(const unsigned char* p) {
    return (uint32_t(p[0]) << 24) | (uint32_t(p[1]) << 16) | (uint32_t(p[2]) << 8) | uint32_t(p[3]);
}

// The bytes of a PNG's filtered image data (a filter byte and the packed samples of each row, every Adam7
// pass in turn when interlaced), from its header's fields; 0 for a header libpng refuses (a zero size, a
// bit depth its colour type does not take, an unknown method), whose own message would go to stderr.
uint64_t pngImageBytes(const unsigned char* ihdr) {
    const uint64_t width = bigEndian32(ihdr), height = bigEndian32(ihdr + 4);
    const int depth = ihdr[8], colour = ihdr[9];
    const bool depthOk =
        (colour == 0 && (depth == 1 || depth == 2 || depth == 4 || depth == 8 || depth == 16)) ||
        (colour == 3 && (depth == 1 || depth == 2 || depth == 4 || depth == 8)) ||
        ((colour == 2 || colour == 4 || colour == 6) && (depth == 8 || depth == 16));
    if (width == 0 || height == 0 || width > 0x7fffffffu || height > 0x7fffffffu || !depthOk ||
        ihdr[10] != 0 || ihdr[11] != 0 || ihdr[12] > 1)
        return 0;
    const uint64_t samples = colour == 2 ? 3 : colour == 4 ? 2 : colour == 6 ? 4 : 1;
    const auto rows = [&](uint64_t w, uint64_t h) {
        return w == 0 || h == 0 ? 0 : h * (1 + (w * samples * static_cast<uint64_t>(depth) + 7) / 8);
    };
    if (ihdr[12] == 0) return rows(width, height);
    // Adam7: pass p takes columns x0 + k dx and rows y0 + k dy.
    static constexpr int kPass[7][4] = {{0, 0, 8, 8}, {4, 0, 8, 8}, {0, 4, 4, 8}, {2, 0, 4, 4},
                                        {0, 2, 2, 4}, {1, 0, 2, 2}, {0, 1, 1, 2}};
    uint64_t total = 0;
    for (const auto& [x0, y0, dx, dy] : kPass) {
        const uint64_t w = width > static_cast<uint64_t>(x0) ? (width - x0 + dx - 1) / dx : 0;
        const uint64_t h = height > static_cast<uint64_t>(y0) ? (height - y0 + dy - 1) / dy : 0;
        total += rows(w, h);
    }
    return total;
}

// libpng prints its own message to stderr before failing on a truncated or corrupt file, and
// OpenImageIO gives no way to silence it. Walking the chunk structure first (lengths, CRCs, a final
// IEND), then the header's fields and the image data's zlib stream (its size, each non-interlaced row's
// filter type), catches those files with a precise error and keeps the one-line error contract.
// `headerOnly`: the chunks before the pixels (IDAT), which a header read parses.
void requireCompletePng(const fs::path& path, bool headerOnly = false) {
    static constexpr std::array<unsigned char, 8> kSignature{0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    std::ifstream in(path, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const auto* data = reinterpret_cast<const unsigned char*>(bytes.data());
    if (bytes.size() < 8 || std::memcmp(data, kSignature.data(), 8) != 0) return;  // not a PNG: OIIO decides
    size_t pos = 8;
    uint64_t imageBytes = 0;
    std::vector<std::pair<size_t, uint32_t>> idat;  // each IDAT chunk's data: offset, length
    while (true) {
        if (pos + 12 > bytes.size()) {
            throw ParseError(formatError(path.string(), "byte " + std::to_string(pos),
                                         "the file ends inside a chunk header (truncated PNG)",
                                         "a complete PNG ending with an IEND chunk"));
        }
        const uint32_t length = bigEndian32(data + pos);
        const std::string type(bytes.data() + pos + 4, 4);
        if (headerOnly && type == "IDAT") return;
        if (length > bytes.size() - pos - 12) {
            throw ParseError(formatError(path.string(), "chunk " + type + " at byte " + std::to_string(pos),
                                         "declares " + std::to_string(length) +
                                             " bytes but the file ends after " +
                                             std::to_string(bytes.size() - pos - 12) + " (truncated PNG)",
                                         "a complete PNG"));
        }
        const uLong crc = crc32(crc32(0L, Z_NULL, 0), data + pos + 4, length + 4);
        if (crc != bigEndian32(data + pos + 8 + length)) {
            throw ParseError(formatError(path.string(), "chunk " + type + " at byte " + std::to_string(pos),
                                         "fails its CRC check (corrupt PNG)", "an uncorrupted PNG"));
        }
        if (type == "IHDR") {
            imageBytes = length == 13 ? pngImageBytes(data + pos + 8) : 0;
            if (imageBytes == 0) {
                throw ParseError(formatError(path.string(), "chunk IHDR",
                                             "holds a size, bit depth, colour type or method libpng refuses",
                                             "a PNG header with sizes above 0 and a valid bit depth for its "
                                             "colour type"));
            }
        }
        if (type == "IDAT") idat.emplace_back(pos + 8, length);
        pos += 12 + length;
        if (type == "IEND") break;
    }
    if (headerOnly) return;
    const auto corrupt = [&](const std::string& what) {
        throw ParseError(
            formatError(path.string(), "image data (IDAT)", what + " (corrupt PNG)",
                        "a zlib stream of the " + std::to_string(imageBytes) + " bytes its header declares"));
    };
    if (idat.empty()) corrupt("is missing");
    // Inflated in slices, nothing kept but each non-interlaced row's filter byte.
    const bool interlaced = data[8 + 8 + 12] == 1;  // IHDR is the first chunk
    const uint64_t rowBytes = interlaced ? 0 : imageBytes / bigEndian32(data + 8 + 8 + 4);
    z_stream z{};
    if (inflateInit(&z) != Z_OK) corrupt("cannot be inflated");
    std::array<unsigned char, 1 << 16> slice{};
    uint64_t produced = 0;
    int status = Z_OK;
    for (size_t chunk = 0; chunk < idat.size() && status != Z_STREAM_END; ++chunk) {
        z.next_in = const_cast<Bytef*>(data + idat[chunk].first);
        z.avail_in = idat[chunk].second;
        while (z.avail_in > 0 && status != Z_STREAM_END) {
            z.next_out = slice.data();
            z.avail_out = static_cast<uInt>(slice.size());
            status = inflate(&z, Z_NO_FLUSH);
            if (status != Z_OK && status != Z_STREAM_END && status != Z_BUF_ERROR) {
                const std::string message = z.msg ? z.msg : "a zlib error";
                inflateEnd(&z);
                corrupt("does not inflate: " + message);
            }
            const uint64_t got = slice.size() - z.avail_out;
            if (rowBytes > 0) {
                for (uint64_t row = (produced + rowBytes - 1) / rowBytes * rowBytes; row < produced + got;
                     row += rowBytes) {
                    if (slice[row - produced] > 4) {
                        inflateEnd(&z);
                        corrupt("gives row " + std::to_string(row / rowBytes) + " the filter type " +
                                std::to_string(slice[row - produced]) + ", beyond 4");
                    }
                }
            }
            produced += got;
            if (status == Z_BUF_ERROR && got == 0) break;  // needs the next chunk's bytes
        }
    }
    inflateEnd(&z);
    if (status != Z_STREAM_END || produced != imageBytes) {
        corrupt("inflates to " + std::to_string(produced) + " bytes" +
                (status == Z_STREAM_END ? std::string() : ", its stream unfinished"));
    }
}

std::string channelCount(int32_t n) {
    return std::to_string(n) + (n == 1 ? " channel" : " channels");
}

// The smallest magnitude a half rounds to inf (the largest finite half is 65504, the next step 65536).
constexpr float kHalfOverflow = 65520.0f;

// The first value of `count` at `values` that is finite and rounds to inf as a half, or `count` when none
// does.
size_t firstBeyondHalf(const float* values, size_t count) {
    for (size_t i = 0; i < count; ++i)
        if (std::isfinite(values[i]) && std::abs(values[i]) >= kHalfOverflow) return i;
    return count;
}

// Refuses a finite value a half cannot hold among `rows` rows of pixels starting at row `firstRow`: it would
// be written as inf.
void requireHalfRange(const fs::path& path, const float* pixels, int32_t width, int32_t rows,
                      int32_t channels, int32_t firstRow) {
    const size_t count = static_cast<size_t>(width) * rows * channels;
    const size_t at = firstBeyondHalf(pixels, count);
    if (at == count) return;
    const size_t pixel = at / static_cast<size_t>(channels);
    throw InvalidInput(formatError(
        path.string(),
        "pixel (" + std::to_string(pixel % static_cast<size_t>(width)) + ", " +
            std::to_string(firstRow + static_cast<int64_t>(pixel / static_cast<size_t>(width))) +
            ") channel " + std::to_string(at % static_cast<size_t>(channels)),
        "is " + numberText(pixels[at]) + ", which a half would hold as inf (the largest half is 65504)",
        "a float image for such values"));
}

// The pixel type's name, as the codec takes it. Auto writes EXR as half, unless a finite value is beyond
// half's range (`fitsHalf()` false, asked only then): then as float, rather than as inf.
std::string requestedType(PixelType type, std::string_view format, const std::function<bool()>& fitsHalf) {
    switch (type) {
        case PixelType::UInt8:
            return "uint8";
        case PixelType::UInt16:
            return "uint16";
        case PixelType::Half:
            return "half";
        case PixelType::Float:
            return "float";
        case PixelType::Auto:
            break;
    }
    if (format != "openexr") return "uint8";
    return fitsHalf() ? "half" : "float";
}

InvalidInput noWriter(const fs::path& path) {
    return InvalidInput(formatError(path.string(), "",
                                    "no image format for the extension '" + path.extension().string() + "'",
                                    "an extension OpenImageIO writes, such as .exr, .png or .tif"));
}

bool hasAttribute(const ImageWriteOptions& options, std::string_view name) {
    for (const auto& [key, value] : options.attributes) {
        if (key == name) return true;
    }
    return false;
}

// Reads the written file's header back: OpenImageIO silently drops metadata a format cannot hold
// (TIFF keeps only its standard tags), and a map that loses how it was made must not pass as written.
void requireAttributesStored(const codec::Codec& oiio, const fs::path& path, const fs::path& written,
                             std::string_view format, const ImageWriteOptions& options) {
    if (options.attributes.empty()) return;
    discardPendingOiioErrors(oiio);
    auto in = oiio.openReader(written.string(), false);
    if (!in)
        throw IoError(
            formatError(path.string(), "", "cannot read back the written header: " + oiioError(oiio)));
    for (const auto& [name, value] : options.attributes) {
        if (!in->hasAttribute(name)) {
            // An EXR stores any attribute but those its own header defines under that name (channels, ...).
            if (format == "openexr") {
                throw InvalidInput(
                    formatError(path.string(), "attribute '" + name + "'",
                                "is a name the EXR header itself uses, so it is not stored as given",
                                "another name, such as 'studio:" + name + "'"));
            }
            throw InvalidInput(formatError(path.string(), "attribute '" + name + "'",
                                           std::string(format) + " files cannot store this header attribute",
                                           "a format with arbitrary metadata, such as .exr"));
        }
    }
    in->close();
}

}  // namespace

PixelType pixelTypeOf(const ImageInfo& info) {
    if (info.pixelType == "float") return PixelType::Float;
    if (info.pixelType == "half") return PixelType::Half;
    if (info.pixelType == "uint16") return PixelType::UInt16;
    if (info.pixelType == "uint8") return PixelType::UInt8;
    return PixelType::Auto;
}

void requireFinitePixels(const Image& image, const std::string& source, const std::string& expected) {
    // Blocks scanned branch-free on the exponent bits (vectorised: a texture is checked at memory speed),
    // the first non-finite value then found in its block.
    constexpr size_t kBlock = 4096;
    const size_t n = image.pixels.size();
    size_t block = 0;
    for (; block < n; block += kBlock) {
        const size_t end = std::min(n, block + kBlock);
        uint32_t any = 0;
        for (size_t i = block; i < end; ++i)
            any |= (std::bit_cast<uint32_t>(image.pixels[i]) & 0x7f800000u) == 0x7f800000u ? 1u : 0u;
        if (any != 0) break;
    }
    if (block >= n) return;
    const auto bad = std::find_if(image.pixels.begin() + static_cast<ptrdiff_t>(block), image.pixels.end(),
                                  [](float v) { return !std::isfinite(v); });
    const auto k = static_cast<size_t>(bad - image.pixels.begin());
    const auto channels = static_cast<size_t>(std::max(image.channels, 1));
    const size_t pixel = k / channels, width = static_cast<size_t>(std::max(image.width, 1));
    throw InvalidInput(formatError(source,
                                   "pixel (" + std::to_string(pixel % width) + ", " +
                                       std::to_string(pixel / width) + ") channel " +
                                       std::to_string(k % channels),
                                   "is " + numberText(*bad), expected));
}

Image readImage(const fs::path& path, const ImageReadOptions& options) {
    requireReadableFile(path);
    requireCompletePng(path);
    const codec::Codec& oiio = codec::load(path.string());
    auto in = openInput(oiio, path);
    const codec::Spec& spec = in->spec();
    if (options.expectedChannels > 0 && spec.channels != options.expectedChannels) {
        throw InvalidInput(formatError(path.string(), options.role, "has " + channelCount(spec.channels),
                                       channelCount(options.expectedChannels)));
    }
    const std::string pixels = std::to_string(spec.width) + "x" + std::to_string(spec.height) +
                               " pixels with " + channelCount(spec.channels);
    std::error_code ec;
    const uint64_t fileBytes = fs::file_size(path, ec);
    const uint64_t fewest = fewestFileBytes(spec, in->formatName());
    if (!ec && fileBytes < fewest) {
        throw ParseError(formatError(path.string(), "header",
                                     "declares " + pixels + ", which take at least " +
                                         std::to_string(fewest) + " bytes, but the file has " +
                                         std::to_string(fileBytes),
                                     "a complete, uncorrupted image file"));
    }
    size_t count = 0;
    if (__builtin_mul_overflow(static_cast<size_t>(spec.width), static_cast<size_t>(spec.height), &count) ||
        __builtin_mul_overflow(count, static_cast<size_t>(spec.channels), &count) ||
        count > std::vector<float>().max_size()) {
        throw InvalidInput(formatError(path.string(), "", "image of " + pixels + " is too large to load",
                                       "an image that fits in memory"));
    }
    Image image;
    try {
        image = Image(spec.width, spec.height, spec.channels);
    } catch (const std::bad_alloc&) {
        // Memory that ran out, not a bad file: exit 1, as any out-of-memory (a larger machine may do).
        throw OutOfMemory(formatError(path.string(), "",
                                      "cannot be read into memory: " + pixels + " (" +
                                          std::to_string(count * sizeof(float)) + " bytes)",
                                      "the image to fit in this machine's memory"));
    }
    if (!in->readFloats(image.pixels.data())) {
        throw ParseError(formatError(path.string(), "pixels", "cannot read: " + oiioError(oiio, in->error()),
                                     "a complete, uncorrupted image file"));
    }
    in->close();
    discardPendingOiioErrors(oiio);
    return image;
}

ImageInfo readImageInfo(const fs::path& path) {
    requireReadableFile(path);
    requireCompletePng(path, true);
    const codec::Codec& oiio = codec::load(path.string());
    auto in = openInput(oiio, path);
    const codec::Spec& spec = in->spec();
    ImageInfo info;
    info.width = spec.width;
    info.height = spec.height;
    info.channels = spec.channels;
    info.format = in->formatName();
    info.pixelType = spec.pixelType;
    info.channelNames = spec.channelNames;
    info.attributes = spec.stringAttributes;
    in->close();
    discardPendingOiioErrors(oiio);
    return info;
}

namespace {

// Checks the size and format, opens the file under a temporary name, lets `writePixels` write every pixel
// in the type it is given (false: OpenImageIO failed, its error is reported), closes it and moves it into
// place. `fitsHalf`: whether every finite value is within half's range (requestedType asks it for an EXR of
// Auto type only: a scan of the pixels, which other writes do not pay).
void writeChecked(const fs::path& path, int32_t width, int32_t height, int32_t channels,
                  const ImageWriteOptions& options, const std::function<bool()>& fitsHalf,
                  const std::function<bool(codec::Writer&, const std::string& type)>& writePixels) {
    if (width < 1 || height < 1 || channels < 1) {
        throw InvalidInput(formatError(path.string(), "",
                                       "cannot write an empty image (" + std::to_string(width) + "x" +
                                           std::to_string(height) + " pixels, " + channelCount(channels) +
                                           ")",
                                       "at least 1x1 pixels and 1 channel"));
    }
    const codec::Codec& oiio = codec::load(path.string());
    discardPendingOiioErrors(oiio);
    // Created from the final name (nothing is opened yet): its format decides the checks below.
    std::unique_ptr<codec::Writer> probe = oiio.createWriter(path.string());
    if (!probe) throw noWriter(path);
    const std::string format = probe->formatName();
    if (channels > 4 && !probe->supportsAnyChannelCount()) {
        throw InvalidInput(formatError(path.string(), "", "has " + channelCount(channels),
                                       "at most 4 channels in " + format + " files"));
    }
    // JPEG holds grey or RGB: OpenImageIO's writer drops a second or fourth channel (alpha, a coverage
    // channel) without a word.
    if (format == "jpeg" && channels != 1 && channels != 3) {
        throw InvalidInput(formatError(path.string(), "", "has " + channelCount(channels),
                                       "1 or 3 channels in jpeg files (no alpha; PNG, TIFF or EXR keep it)"));
    }
    // OpenJPEG codes 6 resolution levels, which need 32 pixels a side: OpenImageIO wrote a smaller image as
    // a 77-byte file no reader opens, and reported success.
    if (format == "jpeg2000" && (width < 32 || height < 32)) {
        throw InvalidInput(formatError(
            path.string(), "", "is " + std::to_string(width) + "x" + std::to_string(height) + " pixels",
            "at least 32 pixels a side in jpeg2000 files"));
    }
    const std::string type = requestedType(options.type, format, fitsHalf);

    writeAtomically(path, [&](const fs::path& tmp) {
        const std::unique_ptr<codec::Writer> out = std::move(probe);  // owned here: closed before rename

        codec::WriteSpec spec;
        spec.width = width;
        spec.height = height;
        spec.channels = channels;
        spec.pixelType = type;
        // EXR keeps channels sorted by name and OpenImageIO restores R, G, B, A but orders other names as
        // strings ("channel10" before "channel4"): zero-padded names keep channels 5 and up in place.
        const size_t digits = std::to_string(channels - 1).size();
        for (int32_t c = 4; c < channels; ++c) {
            const std::string index = std::to_string(c);
            spec.channelNames.emplace_back(c, "channel" + std::string(digits - index.size(), '0') + index);
        }
        // Stored as given: no unpremultiplication of 2- or 4-channel data on the way out.
        spec.intAttributes.emplace_back("oiio:UnassociatedAlpha", 1);
        // TIFF writes float unless half is asked for explicitly.
        if (format == "tiff" && type == "half") spec.intAttributes.emplace_back("tiff:half", 1);
        // EXR and TIFF writers stamp the current time unless given one; an empty stamp keeps the same
        // image written twice byte-identical.
        if ((format == "openexr" || format == "tiff") && !hasAttribute(options, "DateTime")) {
            spec.stringAttributes.emplace_back("DateTime", "");
        }
        for (const auto& attribute : options.attributes)
            spec.stringAttributes.push_back(attribute);

        if (!out->open(tmp.string(), spec)) {
            throw IoError(formatError(path.string(), "", "cannot write: " + oiioError(oiio, out->error()),
                                      "a writable file"));
        }
        if (out->openedChannels() != channels) {
            throw InvalidInput(formatError(path.string(), "", "has " + channelCount(channels),
                                           channelCount(out->openedChannels()) + " in " + format + " files"));
        }
        std::string rejected;
        if (options.type != PixelType::Auto && out->openedPixelType() != type) {
            rejected =
                formatError(path.string(), "pixel type", format + " files cannot store " + type + " pixels",
                            "a type the format stores, such as " + out->openedPixelType());
        }
        if (!writePixels(*out, type)) {
            throw StorageError(formatError(path.string(), "pixels",
                                           "cannot write: " + oiioError(oiio, out->error()),
                                           "enough space to write"));
        }
        if (!out->close()) {
            throw StorageError(formatError(path.string(), "",
                                           "cannot finish writing: " + oiioError(oiio, out->error()),
                                           "enough space to write"));
        }
        // Rejected only now: a PNG writer closed before its pixels makes libpng print to stderr.
        if (!rejected.empty()) throw InvalidInput(rejected);
        requireAttributesStored(oiio, path, tmp, format, options);
    });
    discardPendingOiioErrors(oiio);
}

}  // namespace

void writeImage(const fs::path& path, const Image& image, const ImageWriteOptions& options) {
    const size_t expected = static_cast<size_t>(std::max(image.width, 0)) * std::max(image.height, 0) *
                            std::max(image.channels, 0);
    if (image.width >= 1 && image.height >= 1 && image.channels >= 1 && image.pixels.size() != expected) {
        throw InvalidInput(formatError(path.string(), "pixels",
                                       "has " + std::to_string(image.pixels.size()) + " values",
                                       std::to_string(expected) + " = width * height * channels"));
    }
    const auto fitsHalf = [&] {
        return firstBeyondHalf(image.pixels.data(), image.pixels.size()) == image.pixels.size();
    };
    writeChecked(path, image.width, image.height, image.channels, options, fitsHalf,
                 [&](codec::Writer& out, const std::string& type) {
                     // Half asked for is checked here; Auto chose half only for pixels that fit.
                     if (type == "half" && options.type == PixelType::Half) {
                         requireHalfRange(path, image.pixels.data(), image.width, image.height,
                                          image.channels, 0);
                     }
                     return out.writeFloats(image.pixels.data());
                 });
}

void writeImageInBands(const fs::path& path, int32_t width, int32_t height, int32_t channels,
                       int32_t bandRows, const ImageBand& fill, const ImageWriteOptions& options) {
    if (bandRows < 1) {
        throw InvalidInput(formatError(path.string(), "band", "has " + std::to_string(bandRows) + " rows",
                                       "at least 1 row"));
    }
    writeChecked(
        path, width, height, channels, options, [] { return true; },
        [&](codec::Writer& out, const std::string& type) {
            Image band;
            int32_t written = 0;  // rows in the file
            try {
                for (; written < height; written += bandRows) {
                    const int32_t rows = std::min(bandRows, height - written);
                    if (band.height != rows) band = Image(width, rows, channels);
                    std::fill(band.pixels.begin(), band.pixels.end(), 0.0f);
                    fill(written, band);
                    if (band.width != width || band.height != rows || band.channels != channels ||
                        band.pixels.size() != static_cast<size_t>(width) * rows * channels) {
                        throw InvalidInput(formatError(
                            path.string(), "band at row " + std::to_string(written),
                            "was resized to " + std::to_string(band.width) + "x" +
                                std::to_string(band.height) + " pixels, " + channelCount(band.channels),
                            std::to_string(width) + "x" + std::to_string(rows) + " pixels, " +
                                channelCount(channels)));
                    }
                    if (type == "half")
                        requireHalfRange(path, band.pixels.data(), width, rows, channels, written);
                    if (!out.writeRows(written, written + rows, band.pixels.data())) return false;
                }
            } catch (...) {
                // The temporary file is dropped, but a PNG writer closed short of its rows makes libpng print
                // to stderr: the rest is written as zeros first, one row at a time.
                const std::vector<float> zeros(static_cast<size_t>(width) * channels, 0.0f);
                for (int32_t y = written; y < height; ++y)
                    if (!out.writeRows(y, y + 1, zeros.data())) break;
                throw;
            }
            return true;
        });
}

void requireImageWriter(const fs::path& path) {
    const codec::Codec& oiio = codec::load(path.string());
    discardPendingOiioErrors(oiio);
    const bool known = oiio.createWriter(path.string()) != nullptr;
    discardPendingOiioErrors(oiio);
    if (!known) throw noWriter(path);
}

bool isImageFileName(const fs::path& path) {
    if (path.extension().empty()) return false;
    const codec::Codec& oiio = codec::load(path.string());
    discardPendingOiioErrors(oiio);
    const bool known = oiio.hasReaderFor(path.string());
    discardPendingOiioErrors(oiio);
    return known;
}

}  // namespace deformkit::io
