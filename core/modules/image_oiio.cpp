// deformkit_image_oiio: the library's image I/O through OpenImageIO, as a module the library loads on its
// first image read or write (io/image_codec.h). It translates calls and nothing more: every check and
// message is the library's.
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cstdint>
#include <memory>
#include <string>

#include "io/image_codec.h"

namespace {

namespace codec = deformkit::io::codec;

std::string typeName(OIIO::TypeDesc type) {
    if (type == OIIO::TypeDesc::UINT8) return "uint8";
    if (type == OIIO::TypeDesc::UINT16) return "uint16";
    if (type == OIIO::TypeDesc::HALF) return "half";
    if (type == OIIO::TypeDesc::FLOAT) return "float";
    return type.c_str();
}

OIIO::TypeDesc typeOf(const std::string& name) {
    return OIIO::TypeDesc(name);  // "uint8", "uint16", "half", "float": OpenImageIO's own names
}

class OiioReader final : public codec::Reader {
  public:
    explicit OiioReader(std::unique_ptr<OIIO::ImageInput> in) : in_(std::move(in)) {
        const OIIO::ImageSpec& s = in_->spec();
        spec_.width = s.width;
        spec_.height = s.height;
        spec_.depth = s.depth;
        spec_.channels = s.nchannels;
        spec_.deep = s.deep;
        spec_.tileWidth = s.tile_width;
        spec_.tileHeight = s.tile_height;
        spec_.x = s.x;
        spec_.y = s.y;
        spec_.fullX = s.full_x;
        spec_.fullY = s.full_y;
        spec_.fullWidth = s.full_width;
        spec_.fullHeight = s.full_height;
        spec_.pixelType = typeName(s.format);
        spec_.channelNames = s.channelnames;
        for (const OIIO::ParamValue& p : s.extra_attribs) {
            if (p.type() == OIIO::TypeString)
                spec_.stringAttributes.emplace_back(p.name().string(), p.get_string());
        }
    }
    const codec::Spec& spec() const override { return spec_; }
    std::string formatName() const override { return in_->format_name(); }
    bool hasAttribute(const std::string& name) const override {
        return in_->spec().find_attribute(name) != nullptr;
    }
    bool readFloats(float* pixels) override {
        // A reader that met an error (a TIFF strip cut short) may still report success, the pixels it could
        // not read left as they were: its pending error counts.
        //
        // OpenImageIO converts a chunk of pixels with an int count: an image of more than 2^31 - 1 values in
        // one strip would overflow it (a crash). Such an image is read in bands of rows below that count.
        const auto rowValues = static_cast<int64_t>(spec_.width) * spec_.channels;
        constexpr int64_t kMostValues = int64_t{1} << 30;
        if (spec_.tileWidth > 0 || rowValues * spec_.height <= kMostValues) {
            return in_->read_image(0, 0, 0, spec_.channels, OIIO::TypeDesc::FLOAT, pixels) &&
                   !in_->has_error();
        }
        const int32_t band = static_cast<int32_t>(std::max<int64_t>(1, kMostValues / rowValues));
        for (int32_t y = 0; y < spec_.height; y += band) {
            const int32_t end = std::min(spec_.height, y + band);
            if (!in_->read_scanlines(0, 0, y, end, 0, 0, spec_.channels, OIIO::TypeDesc::FLOAT,
                                     pixels + static_cast<int64_t>(y) * rowValues) ||
                in_->has_error()) {
                return false;
            }
        }
        return true;
    }
    std::string error() override { return in_->geterror(); }
    void close() override { in_->close(); }

  private:
    std::unique_ptr<OIIO::ImageInput> in_;
    codec::Spec spec_;
};

class OiioWriter final : public codec::Writer {
  public:
    explicit OiioWriter(std::unique_ptr<OIIO::ImageOutput> out) : out_(std::move(out)) {}
    std::string formatName() const override { return out_->format_name(); }
    bool supportsAnyChannelCount() const override { return out_->supports("nchannels") != 0; }
    bool open(const std::string& path, const codec::WriteSpec& ws) override {
        OIIO::ImageSpec spec(ws.width, ws.height, ws.channels, typeOf(ws.pixelType));
        for (const auto& [index, name] : ws.channelNames)
            spec.channelnames[index] = name;
        for (const auto& [name, value] : ws.intAttributes)
            spec.attribute(name, value);
        for (const auto& [name, value] : ws.stringAttributes)
            spec.attribute(name, value);
        return out_->open(path, spec);
    }
    int32_t openedChannels() const override { return out_->spec().nchannels; }
    std::string openedPixelType() const override { return typeName(out_->spec().format); }
    bool writeFloats(const float* pixels) override {
        return out_->write_image(OIIO::TypeDesc::FLOAT, pixels);
    }
    bool writeRows(int32_t yBegin, int32_t yEnd, const float* pixels) override {
        return out_->write_scanlines(yBegin, yEnd, 0, OIIO::TypeDesc::FLOAT, pixels);
    }
    bool close() override { return out_->close(); }
    std::string error() override { return out_->geterror(); }

  private:
    std::unique_ptr<OIIO::ImageOutput> out_;
};

std::unique_ptr<codec::Reader> openReader(const std::string& path, bool keepAlphaAsStored) {
    OIIO::ImageSpec config;
    if (keepAlphaAsStored) config.attribute("oiio:UnassociatedAlpha", 1);
    auto in = OIIO::ImageInput::open(path, &config);
    if (!in) return nullptr;
    return std::make_unique<OiioReader>(std::move(in));
}

std::unique_ptr<codec::Writer> createWriter(const std::string& path) {
    auto out = OIIO::ImageOutput::create(path);
    if (!out) return nullptr;
    return std::make_unique<OiioWriter>(std::move(out));
}

bool hasReaderFor(const std::string& fileName) {
    return OIIO::ImageInput::create(fileName, false) != nullptr;
}

std::string takeGlobalError() {
    return OIIO::geterror();
}

const codec::Codec kCodec{codec::kAbiVersion, &openReader, &createWriter, &hasReaderFor, &takeGlobalError};

}  // namespace

extern "C" __attribute__((visibility("default"))) const codec::Codec* deformkit_image_codec() {
    return &kCodec;
}
