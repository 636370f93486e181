#include <cmath>
#include <cstring>
#include <random>
#include <thread>

#include <omp.h>
#include <catch2/catch.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include "deformkit/error.h"
#include "deformkit/slide/slider.h"
#include "slide_test_support.h"

using namespace deformkit;
using deformkit::slide::SlideDrive;
using deformkit::slide::SlideHandle;
using deformkit::slide::Slider;
using deformkit::slide::SlideResult;

namespace {

std::vector<glm::vec3> restPoints(const geom::Mesh& mesh) {
    return {mesh.points().begin(), mesh.points().end()};
}

std::vector<glm::vec3> runSlide(const geom::Mesh& mesh, std::vector<SlideHandle> handles,
                                std::vector<SlideDrive> drives, std::span<const float> weights = {},
                                float envelope = 1.0f, SlideResult* result = nullptr,
                                const slide::SlideOptions& options = {}) {
    return slide::slide(mesh, handles, drives, weights, envelope, options, result);
}

glm::mat3 someRotation() {
    return glm::mat3(glm::rotate(glm::mat4(1.0f), 0.7f, glm::normalize(glm::vec3(0.3f, -0.5f, 0.8f))));
}

}  // namespace

TEST_CASE("slide on a plane is the in-plane translation d times falloff", "[slide]") {
    // Closed form (paper Eq. 7 on a plane: local maps are isometries, the basis is constant).
    // Tolerance: positions are float (~1e-7 relative); 2e-6 on a 2-unit plane is a few float ulps.
    const glm::mat3 rotation = someRotation();
    const glm::vec3 offset(0.3f, -1.2f, 0.5f);
    const geom::Mesh mesh = test::planeGrid(40, 40, 0.05f, rotation, offset);
    const int handle = 20 * 41 + 20;
    const double radius = 0.6;
    const glm::dvec3 d = glm::dvec3(rotation * glm::vec3(0.07f, 0.04f, 0.0f));
    SlideResult result;
    const auto out = runSlide(mesh, {{handle, radius}}, {{d}}, {}, 1.0f, &result);
    const glm::dvec3 p0(mesh.points()[handle]);
    int expectedMoved = 0;
    double worst = 0.0;
    for (int v = 0; v < mesh.numVertices(); ++v) {
        const glm::dvec3 p(mesh.points()[v]);
        const double f = test::smoothFalloff(glm::length(p - p0) / radius);
        expectedMoved += f > 0.0 ? 1 : 0;
        worst = std::max(worst, glm::length(glm::dvec3(out[v]) - (p + f * d)));
    }
    CHECK(worst < 2e-6);
    CHECK(test::distanceToSurface(mesh, out) <
          1e-6 * 2.9);  // Hausdorff to the rest surface, 1e-6 of the diagonal
    CHECK(result.moved == expectedMoved);
    CHECK(result.boundaryStopped == 0);
    CHECK(result.walkLimitStopped == 0);
    CHECK(result.unreachable == 0);
    // Every landing reproduces the output through its triangle and barycentric coordinates.
    for (const auto& landing : result.landings) {
        glm::dvec3 q(0.0);
        for (int k = 0; k < 3; ++k)
            q += landing.barycentric[k] * glm::dvec3(mesh.points()[landing.triangle[k]]);
        CHECK(glm::length(q - glm::dvec3(out[landing.vertex])) < 1e-6);
    }
}

TEST_CASE("slide around a cylinder is a rotation about its axis by |d| falloff / radius", "[slide]") {
    // 128 sides: the polygon's chords differ from the circle's arcs by (pi/128)^2/24 ~ 2.5e-5 relative.
    const int around = 128, rows = 40;
    const float R = 1.0f;
    const geom::Mesh mesh = test::cylinder(around, rows, R, 2.0f);
    const int handle = 20 * around;  // angle 0, z = 1
    const double radius = 0.8, travel = 0.1;
    const glm::dvec3 d(0.0, travel, 0.0);  // tangent to the circumference at the handle
    SlideResult result;
    const auto out = runSlide(mesh, {{handle, radius}}, {{d}}, {}, 1.0f, &result);
    const glm::dvec3 p0(mesh.points()[handle]);
    const double delta = 2.0 * M_PI / around;
    const double chord = 2.0 * R * std::sin(delta / 2.0);
    double worstAngle = 0.0, worstPolygon = 0.0, worstZ = 0.0;
    int moved = 0, onTheRadius = 0;
    for (int v = 0; v < mesh.numVertices(); ++v) {
        const glm::dvec3 p(mesh.points()[v]);
        const double x = glm::length(p - p0) / radius;
        // A vertex within a float's rounding of the radius (the slide keeps normalised distances in float;
        // 16 rows above the handle is 16 x 0.05 = 0.8 in exact arithmetic) falls on either side, here or in
        // the slide: counted apart, it moves by f < 1e-13 if at all.
        if (std::abs(x - 1.0) < 1.2e-7) ++onTheRadius;
        const double f = test::smoothFalloff(x);
        if (f <= 0.0) continue;
        ++moved;
        const glm::dvec3 q(out[v]);
        const double angle0 = std::atan2(p.y, p.x), angle1 = std::atan2(q.y, q.x);
        double turned = angle1 - angle0;
        turned = std::remainder(turned, 2.0 * M_PI);
        worstAngle = std::max(worstAngle, std::abs(turned - travel * f / R));
        // The surface actually slid over is the polygon: travel along its chords is exactly |d| f.
        const int k0 = v % around;
        const double steps = turned / delta;
        const int whole = static_cast<int>(std::floor(steps));
        const int kw = ((k0 + whole) % around + around) % around;
        const glm::dvec3 corner(R * std::cos(kw * delta), R * std::sin(kw * delta), p.z);
        const double along = whole * chord + glm::length(q - corner);
        worstPolygon = std::max(worstPolygon, std::abs(along - travel * f));
        worstZ = std::max(worstZ, std::abs(q.z - p.z));
    }
    INFO("angle error " << worstAngle << ", polygon-length error " << worstPolygon << ", z drift " << worstZ);
    CHECK(result.moved >= moved);
    CHECK(result.moved <= moved + onTheRadius);
    // Along chords the polar angle runs ahead of or behind the arc by at most a (delta^2 / 12) fraction.
    CHECK(worstAngle < travel * delta * delta / 12.0);
    CHECK(worstPolygon < 2e-6);  // exact up to float positions
    CHECK(worstZ < 2e-6);
    CHECK(test::distanceToSurface(mesh, out) < 1e-6 * 2.9);
}

TEST_CASE("slide on a sphere stays on the mesh, travels |d| falloff, in the transported direction",
          "[slide]") {
    const float R = 1.0f;
    const geom::Mesh mesh = test::icosphere(4, R);  // 2562 vertices, edges ~0.07
    const glm::dvec3 towards = glm::normalize(glm::dvec3(0.3, 0.5, 0.8));
    int handle = 0;
    for (int v = 0; v < mesh.numVertices(); ++v) {
        if (glm::dot(glm::dvec3(mesh.points()[v]), towards) >
            glm::dot(glm::dvec3(mesh.points()[handle]), towards))
            handle = v;
    }
    const glm::dvec3 p0 = glm::normalize(glm::dvec3(mesh.points()[handle]));
    const glm::dvec3 u0 =
        glm::normalize(glm::cross(p0, glm::dvec3(0.0, 0.0, 1.0)));  // a tangent at the handle
    const double magnitude = 0.05, radius = 0.5;
    SlideResult result;
    const auto out = runSlide(mesh, {{handle, radius}}, {{magnitude * u0}}, {}, 1.0f, &result);
    REQUIRE(result.moved > 100);

    double worstTravel = 0.0, worstDirection = 0.0;
    int checked = 0;
    for (int v = 0; v < mesh.numVertices(); ++v) {
        const glm::dvec3 p(mesh.points()[v]);
        const double f = test::smoothFalloff(glm::length(p - glm::dvec3(mesh.points()[handle])) / radius);
        if (f < 0.2) continue;  // relative errors of sub-millimetre travels say nothing
        const glm::dvec3 q(out[v]);
        const glm::dvec3 pn = glm::normalize(p), qn = glm::normalize(q);
        const double geodesic = R * std::acos(std::clamp(glm::dot(pn, qn), -1.0, 1.0));
        worstTravel = std::max(worstTravel, std::abs(geodesic / (magnitude * f) - 1.0));
        // Closed-form parallel transport of u0 along the great circle from p0 to p.
        glm::dvec3 transported = u0;
        const glm::dvec3 axis = glm::cross(p0, pn);
        const double s = glm::length(axis);
        if (s > 1e-12) {
            const glm::dvec3 k = axis / s;
            const double c = glm::dot(p0, pn);
            transported = u0 * c + glm::cross(k, u0) * s + k * glm::dot(k, u0) * (1.0 - c);
        }
        const glm::dvec3 moved = glm::normalize(qn - glm::dot(qn, pn) * pn);
        worstDirection =
            std::max(worstDirection, std::acos(std::clamp(glm::dot(moved, transported), -1.0, 1.0)));
        ++checked;
    }
    INFO("checked " << checked << ", travel relative error " << worstTravel << ", direction error (deg) "
                    << glm::degrees(worstDirection));
    CHECK(checked > 50);
    CHECK(worstTravel < 0.01);  // travel within 1% of the asked distance
    CHECK(glm::degrees(worstDirection) < 3.0);
    CHECK(test::distanceToSurface(mesh, out) <= 1e-6 * 2.0 * std::sqrt(3.0) * R);
}

TEST_CASE("slide with zero displacement or zero envelope changes nothing, bit for bit", "[slide]") {
    const geom::Mesh mesh = test::icosphere(3, 1.0f);
    const auto rest = restPoints(mesh);
    const auto still = runSlide(mesh, {{5, 0.7}}, {{glm::dvec3(0.0)}});
    CHECK(std::memcmp(still.data(), rest.data(), rest.size() * sizeof(glm::vec3)) == 0);
    const auto off = runSlide(mesh, {{5, 0.7}}, {{glm::dvec3(0.1, 0.2, 0.0)}}, {}, 0.0f);
    CHECK(std::memcmp(off.data(), rest.data(), rest.size() * sizeof(glm::vec3)) == 0);
}

TEST_CASE("slide gives the same bytes for 1 and 2 threads", "[slide]") {
    // Regions of more than 4096 vertices, so the loops really run on two threads (smaller ones stay on
    // the calling thread), with the fold count and the fold limit's bisection.
    const geom::Mesh mesh = test::icosphere(5, 1.0f);
    const std::vector<SlideHandle> handles = {{10, 1.2}, {400, 1.0, slide::RegionMetric::Geodesic}};
    const std::vector<SlideDrive> drives = {{glm::dvec3(0.5, -0.2, 0.3)}, {glm::dvec3(-0.4, 0.1, 0.2)}};
    slide::SlideOptions options;
    options.foldLimit = true;
    const int saved = omp_get_max_threads();
    auto run = [&](int threads, SlideResult& result) {
        omp_set_num_threads(threads);
        slide::Slider slider(mesh, handles, options);
        REQUIRE(slider.activeVertices().size() > 4096);
        std::vector<glm::vec3> points(mesh.points().begin(), mesh.points().end());
        slider.evaluate(drives, points, {}, 1.0f, &result);
        return points;
    };
    SlideResult r1, r2;
    const auto one = run(1, r1);
    const auto two = run(2, r2);
    omp_set_num_threads(saved);
    CHECK(std::memcmp(one.data(), two.data(), one.size() * sizeof(glm::vec3)) == 0);
    CHECK(r1.foldScale == r2.foldScale);
    CHECK(r1.moved == r2.moved);
    CHECK(r1.flippedTriangles == r2.flippedTriangles);
}

TEST_CASE("slide: painted weights and the envelope scale the displacement", "[slide]") {
    const geom::Mesh mesh = test::planeGrid(30, 30, 0.05f);
    const int handle = 15 * 31 + 15;
    const glm::dvec3 d(0.05, -0.03, 0.0);
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
    std::vector<float> weights(mesh.numVertices());
    for (float& w : weights)
        w = uniform(rng);
    const auto out = runSlide(mesh, {{handle, 0.5}}, {{d}}, weights, 0.5f);
    const glm::dvec3 p0(mesh.points()[handle]);
    double worst = 0.0;
    for (int v = 0; v < mesh.numVertices(); ++v) {
        const glm::dvec3 p(mesh.points()[v]);
        const double f = test::smoothFalloff(glm::length(p - p0) / 0.5) * weights[v] * 0.5;
        worst = std::max(worst, glm::length(glm::dvec3(out[v]) - (p + f * d)));
    }
    CHECK(worst < 2e-6);
}

TEST_CASE("slide: a user falloff ramp replaces the smooth curve", "[slide]") {
    const geom::Mesh mesh = test::planeGrid(30, 30, 0.05f);
    const int handle = 15 * 31 + 15;
    const glm::dvec3 d(0.04, 0.02, 0.0);
    const std::vector<float> samples = {1.0f, 1.0f, 0.5f, 0.0f};  // flat top, then linear to zero
    const auto out = runSlide(mesh, {{handle, 0.6}}, {{d, slide::Falloff::ramp(samples)}});
    const glm::dvec3 p0(mesh.points()[handle]);
    double worst = 0.0;
    for (int v = 0; v < mesh.numVertices(); ++v) {
        const glm::dvec3 p(mesh.points()[v]);
        const double x = glm::length(p - p0) / 0.6;
        const double f = x < 1.0 / 3.0   ? 1.0
                         : x < 2.0 / 3.0 ? 1.0 - 1.5 * (x - 1.0 / 3.0)
                         : x < 1.0       ? 1.5 * (1.0 - x)
                                         : 0.0;
        worst = std::max(worst, glm::length(glm::dvec3(out[v]) - (p + f * d)));
    }
    CHECK(worst < 2e-6);
}

TEST_CASE("slide: a ramp's last value reaches every vertex strictly inside the radius", "[slide]") {
    // The normalised distance is stored in float: a vertex at 0.99999998 r rounded to 1, the falloff's
    // outside, and a constant ramp [1, 1] left it behind. Radii picked so that some vertex's distance is
    // within a float rounding of the radius.
    const geom::Mesh mesh = test::planeGrid(40, 40, 0.05f);
    const int handle = 20 * 41 + 20;
    const glm::dvec3 p0(mesh.points()[handle]);
    const std::vector<float> flat = {1.0f, 1.0f};
    int edgeCases = 0;
    for (const int k : {7, 9, 10}) {
        // A vertex k grid steps away along x: the radius just beyond it.
        const double distance = glm::length(glm::dvec3(mesh.points()[handle + k]) - p0);
        const double radius = distance * (1.0 + 2e-8);
        REQUIRE(static_cast<float>(distance / radius) == 1.0f);  // the case at stake
        const glm::dvec3 d(0.01, 0.005, 0.0);
        const auto out = runSlide(mesh, {{handle, radius}}, {{d, slide::Falloff::ramp(flat)}});
        for (int v = 0; v < mesh.numVertices(); ++v) {
            const glm::dvec3 p(mesh.points()[v]);
            if (glm::length(p - p0) >= radius) continue;
            INFO("radius " << radius << ", vertex " << v);
            CHECK(glm::length(glm::dvec3(out[v]) - (p + d)) < 2e-6);  // the flat ramp: every one by d
            edgeCases += glm::length(p - p0) > radius * (1.0 - 1e-7) ? 1 : 0;
        }
    }
    CHECK(edgeCases >= 3);
}

TEST_CASE("slide: several handles compose by adding their slides", "[slide]") {
    const geom::Mesh mesh = test::planeGrid(40, 40, 0.05f, someRotation());
    const int h1 = 15 * 41 + 12, h2 = 22 * 41 + 25;
    const glm::dvec3 d1 = glm::dvec3(someRotation() * glm::vec3(0.04f, 0.0f, 0.0f));
    const glm::dvec3 d2 = glm::dvec3(someRotation() * glm::vec3(-0.01f, 0.05f, 0.0f));
    const auto out = runSlide(mesh, {{h1, 0.5}, {h2, 0.4}}, {{d1}, {d2, slide::Falloff::linear()}});
    double worst = 0.0;
    for (int v = 0; v < mesh.numVertices(); ++v) {
        const glm::dvec3 p(mesh.points()[v]);
        const double f1 = test::smoothFalloff(glm::length(p - glm::dvec3(mesh.points()[h1])) / 0.5);
        const double x2 = glm::length(p - glm::dvec3(mesh.points()[h2])) / 0.4;
        const double f2 = x2 < 1.0 ? 1.0 - x2 : 0.0;
        worst = std::max(worst, glm::length(glm::dvec3(out[v]) - (p + f1 * d1 + f2 * d2)));
    }
    CHECK(worst < 2e-6);
}

TEST_CASE("slide: vertices stop on a mesh boundary, counted", "[slide]") {
    const geom::Mesh mesh = test::planeGrid(20, 20, 0.05f);  // [0, 1]^2
    const int handle = 10 * 21 + 15;                         // (0.75, 0.5)
    const glm::dvec3 d(0.6, 0.0, 0.0);                       // pushes the region over x = 1
    SlideResult result;
    const auto out = runSlide(mesh, {{handle, 0.5}}, {{d}}, {}, 1.0f, &result);
    const glm::dvec3 p0(mesh.points()[handle]);
    int expectedStopped = 0;
    double worst = 0.0;
    for (int v = 0; v < mesh.numVertices(); ++v) {
        const glm::dvec3 p(mesh.points()[v]);
        const double f = test::smoothFalloff(glm::length(p - p0) / 0.5);
        glm::dvec3 expected = p + f * d;
        if (f > 0.0 && expected.x > 1.0) {
            ++expectedStopped;
            expected.x = 1.0;  // stops where its straight path meets the boundary x = 1
        }
        worst = std::max(worst, glm::length(glm::dvec3(out[v]) - expected));
    }
    CHECK(result.boundaryStopped == expectedStopped);
    CHECK(expectedStopped > 10);
    CHECK(worst < 2e-6);
}

TEST_CASE("slide: parts inside the radius that the propagation cannot reach stay, counted", "[slide]") {
    // Two parallel sheets 0.1 apart, not connected: the second lies inside the 3D radius.
    geom::Mesh::Data data;
    const geom::Mesh a = test::planeGrid(20, 20, 0.05f);
    const geom::Mesh b = test::planeGrid(20, 20, 0.05f, glm::mat3(1.0f), glm::vec3(0.0f, 0.0f, 0.1f));
    for (const geom::Mesh* m : {&a, &b}) {
        const int base = static_cast<int>(data.points.size());
        data.points.insert(data.points.end(), m->points().begin(), m->points().end());
        data.faceCounts.insert(data.faceCounts.end(), m->faceCounts().begin(), m->faceCounts().end());
        for (int i : m->faceIndices())
            data.faceIndices.push_back(base + i);
    }
    const geom::Mesh mesh(std::move(data), "two sheets");
    const int handle = 10 * 21 + 10;
    SlideResult result;
    const auto out = runSlide(mesh, {{handle, 0.4}}, {{glm::dvec3(0.05, 0.0, 0.0)}}, {}, 1.0f, &result);
    int expectedUnreachable = 0;
    for (int v = a.numVertices(); v < mesh.numVertices(); ++v) {
        if (glm::length(mesh.points()[v] - mesh.points()[handle]) <= 0.4f) ++expectedUnreachable;
        CHECK(out[v] == mesh.points()[v]);
    }
    CHECK(expectedUnreachable > 20);
    CHECK(result.unreachable == expectedUnreachable);
    // A second handle on the second sheet moves what the first cannot reach: nothing is unreachable then
    // (the count was each handle's own, 2 x the sheet's share, while every one of them moved).
    const int other = a.numVertices() + handle;
    SlideResult both;
    const glm::dvec3 d(0.05, 0.0, 0.0);
    const auto twice = runSlide(mesh, {{handle, 0.4}, {other, 0.4}}, {{d}, {d}}, {}, 1.0f, &both);
    CHECK(both.unreachable == 0);
    int movedOnB = 0;
    for (int v = a.numVertices(); v < mesh.numVertices(); ++v)
        movedOnB += twice[v] != mesh.points()[v] ? 1 : 0;
    CHECK(movedOnB >= expectedUnreachable - 8);  // all but those on the radius, where the falloff is 0
}

namespace {

// A strip folded over itself: sheet A at z = 0 for x in [0, 1], a half circle of radius 0.1 around
// x = 1, sheet B at z = 0.2 running back. Parameter s along the strip (arc length), y across.
geom::Mesh foldedStrip(std::vector<double>& arcLength) {
    const double rFold = 0.1;
    const double total = 2.0 + M_PI * rFold;
    const int ns = 120, ny = 10;
    geom::Mesh::Data d;
    arcLength.clear();
    for (int j = 0; j <= ny; ++j)
        for (int i = 0; i <= ns; ++i) {
            const double s = total * i / ns, y = 0.5 * j / ny;
            glm::dvec3 p;
            if (s <= 1.0) {
                p = {s, y, 0.0};
            } else if (s <= 1.0 + M_PI * rFold) {
                const double a = (s - 1.0) / rFold;  // 0 .. pi
                p = {1.0 + rFold * std::sin(a), y, rFold * (1.0 - std::cos(a))};
            } else {
                p = {1.0 - (s - 1.0 - M_PI * rFold), y, 2.0 * rFold};
            }
            d.points.push_back(glm::vec3(p));
            arcLength.push_back(s);
        }
    for (int j = 0; j < ny; ++j)
        for (int i = 0; i < ns; ++i) {
            const int a = j * (ns + 1) + i;
            d.faceCounts.push_back(4);
            d.faceIndices.insert(d.faceIndices.end(), {a, a + 1, a + ns + 2, a + ns + 1});
        }
    return geom::Mesh(std::move(d), "folded strip");
}

}  // namespace

TEST_CASE("slide: a geodesic region does not leak across a gap that a 3D radius crosses", "[slide]") {
    std::vector<double> s;
    const geom::Mesh mesh = foldedStrip(s);
    const int handle = 5 * 121 + 45;  // s = 0.8, middle row, on sheet A
    const double sHandle = s[handle], radius = 0.45;
    const glm::dvec3 d(0.03, 0.0, 0.0);  // along the strip: the rows on its long edges slide along them
    const double sheetB = 1.0 + M_PI * 0.1;
    auto movedOnB = [&](const std::vector<glm::vec3>& out) {
        int count = 0;
        for (int v = 0; v < mesh.numVertices(); ++v)
            count += (s[v] > sheetB && out[v] != mesh.points()[v]) ? 1 : 0;
        return count;
    };
    const auto euclidean = runSlide(mesh, {{handle, radius}}, {{d}});
    CHECK(movedOnB(euclidean) > 0);  // the paper's 3D radius reaches sheet B around the fold
    SlideResult result;
    const auto geodesic =
        runSlide(mesh, {{handle, radius, slide::RegionMetric::Geodesic}}, {{d}}, {}, 1.0f, &result);
    CHECK(movedOnB(geodesic) == 0);
    // Closed form: the strip's geodesic distance is |s - s0| along x plus the offset across y.
    for (int v = 0; v < mesh.numVertices(); ++v) {
        const double dy = mesh.points()[v].y - mesh.points()[handle].y;
        const double g = std::hypot(s[v] - sHandle, static_cast<double>(dy));
        if (g < 0.9 * radius && s[v] < 1.0) {
            INFO("vertex " << v << " geodesic distance " << g);
            CHECK(geodesic[v] != mesh.points()[v]);
        }
        if (g > 1.05 * radius) CHECK(geodesic[v] == mesh.points()[v]);
    }
    CHECK(test::distanceToSurface(mesh, geodesic) < 1e-6 * 3.0);
}

TEST_CASE("slide: a displacement far larger than the region stops at the boundary or the expansion limit",
          "[slide]") {
    {
        const geom::Mesh mesh = test::planeGrid(20, 20, 0.05f);
        SlideResult result;
        const glm::dvec3 d(40.0, 25.0, 0.0);
        const int handle = 10 * 21 + 10;
        const auto out = runSlide(mesh, {{handle, 0.3}}, {{d}}, {}, 1.0f, &result);
        int leaving = 0;  // vertices whose target P + f d lies off the unit square
        for (int v = 0; v < mesh.numVertices(); ++v) {
            const glm::dvec3 p(mesh.points()[v]);
            const glm::dvec3 t =
                p + test::smoothFalloff(glm::length(p - glm::dvec3(mesh.points()[handle])) / 0.3) * d;
            leaving += (t.x > 1.0 || t.y > 1.0) ? 1 : 0;
        }
        CHECK(leaving > 50);
        CHECK(result.boundaryStopped == leaving);
        CHECK(test::distanceToSurface(mesh, out) < 1e-6 * 1.5);
    }
    {
        const geom::Mesh mesh = test::icosphere(3, 1.0f);  // closed: only the expansion limit stops it
        slide::SlideOptions options;
        options.maxWalkTriangles = 64;
        SlideResult result;
        const auto out =
            runSlide(mesh, {{0, 0.5}}, {{glm::dvec3(0.0, 0.0, 30.0)}}, {}, 1.0f, &result, options);
        CHECK(result.walkLimitStopped > 0);
        CHECK(result.boundaryStopped == 0);
        for (const auto& p : out)
            CHECK(std::isfinite(p.x + p.y + p.z));
        CHECK(test::distanceToSurface(mesh, out) < 1e-6 * 3.5);
    }
}

TEST_CASE("slide: degenerate faces in the region are skipped and counted", "[slide]") {
    geom::Mesh::Data data;
    {
        const geom::Mesh grid = test::planeGrid(20, 20, 0.05f);
        data.points.assign(grid.points().begin(), grid.points().end());
        data.faceCounts.assign(grid.faceCounts().begin(), grid.faceCounts().end());
        data.faceIndices.assign(grid.faceIndices().begin(), grid.faceIndices().end());
    }
    data.points[9 * 21 + 11] = data.points[9 * 21 + 12];  // collapse an edge near the handle
    const geom::Mesh mesh(std::move(data), "collapsed edge");
    SlideResult result;
    const auto out =
        runSlide(mesh, {{10 * 21 + 10, 0.4}}, {{glm::dvec3(0.03, -0.05, 0.0)}}, {}, 1.0f, &result);
    CHECK(result.degenerateTriangles >= 2);
    CHECK(result.moved > 0);
    for (const auto& p : out)
        CHECK(std::isfinite(p.x + p.y + p.z));
    CHECK(test::distanceToSurface(mesh, out) < 1e-6 * 1.5);
}

TEST_CASE("slide: bad input gives an error naming the element", "[slide]") {
    const geom::Mesh mesh = test::planeGrid(4, 4, 0.25f);
    auto message = [](auto&& f) {
        try {
            f();
        } catch (const InvalidInput& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    CHECK_THAT(message([&] { Slider(mesh, {{25, 0.5}}); }), Catch::Contains("vertex index out of range"));
    CHECK_THAT(message([&] { Slider(mesh, {{-1, 0.5}}); }), Catch::Contains("handle 0 (vertex -1)"));
    CHECK_THAT(message([&] { Slider(mesh, {{3, 0.0}}); }), Catch::Contains("radius"));
    CHECK_THAT(message([&] { Slider(mesh, {{3, std::nan("")}}); }), Catch::Contains("finite radius > 0"));
    CHECK_THAT(message([&] { Slider(mesh, {}); }), Catch::Contains("no handle"));

    Slider slider(mesh, {{12, 0.5}});
    std::vector<glm::vec3> points = restPoints(mesh);
    const std::vector<SlideDrive> bad = {{glm::dvec3(std::numeric_limits<double>::infinity(), 0.0, 0.0)}};
    CHECK_THAT(message([&] { slider.evaluate(bad, points); }), Catch::Contains("handle 0 displacement"));
    const std::vector<SlideDrive> good = {{glm::dvec3(0.1, 0.0, 0.0)}};
    const std::vector<float> shortWeights(3, 1.0f);
    CHECK_THAT(message([&] { slider.evaluate(good, points, shortWeights); }),
               Catch::Contains("weights: 3 given"));
    CHECK_THAT(message([&] { slider.evaluate({}, points); }), Catch::Contains("one per handle"));
    CHECK(points == restPoints(mesh));  // nothing written by a failed call

    // An isolated vertex and a bow-tie (non-manifold) vertex as handles.
    geom::Mesh::Data data;
    data.points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {-1, 0, 0}, {0, -1, 0}, {5, 5, 5}};
    data.faceCounts = {3, 3};
    data.faceIndices = {0, 1, 2, 0, 3, 4};
    const geom::Mesh bowTie(std::move(data), "bow tie");
    CHECK_THAT(message([&] { Slider(bowTie, {{5, 0.5}}); }), Catch::Contains("no face uses this vertex"));
    CHECK_THAT(message([&] { Slider(bowTie, {{0, 0.5}}); }), Catch::Contains("non-manifold"));
}

TEST_CASE("slide on the limit surface follows the Catmull-Clark limit of the cage", "[slide]") {
    // An 8-sided prism: away from its ends the Catmull-Clark limit is a straight extrusion of the periodic
    // uniform cubic B-spline of the octagon, a curve written here in closed form. A vertex moves by how far
    // the limit point under it travels, so (output - rest + limit point under the rest vertex) must lie on
    // that curve, at the same height.
    const int around = 8, rows = 20;
    const float R = 1.0f;
    const geom::Mesh mesh = test::cylinder(around, rows, R, 4.0f);
    const int handle = 10 * around;
    const glm::dvec3 d(0.0, 0.3, 0.0);
    slide::SlideOptions options;
    options.surface = slide::SurfaceMode::Limit;
    SlideResult result;
    const auto out = runSlide(mesh, {{handle, 0.9}}, {{d}}, {}, 1.0f, &result, options);
    REQUIRE(result.moved > 10);

    auto ring = [&](int k) {
        const double a = 2.0 * M_PI * ((k % around + around) % around) / around;
        return glm::dvec2(R * std::cos(a), R * std::sin(a));
    };
    auto curve = [&](int span, double t) {  // uniform cubic B-spline basis, controls span-1 .. span+2
        const double b0 = (1 - t) * (1 - t) * (1 - t) / 6.0, b1 = (3 * t * t * t - 6 * t * t + 4) / 6.0,
                     b2 = (-3 * t * t * t + 3 * t * t + 3 * t + 1) / 6.0, b3 = t * t * t / 6.0;
        return b0 * ring(span - 1) + b1 * ring(span) + b2 * ring(span + 1) + b3 * ring(span + 2);
    };
    auto curveAt = [&](double tau) {  // the whole closed curve by one parameter, span + t
        const double wrapped = tau - around * std::floor(tau / around);
        const int span = std::min(static_cast<int>(wrapped), around - 1);
        return curve(span, wrapped - span);
    };
    auto distanceToCurve =
        [&](const glm::dvec2& q) {  // coarse samples, then a ternary search around the best
            const int samples = 200 * around;
            double bestTau = 0.0, best = 1e300;
            for (int i = 0; i < samples; ++i) {
                const double tau = double(i) * around / samples;
                if (glm::length(q - curveAt(tau)) < best) {
                    best = glm::length(q - curveAt(tau));
                    bestTau = tau;
                }
            }
            double lo = bestTau - double(around) / samples, hi = bestTau + double(around) / samples;
            for (int it = 0; it < 200; ++it) {
                const double m1 = lo + (hi - lo) / 3.0, m2 = hi - (hi - lo) / 3.0;
                if (glm::length(q - curveAt(m1)) < glm::length(q - curveAt(m2)))
                    hi = m2;
                else
                    lo = m1;
            }
            return std::min(best, glm::length(q - curveAt(0.5 * (lo + hi))));
        };
    double worst = 0.0, worstZ = 0.0, largestMove = 0.0;
    for (const auto& landing : result.landings) {
        const int v = landing.vertex;
        const int k = v % around;
        const glm::dvec3 p(mesh.points()[v]);
        const glm::dvec2 under =
            curve(k, 0.0);  // limit point under the vertex: (P[k-1] + 4 P[k] + P[k+1]) / 6
        const glm::dvec3 q = glm::dvec3(out[v]) - p + glm::dvec3(under, p.z);
        worst = std::max(worst, distanceToCurve(glm::dvec2(q)));
        worstZ = std::max(worstZ, std::abs(q.z - p.z));
        largestMove = std::max(largestMove, glm::length(glm::dvec3(out[v]) - p));
    }
    INFO("distance to the limit curve " << worst << ", height drift " << worstZ << ", largest move "
                                        << largestMove);
    CHECK(largestMove > 0.2);
    CHECK(worst < 1e-5);  // float positions (~1e-7); the closest curve point is found to ~1e-12
    CHECK(worstZ < 1e-5);
}

TEST_CASE("slide: evaluations from several threads match sequential ones", "[slide]") {
    // Evaluation writes per-vertex scratch (displacements, landings): concurrent calls must not mix it.
    const geom::Mesh mesh = test::icosphere(4, 1.0f);
    const std::vector<SlideDrive> small = {{glm::dvec3(0.02, 0.05, -0.01)}};
    const std::vector<SlideDrive> large = {{glm::dvec3(-0.2, 0.1, 0.15)}};  // walks far beyond one-rings
    Slider reference(mesh, {{30, 0.6}});
    auto expectedSmall = restPoints(mesh), expectedLarge = restPoints(mesh);
    reference.evaluate(small, expectedSmall);
    reference.evaluate(large, expectedLarge);

    Slider shared(mesh, {{30, 0.6}});
    std::vector<std::vector<glm::vec3>> outs(8, restPoints(mesh));
    std::vector<std::thread> threads;
    for (int i = 0; i < 8; ++i)
        threads.emplace_back([&, i] { shared.evaluate(i % 2 ? large : small, outs[i]); });
    for (auto& t : threads)
        t.join();
    for (int i = 0; i < 8; ++i)
        CHECK(outs[i] == (i % 2 ? expectedLarge : expectedSmall));
}
