// The demo's Ptex-painted slide: the painting, the weights read back, the slide they drive, the files.

#include <catch2/catch.hpp>

#include <cmath>
#include <cstring>
#include <numbers>

#include <glm/geometric.hpp>

#include "deformkit/geom/primitives.h"
#include "deformkit/io/image.h"
#include "deformkit/ptex/ptex_file.h"
#include "deformkit/ptex/ptex_mesh.h"
#include "demo_ptex.h"
#include "demo_slide.h"
#include "test_support.h"

using namespace deformkit;

namespace {

// The demo tube's shape (radius 1, y in [0, 4]) with fewer faces, so the tests stay quick.
geom::Mesh smallTube() {
    geom::CappedTubeOptions options;
    options.segments = 48;
    options.rows = 36;
    options.capRings = 3;
    return geom::makeCappedTube(options);
}

}  // namespace

TEST_CASE("demo ptex: the star is 1 at its centre, 0 away from it, soft in between",
          "[harness][demo][ptex]") {
    const double angle = 0.4, y = 2.0;
    const auto at = [&](double dAngle, double dy) {
        return glm::dvec3(std::cos(angle + dAngle), y + dy, std::sin(angle + dAngle));
    };
    CHECK(harness::demoStar(at(0, 0), angle, y) == 1.0);
    CHECK(harness::demoStar(at(std::numbers::pi, 0), angle, y) == 0.0);
    // Straight up is a point of the star: radius 0.95, edge from 0.65 to 1.25 (smoothstep, 1/2 at 0.95).
    CHECK(harness::demoStar(at(0, 0.6), angle, y) == 1.0);
    CHECK(harness::demoStar(at(0, 0.95), angle, y) == Approx(0.5).margin(1e-12));
    CHECK(harness::demoStar(at(0, 1.3), angle, y) == 0.0);
    // Between two points (36 degrees from straight up) the radius is 0.45: 1/2 there.
    const double between = 36.0 * std::numbers::pi / 180.0;
    CHECK(harness::demoStar(at(-0.45 * std::sin(between), 0.45 * std::cos(between)), angle, y) ==
          Approx(0.5).margin(1e-9));
}

TEST_CASE("demo ptex: the painted file, its weights and the slide they drive", "[harness][demo][ptex]") {
    const geom::Mesh tube = smallTube();
    const harness::DemoPtex demo = harness::makeDemoPtex(tube);
    CHECK_FALSE(demo.mesh.hasUVs());
    REQUIRE(demo.mesh.numVertices() == tube.numVertices());
    CHECK(test::sameBits(demo.mesh.points(), tube.points()));

    // The star is centred on the demo slide's handle; every texel holds the star at its centre's point,
    // computed here from the Ptex convention (quad corners; sub-face corner, midpoints, centre).
    const int32_t peak = harness::makeDemoSlide(demo.mesh).handle.vertex;
    const glm::dvec3 centre(demo.mesh.points()[peak]);
    const double centreAngle = std::atan2(centre.z, centre.x);
    const ptex::PtexMesh pm(demo.mesh);
    REQUIRE(demo.falloff.faces.size() == static_cast<size_t>(pm.numPtexFaces()));
    double worst = 0.0;
    for (int32_t p = 0; p < pm.numPtexFaces(); ++p) {
        const auto face = demo.mesh.face(pm.meshFace(p));
        const auto P = [&](size_t k) { return glm::dvec3(demo.mesh.points()[face[k % face.size()]]); };
        std::array<glm::dvec3, 4> c;
        if (face.size() == 4) {
            c = {P(0), P(1), P(2), P(3)};
        } else {
            const size_t n = face.size(), k = static_cast<size_t>(pm.subFace(p));
            glm::dvec3 mid(0.0);
            for (size_t i = 0; i < n; ++i)
                mid += P(i) / static_cast<double>(n);
            c = {P(k), 0.5 * (P(k) + P(k + 1)), mid, 0.5 * (P(k + n - 1) + P(k))};
        }
        for (int j = 0; j < 8; ++j)
            for (int i = 0; i < 8; ++i) {
                const double u = (i + 0.5) / 8, v = (j + 0.5) / 8;
                const glm::dvec3 x =
                    (1 - u) * (1 - v) * c[0] + u * (1 - v) * c[1] + u * v * c[2] + (1 - u) * v * c[3];
                float texel = 0.0f;
                std::memcpy(&texel, demo.falloff.texels[p].data() + 4 * (j * 8 + i), 4);
                worst = std::max(worst, std::abs(texel - harness::demoStar(x, centreAngle, centre.y)));
            }
    }
    // The same point and the same function in double: float rounding of the texels only.
    CHECK(worst < 1e-6);
    CHECK(demo.weights[peak] > 0.99f);

    // Weight-0 vertices stay exactly where they were; the peak moves; no triangle turns over.
    int32_t still = 0;
    for (int32_t v = 0; v < demo.mesh.numVertices(); ++v) {
        if (demo.weights[v] == 0.0f) {
            ++still;
            CHECK(demo.slid.points()[v] == demo.mesh.points()[v]);
        }
    }
    CHECK(still > demo.mesh.numVertices() / 2);
    CHECK(glm::length(demo.slid.points()[peak] - demo.mesh.points()[peak]) > 0.2f);
    int flipped = 0;
    for (int32_t f = 0; f < demo.mesh.numFaces(); ++f) {
        const auto face = demo.mesh.face(f);
        for (size_t k = 1; k + 1 < face.size(); ++k) {
            const auto normal = [&](const geom::Mesh& m) {
                const glm::vec3 a = m.points()[face[0]], b = m.points()[face[k]], c = m.points()[face[k + 1]];
                return glm::cross(b - a, c - a);
            };
            flipped += glm::dot(normal(demo.mesh), normal(demo.slid)) <= 0.0f ? 1 : 0;
        }
    }
    CHECK(flipped == 0);
}

TEST_CASE("demo ptex: files on disk read back as made", "[harness][demo][ptex]") {
    test::TempDir dir;
    const geom::Mesh tube = smallTube();
    const auto written = harness::writeDemoPtex(tube, dir.path());
    REQUIRE(written.size() == 6);
    const harness::DemoPtex demo = harness::makeDemoPtex(tube);
    const ptex::PtexFile file = ptex::readPtex(dir / "ptex" / "falloff.ptx");
    REQUIRE(file.faces.size() == demo.falloff.faces.size());
    for (size_t f = 0; f < file.faces.size(); ++f)
        CHECK(ptex::expandedTexels(file, f) == ptex::expandedTexels(demo.falloff, f));
    bool hasMesh = false;
    for (const auto& meta : file.metadata)
        hasMesh = hasMesh || meta.key == "PtexFaceVertCounts";
    CHECK(hasMesh);
    const io::ImageInfo info = io::readImageInfo(dir / "ptex" / "ptex.png");
    CHECK(info.width == 2 * 480 + 8);
    CHECK(info.height == 480);
}
