#include <cmath>
#include <string>

#include <catch2/catch.hpp>

#include "deformkit/error.h"
#include "deformkit/slide/slider.h"
#include "deformkit/slide/surface.h"
#include "slide_test_support.h"

using namespace deformkit;

namespace {

std::string errorOf(const auto& f) {
    try {
        f();
    } catch (const InvalidInput& e) {
        return e.what();
    }
    return "no error";
}

}  // namespace

TEST_CASE("slide surface: a mesh too large for single precision is an error naming the mesh", "[slide]") {
    // 2 x 2 quads of side 1e20: the bounding-box diagonal (2.8e20) squared overflows a float, so the scale
    // that degenerate triangles are measured against would be infinite.
    const geom::Mesh huge = test::planeGrid(2, 2, 1e20f);
    const std::string direct = errorOf([&] { slide::SlideSurface(huge, "huge.obj"); });
    CHECK_THAT(direct, Catch::StartsWith("huge.obj: bounding box: diagonal"));
    CHECK_THAT(direct, Catch::Contains("overflows single precision"));
    // The slider names its mesh the same way.
    CHECK_THAT(errorOf([&] {
                   slide::Slider(huge, {{4, 1e20}}, {}, "body.obj");
               }),
               Catch::StartsWith("body.obj: bounding box: diagonal"));

    // Below the limit the scale is the bounding-box diagonal: 2 x 2 quads of side 5e17 span 1e18 x 1e18.
    const slide::SlideSurface large(test::planeGrid(2, 2, 5e17f), "large.obj");
    CHECK(large.scale() == Approx(std::sqrt(2.0) * 1e18).epsilon(1e-6));
    CHECK(large.numDegenerateTriangles() == 0);
}
