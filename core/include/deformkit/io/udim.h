#pragma once

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace deformkit::io {

// UDIM path tokens, all replaced by the tile of a UV (tile = 1001 + floor(u) + 10 floor(v)):
//   <UDIM>      1001                   (Mari, Katana, USD, Arnold)
//   <UVTILE>    u1_v1                  (Mudbox/ZBrush: 1-based u and v tile indices)
//   %(UDIM)d    1001                   (Houdini)
//   _MAPID_     1001                   (Mari's older convention, RenderMan)

// True when `pattern` contains one of the tokens above.
[[nodiscard]] bool hasUdimToken(std::string_view pattern);

// Replaces every token in `pattern` by `tile`'s spelling. Throws InvalidInput if `pattern` has no token
// or `tile` is not a valid UDIM (1001..9999 with a u index 0..9).
[[nodiscard]] std::string expandUdim(std::string_view pattern, int tile);

// Tile origin (floor(u), floor(v)) of a UDIM tile number: 1001 -> (0, 0), 1012 -> (1, 1).
struct TileOrigin {
    int u = 0;
    int v = 0;
};
[[nodiscard]] TileOrigin udimOrigin(int tile);

struct UdimFile {
    int tile = 0;
    std::filesystem::path path;
};

// The files that exist for `pattern`, sorted by tile. Throws InvalidInput if the pattern has no token,
// IoError if its folder does not exist or no file matches (naming the pattern and its folder).
[[nodiscard]] std::vector<UdimFile> findUdimFiles(const std::filesystem::path& pattern);

}  // namespace deformkit::io
