#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>

#include <glm/geometric.hpp>

#include "deformkit/geom/bvh.h"
#include "deformkit/geom/primitives.h"
#include "deformkit/io/image.h"
#include "deformkit/io/obj.h"
#include "demo_slide.h"
#include "test_support.h"

using namespace deformkit;

namespace {

constexpr double kPi = std::numbers::pi;

// Distance from (x, z) to the side of the regular `segments`-gon of radius 1 (corners at angles 2 pi k / s),
// measured to the edge line of the sector the point's angle falls in: the demo tube's side in closed form.
double distanceToPrismSide(const glm::dvec3& p, int segments) {
    const double delta = 2.0 * kPi / segments;
    double angle = std::atan2(p.z, p.x);
    if (angle < 0.0) angle += 2.0 * kPi;
    const double mid = (std::floor(angle / delta) + 0.5) * delta;
    return std::abs(p.x * std::cos(mid) + p.z * std::sin(mid) - std::cos(delta / 2.0));
}

// Arc length along the polygon from angle 0 to the point's angle (the side unrolled).
double unrolled(const glm::dvec3& p, int segments) {
    const double delta = 2.0 * kPi / segments;
    const double chord = 2.0 * std::sin(delta / 2.0);
    double angle = std::atan2(p.z, p.x);
    if (angle < 0.0) angle += 2.0 * kPi;
    const double whole = std::floor(angle / delta);
    const glm::dvec3 corner(std::cos(whole * delta), p.y, std::sin(whole * delta));
    return whole * chord + glm::length(p - corner);
}

}  // namespace

TEST_CASE("demo slide: files exist and every slid vertex lies on the rest tube", "[harness][demo][slide]") {
    test::TempDir dir;
    const geom::Mesh tube = geom::makeCappedTube();  // the demo's tube: 160 segments, 120 rows
    const auto files = harness::writeDemoSlide(tube, dir.path());
    for (const char* name :
         {"tube_slid.obj", "checker.1001.png", "checker.1002.png", "before.png", "after.png", "slide.png"}) {
        INFO(name);
        CHECK(std::filesystem::file_size(dir / ("slide/" + std::string(name))) > 1000);
    }
    CHECK(files.size() == 6);
    const io::Image sheet = io::readImage(dir / "slide/slide.png");
    CHECK(sheet.width == 2 * 480 + 8);
    CHECK(sheet.height == 480);

    const geom::Mesh slid = io::readObj(dir / "slide/tube_slid.obj").mesh;
    REQUIRE(slid.numVertices() == tube.numVertices());
    const geom::Bvh bvh(tube);
    double worstBvh = 0.0, worstPrism = 0.0, largestMove = 0.0;
    int moved = 0;
    for (int32_t v = 0; v < tube.numVertices(); ++v) {
        const glm::vec3 p = slid.points()[v];
        if (p == tube.points()[v]) continue;
        ++moved;
        largestMove = std::max(largestMove, static_cast<double>(glm::length(p - tube.points()[v])));
        worstBvh = std::max(worstBvh, static_cast<double>(bvh.closestPoint(p).distance));
        worstPrism = std::max(worstPrism, distanceToPrismSide(glm::dvec3(p), 160));
    }
    INFO("moved " << moved << ", largest move " << largestMove << ", to the tube (BVH) " << worstBvh
                  << ", to the prism side (closed form) " << worstPrism);
    CHECK(moved > 1000);       // a region of radius 1.2 on a tube with ~0.04-unit quads
    CHECK(largestMove > 0.5);  // |d| = 0.57 at the handle: visible in the pictures
    // Float positions of magnitude ~4: a few ulps (~5e-7 each) from the surface.
    CHECK(worstBvh < 5e-6);
    CHECK(worstPrism < 5e-6);
}

TEST_CASE("demo slide: the handle lands where the geodesic of a cylinder puts d, not the normal section",
          "[harness][demo][slide]") {
    // The slide walks |d| along the straightest geodesic in the direction of d (paper §3.3; decisions SL-5).
    // A cylinder is developable: the geodesic is a straight line of the unrolled tube, so the handle
    // (falloff 1) lands at the unrolled translation, |d| cos phi around the tube and |d| sin phi up it.
    // The normal-section map of §3.1 (the cut of the surface by the plane through the normal n and the
    // direction, P + a(b) n + b u with a(b) = sqrt(R^2 - b^2 cos^2 phi) - R) approximates that geodesic and
    // differs from it off the principal directions: around R asin(B cos phi / R), up B sin phi where the
    // cut's length is |d|. Both closed forms are computed here (Simpson, bisection), independent of the
    // mesh, and the landing must be the first and tell itself apart from the second.
    const geom::Mesh tube = geom::makeCappedTube();
    const harness::DemoSlide demo = harness::makeDemoSlide(tube);
    const int32_t h = demo.handle.vertex;
    const glm::dvec3 before(tube.points()[h]), after(demo.mesh.points()[h]);
    REQUIRE(std::abs(before.y - 2.0) < 1e-6);
    const double R = 1.0, dAround = 0.45, dUp = 0.35;  // makeDemoSlide's displacement, in the tangent plane
    CHECK(glm::length(demo.displacement) == Approx(std::hypot(dAround, dUp)).epsilon(1e-12));
    const double phi = std::atan2(dUp, dAround), c = std::cos(phi), length = std::hypot(dAround, dUp);
    auto cutLength = [&](double B) {
        const int n = 2000;  // Simpson on a smooth integrand: error far below 1e-9
        auto f = [&](double b) {
            const double slope = b * c * c / std::sqrt(R * R - b * b * c * c);
            return std::sqrt(1.0 + slope * slope);
        };
        double sum = f(0.0) + f(B);
        for (int i = 1; i < n; ++i)
            sum += f(B * i / n) * (i % 2 ? 4.0 : 2.0);
        return sum * B / (3.0 * n);
    };
    double lo = 0.0, hi = 0.99 * R / c;
    for (int i = 0; i < 100; ++i)
        (cutLength(0.5 * (lo + hi)) < length ? lo : hi) = 0.5 * (lo + hi);
    const double sectionAround = R * std::asin(lo * c / R), sectionUp = lo * std::sin(phi);
    const double around = unrolled(after, 160) - unrolled(before, 160), up = after.y - before.y;
    INFO("around " << around << ", up " << up << " (geodesic " << dAround << ", " << dUp
                   << "; normal section " << sectionAround << ", " << sectionUp << ")");
    // The 160-gon stands in for the circle: lengths and angles on it differ by factors cos(delta / 2),
    // delta = 2 pi / 160, a relative error of order delta^2 / 8 ~ 2e-4 of the 0.57 travelled.
    const double delta = 2.0 * kPi / 160.0, tolerance = length * delta * delta / 8.0;
    CHECK(std::abs(around - dAround) < tolerance);
    CHECK(std::abs(up - dUp) < tolerance);
    // The two closed forms differ by far more than the tolerance in this case, so the check can tell them.
    CHECK(std::abs(sectionAround - dAround) > 10.0 * tolerance);
    CHECK(std::abs(sectionUp - dUp) > 10.0 * tolerance);
    CHECK(demo.result.boundaryStopped == 0);
    CHECK(demo.result.unreachable == 0);
}
