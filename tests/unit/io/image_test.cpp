#include <catch2/catch.hpp>

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <random>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include <unistd.h>
#include <zlib.h>

#include <cstdio>
#include <functional>

#include "deformkit/error.h"
#include "deformkit/io/image.h"
#include "test_support.h"

using namespace deformkit::io;
using deformkit::test::readText;
using deformkit::test::runUnprivileged;
using deformkit::test::TempDir;
using deformkit::test::writeText;
namespace fs = std::filesystem;

namespace {

// A PNG of the given header whose IDAT holds `data` deflated at zlib's best (or as it is, `deflated`
// false: not a zlib stream).
std::string pngOf(uint32_t width, uint32_t height, unsigned char depth, unsigned char colour,
                  const std::string& data, bool deflated = true) {
    const auto bigEndian = [](uint32_t v) {
        return std::string{static_cast<char>(v >> 24), static_cast<char>(v >> 16), static_cast<char>(v >> 8),
                           static_cast<char>(v)};
    };
    const auto chunk = [&](const std::string& type, const std::string& body) {
        const std::string typed = type + body;
        const uLong crc = crc32(crc32(0L, Z_NULL, 0), reinterpret_cast<const Bytef*>(typed.data()),
                                static_cast<uInt>(typed.size()));
        return bigEndian(static_cast<uint32_t>(body.size())) + typed + bigEndian(static_cast<uint32_t>(crc));
    };
    std::string packed = data;
    if (deflated) {
        packed.assign(compressBound(data.size()), '\0');
        uLongf packedSize = packed.size();
        REQUIRE(compress2(reinterpret_cast<Bytef*>(packed.data()), &packedSize,
                          reinterpret_cast<const Bytef*>(data.data()), data.size(), 9) == Z_OK);
        packed.resize(packedSize);
    }
    const std::string header = bigEndian(width) + bigEndian(height) +
                               std::string{static_cast<char>(depth), static_cast<char>(colour), 0, 0, 0};
    return std::string("\x89PNG\r\n\x1a\n", 8) + chunk("IHDR", header) + chunk("IDAT", packed) +
           chunk("IEND", "");
}

// A 1-bit gray PNG declaring width x height pixels: its IDAT the first row only (a header that lies), or
// with `whole` every row, all 0.
std::string pngDeclaring(uint32_t width, uint32_t height, bool whole = false) {
    return pngOf(width, height, 1, 0,
                 std::string((whole ? height : 1) * static_cast<size_t>(1 + (width + 7) / 8), '\0'));
}

// A little-endian TIFF of one strip holding `data` as it is (spelled out from the TIFF 6.0 layout: the
// header, one directory, then the strip and the colour map). Compression 1 none, 4 CCITT Group 4, 5 LZW, 8
// Deflate, 32773 PackBits. Gray, white-is-zero; with `palette` a palette image (photometric 3) whose colour
// map (tag 320) gives index 0 black and every other index white, which a reader shows as RGB.
std::string tiffOf(uint32_t width, uint32_t height, uint16_t bitsPerSample, uint16_t compression,
                   const std::string& data, bool palette = false) {
    std::string out("II*\0\x08\0\0\0", 8);
    const auto u16 = [&](uint16_t v) { out.append(reinterpret_cast<const char*>(&v), 2); };
    const auto u32 = [&](uint32_t v) { out.append(reinterpret_cast<const char*>(&v), 4); };
    const auto entry = [&](uint16_t tag, uint16_t type, uint32_t count, uint32_t value) {
        u16(tag), u16(type), u32(count);
        if (type == 3 && count == 1) {
            u16(static_cast<uint16_t>(value)), u16(0);
        } else {
            u32(value);
        }
    };
    constexpr uint16_t kShort = 3, kLong = 4;
    const uint16_t entries = palette ? 10 : 9;
    const uint32_t strip = 8 + 2 + 12 * entries + 4;  // the strip right after the directory
    const uint32_t colours = uint32_t{1} << bitsPerSample;
    u16(entries);
    entry(256, kLong, 1, width);
    entry(257, kLong, 1, height);
    entry(258, kShort, 1, bitsPerSample);
    entry(259, kShort, 1, compression);
    entry(262, kShort, 1, palette ? 3 : 0);
    entry(273, kLong, 1, strip);
    entry(277, kShort, 1, 1);
    entry(278, kLong, 1, height);  // one strip
    entry(279, kLong, 1, static_cast<uint32_t>(data.size()));
    if (palette) entry(320, kShort, 3 * colours, strip + static_cast<uint32_t>(data.size()));
    u32(0);
    out += data;
    for (uint32_t c = 0; palette && c < 3 * colours; ++c)
        u16(c % colours == 0 ? 0 : 65535);  // red, green, blue tables
    return out;
}

// What `run` writes to the process's stderr (file descriptor 2) while it runs; its exception is ignored.
std::string stderrOf(const std::function<void()>& run) {
    std::fflush(stderr);
    FILE* capture = std::tmpfile();
    const int saved = dup(2);
    dup2(fileno(capture), 2);
    try {
        run();
    } catch (...) {
    }
    std::fflush(stderr);
    dup2(saved, 2);
    close(saved);
    std::rewind(capture);
    std::string text;
    for (int c = std::fgetc(capture); c != EOF; c = std::fgetc(capture))
        text += static_cast<char>(c);
    std::fclose(capture);
    return text;
}

// The header of a single-part OpenEXR file of `channels` float channels, uncompressed, declaring width x
// height pixels, followed by its offset table (of zeros) and no chunks (spelled out from the OpenEXR file
// layout: magic, version, attributes, an empty name closing them). Tiled: one tile of `tile` x `tile` pixels.
// The pixels (data window) from (x, y); the display window `display` (x0, y0, x1, y1), or the data window.
std::string exrWithoutPixels(int32_t width, int32_t height, int channels, int32_t tile = 0, int32_t x = 0,
                             int32_t y = 0, std::optional<std::array<int32_t, 4>> display = {}) {
    std::string out;
    auto bytes = [&](const void* p, size_t n) { out.append(static_cast<const char*>(p), n); };
    auto i32 = [&](int32_t v) { bytes(&v, 4); };
    auto attribute = [&](const std::string& name, const std::string& type, const std::string& value) {
        out += name + '\0' + type + '\0';
        i32(static_cast<int32_t>(value.size()));
        out += value;
    };
    auto packed = [](std::initializer_list<int32_t> values) {
        std::string v;
        for (int32_t x : values)
            v.append(reinterpret_cast<const char*>(&x), 4);
        return v;
    };
    out += "\x76\x2f\x31\x01";
    i32(tile > 0 ? 2 | 0x200 : 2);
    std::string list;
    for (int c = 0; c < channels; ++c)
        list +=
            "c" + std::to_string(c) + '\0' + packed({2, 0, 1, 1});  // float, pLinear 0 + reserved, sampling
    attribute("channels", "chlist", list + '\0');
    attribute("compression", "compression", std::string(1, '\0'));
    attribute("dataWindow", "box2i", packed({x, y, x + width - 1, y + height - 1}));
    const std::array<int32_t, 4> shown = display.value_or(std::array{x, y, x + width - 1, y + height - 1});
    attribute("displayWindow", "box2i", packed({shown[0], shown[1], shown[2], shown[3]}));
    attribute("lineOrder", "lineOrder", std::string(1, '\0'));
    attribute("pixelAspectRatio", "float", packed({0x3f800000}));
    attribute("screenWindowCenter", "v2f", packed({0, 0}));
    attribute("screenWindowWidth", "float", packed({0x3f800000}));
    if (tile > 0) attribute("tiles", "tiledesc", packed({tile, tile}) + '\0');
    out += '\0';
    out += std::string(8 * static_cast<size_t>(tile > 0 ? 1 : height), '\0');  // the chunks' offset table
    return out;
}

// Independent float -> half -> float reference: round to 11 significant bits (10 stored), ties to even,
// with the subnormal quantum 2^-24 below 2^-14 and overflow to infinity past 65504.
float roundToHalf(float value) {
    if (value == 0.0f || !std::isfinite(value)) return value;
    int exponent = 0;
    std::frexp(static_cast<double>(value), &exponent);  // |value| = m 2^exponent, m in [0.5, 1)
    const int quantumExponent = std::max(exponent - 11, -24);
    const double rounded =
        std::ldexp(std::nearbyint(std::ldexp(static_cast<double>(value), -quantumExponent)), quantumExponent);
    if (std::abs(rounded) > 65504.0) return std::copysign(INFINITY, value);
    return static_cast<float>(rounded);
}

// A distinct value per (x, y, c) that tells a transposed, flipped or channel-swapped read apart.
// Multiples of 1/255 so 8-bit files store it exactly; alpha-like channels include 0 under non-zero colour.
float patternValue(int32_t x, int32_t y, int32_t c) {
    return static_cast<float>((x * 5 + y * 41 + c * 67 + (x * y) % 7) % 256) / 255.0f;
}

Image patternImage(int32_t w, int32_t h, int32_t channels) {
    Image img(w, h, channels);
    for (int32_t y = 0; y < h; ++y) {
        for (int32_t x = 0; x < w; ++x) {
            for (int32_t c = 0; c < channels; ++c)
                img.at(x, y, c) = patternValue(x, y, c);
        }
    }
    return img;
}

std::vector<float> randomUnit(size_t n, uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> dist(0.0f, 1.0f);
    std::vector<float> v(n);
    for (float& x : v)
        x = dist(rng);
    v[0] = 0.0f;
    v[1] = 1.0f;
    return v;
}

// Reads with OpenImageIO directly, as an independent check of what writeImage put in the file.
std::vector<float> readWithOiio(const fs::path& path, int& w, int& h, int& c) {
    OIIO::ImageSpec config;  // as stored: no premultiplication of 2- and 4-channel PNGs
    config.attribute("oiio:UnassociatedAlpha", 1);
    auto in = OIIO::ImageInput::open(path.string(), &config);
    REQUIRE(in);
    w = in->spec().width;
    h = in->spec().height;
    c = in->spec().nchannels;
    std::vector<float> px(static_cast<size_t>(w) * h * c);
    REQUIRE(in->read_image(0, 0, 0, c, OIIO::TypeDesc::FLOAT, px.data()));
    return px;
}

std::set<std::string> folderEntries(const fs::path& folder) {
    std::set<std::string> names;
    for (const auto& e : fs::directory_iterator(folder))
        names.insert(e.path().filename().string());
    return names;
}

// True when `stored` is the level of `levels` nearest to `value`. Where value * levels lies within
// 1e-3 of a tie, the writer's float arithmetic may round either way, so both neighbours are accepted.
bool isNearestLevel(float stored, float value, double levels) {
    const double exact = static_cast<double>(value) * levels;
    const double level = static_cast<double>(stored) * levels;
    if (std::abs(level - std::round(level)) > 1e-2) return false;  // not a level (float error is < 5e-3)
    if (std::abs(exact - std::floor(exact) - 0.5) < 1e-3) {
        return std::round(level) == std::floor(exact) || std::round(level) == std::ceil(exact);
    }
    return std::round(level) == std::round(exact);
}

void truncateToHalf(const fs::path& path) {
    fs::resize_file(path, fs::file_size(path) / 2);
}

}  // namespace

TEST_CASE("the half reference rounds like IEEE binary16", "[io][image]") {
    CHECK(roundToHalf(1.0f) == 1.0f);
    CHECK(roundToHalf(0.1f) == 0.0999755859375f);
    CHECK(roundToHalf(1.0f / 3.0f) == 0.333251953125f);
    CHECK(roundToHalf(1.0f + 0x1p-11f) == 1.0f);                // tie to even (down)
    CHECK(roundToHalf(1.0f + 3 * 0x1p-11f) == 1.0f + 0x1p-9f);  // tie to even (up)
    CHECK(roundToHalf(65504.0f) == 65504.0f);
    CHECK(roundToHalf(65519.0f) == 65504.0f);
    CHECK(std::isinf(roundToHalf(65520.0f)));
    CHECK(roundToHalf(1e-7f) == 0x1p-23f);  // subnormal: 1e-7 / 2^-24 = 1.68 quanta -> 2
    CHECK(roundToHalf(-2.5e-8f) == 0.0f);
}

TEST_CASE("EXR float round trip is bit exact", "[io][image]") {
    TempDir dir;
    Image img(13, 7, 3);
    std::mt19937 rng(7);
    for (float& v : img.pixels) {
        do {
            v = std::bit_cast<float>(static_cast<uint32_t>(rng()));
        } while (std::isnan(v));
    }
    img.pixels[0] = -0.0f;
    img.pixels[1] = INFINITY;
    img.pixels[2] = -3.75e30f;
    img.pixels[3] = 1e-42f;  // subnormal
    writeImage(dir / "f.exr", img, {PixelType::Float, {}});
    const Image back = readImage(dir / "f.exr");
    REQUIRE(back.width == 13);
    REQUIRE(back.height == 7);
    REQUIRE(back.channels == 3);
    for (size_t i = 0; i < img.pixels.size(); ++i) {
        INFO("index " << i << " value " << img.pixels[i]);
        REQUIRE(std::bit_cast<uint32_t>(back.pixels[i]) == std::bit_cast<uint32_t>(img.pixels[i]));
    }
    CHECK(readImageInfo(dir / "f.exr").pixelType == "float");
}

TEST_CASE("EXR half round trip equals the value rounded to half", "[io][image]") {
    TempDir dir;
    Image img(16, 9, 2);
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> wide(-3000.0f, 3000.0f), narrow(-1.0f, 1.0f);
    std::uniform_real_distribution<float> tiny(-1e-4f, 1e-4f);
    for (size_t i = 0; i < img.pixels.size(); ++i)
        img.pixels[i] = i % 3 == 0 ? wide(rng) : i % 3 == 1 ? narrow(rng) : tiny(rng);
    img.pixels[0] = 1.0f + 0x1p-11f;
    img.pixels[1] = 1.0f + 3 * 0x1p-11f;
    img.pixels[2] = 65519.0f;
    img.pixels[3] = 3e-8f;
    writeImage(dir / "h.exr", img);  // Auto: half for EXR
    CHECK(readImageInfo(dir / "h.exr").pixelType == "half");
    const Image back = readImage(dir / "h.exr");
    REQUIRE(back.pixels.size() == img.pixels.size());
    int changed = 0;
    for (size_t i = 0; i < img.pixels.size(); ++i) {
        INFO("index " << i << " value " << img.pixels[i]);
        REQUIRE(back.pixels[i] == roundToHalf(img.pixels[i]));
        changed += back.pixels[i] != img.pixels[i];
    }
    CHECK(changed > static_cast<int>(img.pixels.size()) / 2);  // the rounding really happened
}

TEST_CASE("PNG 8-bit round trip equals round(v * 255) / 255", "[io][image]") {
    TempDir dir;
    Image img(11, 6, 3);
    img.pixels = randomUnit(img.pixels.size(), 3);
    writeImage(dir / "a.png", img);  // Auto: 8-bit
    CHECK(readImageInfo(dir / "a.png").pixelType == "uint8");
    const Image back = readImage(dir / "a.png");
    REQUIRE(back.pixels.size() == img.pixels.size());
    for (size_t i = 0; i < img.pixels.size(); ++i) {
        INFO("index " << i << " value " << img.pixels[i]);
        REQUIRE(isNearestLevel(back.pixels[i], img.pixels[i], 255.0));
    }
}

TEST_CASE("PNG and TIFF 16-bit round trip equals round(v * 65535) / 65535", "[io][image]") {
    TempDir dir;
    for (const char* name : {"a.png", "a.tif"}) {
        INFO(name);
        Image img(9, 14, 4);
        img.pixels = randomUnit(img.pixels.size(), 5);
        writeImage(dir / name, img, {PixelType::UInt16, {}});
        CHECK(readImageInfo(dir / name).pixelType == "uint16");
        const Image back = readImage(dir / name);
        REQUIRE(back.pixels.size() == img.pixels.size());
        for (size_t i = 0; i < img.pixels.size(); ++i) {
            INFO("index " << i << " value " << img.pixels[i]);
            REQUIRE(isNearestLevel(back.pixels[i], img.pixels[i], 65535.0));
        }
    }
}

TEST_CASE("TIFF stores half and float", "[io][image]") {
    TempDir dir;
    Image img(5, 4, 1);
    std::mt19937 rng(2);
    std::uniform_real_distribution<float> dist(-5.0f, 5.0f);
    for (float& v : img.pixels)
        v = dist(rng);
    writeImage(dir / "h.tif", img, {PixelType::Half, {}});
    writeImage(dir / "f.tif", img, {PixelType::Float, {}});
    CHECK(readImageInfo(dir / "h.tif").pixelType == "half");
    CHECK(readImageInfo(dir / "f.tif").pixelType == "float");
    const Image h = readImage(dir / "h.tif"), f = readImage(dir / "f.tif");
    for (size_t i = 0; i < img.pixels.size(); ++i) {
        REQUIRE(h.pixels[i] == roundToHalf(img.pixels[i]));
        REQUIRE(f.pixels[i] == img.pixels[i]);
    }
}

TEST_CASE("pixel (x, y, c) comes back at (x, y, c) for 1 to 4 channels", "[io][image]") {
    TempDir dir;
    const int32_t w = 7, h = 4;
    for (const char* ext : {".exr", ".png", ".tif"}) {
        for (int32_t channels = 1; channels <= 4; ++channels) {
            INFO(ext << " with " << channels << " channels");
            const fs::path path = dir / ("p" + std::to_string(channels) + ext);
            const Image img = patternImage(w, h, channels);
            writeImage(path, img, {std::string(ext) == ".exr" ? PixelType::Float : PixelType::UInt16, {}});

            const Image back = readImage(path);
            REQUIRE(back.width == w);
            REQUIRE(back.height == h);
            REQUIRE(back.channels == channels);
            int ow = 0, oh = 0, oc = 0;
            const std::vector<float> oiio = readWithOiio(path, ow, oh, oc);
            REQUIRE((ow == w && oh == h && oc == channels));
            for (int32_t y = 0; y < h; ++y) {
                for (int32_t x = 0; x < w; ++x) {
                    for (int32_t c = 0; c < channels; ++c) {
                        INFO("pixel " << x << ", " << y << ", channel " << c);
                        REQUIRE(back.at(x, y, c) == Approx(patternValue(x, y, c)).margin(1e-6));
                        REQUIRE(oiio[(static_cast<size_t>(y) * w + x) * channels + c] ==
                                Approx(patternValue(x, y, c)).margin(1e-6));
                    }
                }
            }
        }
    }
}

TEST_CASE("readImage lays out a file written by OpenImageIO directly as (H, W, C), top row first",
          "[io][image]") {
    TempDir dir;
    const int w = 6, h = 3, channels = 3;
    std::vector<uint8_t> bytes(static_cast<size_t>(w) * h * channels);
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
            for (int c = 0; c < channels; ++c)
                bytes[(static_cast<size_t>(y) * w + x) * channels + c] = 100 * c + 10 * y + x;
        }
    }
    const fs::path path = dir / "direct.png";
    auto out = OIIO::ImageOutput::create(path.string());
    REQUIRE(out);
    REQUIRE(out->open(path.string(), OIIO::ImageSpec(w, h, channels, OIIO::TypeDesc::UINT8)));
    REQUIRE(out->write_image(OIIO::TypeDesc::UINT8, bytes.data()));
    REQUIRE(out->close());

    const Image img = readImage(path);
    REQUIRE((img.width == w && img.height == h && img.channels == channels));
    CHECK(img.at(0, 0, 0) == Approx(0.0f));
    CHECK(img.at(5, 0, 0) == Approx(5.0f / 255.0f));
    CHECK(img.at(0, 2, 0) == Approx(20.0f / 255.0f));
    CHECK(img.at(4, 1, 2) == Approx(214.0f / 255.0f));
    CHECK(img.pixels[3] == Approx(1.0f / 255.0f));  // second pixel, first channel
}

TEST_CASE("readImageInfo reads the header: format, pixel type, channels, string attributes", "[io][image]") {
    TempDir dir;
    writeImage(dir / "rgb.exr", patternImage(8, 5, 3),
               {PixelType::Auto, {{"deformkit:solver", "uvwarp 0.1"}, {"deformkit:frame", "1042"}}});
    const ImageInfo exr = readImageInfo(dir / "rgb.exr");
    CHECK(exr.width == 8);
    CHECK(exr.height == 5);
    CHECK(exr.channels == 3);
    CHECK(exr.format == "openexr");
    CHECK(exr.pixelType == "half");
    CHECK(exr.channelNames == std::vector<std::string>{"R", "G", "B"});
    using Attr = std::pair<std::string, std::string>;
    CHECK(std::count(exr.attributes.begin(), exr.attributes.end(), Attr{"deformkit:solver", "uvwarp 0.1"}) ==
          1);
    CHECK(std::count(exr.attributes.begin(), exr.attributes.end(), Attr{"deformkit:frame", "1042"}) == 1);

    // Independently, through OpenImageIO.
    auto in = OIIO::ImageInput::open((dir / "rgb.exr").string());
    REQUIRE(in);
    CHECK(in->spec().get_string_attribute("deformkit:solver") == "uvwarp 0.1");

    writeImage(dir / "ga.png", patternImage(3, 2, 2), {PixelType::UInt16, {}});
    const ImageInfo png = readImageInfo(dir / "ga.png");
    CHECK(png.format == "png");
    CHECK(png.pixelType == "uint16");
    CHECK(png.channels == 2);

    // Header only: a PNG cut after its header still describes itself, though its pixels are gone.
    writeImage(dir / "big.png", patternImage(256, 256, 3));
    truncateToHalf(dir / "big.png");
    CHECK(readImageInfo(dir / "big.png").width == 256);
    CHECK_THROWS_AS(readImage(dir / "big.png"), deformkit::ParseError);
}

TEST_CASE("written headers carry no clock time unless given one", "[io][image]") {
    TempDir dir;
    const Image img = patternImage(4, 4, 1);
    for (const char* name : {"a.exr", "a.tif"}) {
        INFO(name);
        writeImage(dir / name, img);
        for (const auto& [key, value] : readImageInfo(dir / name).attributes) {
            if (key == "DateTime") CHECK(value.empty());
        }
    }
    writeImage(dir / "b.exr", img);
    CHECK(readText(dir / "a.exr") == readText(dir / "b.exr"));

    writeImage(dir / "c.exr", img, {PixelType::Auto, {{"DateTime", "2024:05:06 07:08:09"}}});
    auto in = OIIO::ImageInput::open((dir / "c.exr").string());
    REQUIRE(in);
    CHECK(in->spec().get_string_attribute("DateTime") == "2024:05:06 07:08:09");
}

TEST_CASE("readImage errors name the file and the cause", "[io][image]") {
    TempDir dir;
    using deformkit::InvalidInput;
    using deformkit::IoError;
    using deformkit::ParseError;

    SECTION("missing file or a folder") {
        CHECK_THROWS_AS(readImage(dir / "none.exr"), IoError);
        CHECK_THROWS_WITH(readImage(dir / "none.exr"),
                          Catch::Contains((dir / "none.exr").string() + ": no such file"));
        CHECK_THROWS_AS(readImageInfo(dir / "none.exr"), IoError);
        CHECK_THROWS_AS(readImage(dir.path()), IoError);
    }

    SECTION("a header declaring more pixels than the file can hold, or than memory can") {
        // 30000 uncompressed scanlines are 30000 chunks of at least 16 bytes (an offset and a chunk header):
        // a file of 240 KB cannot hold them, refused before 3.6 GB are allocated for its pixels.
        writeText(dir / "bomb.exr", exrWithoutPixels(30000, 30000, 1));
        CHECK_THROWS_AS(readImage(dir / "bomb.exr"), ParseError);
        CHECK_THROWS_WITH(
            readImage(dir / "bomb.exr"),
            Catch::Contains((dir / "bomb.exr").string() +
                            ": header: declares 30000x30000 pixels with 1 channel, which take at "
                            "least 480000 bytes, but the file has "));
        CHECK(readImageInfo(dir / "bomb.exr").width == 30000);  // the header alone reads
        // A PNG of 20000^2 gray pixels in 82 bytes: its data, inflated and measured before any pixel is
        // allocated, is one row of 2501 bytes, not the 50 MB its header declares.
        writeText(dir / "bomb.png", pngDeclaring(20000, 20000));
        CHECK_THROWS_AS(readImage(dir / "bomb.png"), ParseError);
        CHECK_THROWS_WITH(
            readImage(dir / "bomb.png"),
            Catch::Contains("bomb.png: image data (IDAT): inflates to 2501 bytes (corrupt PNG) "
                            "(expected a zlib stream of the 50020000 bytes its header declares)"));
        // A real file of that kind reads: a blank 1-bit PNG deflated as hard as zlib can.
        writeText(dir / "blank.png", pngDeclaring(4096, 4096, true));
        CHECK(readImage(dir / "blank.png").width == 4096);
        // TIFF headers of 30000^2 8-bit pixels over 16 bytes, refused by their compression's largest ratio
        // (the pixels counted at 1 bit: 112.5 MB uncompressed; over 64, 4096 and 1032; fax coding at least
        // one bit a row) before 3.6 GB are allocated; a 10-GB fax page used to crash OpenImageIO.
        for (const auto& [compression, fewest] : {std::pair<uint16_t, uint64_t>{1, 112500000},
                                                  {32773, 1757813},
                                                  {5, 27466},
                                                  {8, 109012},
                                                  {4, 3750}}) {
            CAPTURE(compression);
            writeText(dir / "bomb.tif",
                      tiffOf(30000, 30000, compression == 4 ? 1 : 8, compression, std::string(16, '\0')));
            CHECK_THROWS_AS(readImage(dir / "bomb.tif"), ParseError);
            CHECK_THROWS_WITH(readImage(dir / "bomb.tif"),
                              Catch::Contains(": header: declares 30000x30000 pixels with 1 channel, which "
                                              "take at least " +
                                              std::to_string(fewest) + " bytes, but the file has 138"));
        }
        // The fax bound is tight: a blank Group 4 page codes each row as one vertical-mode bit (V0, '1'),
        // then the end-of-facsimile block. 4096 rows in 512 bytes read, white.
        writeText(dir / "blank.tif",
                  tiffOf(4096, 4096, 1, 4, std::string(4096 / 8, '\xff') + std::string("\x00\x10\x01", 3)));
        const Image blankPage = readImage(dir / "blank.tif");
        REQUIRE(blankPage.width == 4096);
        CHECK(std::ranges::all_of(blankPage.pixels, [](float v) { return v == 1.0f; }));
        // A 1-bit palette image holds one bit a pixel however many channels it reads as (RGB): the bound
        // counts pixels, so a whole one reads (512 bytes for 64 x 64), and a cut one is refused.
        std::string bits(64 * 64 / 8, '\0');
        bits[5] = '\x80';  // pixel (40, 0): index 1, white
        writeText(dir / "palette.tif", tiffOf(64, 64, 1, 1, bits, true));
        const Image palette = readImage(dir / "palette.tif");
        REQUIRE(palette.channels == 3);
        CHECK(palette.at(40, 0, 1) == 1.0f);
        CHECK(palette.at(41, 0, 1) == 0.0f);
        writeText(dir / "palette.tif", tiffOf(640, 640, 1, 1, bits, true));
        CHECK_THROWS_WITH(readImage(dir / "palette.tif"), Catch::Contains("which take at least 51200 bytes"));
        // Files as compressible as can be, as OpenImageIO writes them, read whatever their compression.
        for (const char* compression : {"none", "packbits", "lzw", "zip"}) {
            CAPTURE(compression);
            writeImage(dir / "flat.tif", Image(1024, 1024, 1),
                       {PixelType::UInt8, {{"compression", compression}}});
            const auto attributes = readImageInfo(dir / "flat.tif").attributes;
            CHECK(std::ranges::count(attributes,
                                     std::pair<std::string, std::string>{"compression", compression}) == 1);
            CHECK(readImage(dir / "flat.tif").width == 1024);
        }
        // One tile of 2^29 x 2^29 pixels of 64 channels: 2^64 floats, whose count wraps in size_t.
        writeText(dir / "wrap.exr", exrWithoutPixels(1 << 29, 1 << 29, 64, 1 << 29));
        CHECK_THROWS_AS(readImage(dir / "wrap.exr"), InvalidInput);
        CHECK_THROWS_WITH(readImage(dir / "wrap.exr"),
                          Catch::Contains("wrap.exr: image of 536870912x536870912 pixels with 64 channels is "
                                          "too large to load"));
    }

    SECTION("an EXR whose pixels are a crop or an overscan of its image") {
        // Read as they are, the pixels of a crop were stretched over the whole image (a rigidity map over
        // the whole tile): refused, naming both windows, by the header read too.
        for (const auto& [name, header, message] :
             {std::tuple{"crop.exr", exrWithoutPixels(64, 64, 1, 0, 32, 32, std::array{0, 0, 127, 127}),
                         "holds pixels 64x64 at (32, 32) (its data window) of an image 128x128 at (0, 0)"},
              std::tuple{"overscan.exr", exrWithoutPixels(256, 256, 1, 0, 0, 0, std::array{0, 0, 127, 127}),
                         "holds pixels 256x256 at (0, 0) (its data window) of an image 128x128 at (0, 0)"},
              std::tuple{"moved.exr", exrWithoutPixels(128, 128, 1, 0, 5, 0, std::array{0, 0, 127, 127}),
                         "holds pixels 128x128 at (5, 0) (its data window) of an image 128x128 at (0, 0)"}}) {
            CAPTURE(name);
            writeText(dir / name, header);
            CHECK_THROWS_AS(readImage(dir / name), deformkit::InvalidInput);
            CHECK_THROWS_WITH(readImage(dir / name),
                              Catch::Contains(std::string(name) + ": header: " + message) &&
                                  Catch::Contains("--croptofull"));
            CHECK_THROWS_WITH(readImageInfo(dir / name), Catch::Contains(message));
        }
        // The same window both ways, anywhere, is a whole image.
        writeText(dir / "offset.exr", exrWithoutPixels(64, 64, 1, 0, 32, 32));
        CHECK(readImageInfo(dir / "offset.exr").width == 64);
    }

    SECTION("truncated EXR, PNG and TIFF") {
        writeImage(dir / "t.exr", patternImage(64, 64, 3), {PixelType::Float, {}});
        writeImage(dir / "t.png", patternImage(64, 64, 3));
        truncateToHalf(dir / "t.exr");
        truncateToHalf(dir / "t.png");
        CHECK_THROWS_AS(readImage(dir / "t.exr"), ParseError);
        CHECK_THROWS_WITH(readImage(dir / "t.exr"),
                          Catch::Contains((dir / "t.exr").string()) &&
                              Catch::Contains("end of file", Catch::CaseSensitive::No));
        CHECK_THROWS_AS(readImage(dir / "t.png"), ParseError);
        CHECK_THROWS_WITH(readImage(dir / "t.png"), Catch::Contains((dir / "t.png").string()) &&
                                                        Catch::Contains("chunk IDAT") &&
                                                        Catch::Contains("truncated PNG"));
        // A TIFF cut short (libtiff reads what is there and OpenImageIO may report success, the rest left 0):
        // the reader's error counts, naming the pixels.
        writeImage(dir / "t.tif", patternImage(64, 64, 3), {PixelType::Float, {}});
        truncateToHalf(dir / "t.tif");
        CHECK_THROWS_AS(readImage(dir / "t.tif"), ParseError);
        CHECK_THROWS_WITH(readImage(dir / "t.tif"),
                          Catch::Contains((dir / "t.tif").string() + ": pixels: cannot read"));
        // A header read checks the chunks before the pixels (libpng would print its own message first).
        std::string bytes = readText(dir / "t.png");
        writeText(dir / "t.png", bytes.substr(0, bytes.find("IHDR") + 10));
        CHECK_THROWS_WITH(readImageInfo(dir / "t.png"),
                          Catch::Contains("chunk IHDR at byte 8") && Catch::Contains("truncated PNG"));
    }

    SECTION(
        "a PNG whose chunks are whole but whose header or data libpng refuses: one error, nothing on "
        "stderr") {
        // 16 x 4 gray, 8 bits: rows of a filter byte and 16 samples.
        const std::string rows(4 * 17, '\0');
        std::string filtered = rows;
        filtered[17] = 9;  // row 1's filter type
        for (const auto& [bytes, message] :
             {std::pair{pngOf(16, 4, 7, 0, rows),
                        "chunk IHDR: holds a size, bit depth, colour type or method"},
              std::pair{pngOf(0, 4, 8, 0, rows), "chunk IHDR: holds a size"},
              std::pair{pngOf(16, 4, 8, 0, "garbage!!", false), "image data (IDAT): does not inflate"},
              std::pair{pngOf(16, 4, 8, 0, filtered),
                        "image data (IDAT): gives row 1 the filter type 9, beyond 4"},
              std::pair{pngOf(16, 4, 8, 0, rows.substr(0, 40)), "image data (IDAT): inflates to 40 bytes"}}) {
            writeText(dir / "bad.png", bytes);
            CAPTURE(message);
            CHECK_THROWS_AS(readImage(dir / "bad.png"), ParseError);
            CHECK_THROWS_WITH(readImage(dir / "bad.png"),
                              Catch::Contains("bad.png: " + std::string(message)));
            CHECK(stderrOf([&] { (void)readImage(dir / "bad.png"); }).empty());
        }
        // The same rows whole read, interlaced too.
        writeText(dir / "good.png", pngOf(16, 4, 8, 0, rows));
        CHECK(readImage(dir / "good.png").height == 4);
        // Adam7's passes of 16 x 4: 2x1, 2x1, none, 4x1, 8x1, 8x2, 16x2 samples, each row after a filter
        // byte.
        std::string interlaced = pngOf(16, 4, 8, 0, std::string(3 + 3 + 5 + 9 + 2 * 9 + 2 * 17, '\0'));
        interlaced[8 + 8 + 12] = 1;  // IHDR's interlace method; its CRC made again below
        const uLong crc =
            crc32(crc32(0L, Z_NULL, 0), reinterpret_cast<const Bytef*>(interlaced.data() + 12), 17);
        for (int k = 0; k < 4; ++k)
            interlaced[29 + k] = static_cast<char>(crc >> (24 - 8 * k));
        writeText(dir / "adam7.png", interlaced);
        CHECK(readImage(dir / "adam7.png").width == 16);
    }

    SECTION("a PNG with a flipped byte inside its pixel data fails its CRC") {
        writeImage(dir / "c.png", patternImage(64, 64, 3));
        std::string bytes = readText(dir / "c.png");
        const size_t idat = bytes.find("IDAT");
        REQUIRE(idat != std::string::npos);
        bytes[idat + 10] = static_cast<char>(bytes[idat + 10] ^ 0x5a);
        writeText(dir / "c.png", bytes);
        CHECK_THROWS_AS(readImage(dir / "c.png"), ParseError);
        CHECK_THROWS_WITH(readImage(dir / "c.png"), Catch::Contains("chunk IDAT") && Catch::Contains("CRC"));
    }

    SECTION("garbage bytes under an image name") {
        writeText(dir / "g.exr", std::string(300, 'x'));
        writeText(dir / "g.png", "not a picture, just text\n");
        CHECK_THROWS_AS(readImage(dir / "g.exr"), ParseError);
        CHECK_THROWS_WITH(readImage(dir / "g.exr"), Catch::Contains((dir / "g.exr").string()) &&
                                                        Catch::Contains("not an OpenEXR file"));
        CHECK_THROWS_AS(readImage(dir / "g.png"), ParseError);
        CHECK_THROWS_WITH(readImage(dir / "g.png"),
                          Catch::Contains((dir / "g.png").string()) && Catch::Contains("Not a PNG file"));
        CHECK_THROWS_AS(readImageInfo(dir / "g.png"), ParseError);
    }

    SECTION("no stale OpenImageIO error leaks into the next message") {
        // A failed create leaves a pending per-thread error that OpenImageIO appends to later ones.
        const auto leaveStaleError = [&] {
            CHECK_FALSE(OIIO::ImageOutput::create((dir / "stale.unknownformat").string()));
            REQUIRE(OIIO::has_error());
        };
        writeImage(dir / "t.png", patternImage(64, 64, 3));
        truncateToHalf(dir / "t.png");
        writeText(dir / "g.exr", "garbage");
        for (const char* name : {"t.png", "g.exr"}) {
            INFO(name);
            leaveStaleError();
            try {
                (void)readImage(dir / name);
                FAIL("no error");
            } catch (const ParseError& e) {
                CHECK_THAT(e.what(), Catch::Contains(name) && !Catch::Contains("unknownformat"));
            }
        }
        leaveStaleError();
        writeImage(dir / "ok.png", patternImage(2, 2, 1));
        CHECK(readImage(dir / "ok.png").width == 2);
        CHECK_FALSE(OIIO::has_error());
    }

    SECTION("channel count other than expected") {
        writeImage(dir / "rgb.exr", patternImage(4, 4, 3));
        CHECK_THROWS_AS(readImage(dir / "rgb.exr", {1, ""}), InvalidInput);
        CHECK_THROWS_WITH(
            readImage(dir / "rgb.exr", {1, ""}),
            Catch::Contains((dir / "rgb.exr").string() + ": has 3 channels (expected 1 channel)"));
        CHECK_THROWS_WITH(readImage(dir / "rgb.exr", {1, "rigidity map"}),
                          Catch::Contains((dir / "rgb.exr").string() +
                                          ": rigidity map: has 3 channels (expected 1 channel)"));
        CHECK(readImage(dir / "rgb.exr", {3, "colour"}).channels == 3);
    }

    SECTION("unreadable file") {
        writeImage(dir / "locked.png", patternImage(4, 4, 1));
        fs::permissions(dir / "locked.png", fs::perms::none);
        const fs::path locked = dir / "locked.png";
        CHECK(runUnprivileged([&] {
            try {
                (void)readImage(locked);
            } catch (const IoError& e) {
                return std::string(e.what()).find("permission denied") != std::string::npos;
            } catch (...) {
            }
            return false;
        }));
    }
}

TEST_CASE("writeImage rejects what it cannot store faithfully and leaves no file", "[io][image]") {
    TempDir dir;
    using deformkit::InvalidInput;
    const Image img = patternImage(4, 3, 3);

    CHECK_THROWS_AS(writeImage(dir / "e.exr", Image{}), InvalidInput);
    CHECK_THROWS_WITH(writeImage(dir / "e.exr", Image(0, 3, 1)), Catch::Contains("empty image"));
    Image wrongSize = img;
    wrongSize.pixels.pop_back();
    CHECK_THROWS_WITH(writeImage(dir / "w.exr", wrongSize),
                      Catch::Contains("has 35 values") && Catch::Contains("36 = width * height * channels"));

    for (const PixelType type : {PixelType::Half, PixelType::Float}) {
        CHECK_THROWS_AS(writeImage(dir / "a.png", img, {type, {}}), InvalidInput);
    }
    CHECK_THROWS_WITH(writeImage(dir / "a.png", img, {PixelType::Half, {}}),
                      Catch::Contains("a.png") && Catch::Contains("png files cannot store half pixels"));
    CHECK_THROWS_AS(writeImage(dir / "a.exr", img, {PixelType::UInt8, {}}), InvalidInput);
    CHECK_THROWS_AS(writeImage(dir / "a.exr", img, {PixelType::UInt16, {}}), InvalidInput);
    CHECK_THROWS_AS(writeImage(dir / "a.jpg", img, {PixelType::Float, {}}), InvalidInput);
    CHECK_THROWS_AS(writeImage(dir / "five.png", patternImage(2, 2, 5)), InvalidInput);
    // JPEG holds grey or RGB: a second or fourth channel was dropped without a word.
    for (const int32_t channels : {2, 4}) {
        CHECK_THROWS_WITH(writeImage(dir / "a.jpg", patternImage(2, 2, channels)),
                          Catch::Contains("a.jpg: has " + std::to_string(channels) +
                                          " channels (expected 1 or 3 channels in jpeg files"));
    }
    CHECK_FALSE(fs::exists(dir / "a.jpg"));
    for (const int32_t channels : {1, 3}) {
        writeImage(dir / "a.jpg", patternImage(2, 2, channels));
        CHECK(readImage(dir / "a.jpg").channels == channels);
    }
    fs::remove(dir / "a.jpg");  // the checks below count what the refused writes left
    CHECK_THROWS_WITH(writeImage(dir / "a.notaformat", img), Catch::Contains("'.notaformat'"));
    // TIFF keeps only its standard tags: a custom attribute would be lost.
    CHECK_THROWS_WITH(writeImage(dir / "a.tif", img, {PixelType::Auto, {{"deformkit:solver", "x"}}}),
                      Catch::Contains("attribute 'deformkit:solver'") && Catch::Contains("cannot store"));
    // An EXR stores any attribute but one named as its own header's (channels): said so, not "use an EXR".
    CHECK_THROWS_WITH(writeImage(dir / "a.exr", img, {PixelType::Auto, {{"channels", "x"}}}),
                      Catch::Contains("attribute 'channels': is a name the EXR header itself uses") &&
                          Catch::Contains("'studio:channels'"));
    // JPEG 2000 below 32 pixels a side: a 77-byte file no reader opens was written, and reported written.
    for (const auto& [w, h] : {std::pair{16, 64}, std::pair{64, 31}, std::pair{1, 1}}) {
        CHECK_THROWS_WITH(writeImage(dir / "small.jp2", patternImage(w, h, 3)),
                          Catch::Contains("small.jp2: is " + std::to_string(w) + "x" + std::to_string(h) +
                                          " pixels (expected at least 32 pixels a side in jpeg2000 files)"));
    }
    CHECK(folderEntries(dir.path()).empty());
    writeImage(dir / "square.jp2", patternImage(32, 32, 3));
    CHECK(readImage(dir / "square.jp2").width == 32);
    fs::remove(dir / "square.jp2");

    // A rejected write over an existing file leaves it as it was.
    writeImage(dir / "keep.png", img);
    const std::string before = readText(dir / "keep.png");
    CHECK_THROWS_AS(writeImage(dir / "keep.png", patternImage(9, 9, 1), {PixelType::Float, {}}),
                    InvalidInput);
    CHECK(readText(dir / "keep.png") == before);
    CHECK(folderEntries(dir.path()) == std::set<std::string>{"keep.png"});

    // More than 4 channels where the format takes them.
    const Image many = patternImage(3, 2, 12);
    writeImage(dir / "many.exr", many, {PixelType::Float, {}});
    const Image back = readImage(dir / "many.exr");
    REQUIRE(back.channels == 12);
    for (size_t i = 0; i < many.pixels.size(); ++i)
        REQUIRE(back.pixels[i] == many.pixels[i]);
}

TEST_CASE("values beyond half's range are not written as inf", "[io][image]") {
    // The largest finite half is 65504 (binary16: (2 - 2^-10) * 2^15); from 65520, halfway to the next step
    // 65536, values round to inf.
    TempDir dir;
    Image img = patternImage(3, 2, 2);
    img.at(2, 1, 1) = std::nextafter(65520.0f, 0.0f);
    img.at(0, 0, 0) = -std::numeric_limits<float>::infinity();  // not finite: a half holds it as it is
    writeImage(dir / "fits.exr", img);
    CHECK(readImageInfo(dir / "fits.exr").pixelType == "half");
    CHECK(readImage(dir / "fits.exr").at(2, 1, 1) == 65504.0f);
    // Auto: float once a finite value would not fit, so the file holds what was given.
    img.at(2, 1, 1) = 65520.0f;
    writeImage(dir / "beyond.exr", img);
    CHECK(readImageInfo(dir / "beyond.exr").pixelType == "float");
    CHECK(readImage(dir / "beyond.exr").pixels == img.pixels);
    // Half asked for: refused, naming the pixel, in an EXR and a TIFF; nothing is left.
    for (const char* name : {"half.exr", "half.tif"}) {
        CHECK_THROWS_WITH(
            writeImage(dir / name, img, {PixelType::Half, {}}),
            Catch::Contains(std::string(name) + ": pixel (2, 1) channel 1: is 65520, which a half would "
                                                "hold as inf"));
        CHECK_FALSE(fs::exists(dir / name));
    }
    // A band of an EXR written in bands (Auto is half there): refused at its row.
    CHECK_THROWS_WITH(writeImageInBands(dir / "bands.exr", 4, 4, 1, 2,
                                        [](int32_t y0, Image& band) {
                                            if (y0 == 2) band.at(3, 1, 0) = -1e5f;
                                        }),
                      Catch::Contains("bands.exr: pixel (3, 3) channel 0: is -1e+05"));
    CHECK_FALSE(fs::exists(dir / "bands.exr"));
}

TEST_CASE("writeImage replaces a file atomically and fails on a missing or unwritable folder",
          "[io][image]") {
    TempDir dir;
    using deformkit::IoError;
    const fs::path target = dir / "map.exr";
    writeImage(target, patternImage(4, 4, 1));
    writeImage(target, patternImage(6, 2, 2));
    CHECK(readImage(target).width == 6);
    CHECK(folderEntries(dir.path()) == std::set<std::string>{"map.exr"});

    CHECK_THROWS_AS(writeImage(dir / "missing" / "map.exr", patternImage(2, 2, 1)), IoError);
    CHECK_THROWS_WITH(writeImage(dir / "missing" / "map.exr", patternImage(2, 2, 1)),
                      Catch::Contains((dir / "missing").string()) && Catch::Contains("does not exist"));
    CHECK_FALSE(fs::exists(dir / "missing"));

    const std::string before = readText(target);
    fs::permissions(dir.path(), fs::perms::owner_read | fs::perms::owner_exec | fs::perms::group_read |
                                    fs::perms::group_exec | fs::perms::others_read | fs::perms::others_exec);
    const bool rejected = runUnprivileged([&] {
        try {
            writeImage(target, patternImage(8, 8, 3));
        } catch (const IoError& e) {
            return std::string(e.what()).find("not writable") != std::string::npos;
        } catch (...) {
        }
        return false;
    });
    fs::permissions(dir.path(), fs::perms::owner_all);
    CHECK(rejected);
    CHECK(readText(target) == before);
    CHECK(folderEntries(dir.path()) == std::set<std::string>{"map.exr"});
}

TEST_CASE("writeImageInBands writes the bytes writeImage writes, a band at a time", "[io][image]") {
    // The whole image written at once is the reference; bands of 1 row, of a count that does not divide
    // the height (a short last band), and of more rows than the image must give the same file, for an 8-bit
    // PNG and a float EXR. Each band is filled from the reference at the rows it is told.
    TempDir dir;
    const Image img = patternImage(7, 10, 3);
    for (const char* name : {"a.png", "a.exr"}) {
        const ImageWriteOptions options{std::string(name) == "a.exr" ? PixelType::Float : PixelType::Auto,
                                        {}};
        writeImage(dir / (std::string("whole_") + name), img, options);
        const std::string whole = readText(dir / (std::string("whole_") + name));
        for (const int32_t bandRows : {1, 3, 4, 10, 64}) {
            std::vector<int32_t> starts;
            writeImageInBands(
                dir / name, img.width, img.height, img.channels, bandRows,
                [&](int32_t y0, Image& band) {
                    starts.push_back(y0);
                    REQUIRE(band.width == img.width);
                    REQUIRE(band.height == std::min(bandRows, img.height - y0));
                    for (float v : band.pixels)
                        REQUIRE(v == 0.0f);
                    for (int32_t y = 0; y < band.height; ++y)
                        for (int32_t x = 0; x < band.width; ++x)
                            for (int32_t c = 0; c < 3; ++c)
                                band.at(x, y, c) = img.at(x, y0 + y, c);
                },
                options);
            CAPTURE(name, bandRows);
            CHECK(readText(dir / name) == whole);
            std::vector<int32_t> expected;
            for (int32_t y = 0; y < img.height; y += bandRows)
                expected.push_back(y);
            CHECK(starts == expected);
        }
    }
}

TEST_CASE("writeImageInBands refuses bad bands and leaves no file when a band fails", "[io][image]") {
    TempDir dir;
    using deformkit::InvalidInput;
    const auto fillNothing = [](int32_t, Image&) {};
    CHECK_THROWS_WITH(writeImageInBands(dir / "a.png", 4, 4, 3, 0, fillNothing),
                      Catch::Contains("a.png") && Catch::Contains("at least 1 row"));
    CHECK_THROWS_WITH(writeImageInBands(dir / "a.png", 0, 4, 3, 2, fillNothing),
                      Catch::Contains("empty image"));
    CHECK_THROWS_WITH(
        writeImageInBands(dir / "a.png", 4, 4, 3, 2, [](int32_t, Image& band) { band = Image(3, 2, 3); }),
        Catch::Contains("band at row 0") && Catch::Contains("was resized to 3x2 pixels") &&
            Catch::Contains("4x2 pixels, 3 channels"));
    // A band that fails half way (a preview that cannot be read) leaves neither the file nor a temporary.
    CHECK_THROWS_WITH(writeImageInBands(dir / "a.png", 4, 4, 3, 2,
                                        [](int32_t y0, Image&) {
                                            if (y0 > 0) throw deformkit::IoError("preview.png: no such file");
                                        }),
                      Catch::Contains("no such file"));
    CHECK(folderEntries(dir.path()).empty());
    // Over an existing file, the old file stays.
    writeImage(dir / "keep.png", patternImage(4, 4, 3));
    const std::string before = readText(dir / "keep.png");
    CHECK_THROWS_AS(writeImageInBands(dir / "keep.png", 4, 4, 3, 2,
                                      [](int32_t y0, Image&) {
                                          if (y0 > 0) throw deformkit::IoError("stop");
                                      }),
                    deformkit::IoError);
    CHECK(readText(dir / "keep.png") == before);
    CHECK(folderEntries(dir.path()) == std::set<std::string>{"keep.png"});
}
