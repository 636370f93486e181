#include "deformkit/io/image.h"

#include <unistd.h>

#include <OpenImageIO/imageio.h>
#include <zlib.h>

#include <array>
#include <cstring>
#include <fstream>
#include <iterator>
#include <memory>
#include <new>
#include <string>
#include <string_view>
#include <system_error>

#include "deformkit/error.h"
#include "deformkit/io/atomic_file.h"

namespace deformkit::io {
namespace fs = std::filesystem;

namespace {

// OpenImageIO keeps a per-thread global error and appends to it; a message left by an earlier failure
// would otherwise be reported with the next one.
void discardPendingOiioErrors() {
    (void)OIIO::geterror();
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

std::string oiioError(const std::string& objectError = {}) {
    std::string message = objectError;
    const std::string global = OIIO::geterror();
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

std::unique_ptr<OIIO::ImageInput> openInput(const fs::path& path) {
    requireReadableFile(path);
    discardPendingOiioErrors();
    // Keep colour and alpha as stored: a 4-channel data map must not come back premultiplied.
    OIIO::ImageSpec config;
    config.attribute("oiio:UnassociatedAlpha", 1);
    auto in = OIIO::ImageInput::open(path.string(), &config);
    if (!in) {
        throw ParseError(formatError(path.string(), "", "cannot read the image: " + oiioError(),
                                     "a complete image file in a format OpenImageIO reads"));
    }
    const OIIO::ImageSpec& spec = in->spec();
    if (spec.deep) throw InvalidInput(formatError(path.string(), "", "is a deep image", "a flat image"));
    if (spec.width < 1 || spec.height < 1 || spec.depth > 1 || spec.nchannels < 1) {
        throw ParseError(formatError(path.string(), "header",
                                     "declares " + std::to_string(spec.width) + "x" +
                                         std::to_string(spec.height) + "x" + std::to_string(spec.depth) +
                                         " pixels with " + std::to_string(spec.nchannels) + " channels",
                                     "a 2D image with at least one pixel and one channel"));
    }
    return in;
}

uint32_t bigEndian32(const unsigned char* p) {
    return (uint32_t(p[0]) << 24) | (uint32_t(p[1]) << 16) | (uint32_t(p[2]) << 8) | uint32_t(p[3]);
}

// libpng prints its own message to stderr before failing on a truncated or corrupt file, and
// OpenImageIO gives no way to silence it. Walking the chunk structure first (lengths, CRCs, a final
// IEND) catches those files with a precise error and keeps the one-line error contract.
void requireCompletePng(const fs::path& path) {
    static constexpr std::array<unsigned char, 8> kSignature{0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    std::ifstream in(path, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const auto* data = reinterpret_cast<const unsigned char*>(bytes.data());
    if (bytes.size() < 8 || std::memcmp(data, kSignature.data(), 8) != 0) return;  // not a PNG: OIIO decides
    size_t pos = 8;
    while (true) {
        if (pos + 12 > bytes.size()) {
            throw ParseError(formatError(path.string(), "byte " + std::to_string(pos),
                                         "the file ends inside a chunk header (truncated PNG)",
                                         "a complete PNG ending with an IEND chunk"));
        }
        const uint32_t length = bigEndian32(data + pos);
        const std::string type(bytes.data() + pos + 4, 4);
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
        pos += 12 + length;
        if (type == "IEND") return;
    }
}

std::string pixelTypeName(OIIO::TypeDesc type) {
    if (type == OIIO::TypeDesc::UINT8) return "uint8";
    if (type == OIIO::TypeDesc::UINT16) return "uint16";
    if (type == OIIO::TypeDesc::HALF) return "half";
    if (type == OIIO::TypeDesc::FLOAT) return "float";
    return type.c_str();
}

std::string channelCount(int32_t n) {
    return std::to_string(n) + (n == 1 ? " channel" : " channels");
}

OIIO::TypeDesc requestedType(PixelType type, std::string_view format) {
    switch (type) {
        case PixelType::UInt8:
            return OIIO::TypeDesc::UINT8;
        case PixelType::UInt16:
            return OIIO::TypeDesc::UINT16;
        case PixelType::Half:
            return OIIO::TypeDesc::HALF;
        case PixelType::Float:
            return OIIO::TypeDesc::FLOAT;
        case PixelType::Auto:
            break;
    }
    return format == "openexr" ? OIIO::TypeDesc::HALF : OIIO::TypeDesc::UINT8;
}

bool hasAttribute(const ImageWriteOptions& options, std::string_view name) {
    for (const auto& [key, value] : options.attributes) {
        if (key == name) return true;
    }
    return false;
}

// Reads the written file's header back: OpenImageIO silently drops metadata a format cannot hold
// (TIFF keeps only its standard tags), and a map that loses how it was made must not pass as written.
void requireAttributesStored(const fs::path& path, const fs::path& written, std::string_view format,
                             const ImageWriteOptions& options) {
    if (options.attributes.empty()) return;
    discardPendingOiioErrors();
    auto in = OIIO::ImageInput::open(written.string());
    if (!in)
        throw IoError(formatError(path.string(), "", "cannot read back the written header: " + oiioError()));
    for (const auto& [name, value] : options.attributes) {
        if (!in->spec().find_attribute(name)) {
            throw InvalidInput(formatError(path.string(), "attribute '" + name + "'",
                                           std::string(format) + " files cannot store this header attribute",
                                           "a format with arbitrary metadata, such as .exr"));
        }
    }
    in->close();
}

}  // namespace

Image readImage(const fs::path& path, const ImageReadOptions& options) {
    requireReadableFile(path);
    requireCompletePng(path);
    auto in = openInput(path);
    const OIIO::ImageSpec& spec = in->spec();
    if (options.expectedChannels > 0 && spec.nchannels != options.expectedChannels) {
        throw InvalidInput(formatError(path.string(), options.role, "has " + channelCount(spec.nchannels),
                                       channelCount(options.expectedChannels)));
    }
    Image image;
    try {
        image = Image(spec.width, spec.height, spec.nchannels);
    } catch (const std::bad_alloc&) {
        throw InvalidInput(formatError(path.string(), "",
                                       "image of " + std::to_string(spec.width) + "x" +
                                           std::to_string(spec.height) + " pixels with " +
                                           channelCount(spec.nchannels) + " is too large to load",
                                       "an image that fits in memory"));
    }
    if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, image.pixels.data())) {
        throw ParseError(formatError(path.string(), "pixels", "cannot read: " + oiioError(in->geterror()),
                                     "a complete, uncorrupted image file"));
    }
    in->close();
    discardPendingOiioErrors();
    return image;
}

ImageInfo readImageInfo(const fs::path& path) {
    auto in = openInput(path);
    const OIIO::ImageSpec& spec = in->spec();
    ImageInfo info;
    info.width = spec.width;
    info.height = spec.height;
    info.channels = spec.nchannels;
    info.format = in->format_name();
    info.pixelType = pixelTypeName(spec.format);
    info.channelNames = spec.channelnames;
    for (const OIIO::ParamValue& p : spec.extra_attribs) {
        if (p.type() == OIIO::TypeString) info.attributes.emplace_back(p.name().string(), p.get_string());
    }
    in->close();
    discardPendingOiioErrors();
    return info;
}

void writeImage(const fs::path& path, const Image& image, const ImageWriteOptions& options) {
    if (image.width < 1 || image.height < 1 || image.channels < 1) {
        throw InvalidInput(formatError(path.string(), "",
                                       "cannot write an empty image (" + std::to_string(image.width) + "x" +
                                           std::to_string(image.height) + " pixels, " +
                                           channelCount(image.channels) + ")",
                                       "at least 1x1 pixels and 1 channel"));
    }
    const size_t expected = static_cast<size_t>(image.width) * image.height * image.channels;
    if (image.pixels.size() != expected) {
        throw InvalidInput(formatError(path.string(), "pixels",
                                       "has " + std::to_string(image.pixels.size()) + " values",
                                       std::to_string(expected) + " = width * height * channels"));
    }

    discardPendingOiioErrors();
    // Created from the final name (nothing is opened yet): its format decides the checks below.
    std::unique_ptr<OIIO::ImageOutput> probe = OIIO::ImageOutput::create(path.string());
    if (!probe) {
        throw InvalidInput(formatError(
            path.string(), "", "no image format for the extension '" + path.extension().string() + "'",
            "an extension OpenImageIO writes, such as .exr, .png or .tif"));
    }
    const std::string format = probe->format_name();
    if (image.channels > 4 && !probe->supports("nchannels")) {
        throw InvalidInput(formatError(path.string(), "", "has " + channelCount(image.channels),
                                       "at most 4 channels in " + format + " files"));
    }
    const OIIO::TypeDesc type = requestedType(options.type, format);

    writeAtomically(path, [&](const fs::path& tmp) {
        const std::unique_ptr<OIIO::ImageOutput> out = std::move(probe);  // owned here: closed before rename

        OIIO::ImageSpec spec(image.width, image.height, image.channels, type);
        // EXR keeps channels sorted by name and OpenImageIO restores R, G, B, A but orders other names as
        // strings ("channel10" before "channel4"): zero-padded names keep channels 5 and up in place.
        const size_t digits = std::to_string(image.channels - 1).size();
        for (int32_t c = 4; c < image.channels; ++c) {
            const std::string index = std::to_string(c);
            spec.channelnames[c] = "channel" + std::string(digits - index.size(), '0') + index;
        }
        // Stored as given: no unpremultiplication of 2- or 4-channel data on the way out.
        spec.attribute("oiio:UnassociatedAlpha", 1);
        // TIFF writes float unless half is asked for explicitly.
        if (format == "tiff" && type == OIIO::TypeDesc::HALF) spec.attribute("tiff:half", 1);
        // EXR and TIFF writers stamp the current time unless given one; an empty stamp keeps the same
        // image written twice byte-identical.
        if ((format == "openexr" || format == "tiff") && !hasAttribute(options, "DateTime")) {
            spec.attribute("DateTime", "");
        }
        for (const auto& [name, value] : options.attributes)
            spec.attribute(name, value);

        if (!out->open(tmp.string(), spec)) {
            throw IoError(formatError(path.string(), "", "cannot write: " + oiioError(out->geterror()),
                                      "a writable file"));
        }
        if (out->spec().nchannels != image.channels) {
            throw InvalidInput(formatError(path.string(), "", "has " + channelCount(image.channels),
                                           channelCount(out->spec().nchannels) + " in " + format + " files"));
        }
        std::string rejected;
        if (options.type != PixelType::Auto && out->spec().format != type) {
            rejected = formatError(path.string(), "pixel type",
                                   format + " files cannot store " + pixelTypeName(type) + " pixels",
                                   "a type the format stores, such as " + pixelTypeName(out->spec().format));
        }
        if (!out->write_image(OIIO::TypeDesc::FLOAT, image.pixels.data())) {
            throw IoError(formatError(path.string(), "pixels", "cannot write: " + oiioError(out->geterror()),
                                      "enough space to write"));
        }
        if (!out->close()) {
            throw IoError(formatError(path.string(), "",
                                      "cannot finish writing: " + oiioError(out->geterror()),
                                      "enough space to write"));
        }
        // Rejected only now: a PNG writer closed before its pixels makes libpng print to stderr.
        if (!rejected.empty()) throw InvalidInput(rejected);
        requireAttributesStored(path, tmp, format, options);
    });
    discardPendingOiioErrors();
}

bool isImageFileName(const fs::path& path) {
    if (path.extension().empty()) return false;
    discardPendingOiioErrors();
    const bool known = OIIO::ImageInput::create(path.string(), false) != nullptr;
    discardPendingOiioErrors();
    return known;
}

}  // namespace deformkit::io
