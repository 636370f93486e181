#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <numbers>

#include <glm/geometric.hpp>

#include "deformkit/error.h"
#include "deformkit/warp/barr_dcc.h"

using namespace deformkit;
using namespace deformkit::warp;

TEST_CASE("Maya twist: start angle at lowBound, end angle at highBound, held beyond", "[barr][host]") {
    MayaTwist maya;
    maya.handleOrigin = {1, 0, 0};
    maya.handleY = {0, 2, 0};  // handle scaled 2 along Y: bounds -1..1 become y in [-2, 2]
    maya.startAngle = 0.0;
    maya.endAngle = std::numbers::pi / 2;
    const AxialSetup setup = fromMayaTwist(maya);
    TwistWarp twist(setup.frame, setup.profile);
    std::vector<glm::vec3> points{{2, 0, 0}, {2, 5, 0}, {2, -3, 0}, {1, 1, 0}};
    SparseFields fields;
    twist.bind(points, fields);
    twist.deform(points);
    // Hand-worked: the offset (1, 0, 0) from the axis turns right-handed about +y by the angle at y.
    const float q = std::numbers::pi_v<float> / 4;
    CHECK(glm::length(points[0] - glm::vec3(1 + std::cos(q), 0, -std::sin(q))) < 1e-5f);  // y = 0: pi/4
    CHECK(glm::length(points[1] - glm::vec3(1, 5, -1)) < 1e-5f);                          // above: pi/2
    CHECK(glm::length(points[2] - glm::vec3(2, -3, 0)) < 1e-5f);                          // below: 0
    CHECK(glm::length(points[3] - glm::vec3(1, 1, 0)) < 1e-6f);                           // on the axis

    MayaTwist bad = maya;
    bad.lowBound = 1.0;
    CHECK_THROWS_WITH(fromMayaTwist(bad), Catch::Contains("Maya twist: lowBound"));
    bad = maya;
    bad.handleY = {0, 0, 0};
    CHECK_THROWS_WITH(fromMayaTwist(bad), Catch::Contains("handle Y axis"));
    bad = maya;
    bad.endAngle = std::numeric_limits<double>::quiet_NaN();
    CHECK_THROWS_WITH(fromMayaTwist(bad), Catch::Contains("endAngle"));
}
