#pragma once

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "deformkit/warp/beier_neely.h"
#include "deformkit/warp/image_warp.h"

// `deformkit warp IMAGE --lines FILE.json --out OUT [--variant global] [--interp bicubic]`: the Beier-Neely
// image warp (paper §4.2, §5.2) as a CLI command; the lines file as scene/feature_lines_file.h reads it (src
// lines in IMAGE, dst lines in OUT).
namespace deformkit::harness {

struct WarpImageCommand {
    std::filesystem::path image;  // source image, any format OpenImageIO reads
    std::filesystem::path lines;  // segment pairs, JSON as above
    std::filesystem::path out;    // written atomically, same size and channels as image
    warp::BeierNeelyVariant variant = warp::BeierNeelyVariant::Original;
    io::SampleFilter interpolation = io::SampleFilter::Bilinear;
};

// Reads IMAGE and the lines file, warps, writes OUT atomically. Throws IoError / ParseError / InvalidInput
// (deformkit::Error) before anything is written.
void warpImageCommand(const WarpImageCommand& command);

}  // namespace deformkit::harness
