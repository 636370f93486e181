#include "warp_command.h"
#include <iostream>
#include "cli.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "deformkit/error.h"
#include "deformkit/io/file_uses.h"
#include "deformkit/io/image.h"
#include "deformkit/scene/feature_lines_file.h"

namespace deformkit::harness {

namespace fs = std::filesystem;

void warpImageCommand(const WarpImageCommand& command) {
    io::requireFilesApart({{command.out, "the output (--out)", true},
                           {command.image, "the image"},
                           {command.lines, "the lines (--lines)"}});
    const std::vector<warp::SegmentPair> pairs = scene::readFeatureLines(command.lines);
    const io::Image source = io::readImage(command.image);
    if (source.width <= 0 || source.height <= 0) {
        throw InvalidInput(formatError(command.image.string(), "", "has 0 pixels", "a non-empty image"));
    }
    const warp::BeierNeelyWarp warp(pairs, {command.variant});
    std::vector<glm::vec2> map(static_cast<size_t>(source.width) * source.height);
    warp.mapPixelCentres(source.width, source.height, map);
    const io::Image out = warp::resampleImage(source, map, source.width, source.height, command.interpolation,
                                              command.image.string());
    // Written as the source is stored when the output has its format (an identity warp is then a copy: a
    // 16-bit PNG stays 16-bit, a float EXR float); the output format's default otherwise.
    const auto lowercase = [](const fs::path& path) {
        std::string extension = path.extension().string();
        std::ranges::transform(extension, extension.begin(), [](unsigned char c) { return std::tolower(c); });
        return extension;
    };
    io::ImageWriteOptions write;
    if (lowercase(command.out) == lowercase(command.image))
        write.type = io::pixelTypeOf(io::readImageInfo(command.image));
    io::writeImage(command.out, out, write);
}

void addWarpCommand(CommandLine& cli) {
    struct Options {
        WarpImageCommand command;
        std::string image, lines, out, variant = "original", filter = "bilinear";
    };
    auto o = std::make_shared<Options>();
    Command warp = cli.add("warp", "Warp an image with Beier-Neely segment pairs (inverse mapping)", [o] {
        WarpImageCommand& c = o->command;
        c.image = o->image;
        c.lines = o->lines;
        c.out = o->out;
        c.variant =
            o->variant == "global" ? warp::BeierNeelyVariant::Global : warp::BeierNeelyVariant::Original;
        c.interpolation = o->filter == "bicubic" ? io::SampleFilter::Bicubic : io::SampleFilter::Bilinear;
        warpImageCommand(c);
        std::cout << "wrote " << o->out << "\n";
        return 0;
    });
    warp.option("IMAGE", o->image, "source image").required();
    warp.option("--lines", o->lines, "segment pairs, JSON (docs/warps/beier_neely.md)").required();
    warp.option("--out", o->out, "output image, same size and channels").required();
    warp.option("--variant", o->variant, "original or global (no fold-over, paper 5.2)")
        .choices({"original", "global"})
        .showDefault();
    warp.option("--interp", o->filter, "bilinear or bicubic").choices({"bilinear", "bicubic"}).showDefault();
}

}  // namespace deformkit::harness
