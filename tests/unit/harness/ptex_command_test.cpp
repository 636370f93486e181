// `deformkit ptex ...` and the Ptex options of `slide` and `preview`, in process.

#include <catch2/catch.hpp>

#include <cstring>
#include <limits>
#include <map>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include "commands.h"
#include "deformkit/error.h"
#include "deformkit/geom/primitives.h"
#include "deformkit/io/image.h"
#include "deformkit/io/obj.h"
#include "deformkit/ptex/ptex_mesh.h"
#include "deformkit/scene/weights_file.h"
#include "ptex/ptex_mesh_support.h"
#include "ptex_command.h"
#include "slide_command.h"
#include "test_support.h"

using namespace deformkit;
using Catch::Contains;

namespace {

// An 8 x 8 quad grid over [0, 2]^2 (UVs over [0, 1]^2, tile 1001) and a 2-channel file of constant faces:
// face p holds (p / 64, 1 - p / 64).
struct Fixture {
    test::TempDir dir;
    geom::Mesh mesh = geom::makeGrid({8, 8, 2.0f, 2.0f});
    Fixture() {
        io::writeObj(dir / "grid.obj", mesh);
        ptex::WriteOptions options;
        options.mesh = ptex::meshData(mesh);
        ptex::writePtex(
            dir / "paint.ptx",
            test::constantFaces(ptex::PtexMesh(mesh), 2, 2,
                                [](int32_t p, int32_t c) { return c == 0 ? p / 64.0f : 1 - p / 64.0f; }),
            options);
    }
    // Channel c at each vertex by hand: the mean over the faces that use it.
    [[nodiscard]] std::vector<double> expected(int c) const {
        std::map<int32_t, std::vector<double>> faces;
        for (int32_t f = 0; f < mesh.numFaces(); ++f)
            for (int32_t v : mesh.face(f))
                faces[v].push_back(c == 0 ? f / 64.0 : 1 - f / 64.0);
        std::vector<double> out(static_cast<size_t>(mesh.numVertices()));
        for (const auto& [v, list] : faces) {
            for (double x : list)
                out[v] += x / static_cast<double>(list.size());
        }
        return out;
    }
};

}  // namespace

TEST_CASE("ptex command: info lists the header, resolutions, flags and metadata", "[harness][ptex]") {
    Fixture f;
    ptex::PtexFile file = ptex::readPtex(f.dir / "paint.ptx");
    file.faces[5].ulog2 = 3;  // one 8 x 4 face, the others constant 4 x 4
    file.texels[5].resize(32 * 2 * 4);
    for (size_t i = 0; i < 64; ++i) {  // varying values: not a constant face
        const float value = static_cast<float>(i) / 64.0f;
        std::memcpy(file.texels[5].data() + 4 * i, &value, 4);
    }
    file.metadata.push_back(ptex::MetaValue::ofString("author", "painter"));
    ptex::writePtex(f.dir / "mixed.ptx", file);
    std::ostringstream out;
    harness::ptexInfo(f.dir / "mixed.ptx", out);
    const std::string text = out.str();
    CHECK_THAT(text, Contains("data        float x 2 channels"));
    CHECK_THAT(text, Contains("faces       64 (constant 63, sub-faces 0, edited 0)"));
    CHECK_THAT(text, Contains("resolution  4x4: 63 faces"));
    CHECK_THAT(text, Contains("resolution  8x4: 1 faces"));
    CHECK_THAT(text, Contains("metadata    author = string \"painter\""));
    CHECK_THAT(text, Contains("metadata    PtexFaceVertCounts = int32 x 64") && Contains("mesh data   yes"));
    ptex::writePtex(f.dir / "bare.ptx",
                    test::constantFaces(ptex::PtexMesh(f.mesh), 1, 0, [](int32_t, int32_t) { return 0.5f; }));
    std::ostringstream bare;
    harness::ptexInfo(f.dir / "bare.ptx", bare);
    CHECK_THAT(bare.str(), Contains("resolution  1x1: 64 faces") && Contains("mesh data   no"));
}

TEST_CASE("ptex command: to-vertex writes each vertex's mean over its faces as a weights file",
          "[harness][ptex]") {
    Fixture f;
    for (int channel : {0, 1}) {
        harness::PtexToVertexCommand command{f.dir / "paint.ptx", f.dir / "grid.obj", f.dir / "w.json",
                                             channel};
        CHECK(harness::ptexToVertexCommand(command) == 81u);
        const nlohmann::json json = nlohmann::json::parse(test::readText(f.dir / "w.json"));
        const std::vector<double> expected = f.expected(channel);
        REQUIRE(json.size() == expected.size());
        for (size_t v = 0; v < expected.size(); ++v)
            CHECK(json[v].get<double>() == Approx(expected[v]).margin(1e-7));  // float means of exact values
        // The file is the weights format every command reads: the same floats come back.
        const std::vector<float> read = scene::readWeightsFile(f.dir / "w.json", 81);
        for (size_t v = 0; v < expected.size(); ++v)
            CHECK(read[v] == json[v].get<float>());
    }
    harness::PtexToVertexCommand bad{f.dir / "paint.ptx", f.dir / "grid.obj", f.dir / "w.json", 2};
    CHECK_THAT(test::errorOf<InvalidInput>([&] { (void)harness::ptexToVertexCommand(bad); }),
               Contains("paint.ptx") && Contains("channel 2"));
}

TEST_CASE("ptex command: a map of another mesh is refused, naming the file and both face counts",
          "[harness][ptex]") {
    Fixture f;
    io::writeObj(f.dir / "small.obj", geom::makeGrid({2, 2, 1.0f, 1.0f}));
    harness::PtexToVertexCommand command{f.dir / "paint.ptx", f.dir / "small.obj", f.dir / "w.json", 0};
    const std::string message =
        test::errorOf<InvalidInput>([&] { (void)harness::ptexToVertexCommand(command); });
    CHECK_THAT(message, Contains("paint.ptx") && Contains("has 64 faces") && Contains("4 Ptex faces"));
    CHECK_FALSE(std::filesystem::exists(f.dir / "w.json"));
}

TEST_CASE("ptex command: slide and preview take Ptex weights like the same weights from a file",
          "[harness][ptex]") {
    Fixture f;
    harness::PtexToVertexCommand toVertex{f.dir / "paint.ptx", f.dir / "grid.obj", f.dir / "w.json", 0};
    (void)harness::ptexToVertexCommand(toVertex);
    harness::SlideCommand slide;
    slide.mesh = f.dir / "grid.obj";
    slide.handle = {40, 0.8, slide::RegionMetric::Geodesic};  // the centre vertex
    slide.from = {1, 1, 0};
    slide.to = {1.25, 1.125, 0};
    slide.weights = f.dir / "w.json";
    slide.out = f.dir / "json.obj";
    (void)harness::slideCommand(slide);
    slide.weights.reset();
    slide.weightsPtex = f.dir / "paint.ptx";
    slide.out = f.dir / "ptex.obj";
    (void)harness::slideCommand(slide);
    // The JSON holds the shortest text of each float, so both runs get the same weights: the same bytes.
    CHECK(test::readText(f.dir / "json.obj") == test::readText(f.dir / "ptex.obj"));
    CHECK(test::readText(f.dir / "ptex.obj") != test::readText(f.dir / "grid.obj"));
    slide.weights = f.dir / "w.json";
    CHECK_THAT(test::errorOf<InvalidInput>([&] { (void)harness::slideCommand(slide); }),
               Contains("--weights-ptex") && Contains("--weights"));

    harness::PreviewCommand preview;
    preview.mesh = f.dir / "grid.obj";
    preview.options.width = preview.options.height = 64;
    preview.weights = f.dir / "w.json";
    preview.out = f.dir / "json.png";
    harness::preview(preview);
    preview.weights.reset();
    preview.weightsPtex = f.dir / "paint.ptx";
    preview.out = f.dir / "ptex.png";
    harness::preview(preview);
    CHECK(test::readText(f.dir / "json.png") == test::readText(f.dir / "ptex.png"));
}

TEST_CASE("ptex command: from-udim then to-udim gives back a linear painting", "[harness][ptex]") {
    // A painting linear in UV survives both conversions up to float rounding away from the mesh's border
    // (within one Ptex texel of it the look-ups clamp: first order there). The grid's UVs cover the whole
    // tile, so the border band is one Ptex texel (1/64 of the tile) wide.
    Fixture f;
    const int res = 64;
    io::Image image(res, res, 1);
    const auto paint = [](double u, double v) { return 0.25 + 0.5 * u - 0.125 * v; };
    for (int y = 0; y < res; ++y)
        for (int x = 0; x < res; ++x)
            image.at(x, y, 0) = static_cast<float>(paint((x + 0.5) / res, 1.0 - (y + 0.5) / res));
    io::writeImage(f.dir / "paint.1001.exr", image, {io::PixelType::Float, {}});
    harness::PtexFromUdimCommand from;
    from.pattern = (f.dir / "paint.<UDIM>.exr").string();
    from.mesh = f.dir / "grid.obj";
    from.out = f.dir / "from.ptx";
    from.faceLog2 = harness::parseFaceResolution("8");
    harness::ptexFromUdimCommand(from);
    const ptex::PtexFile file = ptex::readPtex(f.dir / "from.ptx");
    CHECK(file.faces.size() == 64);
    CHECK(file.faces[0].ures() == 8);

    harness::PtexToUdimCommand to;
    to.ptex = f.dir / "from.ptx";
    to.mesh = f.dir / "grid.obj";
    to.out = (f.dir / "back.<UDIM>.exr").string();
    to.resolution = res;
    const auto written = harness::ptexToUdimCommand(to);
    REQUIRE(written.size() == 1);
    const io::Image back = io::readImage(written[0]);
    double worst = 0.0;
    for (int y = 1; y < res - 1; ++y)
        for (int x = 1; x < res - 1; ++x)
            worst =
                std::max(worst, std::abs(back.at(x, y, 0) - paint((x + 0.5) / res, 1.0 - (y + 0.5) / res)));
    CHECK(worst < 1e-4);  // float texels and float EXRs: rounding of values below 1

    CHECK(harness::parsePtexType("half") == ptex::DataType::Half);
    CHECK_THAT(test::errorOf<InvalidInput>([] { (void)harness::parsePtexType("f64"); }), Contains("--type"));
    CHECK(harness::parseFaceResolution("auto") == -1);
    CHECK(harness::parseFaceResolution("1") == 0);
    CHECK_THAT(test::errorOf<InvalidInput>([] { (void)harness::parseFaceResolution("12"); }),
               Contains("--face-res") && Contains("power of two"));
    to.out = (f.dir / "back.exr").string();
    CHECK_THAT(test::errorOf<InvalidInput>([&] { (void)harness::ptexToUdimCommand(to); }),
               Contains("--out") && Contains("UDIM"));
}

TEST_CASE("ptex command: from-vertex bakes weights that interpolate the face's corners", "[harness][ptex]") {
    // Weights w = x / 2 (linear over the [0, 2]^2 grid): each texel of a unit-square face holds the
    // bilinear blend of its corners' weights, which for a linear field is w at the texel centre.
    Fixture f;
    std::string json = "[";
    for (int32_t v = 0; v < f.mesh.numVertices(); ++v)
        json += (v ? ", " : "") + std::to_string(f.mesh.points()[v].x / 2.0);
    test::writeText(f.dir / "w.json", json + "]");
    harness::PtexFromVertexCommand command{f.dir / "w.json", f.dir / "grid.obj", f.dir / "w.ptx",
                                           harness::parseFaceResolution("4"), ptex::DataType::Float};
    harness::ptexFromVertexCommand(command);
    const ptex::PtexFile file = ptex::readPtex(f.dir / "w.ptx");
    REQUIRE(file.faces.size() == 64);
    double worst = 0.0;
    for (int32_t face = 0; face < 64; ++face) {
        const auto c = f.mesh.face(face);
        const auto P = [&](int k) { return glm::dvec3(f.mesh.points()[c[k]]); };
        const std::vector<uint8_t> texels = ptex::expandedTexels(file, static_cast<size_t>(face));
        for (int j = 0; j < 4; ++j)
            for (int i = 0; i < 4; ++i) {
                float value = 0.0f;
                std::memcpy(&value, texels.data() + 4 * (j * 4 + i), 4);
                const double u = (i + 0.5) / 4, v = (j + 0.5) / 4;  // the texel centre on the quad
                const glm::dvec3 at =
                    (1 - u) * (1 - v) * P(0) + u * (1 - v) * P(1) + u * v * P(2) + (1 - u) * v * P(3);
                worst = std::max(worst, std::abs(value - at.x / 2.0));
            }
    }
    CHECK(worst < 1e-6);  // float texels and the weights' 6-digit text
    CHECK_THAT(test::errorOf<InvalidInput>([&] {
                   command.faceLog2 = -1;
                   harness::ptexFromVertexCommand(command);
               }),
               Contains("--face-res"));
}

TEST_CASE("ptex command: bad outputs and inputs are refused before anything is written", "[harness][ptex]") {
    Fixture f;
    const std::string before = test::readText(f.dir / "paint.ptx");
    SECTION("to-vertex writes only a .json weights file: a Ptex or mesh named as --out is left alone") {
        for (const char* name : {"paint.ptx", "grid.obj", "weights.txt"}) {
            const harness::PtexToVertexCommand command{f.dir / "paint.ptx", f.dir / "grid.obj", f.dir / name,
                                                       0};
            CHECK_THAT(test::errorOf<InvalidInput>([&] { (void)harness::ptexToVertexCommand(command); }),
                       Contains("--out: is '") && Contains(name) &&
                           Contains("(expected a weights file name ending in .json)"));
        }
        CHECK(test::readText(f.dir / "paint.ptx") == before);
        CHECK(io::readObj(f.dir / "grid.obj").mesh.numVertices() == f.mesh.numVertices());
        const harness::PtexToVertexCommand upper{f.dir / "paint.ptx", f.dir / "grid.obj", f.dir / "W.JSON",
                                                 0};
        CHECK(harness::ptexToVertexCommand(upper) == static_cast<size_t>(f.mesh.numVertices()));
    }
    SECTION("from-udim refuses a NaN or infinite texel, naming the image, the texel and the channel") {
        for (const float bad : {std::nanf(""), std::numeric_limits<float>::infinity()}) {
            io::Image image(16, 16, 2, 0.5f);
            image.at(5, 3, 1) = bad;
            io::writeImage(f.dir / "bad.1001.exr", image, {io::PixelType::Float, {}});
            harness::PtexFromUdimCommand from;
            from.pattern = (f.dir / "bad.<UDIM>.exr").string();
            from.mesh = f.dir / "grid.obj";
            from.out = f.dir / "bad.ptx";
            CHECK_THAT(test::errorOf<InvalidInput>([&] { (void)harness::ptexFromUdimCommand(from); }),
                       Contains("bad.1001.exr: texel (5, 3) channel 1: is ") &&
                           Contains("(expected a finite value)"));
            CHECK_FALSE(std::filesystem::exists(f.dir / "bad.ptx"));
        }
    }
    SECTION("to-udim refuses a tile the mesh has no UV face in (it would be written blank)") {
        harness::PtexToUdimCommand to;
        to.ptex = f.dir / "paint.ptx";
        to.mesh = f.dir / "grid.obj";
        to.out = (f.dir / "t.<UDIM>.exr").string();
        to.resolution = 16;
        to.tiles = {1001, 1002};
        CHECK_THAT(test::errorOf<InvalidInput>([&] { (void)harness::ptexToUdimCommand(to); }),
                   Contains("tile 1002: the mesh '") && Contains("(expected tiles of the mesh: 1001)"));
        CHECK_FALSE(std::filesystem::exists(f.dir / "t.1001.exr"));
    }
    SECTION("--face-res offers auto only where it is taken") {
        CHECK_THAT(test::errorOf<InvalidInput>([] { (void)harness::parseFaceResolution("0", false); }),
                   Contains("(expected a power of two from 1 to 32768") && !Contains("auto"));
        CHECK_THAT(test::errorOf<InvalidInput>([] { (void)harness::parseFaceResolution("auto", false); }),
                   Contains("is 'auto'"));
        CHECK_THAT(test::errorOf<InvalidInput>([] { (void)harness::parseFaceResolution("0"); }),
                   Contains("(expected auto or a power of two"));
    }
}

TEST_CASE("ptex command: to-udim writes an EXR with the map's precision", "[harness][ptex]") {
    // Values a half float cannot hold (1000.3 rounds to 1000.5 in half, 1e5 overflows it) come back exactly
    // from a float map; a half map's EXR is half.
    Fixture f;
    for (const ptex::DataType type : {ptex::DataType::Float, ptex::DataType::Half}) {
        if (type == ptex::DataType::Float) {
            ptex::WriteOptions options;
            options.mesh = ptex::meshData(f.mesh);
            ptex::writePtex(f.dir / "big.ptx",
                            test::constantFaces(ptex::PtexMesh(f.mesh), 1, 2,
                                                [](int32_t p, int32_t) { return p < 32 ? 1000.3f : 1e5f; }),
                            options);
        } else {  // a half map baked from weights of 0.25
            std::string json = "[0.25";
            for (int32_t v = 1; v < f.mesh.numVertices(); ++v)
                json += ", 0.25";
            test::writeText(f.dir / "w.json", json + "]");
            harness::ptexFromVertexCommand(
                {f.dir / "w.json", f.dir / "grid.obj", f.dir / "big.ptx", 2, type});
        }
        harness::PtexToUdimCommand to;
        to.ptex = f.dir / "big.ptx";
        to.mesh = f.dir / "grid.obj";
        to.out = (f.dir / "big.<UDIM>.exr").string();
        to.resolution = 32;
        const auto written = harness::ptexToUdimCommand(to);
        REQUIRE(written.size() == 1);
        CHECK(io::readImageInfo(written[0]).pixelType == (type == ptex::DataType::Float ? "float" : "half"));
        const io::Image image = io::readImage(written[0]);
        std::set<float> values(image.pixels.begin(), image.pixels.end());
        if (type == ptex::DataType::Float) {
            CHECK(values.count(1000.3f) == 1);
            CHECK(values.count(1e5f) == 1);
        } else {
            CHECK(values.count(0.25f) == 1);
        }
    }
}
