#pragma once
// The pictures of a shot report's tile at its worst frame (html_report.h), made again from the files the
// frame's redirect map names in its header, or from a host's callbacks.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "deformkit/uvwarp/html_report.h"
#include "deformkit/uvwarp/redirect_metrics.h"

namespace deformkit::uvwarp::detail {

struct ReportPicture {
    std::string caption;
    io::Image image;  // RGB, at most kReportPictureSide per side
};

// The largest side of a full-size picture: a 16K tile's pictures are box-filtered down to it.
inline constexpr int32_t kReportPictureSide = 2048;

struct TilePictures {
    std::vector<ReportPicture> pictures;         // remaining stretch, identity stretch, plain, warped
    std::optional<DeliveredMetrics> remeasured;  // the worst frame measured again from its files
    nlohmann::json header;           // the map's provenance (inputs, solver, version); null when not read
    std::vector<std::string> notes;  // what could not be made, and why
};

// Where a name from a log or a header is: as it is, then in each of `folders`; nullopt when nowhere.
[[nodiscard]] std::optional<std::filesystem::path> findFile(
    const std::string& name, const std::vector<std::filesystem::path>& folders);

// The pictures of `series` at its worst frame; `folders` are where relative names are looked for.
[[nodiscard]] TilePictures tilePictures(const ShotTileSeries& series, const HtmlReportOptions& options,
                                        std::vector<std::filesystem::path> folders);

// An image box-filtered by the smallest whole factor that brings its longest side to at most `side`.
[[nodiscard]] io::Image shrinkTo(const io::Image& image, int32_t side);

}  // namespace deformkit::uvwarp::detail
