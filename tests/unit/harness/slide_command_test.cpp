#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <sstream>

#include <glm/geometric.hpp>

#include "deformkit/error.h"
#include "deformkit/io/obj.h"
#include "slide_command.h"
#include "test_support.h"

using namespace deformkit;

namespace {

// An n x n grid of unit-spaced quads scaled by h at z = 0, with UVs and two groups, as OBJ text.
// Vertex (i, j) = j (n + 1) + i sits at (i h, j h, 0).
std::string gridObj(int n, double h) {
    std::ostringstream out;
    out.precision(9);
    for (int j = 0; j <= n; ++j)
        for (int i = 0; i <= n; ++i)
            out << "v " << i * h << " " << j * h << " 0\n";
    for (int j = 0; j <= n; ++j)
        for (int i = 0; i <= n; ++i)
            out << "vt " << static_cast<double>(i) / n << " " << static_cast<double>(j) / n << "\n";
    for (int j = 0; j < n; ++j) {
        if (j == 0) out << "g bottom\n";
        if (j == n / 2) out << "g top\n";
        for (int i = 0; i < n; ++i) {
            const int a = j * (n + 1) + i + 1;  // 1-based
            const int c[4] = {a, a + 1, a + n + 2, a + n + 1};
            out << "f";
            for (int k : c)
                out << " " << k << "/" << k;
            out << "\n";
        }
    }
    return out.str();
}

double smoothFalloff(double x) {
    return x >= 1.0 ? 0.0 : 1.0 - x * x * (3.0 - 2.0 * x);
}

}  // namespace

TEST_CASE("slide command: points and falloffs parse, bad text names the option", "[harness][slide]") {
    CHECK(harness::parsePoint("1,-2.5,3e-1", "--from") == glm::dvec3(1.0, -2.5, 0.3));
    CHECK(harness::parsePoint(" 1, 2 ,3", "--to") == glm::dvec3(1.0, 2.0, 3.0));
    CHECK_THAT(test::errorOf<Error>([] { (void)harness::parsePoint("1,2", "--from"); }),
               Catch::Contains("--from") && Catch::Contains("'1,2' is not a point"));
    CHECK_THAT(test::errorOf<Error>([] { (void)harness::parsePoint("1,2,x", "--to"); }),
               Catch::Contains("--to"));
    CHECK_THAT(test::errorOf<Error>([] { (void)harness::parsePoint("1,2,nan", "--to"); }),
               Catch::Contains("three finite numbers"));
    CHECK_THAT(test::errorOf<Error>([] { (void)harness::parsePoint("1,,2,3", "--to"); }),
               Catch::Contains("not a point"));
    // Decimal only: strtod read a hexadecimal float ("0x1" as 1) and "infinity" words.
    CHECK(harness::parsePoint("+0.5,1e2, -3", "--to") == glm::dvec3(0.5, 100.0, -3.0));
    for (const char* text : {"0x1,0,0", "1,0x1p3,0", "inf,0,0", "1,2,3,"}) {
        INFO(text);
        CHECK_THAT(test::errorOf<Error>([&] { (void)harness::parsePoint(text, "--from"); }),
                   Catch::Contains("is not a point"));
    }

    CHECK(harness::parseFalloff("smooth").isSmooth());
    // The linear curve and a ramp: values at x = 0.25 against 1 - x and the samples' interpolation.
    CHECK(harness::parseFalloff("linear")(0.25) == Approx(0.75).margin(1e-12));
    CHECK(harness::parseFalloff("1,1,0")(0.75) == Approx(0.5).margin(1e-7));  // float samples
    CHECK_THAT(test::errorOf<Error>([] { (void)harness::parseFalloff("cubic"); }),
               Catch::Contains("--falloff") && Catch::Contains("'cubic' is not a falloff"));
    CHECK_THAT(test::errorOf<Error>([] { (void)harness::parseFalloff("1,2,0"); }),
               Catch::Contains("--falloff"));
    CHECK_THAT(test::errorOf<Error>([] { (void)harness::parseFalloff("1"); }), Catch::Contains("--falloff"));
}

TEST_CASE("slide command: slides an OBJ plane by d times the falloff, keeping UVs and groups",
          "[harness][slide]") {
    test::TempDir dir;
    const int n = 20;
    const double h = 0.05;
    test::writeText(dir / "grid.obj", gridObj(n, h));
    test::writeText(dir / "w.json", [&] {
        std::string text = "[";  // weight 0.5 on every vertex
        for (int v = 0; v < (n + 1) * (n + 1); ++v)
            text += (v ? ", " : "") + std::string("0.5");
        return text + "]";
    }());
    harness::SlideCommand command;
    command.mesh = dir / "grid.obj";
    command.out = dir / "out.obj";
    command.handle = {10 * 21 + 10, 0.3};  // (0.5, 0.5)
    command.from = {1.0, 1.0, 1.0};
    command.to = {1.08, 0.96, 1.0};
    command.weights = dir / "w.json";
    command.envelope = 0.5f;
    const slide::SlideResult result = harness::slideCommand(command);

    const io::ObjContent in = io::readObj(command.mesh), out = io::readObj(command.out);
    REQUIRE(out.mesh.numVertices() == in.mesh.numVertices());
    // Closed form on a plane (docs/decisions.md SL-8): P + weight * envelope * falloff(|P - P0| / r) * (to -
    // from). Tolerance: float positions of a unit plane, a few ulps.
    const glm::dvec3 d = command.to - command.from, p0(in.mesh.points()[command.handle.vertex]);
    double worst = 0.0;
    int expectedMoved = 0;
    for (int32_t v = 0; v < in.mesh.numVertices(); ++v) {
        const glm::dvec3 p(in.mesh.points()[v]);
        const double f = smoothFalloff(glm::length(p - p0) / 0.3);
        expectedMoved += f > 1e-6 ? 1 : 0;
        worst = std::max(worst, glm::length(glm::dvec3(out.mesh.points()[v]) - (p + 0.25 * f * d)));
    }
    CHECK(worst < 2e-6);
    CHECK(std::abs(result.moved - expectedMoved) <=
          4);  // vertices at the very edge (f ~ 0) may go either way
    CHECK(result.boundaryStopped == 0);
    // UVs and groups pass through unchanged.
    REQUIRE(out.mesh.numUVs() == in.mesh.numUVs());
    CHECK(std::equal(out.mesh.uvs().begin(), out.mesh.uvs().end(), in.mesh.uvs().begin()));
    CHECK(std::equal(out.mesh.uvIndices().begin(), out.mesh.uvIndices().end(), in.mesh.uvIndices().begin()));
    REQUIRE(out.groups.size() == 2);
    CHECK(out.groups[1].name == "top");
    CHECK(out.groups[1].faces == in.groups[1].faces);

    CHECK(harness::slideSummary("o.obj", result) ==
          "wrote o.obj: moved " + std::to_string(result.moved) +
              ", limited 0 (boundary-stopped 0, walk-limit-stopped 0), flipped triangles 0, unreachable 0, "
              "without a tangent plane 0, degenerate triangles 0");
}

TEST_CASE("slide command: bad input is an error naming it, and nothing is written",
          "[harness][slide][errors]") {
    test::TempDir dir;
    test::writeText(dir / "grid.obj", gridObj(4, 0.25));
    test::writeText(dir / "w.json", "[1, 1, 1]");
    harness::SlideCommand command;
    command.mesh = dir / "grid.obj";
    command.out = dir / "out.obj";
    command.handle = {25, 0.5};
    command.to = {0.1, 0.0, 0.0};
    CHECK_THAT(
        test::errorOf<Error>([&] { (void)harness::slideCommand(command); }),
        Catch::Contains("grid.obj") && Catch::Contains("vertex 25") && Catch::Contains("out of range"));
    command.handle.vertex = 12;
    command.weights = dir / "w.json";
    CHECK_THAT(test::errorOf<Error>([&] { (void)harness::slideCommand(command); }),
               Catch::Contains("w.json") && Catch::Contains("has 3 weights") &&
                   Catch::Contains("25, one per vertex"));
    command.weights = dir / "missing.json";
    CHECK_THROWS_AS(harness::slideCommand(command), IoError);
    command.weights.reset();
    command.mesh = dir / "nope.obj";
    CHECK_THROWS_AS(harness::slideCommand(command), IoError);
    CHECK_FALSE(std::filesystem::exists(command.out));
}
