#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace deformkit::io {

// A float32 image in numpy's (H, W, C) layout: rows from the top, pixels left to right, channels
// interleaved. Integer files are normalised to [0, 1] on read (8-bit 255 -> 1.0).
struct Image {
    int32_t width = 0;
    int32_t height = 0;
    int32_t channels = 0;
    std::vector<float> pixels;  // width * height * channels

    Image() = default;
    Image(int32_t w, int32_t h, int32_t c, float fill = 0.0f)
        : width(w), height(h), channels(c), pixels(static_cast<size_t>(w) * h * c, fill) {}

    [[nodiscard]] float& at(int32_t x, int32_t y, int32_t c) {
        return pixels[(static_cast<size_t>(y) * width + x) * channels + c];
    }
    [[nodiscard]] float at(int32_t x, int32_t y, int32_t c) const {
        return pixels[(static_cast<size_t>(y) * width + x) * channels + c];
    }
};

// Pixel type of a written file. Auto: half for EXR (float when a finite value is beyond half's range, which
// would be written as inf), 8-bit for every other format. Half refuses such a value.
enum class PixelType { Auto, UInt8, UInt16, Half, Float };

struct ImageReadOptions {
    int32_t expectedChannels = 0;  // 0: any; otherwise a file with another count is an InvalidInput error
    std::string role;              // what the image is for ("rigidity map"), named in errors when set
};

struct ImageWriteOptions {
    PixelType type = PixelType::Auto;
    // String attributes written into the file's header (EXR/TIFF metadata), e.g. how a map was made.
    std::vector<std::pair<std::string, std::string>> attributes;
};

struct ImageInfo {
    int32_t width = 0;
    int32_t height = 0;
    int32_t channels = 0;
    std::string format;     // OpenImageIO format name: "openexr", "png", "tiff", ...
    std::string pixelType;  // "uint8", "uint16", "half", "float", ...
    std::vector<std::string> channelNames;
    std::vector<std::pair<std::string, std::string>> attributes;  // string header attributes
};

// The pixel type of a file's header (ImageInfo::pixelType): UInt8, UInt16, Half, Float, or Auto for another
// (OpenImageIO's uint32, double, ...), so that a file written again keeps what it held.
[[nodiscard]] PixelType pixelTypeOf(const ImageInfo& info);

// Throws InvalidInput naming `source`, the first pixel (x, y from the top row), its channel and value when a
// value of `image` is not finite; `expected` says why finite values are needed ("finite values (a baked
// texel filters its neighbours)").
void requireFinitePixels(const Image& image, const std::string& source, const std::string& expected);

// Reads any format OpenImageIO reads (first subimage, first mip level) as float32.
// Throws IoError for a missing or unreadable file, ParseError for a truncated or corrupt one (naming
// the file and what OpenImageIO reported), InvalidInput for a channel count other than expected.
[[nodiscard]] Image readImage(const std::filesystem::path& path, const ImageReadOptions& options = {});

// Reads only the header.
[[nodiscard]] ImageInfo readImageInfo(const std::filesystem::path& path);

// True when OpenImageIO has a reader for the file name's extension (the file is not opened).
[[nodiscard]] bool isImageFileName(const std::filesystem::path& path);

// Throws InvalidInput, as writeImage would, when OpenImageIO has no writer for the file name's extension
// (nothing is opened): for outputs checked before the work that makes them.
void requireImageWriter(const std::filesystem::path& path);

// Writes atomically (temporary file in the same folder, then rename): on failure no partial file is
// left and an existing file is intact. The format follows the extension. Throws InvalidInput for an
// empty image, a pixel count that does not match width * height * channels, or a pixel type the format
// cannot store (PNG has no half or float); IoError when the folder is missing or not writable.
void writeImage(const std::filesystem::path& path, const Image& image, const ImageWriteOptions& options = {});

// Fills `band`, rows [y0, y0 + band.height) of an image being written (all zero on entry; its size is
// fixed).
using ImageBand = std::function<void(int32_t y0, Image& band)>;

// Writes a width x height image made `bandRows` rows at a time, top to bottom, so that only one band is in
// memory (a contact sheet of thousands of frames). Atomic and checked as writeImage; a format whose writer
// cannot take rows in order (none of the scanline formats) fails with IoError. An exception thrown by `fill`
// leaves no file. Auto writes EXR as half, whatever the bands hold: a band with a value beyond half's range
// fails as Half does.
void writeImageInBands(const std::filesystem::path& path, int32_t width, int32_t height, int32_t channels,
                       int32_t bandRows, const ImageBand& fill, const ImageWriteOptions& options = {});

}  // namespace deformkit::io
