#include <catch2/catch.hpp>

#include <algorithm>
#include <string>
#include <vector>

#include "deformkit/error.h"
#include "deformkit/io/udim.h"
#include "test_support.h"

using namespace deformkit::io;
using deformkit::test::TempDir;
using deformkit::test::writeText;

namespace {

std::vector<int> tilesOf(const std::vector<UdimFile>& files) {
    std::vector<int> tiles;
    for (const UdimFile& f : files)
        tiles.push_back(f.tile);
    return tiles;
}

std::vector<std::string> namesOf(const std::vector<UdimFile>& files) {
    std::vector<std::string> names;
    for (const UdimFile& f : files)
        names.push_back(f.path.filename().string());
    return names;
}

}  // namespace

TEST_CASE("hasUdimToken recognises the four spellings and nothing else", "[io][udim]") {
    CHECK(hasUdimToken("color.<UDIM>.exr"));
    CHECK(hasUdimToken("color_<UVTILE>.tif"));
    CHECK(hasUdimToken("color.%(UDIM)d.exr"));
    CHECK(hasUdimToken("color._MAPID_.tex"));
    CHECK_FALSE(hasUdimToken("color.1001.exr"));
    CHECK_FALSE(hasUdimToken("color.<UDIM.exr"));
    CHECK_FALSE(hasUdimToken("color.<udim>.exr"));
    CHECK_FALSE(hasUdimToken("color.%(UDIM).exr"));
    CHECK_FALSE(hasUdimToken("color.MAPID.exr"));
    CHECK_FALSE(hasUdimToken(""));
}

TEST_CASE("expandUdim spells each token by hand-computed tiles", "[io][udim]") {
    struct Case {
        int tile;
        const char* number;
        const char* uvTile;
    };
    // u = (tile - 1001) % 10 + 1, v = (tile - 1001) / 10 + 1, worked out by hand.
    const std::vector<Case> cases{
        {1001, "1001", "u1_v1"},  {1002, "1002", "u2_v1"},   {1010, "1010", "u10_v1"},
        {1011, "1011", "u1_v2"},  {1024, "1024", "u4_v3"},   {1100, "1100", "u10_v10"},
        {1101, "1101", "u1_v11"}, {9999, "9999", "u9_v900"},
    };
    for (const Case& c : cases) {
        INFO("tile " << c.tile);
        CHECK(expandUdim("color.<UDIM>.exr", c.tile) == std::string("color.") + c.number + ".exr");
        CHECK(expandUdim("color_<UVTILE>.tif", c.tile) == std::string("color_") + c.uvTile + ".tif");
        CHECK(expandUdim("color.%(UDIM)d.exr", c.tile) == std::string("color.") + c.number + ".exr");
        CHECK(expandUdim("color._MAPID_.tex", c.tile) == std::string("color.") + c.number + ".tex");
    }
}

TEST_CASE("expandUdim replaces every token, including mixed spellings", "[io][udim]") {
    CHECK(expandUdim("/maps/<UDIM>/body.<UDIM>.exr", 1013) == "/maps/1013/body.1013.exr");
    CHECK(expandUdim("body.<UDIM>.<UVTILE>.exr", 1013) == "body.1013.u3_v2.exr");
    CHECK(expandUdim("body_MAPID_%(UDIM)d", 1002) == "body10021002");
}

TEST_CASE("expandUdim rejects patterns without a token and tiles outside 1001..9999", "[io][udim]") {
    CHECK_THROWS_AS(expandUdim("color.1001.exr", 1001), deformkit::InvalidInput);
    CHECK_THROWS_WITH(expandUdim("color.exr", 1001),
                      Catch::Contains("color.exr") && Catch::Contains("no UDIM token"));
    for (const int bad : {1000, 999, 0, -1001, 10000, 10001}) {
        INFO("tile " << bad);
        CHECK_THROWS_AS(expandUdim("color.<UDIM>.exr", bad), deformkit::InvalidInput);
        CHECK_THROWS_WITH(expandUdim("color.<UDIM>.exr", bad),
                          Catch::Contains("tile " + std::to_string(bad)) && Catch::Contains("1001 to 9999"));
    }
    CHECK_NOTHROW(expandUdim("color.<UDIM>.exr", 1011));
    CHECK_NOTHROW(expandUdim("color.<UDIM>.exr", 9999));
}

TEST_CASE("udimOrigin inverts tile = 1001 + u + 10 v", "[io][udim]") {
    CHECK(udimOrigin(1001).u == 0);
    CHECK(udimOrigin(1001).v == 0);
    CHECK(udimOrigin(1012).u == 1);
    CHECK(udimOrigin(1012).v == 1);
    CHECK(udimOrigin(1010).u == 9);
    CHECK(udimOrigin(1010).v == 0);
    CHECK(udimOrigin(1024).u == 3);
    CHECK(udimOrigin(1024).v == 2);
    for (int v = 0; v < 30; ++v) {
        for (int u = 0; u < 10; ++u) {
            const int tile = 1001 + u + 10 * v;
            const TileOrigin o = udimOrigin(tile);
            REQUIRE(o.u == u);
            REQUIRE(o.v == v);
            REQUIRE(expandUdim("<UVTILE>", tile) ==
                    "u" + std::to_string(u + 1) + "_v" + std::to_string(v + 1));
        }
    }
    CHECK_THROWS_AS(udimOrigin(1000), deformkit::InvalidInput);
    CHECK_THROWS_AS(udimOrigin(10000), deformkit::InvalidInput);
}

TEST_CASE("findUdimFiles finds what expandUdim names, sorted by tile, for every token", "[io][udim]") {
    const std::vector<int> tiles{1024, 1001, 1100, 1011, 1002};
    std::vector<int> sorted = tiles;
    std::sort(sorted.begin(), sorted.end());
    for (const char* name :
         {"color.<UDIM>.exr", "color_<UVTILE>.tif", "color.%(UDIM)d.exr", "color._MAPID_.tex"}) {
        INFO(name);
        TempDir dir;
        const auto pattern = dir / name;
        for (const int tile : tiles)
            writeText(expandUdim(pattern.string(), tile), "x");
        const std::vector<UdimFile> found = findUdimFiles(pattern);
        CHECK(tilesOf(found) == sorted);
        for (const UdimFile& f : found)
            CHECK(f.path == std::filesystem::path(expandUdim(pattern.string(), f.tile)));
    }
}

TEST_CASE("findUdimFiles ignores decoys beside the tiles", "[io][udim]") {
    SECTION("numeric token") {
        TempDir dir;
        for (const char* decoy : {"color.0999.exr", "color.1000.exr", "color.10011.exr", "color.101.exr",
                                  "color.1001.exr.bak", "color.1001.tif", "xcolor.1001.exr", "color.100a.exr",
                                  "colorX1002Xexr", "color.1002.EXR", "color..exr", "color.<UDIM>.exr"}) {
            writeText(dir / decoy, "decoy");
        }
        std::filesystem::create_directory(dir / "color.1003.exr");  // a folder, not a file
        writeText(dir / "color.1001.exr", "x");
        writeText(dir / "color.1012.exr", "x");
        const auto found = findUdimFiles(dir / "color.<UDIM>.exr");
        CHECK(namesOf(found) == std::vector<std::string>{"color.1001.exr", "color.1012.exr"});
        CHECK(tilesOf(found) == std::vector<int>{1001, 1012});
    }
    SECTION("<UVTILE>") {
        TempDir dir;
        for (const char* decoy : {"color_u11_v1.exr", "color_u0_v1.exr", "color_u1_v0.exr",
                                  "color_u01_v1.exr", "color_u1_v01.exr", "color_U1_V1.exr", "color_u1v1.exr",
                                  "color_u1_v901.exr", "color_1001.exr"}) {
            writeText(dir / decoy, "decoy");
        }
        writeText(dir / "color_u10_v1.exr", "x");
        writeText(dir / "color_u4_v3.exr", "x");
        writeText(dir / "color_u1_v2.exr", "x");
        const auto found = findUdimFiles(dir / "color_<UVTILE>.exr");
        CHECK(tilesOf(found) == std::vector<int>{1010, 1011, 1024});
        CHECK(namesOf(found) ==
              std::vector<std::string>{"color_u10_v1.exr", "color_u1_v2.exr", "color_u4_v3.exr"});
    }
    SECTION("regular-expression characters in the name are literal") {
        TempDir dir;
        writeText(dir / "map (v2)+[a].1005.exr", "x");
        writeText(dir / "map (v2)+[a]X1006.exr", "decoy");
        writeText(dir / "map v2+a.1007.exr", "decoy");
        writeText(dir / "map (v2)++[a].1008.exr", "decoy");
        CHECK(tilesOf(findUdimFiles(dir / "map (v2)+[a].<UDIM>.exr")) == std::vector<int>{1005});
    }
    SECTION("a digit after <UVTILE> is literal (the v index ends where the pattern's text begins)") {
        TempDir dir;
        writeText(dir / "u2_v11.exr", "x");     // tile u2 v1 then the literal 1: 1002
        writeText(dir / "u2_v121.exr", "x");    // u2 v12: 1112
        writeText(dir / "u2_v1.exr", "decoy");  // no literal 1 left
        CHECK(tilesOf(findUdimFiles(dir / "<UVTILE>1.exr")) == std::vector<int>{1002, 1112});
    }
    SECTION("two tokens must agree") {
        TempDir dir;
        writeText(dir / "1003_u3_v1.exr", "x");
        writeText(dir / "1004_u3_v1.exr", "decoy");
        CHECK(tilesOf(findUdimFiles(dir / "<UDIM>_<UVTILE>.exr")) == std::vector<int>{1003});
    }
}

TEST_CASE("findUdimFiles errors name the pattern and its folder", "[io][udim]") {
    TempDir dir;
    writeText(dir / "other.1001.exr", "x");
    writeText(dir / "color.0999.exr", "decoy");

    CHECK_THROWS_AS(findUdimFiles(dir / "color.1001.exr"), deformkit::InvalidInput);
    CHECK_THROWS_AS(findUdimFiles(dir / "<UDIM>" / "color.exr"), deformkit::InvalidInput);

    const auto missingFolder = dir / "missing" / "color.<UDIM>.exr";
    CHECK_THROWS_AS(findUdimFiles(missingFolder), deformkit::IoError);
    CHECK_THROWS_WITH(findUdimFiles(missingFolder),
                      Catch::Contains((dir / "missing").string()) && Catch::Contains("does not exist"));

    const auto pattern = dir / "color.<UDIM>.exr";
    CHECK_THROWS_AS(findUdimFiles(pattern), deformkit::IoError);
    CHECK_THROWS_WITH(findUdimFiles(pattern),
                      Catch::Contains("UDIM pattern '" + pattern.string() + "' matches no file in '" +
                                      dir.path().string() + "'"));
}
