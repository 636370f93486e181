#pragma once

// The boundary between the library's image I/O (image.cpp) and its OpenImageIO module
// (deformkit_image_oiio.so, core/modules/image_oiio.cpp), loaded on the first image read or write. A
// process that touches no image never maps OpenImageIO and the ~260 shared libraries it depends on, which
// cost about 0.4 s at every start (docs/decisions.md, BUILD-4). Both sides are compiled from this header by
// one build, so C++ types cross it; kAbiVersion changes whenever this header does, and a module of another
// version is refused.
//
// Every policy (messages, checks, defaults, atomic writes) stays in image.cpp: the module only translates
// these calls into OpenImageIO's.

#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace deformkit::io::codec {

inline constexpr int kAbiVersion = 3;

// Pixel types by name: "uint8", "uint16", "half", "float", or OpenImageIO's name of any other type.
struct Spec {
    int32_t width = 0;
    int32_t height = 0;
    int32_t depth = 0;
    int32_t channels = 0;
    bool deep = false;
    int32_t tileWidth = 0;  // 0: scanlines
    int32_t tileHeight = 0;
    // The pixels' place (the data window, width x height from its origin) and the image's frame (the
    // display window); the same in most files, an EXR's may differ (a crop, an overscan).
    int32_t x = 0;
    int32_t y = 0;
    int32_t fullX = 0;
    int32_t fullY = 0;
    int32_t fullWidth = 0;
    int32_t fullHeight = 0;
    std::string pixelType;
    std::vector<std::string> channelNames;
    std::vector<std::pair<std::string, std::string>> stringAttributes;  // in the file's order
};

// An open image file (first subimage, first mip level).
class Reader {
  public:
    virtual ~Reader() = default;
    [[nodiscard]] virtual const Spec& spec() const = 0;
    [[nodiscard]] virtual std::string formatName() const = 0;
    [[nodiscard]] virtual bool hasAttribute(const std::string& name) const = 0;  // of any type
    // Every pixel as float32, (H, W, C). False on failure: error() says why.
    [[nodiscard]] virtual bool readFloats(float* pixels) = 0;
    [[nodiscard]] virtual std::string error() = 0;  // the reader's own pending error, then cleared
    virtual void close() = 0;
};

// What a file is opened with. Attributes are set in this order: integers, then strings.
struct WriteSpec {
    int32_t width = 0;
    int32_t height = 0;
    int32_t channels = 0;
    std::string pixelType;
    std::vector<std::pair<int32_t, std::string>> channelNames;  // overrides of the default names
    std::vector<std::pair<std::string, int32_t>> intAttributes;
    std::vector<std::pair<std::string, std::string>> stringAttributes;
};

// A writer for a format, chosen by a file name's extension before anything is opened.
class Writer {
  public:
    virtual ~Writer() = default;
    [[nodiscard]] virtual std::string formatName() const = 0;
    [[nodiscard]] virtual bool supportsAnyChannelCount() const = 0;
    [[nodiscard]] virtual bool open(const std::string& path, const WriteSpec& spec) = 0;
    // What the opened file holds (a format may store fewer channels or another type than asked).
    [[nodiscard]] virtual int32_t openedChannels() const = 0;
    [[nodiscard]] virtual std::string openedPixelType() const = 0;
    [[nodiscard]] virtual bool writeFloats(const float* pixels) = 0;
    // Rows [yBegin, yEnd) as float32, (H, W, C); rows are given in order, top to bottom.
    [[nodiscard]] virtual bool writeRows(int32_t yBegin, int32_t yEnd, const float* pixels) = 0;
    [[nodiscard]] virtual bool close() = 0;
    [[nodiscard]] virtual std::string error() = 0;
};

// The module's entry points. OpenImageIO keeps a per-thread global error beside each object's own:
// takeGlobalError() returns it and clears it.
struct Codec {
    int abiVersion = kAbiVersion;
    // Null when the file cannot be opened (takeGlobalError() says why). keepAlphaAsStored: no
    // premultiplication of 2- and 4-channel data.
    std::unique_ptr<Reader> (*openReader)(const std::string& path, bool keepAlphaAsStored) = nullptr;
    // Null when no format has that extension.
    std::unique_ptr<Writer> (*createWriter)(const std::string& path) = nullptr;
    bool (*hasReaderFor)(const std::string& fileName) = nullptr;
    std::string (*takeGlobalError)() = nullptr;
};

// The symbol the module exports.
inline constexpr const char* kEntryPoint = "deformkit_image_codec";
using EntryPoint = const Codec* (*)();

// The module, loaded on the first call (thread-safe). Throws IoError naming `imagePath`, every place the
// module was looked for and why each failed, when it cannot be loaded.
[[nodiscard]] const Codec& load(const std::string& imagePath);

}  // namespace deformkit::io::codec
