#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include "deformkit/error.h"
#include "deformkit/geom/bvh.h"
#include "deformkit/geom/limit_surface.h"
#include "deformkit/io/obj.h"
#include "deformkit/slide/slider.h"
#include "slide_real_meshes.h"
#include "slide_test_support.h"

// The slide over the surface a stack hands it (a deformed copy of the rest mesh), the fold count and
// limit, the paper's painted-weights rule and the limit surface built over the reachable part only.

using namespace deformkit;
using slide::Falloff;
using slide::SlideDrive;
using slide::SlideHandle;
using slide::SlideOptions;
using slide::SlideResult;
using test::bob;
using test::diagonal;
using test::spot;

namespace {

// A rotation about a random axis by a random angle (fixed generator).
glm::dmat3 randomRotation(std::mt19937& rng) {
    std::normal_distribution<double> gauss;
    std::uniform_real_distribution<double> angle(0.3, 3.0);
    const glm::dvec3 axis = glm::normalize(glm::dvec3(gauss(rng), gauss(rng), gauss(rng)));
    return glm::dmat3(glm::rotate(glm::dmat4(1.0), angle(rng), axis));
}

std::vector<glm::vec3> slideOver(const geom::Mesh& rest, std::span<const glm::vec3> incoming,
                                 const SlideHandle& handle, const glm::dvec3& d,
                                 const SlideOptions& options = {}, SlideResult* result = nullptr,
                                 std::span<const float> weights = {}) {
    slide::Slider slider(rest, {handle}, options);
    std::vector<glm::vec3> points(incoming.begin(), incoming.end());
    const SlideDrive drive{d, Falloff::smooth()};
    slider.evaluate({&drive, 1}, points, weights, 1.0f, result);
    return points;
}

// Spot's cage with every vertex moved by a smooth non-rigid field: a bend about the x axis growing with z
// and a shear, so each one-ring turns and stretches differently.
std::vector<glm::vec3> bentSpot() {
    std::vector<glm::vec3> out;
    for (const glm::vec3& p : spot().points()) {
        const double angle = 0.8 * p.z;
        const double c = std::cos(angle), s = std::sin(angle);
        out.emplace_back(1.1 * p.x + 0.2 * p.y, c * p.y - s * p.z, s * p.y + c * p.z);
    }
    return out;
}

}  // namespace

TEST_CASE("slide over a rigidly moved mesh is the rigid motion of the rest slide by R^T d", "[slide][real]") {
    // Equivariance: slide(R x + t, d) = R slide(x, R^T d) + t, on Spot at random handles, drags, rotations
    // and translations, over the mesh and over its limit surface.
    const geom::Mesh& mesh = spot();
    const double scale = diagonal(mesh.points());
    std::mt19937 rng(7);
    std::uniform_int_distribution<int32_t> vertex(0, mesh.numVertices() - 1);
    std::normal_distribution<double> gauss;
    double worst = 0.0, largest = 0.0;
    for (int c = 0; c < 12; ++c) {
        SlideOptions options;
        if (c % 4 == 3) options.surface = slide::SurfaceMode::Limit;
        const glm::dmat3 R = randomRotation(rng);
        const glm::dvec3 t(gauss(rng), gauss(rng), gauss(rng));
        std::vector<glm::vec3> moved;
        for (const glm::vec3& p : mesh.points())
            moved.emplace_back(R * glm::dvec3(p) + t);
        const SlideHandle handle{vertex(rng), 0.1 * scale};
        glm::dvec3 d(gauss(rng), gauss(rng), gauss(rng));
        d *= 0.04 * scale / glm::length(d);
        const auto atRest = slideOver(mesh, mesh.points(), handle, glm::transpose(R) * d, options);
        const auto overMoved = slideOver(mesh, moved, handle, d, options);
        for (int32_t v = 0; v < mesh.numVertices(); ++v) {
            const glm::dvec3 expected = R * glm::dvec3(atRest[v]) + t;
            worst = std::max(worst, glm::length(glm::dvec3(overMoved[v]) - expected));
            largest = std::max(largest, glm::length(glm::dvec3(atRest[v]) - glm::dvec3(mesh.points()[v])));
        }
    }
    INFO("largest difference " << worst << " for slides up to " << largest);
    CHECK(largest > 0.02 * scale);
    // Float positions of coordinates up to ~3 units: rounding of the moved copy (~2e-7) and of the
    // handle rotation recovered from it; a rest-space offset (the old behaviour) is off by ~|d|.
    CHECK(worst < 2e-6 * scale);
}

TEST_CASE("slide over a uniformly scaled mesh is the scaled rest slide, however small the scale",
          "[slide][real]") {
    // slide(s x, s d) = s slide(x, d): a rest mesh in millimetres driven by a rig in metres is s = 1e-3. The
    // incoming frame's determinant is s^3; an absolute threshold took s <= 1e-3 for a collapsed ring and
    // the handle travelled 0.1% of the drag.
    const geom::Mesh& mesh = spot();
    const double diag = diagonal(mesh.points());
    const SlideHandle handle{1858, 0.12 * diag};
    const glm::dvec3 d(0.0, 0.02 * diag, 0.01 * diag);
    const auto atRest = slideOver(mesh, mesh.points(), handle, d);
    for (const double s : {0.5, 1e-2, 1e-3, 9e-4, 1e-4}) {
        INFO("scale " << s);
        std::vector<glm::vec3> scaled;
        for (const glm::vec3& p : mesh.points())
            scaled.emplace_back(s * glm::dvec3(p));
        const auto over = slideOver(mesh, scaled, handle, s * d);
        double worst = 0.0;
        for (int32_t v = 0; v < mesh.numVertices(); ++v)
            worst = std::max(worst, glm::length(glm::dvec3(over[v]) / s - glm::dvec3(atRest[v])));
        // Float positions of the scaled copy, relative to its size (a few float ulps of the diagonal).
        CHECK(worst < 1e-6 * diag);
        CHECK(glm::length(glm::dvec3(over[1858]) / s - glm::dvec3(mesh.points()[1858])) >
              0.5 * glm::length(d));
    }
}

TEST_CASE("slide over a bent limb follows the limb: the drag turns with it and stays on it", "[slide]") {
    // A cylinder along z (the limb) kinked at mid-height: the upper half turned 90 degrees about the x axis
    // through the kink. Sliding the upper half along its own (turned) axis translates each region vertex by
    // d falloff(|P - P0| / r) along that axis: the closed form of a slide along a cylinder's ruling.
    const int around = 48, rows = 80;
    const float radius = 0.5f, height = 8.0f;
    const geom::Mesh rest = test::cylinder(around, rows, radius, height);
    const glm::dmat3 R = glm::dmat3(glm::rotate(glm::dmat4(1.0), M_PI / 2.0, glm::dvec3(1.0, 0.0, 0.0)));
    const glm::dvec3 kink(0.0, 0.0, height / 2.0);
    std::vector<glm::vec3> bent;
    for (const glm::vec3& p : rest.points())
        bent.push_back(p.z > kink.z ? glm::vec3(R * (glm::dvec3(p) - kink) + kink) : p);
    const int32_t handle = 60 * around + 5;  // z = 6, two units above the kink
    const double r = 1.2;
    const glm::dvec3 d = R * glm::dvec3(0.0, 0.0, 0.3);  // along the turned axis, in the incoming space
    SlideResult result;
    const auto out = slideOver(rest, bent, {handle, r}, d, {}, &result);
    REQUIRE(result.moved > 100);
    double worst = 0.0;
    const Falloff smooth = Falloff::smooth();
    const glm::dvec3 p0(rest.points()[handle]);
    for (int32_t v = 0; v < rest.numVertices(); ++v) {
        const double f = smooth(glm::length(glm::dvec3(rest.points()[v]) - p0) / r);
        const glm::dvec3 expected = glm::dvec3(bent[v]) + f * d;
        worst = std::max(worst, glm::length(glm::dvec3(out[v]) - expected));
    }
    // The same slide on the straight rest limb by R^T d, against the same closed form: the breadth-first
    // basis (Eq. 4) turns by about the square of the 7.5 degree ring step per step around the 48-gon, so
    // vertices far round the limb miss the ruling by a few thousandths; the bent limb must do no worse.
    const auto straight = slideOver(rest, rest.points(), {handle, r}, glm::transpose(R) * d);
    double restWorst = 0.0;
    for (int32_t v = 0; v < rest.numVertices(); ++v) {
        const double f = smooth(glm::length(glm::dvec3(rest.points()[v]) - p0) / r);
        const glm::dvec3 expected = glm::dvec3(rest.points()[v]) + f * glm::transpose(R) * d;
        restWorst = std::max(restWorst, glm::length(glm::dvec3(straight[v]) - expected));
    }
    INFO("largest distance from the closed form: bent " << worst << ", straight " << restWorst);
    CHECK(glm::length(glm::dvec3(out[handle]) - glm::dvec3(bent[handle]) - d) < 1e-5);
    CHECK(restWorst < 0.03 * glm::length(d));
    CHECK(worst < restWorst + 1e-5);
}

TEST_CASE("slide over a non-rigidly deformed Spot lands on the deformed surface", "[slide][real]") {
    // Every slid vertex lies on the incoming surface: its distance to the nearest triangle of the deformed
    // cage, found by a BVH built here over the deformed triangles, is rounding.
    const geom::Mesh& mesh = spot();
    const std::vector<glm::vec3> bent = bentSpot();
    geom::Mesh::Data data{bent,
                          {mesh.faceCounts().begin(), mesh.faceCounts().end()},
                          {mesh.faceIndices().begin(), mesh.faceIndices().end()}};
    const geom::Mesh deformed(std::move(data), "bent spot");
    const geom::Bvh bvh(deformed);
    const double scale = diagonal(bent);
    std::mt19937 rng(19);
    std::uniform_int_distribution<int32_t> vertex(0, mesh.numVertices() - 1);
    std::normal_distribution<double> gauss;
    double worst = 0.0, largest = 0.0;
    for (int c = 0; c < 20; ++c) {
        glm::dvec3 d(gauss(rng), gauss(rng), gauss(rng));
        d *= 0.03 * scale / glm::length(d);
        const auto out = slideOver(mesh, bent, {vertex(rng), 0.1 * scale}, d);
        for (int32_t v = 0; v < mesh.numVertices(); ++v) {
            REQUIRE(std::isfinite(out[v].x + out[v].y + out[v].z));
            if (out[v] == bent[v]) continue;
            largest = std::max(largest, static_cast<double>(glm::length(out[v] - bent[v])));
            worst =
                std::max(worst, static_cast<double>(glm::length(bvh.closestPoint(out[v]).point - out[v])));
        }
    }
    INFO("largest distance to the deformed surface " << worst << ", largest move " << largest);
    CHECK(largest > 0.01 * scale);
    CHECK(worst < 1e-6 * scale);
}

TEST_CASE(
    "slide folds past |d| = r / 1.5 on a plane, counted; the fold limit stops it there, however far the drag",
    "[slide]") {
    // On a plane each vertex moves by d f(rho), f = 1 - 3 rho^2 + 2 rho^3: the map x -> x + d f(|x| / r)
    // has Jacobian determinant 1 + (|d| / r) f'(rho) cos(angle), and min f' = -1.5 at rho = 1/2, so
    // triangles flip exactly when |d| > r / 1.5 (on the line through the handle along d).
    const int n = 120;
    const float h = 0.05f;
    const geom::Mesh plane = test::planeGrid(n, n, h);
    const int32_t handle = 60 * (n + 1) + 60;
    const double r = 1.5;
    const glm::dvec3 along(1.0, 0.0, 0.0);
    SlideResult below, above;
    slideOver(plane, plane.points(), {handle, r}, 0.9 * r / 1.5 * along, {}, &below);
    slideOver(plane, plane.points(), {handle, r}, 1.1 * r / 1.5 * along, {}, &above);
    CHECK(below.flippedTriangles == 0);
    CHECK(above.flippedTriangles > 0);
    REQUIRE(below.foldScale.size() == 1);
    CHECK(below.foldScale[0] == 1.0);

    SlideOptions options;
    options.foldLimit = true;
    // Drags hundreds and tens of thousands of times the fold limit keep their share, to the same relative
    // precision: the search halves the drag until nothing folds, then bisects.
    for (const double factor : {1.1, 1.5, 3.0, 300.0, 30000.0}) {
        SlideResult limited;
        const auto out =
            slideOver(plane, plane.points(), {handle, r}, factor * r / 1.5 * along, options, &limited);
        INFO("drag " << factor << " r / 1.5: scale " << limited.foldScale[0]);
        CHECK(limited.flippedTriangles == 0);
        // The largest flip-free scale is (r / 1.5) / |d| up to the grid: the fold shows first on a triangle
        // straddling rho = 1/2, where the finite-difference slope of f is within h / r of -1.5.
        CHECK(limited.foldScale[0] == Approx(1.0 / factor).epsilon(0.04));
        CHECK(limited.foldScale[0] <= 1.0 / factor * 1.04);
        const glm::dvec3 handleMove = glm::dvec3(out[handle]) - glm::dvec3(plane.points()[handle]);
        CHECK(glm::length(handleMove - limited.foldScale[0] * factor * r / 1.5 * along) < 1e-5);
    }
}

TEST_CASE("slide: with the paper's rule the painted weight is the falloff", "[slide]") {
    // On a plane the slide is the translation d times the per-vertex factor: weight x falloff by default,
    // the weight alone with PaintedWeights::AreFalloff (the radius still bounds the region).
    const int n = 60;
    const float h = 0.05f;
    const geom::Mesh plane = test::planeGrid(n, n, h);
    const int32_t handle = 30 * (n + 1) + 30;
    const double r = 1.0;
    std::vector<float> weights(plane.numVertices());
    for (int32_t v = 0; v < plane.numVertices(); ++v)
        weights[v] = std::clamp(0.2f + 0.3f * plane.points()[v].x, 0.0f, 1.0f);
    const glm::dvec3 d(0.05, 0.08, 0.0);
    const glm::dvec3 p0(plane.points()[handle]);
    const Falloff smooth = Falloff::smooth();
    for (const auto rule : {slide::PaintedWeights::ScaleFalloff, slide::PaintedWeights::AreFalloff}) {
        SlideOptions options;
        options.weights = rule;
        const auto out = slideOver(plane, plane.points(), {handle, r}, d, options, nullptr, weights);
        double worst = 0.0;
        for (int32_t v = 0; v < plane.numVertices(); ++v) {
            const double distance = glm::length(glm::dvec3(plane.points()[v]) - p0);
            const double inside = distance <= r ? 1.0 : 0.0;
            const double factor = rule == slide::PaintedWeights::AreFalloff
                                      ? inside * weights[v]
                                      : weights[v] * smooth(distance / r);
            const glm::dvec3 expected = glm::dvec3(plane.points()[v]) + factor * d;
            worst = std::max(worst, glm::length(glm::dvec3(out[v]) - expected));
        }
        INFO("rule " << static_cast<int>(rule) << ": largest distance from the closed form " << worst);
        CHECK(worst < 1e-6);
    }
}

TEST_CASE("slide: vertices that travel less than asked are counted as limited", "[slide]") {
    // Near a plane's edge a drag towards it stops vertices on the boundary: those whose move is shorter
    // than |d| falloff, counted here from the positions alone.
    const int n = 40;
    const float h = 0.05f;
    const geom::Mesh plane = test::planeGrid(n, n, h);
    const int32_t handle = 20 * (n + 1) + 3;  // 0.15 from the x = 0 edge
    const double r = 0.6;
    const glm::dvec3 d(-0.3, 0.0, 0.0);
    SlideResult result;
    const auto out = slideOver(plane, plane.points(), {handle, r}, d, {}, &result);
    const Falloff smooth = Falloff::smooth();
    const glm::dvec3 p0(plane.points()[handle]);
    int shortened = 0;
    for (int32_t v = 0; v < plane.numVertices(); ++v) {
        const glm::dvec3 p(plane.points()[v]);
        const double want = glm::length(d) * smooth(glm::length(p - p0) / r);
        if (want > 0.0 && glm::length(glm::dvec3(out[v]) - p) < want - 1e-6) ++shortened;
    }
    CHECK(shortened > 0);
    CHECK(result.limited == shortened);
    CHECK(result.limited == result.boundaryStopped + result.walkLimitStopped);
}

TEST_CASE("slide on the limit surface: the part around the region equals the whole mesh's limit",
          "[slide][real]") {
    // The slider builds the limit surface over the faces its walks can reach and their one-ring. Each slid
    // vertex must move by L(landing) - L(under the vertex) of the whole mesh's limit surface, built here
    // once over all of Spot; and growing the part (a drag larger than the region) must not change a bit.
    const geom::Mesh& mesh = spot();
    const double scale = diagonal(mesh.points());
    const geom::LimitSurface whole(mesh);
    SlideOptions options;
    options.surface = slide::SurfaceMode::Limit;
    const SlideHandle handle{1858, 0.1 * scale};
    slide::Slider slider(mesh, {handle}, options);
    auto evaluate = [&](slide::Slider& s, const glm::dvec3& d, SlideResult* result) {
        std::vector<glm::vec3> points(mesh.points().begin(), mesh.points().end());
        const SlideDrive drive{d, Falloff::smooth()};
        s.evaluate({&drive, 1}, points, {}, 1.0f, result);
        return points;
    };
    auto weightsOf = [&](const slide::SlideLanding& landing) {
        const auto corners = mesh.face(landing.face);
        std::vector<double> w(corners.size(), 0.0);
        for (int k = 0; k < 3; ++k)
            for (size_t j = 0; j < corners.size(); ++j)
                if (corners[j] == landing.triangle[k]) w[j] += landing.barycentric[k];
        return w;
    };
    SlideResult result;
    const glm::dvec3 small(0.01, 0.02, 0.0);
    const auto out = evaluate(slider, small, &result);
    REQUIRE(result.moved > 20);
    double worst = 0.0;
    for (const auto& landing : result.landings) {
        const int32_t v = landing.vertex;
        // The limit point under v through a face using it (corner weight 1), as the slider takes it.
        int32_t f = -1;
        for (int32_t g = 0; g < mesh.numFaces() && f < 0; ++g)
            for (int32_t w : mesh.face(g))
                if (w == v) f = g;
        std::vector<double> under(mesh.face(f).size(), 0.0);
        for (size_t j = 0; j < under.size(); ++j)
            if (mesh.face(f)[j] == v) under[j] = 1.0;
        const glm::dvec3 expected = glm::dvec3(mesh.points()[v]) +
                                    whole.evaluate(landing.face, weightsOf(landing)) -
                                    whole.evaluate(f, under);
        worst = std::max(worst, glm::length(glm::dvec3(out[v]) - expected));
    }
    INFO("largest distance from the whole mesh's limit " << worst);
    CHECK(worst < 1e-6);

    // A drag three times the radius walks far beyond the region's faces: the part grows.
    const glm::dvec3 large = 3.0 * handle.radius * glm::normalize(glm::dvec3(0.3, 1.0, 0.1));
    const auto grown = evaluate(slider, large, nullptr);
    const auto again = evaluate(slider, small, nullptr);
    slide::Slider fresh(mesh, {handle}, options);
    const auto freshLarge = evaluate(fresh, large, nullptr);
    CHECK(std::memcmp(grown.data(), freshLarge.data(), grown.size() * sizeof(glm::vec3)) == 0);
    CHECK(std::memcmp(out.data(), again.data(), out.size() * sizeof(glm::vec3)) == 0);
}

TEST_CASE("slide: a non-finite incoming point it reads is an error naming the vertex", "[slide][errors]") {
    const geom::Mesh plane = test::planeGrid(10, 10, 0.1f);
    const int32_t handle = 5 * 11 + 5;
    slide::Slider slider(plane, {{handle, 0.3}});
    std::vector<glm::vec3> points(plane.points().begin(), plane.points().end());
    points[handle + 1].y = std::nanf("");
    const SlideDrive drive{glm::dvec3(0.05, 0.0, 0.0), Falloff::smooth()};
    const std::vector<glm::vec3> before = points;
    try {
        slider.evaluate({&drive, 1}, points);
        FAIL("no error");
    } catch (const InvalidInput& e) {
        CHECK_THAT(e.what(), Catch::Contains("point of vertex 61") && Catch::Contains("not finite"));
    }
    CHECK(std::memcmp(points.data(), before.data(), points.size() * sizeof(glm::vec3)) == 0);
    // A far vertex the slide never reads passes through untouched.
    points = std::vector<glm::vec3>(plane.points().begin(), plane.points().end());
    points[0].x = std::nanf("");
    slider.evaluate({&drive, 1}, points);
    CHECK(std::isnan(points[0].x));
    CHECK(points[handle].x > plane.points()[handle].x);
    // On the limit surface the patches of the region's faces read the points around them too: a NaN there,
    // outside the region and the handle's ring, made active vertices NaN. Every such point is checked.
    SlideOptions limit;
    limit.surface = slide::SurfaceMode::Limit;
    slide::Slider onLimit(plane, {{handle, 0.3}}, limit);
    const std::span<const int32_t> active = onLimit.activeVertices();
    int32_t outside = -1;  // a vertex sharing a face with an active vertex, not active itself
    for (int32_t f = 0; f < plane.numFaces() && outside < 0; ++f) {
        const auto face = plane.face(f);
        const bool touches =
            std::ranges::any_of(face, [&](int32_t v) { return std::ranges::count(active, v) > 0; });
        for (const int32_t v : face)
            if (touches && std::ranges::count(active, v) == 0) outside = v;
    }
    REQUIRE(outside >= 0);
    points = std::vector<glm::vec3>(plane.points().begin(), plane.points().end());
    for (glm::vec3& p : points)
        p.z += 0.01f;  // moved: the incoming limit surface is built from the points
    points[outside].z = std::nanf("");
    const std::vector<glm::vec3> moved = points;
    CHECK_THROWS_WITH(onLimit.evaluate({&drive, 1}, points),
                      Catch::Contains("point of vertex " + std::to_string(outside) + ": not finite") &&
                          Catch::Contains("the limit surface reads the points around the region's faces"));
    CHECK(std::memcmp(points.data(), moved.data(), points.size() * sizeof(glm::vec3)) == 0);

    // On the cage a landed point combines its triangle's corners: a NaN corner outside the active vertices
    // and the handle's ring made the finite vertices landing beside it NaN. Named, nothing written.
    const std::span<const int32_t> cageActive = slider.activeVertices();
    const SlideDrive far{glm::dvec3(0.15, 0.0, 0.0), Falloff::smooth()};
    int checked = 0;
    for (int32_t corner = 0; corner < plane.numVertices(); ++corner) {
        const bool ring =
            std::abs(corner % 11 - handle % 11) <= 1 && std::abs(corner / 11 - handle / 11) <= 1;
        if (ring || std::ranges::count(cageActive, corner) > 0) continue;
        points = std::vector<glm::vec3>(plane.points().begin(), plane.points().end());
        points[corner].y = std::nanf("");
        const std::vector<glm::vec3> given = points;
        try {
            slider.evaluate({&far, 1}, points);
            // No landing reads it: every vertex but the NaN one stays finite.
            for (int32_t v = 0; v < plane.numVertices(); ++v)
                if (v != corner) CHECK(std::isfinite(points[v].x + points[v].y + points[v].z));
        } catch (const InvalidInput& e) {
            CHECK_THAT(e.what(),
                       Catch::Contains("point of vertex " + std::to_string(corner) + ": not finite") &&
                           Catch::Contains("a corner of the triangle vertex"));
            CHECK(std::memcmp(points.data(), given.data(), points.size() * sizeof(glm::vec3)) == 0);
            ++checked;
        }
    }
    CHECK(checked > 0);  // some corners outside are read
}

TEST_CASE("slide: a drag beyond float range is an error; one within it stays on the surface",
          "[slide][errors]") {
    // A drag of 1e155 once squared to infinity in the walk and wrote NaN positions.
    const geom::Mesh plane = test::planeGrid(10, 10, 0.1f);
    const int32_t handle = 5 * 11 + 5;
    slide::Slider slider(plane, {{handle, 0.3}});
    std::vector<glm::vec3> points(plane.points().begin(), plane.points().end());
    const std::vector<glm::vec3> before = points;
    const SlideDrive huge{glm::dvec3(1e155, 0.0, 0.0), Falloff::smooth()};
    CHECK_THROWS_WITH(
        slider.evaluate({&huge, 1}, points),
        Catch::Contains("handle 0 displacement: has length 1e+155") && Catch::Contains("within float range"));
    CHECK(std::memcmp(points.data(), before.data(), points.size() * sizeof(glm::vec3)) == 0);
    // 3e38: every vertex it moves lands on the plane (z = 0, inside its square), none NaN.
    const SlideDrive far{glm::dvec3(3e38, 1e38, 0.0), Falloff::smooth()};
    slider.evaluate({&far, 1}, points);
    for (const glm::vec3& p : points) {
        REQUIRE(std::isfinite(p.x + p.y + p.z));
        CHECK(p.z == 0.0f);
        CHECK((p.x >= -1e-6f && p.x <= 1.0f + 1e-6f && p.y >= -1e-6f && p.y <= 1.0f + 1e-6f));
    }
    CHECK(points[handle].x > plane.points()[handle].x);
    // Drags of 1e15 to 1e30 radii walk to the limit or the boundary: none lands in its start triangle (the
    // barycentric coordinates of a target that far lost every digit, read as "reached" at 1e24).
    for (const double radii : {1e15, 1e24, 1e30}) {
        INFO(radii << " radii");
        points.assign(plane.points().begin(), plane.points().end());
        const SlideDrive drag{glm::dvec3(0.3 * radii, 0.1 * radii, 0.0), Falloff::linear()};
        SlideResult result;
        slider.evaluate({&drag, 1}, points, {}, 1.0f, &result);
        CHECK(result.moved > 0);
        CHECK(result.limited == result.moved);
        CHECK(points[handle].x > 0.9f);  // the handle reached the far boundary
    }
}

TEST_CASE("slide over a stretched plane: the handle follows the locator", "[slide]") {
    // The rest plane under an affine map A (stretch 1.5 along x, 0.8 along y, a shear, a turn, a move) is
    // still a plane: each vertex lands at A(P + f F^-1 d) = A(P) + f d, with f the falloff of its rest
    // distance, because the drag is carried back through A's linear part (the best fit of the handle's
    // ring is exact for an affine map).
    const int n = 40;
    const geom::Mesh plane = test::planeGrid(n, n, 0.05f);
    const int32_t handle = 20 * (n + 1) + 20;
    const glm::dmat3 turn = glm::dmat3(glm::rotate(glm::dmat4(1.0), 0.6, glm::dvec3(0.2, 1.0, 0.4)));
    const glm::dmat3 A = turn * glm::dmat3(1.5, 0.0, 0.0, 0.3, 0.8, 0.0, 0.0, 0.0, 1.0);  // columns
    const glm::dvec3 move(0.3, -0.2, 1.0);
    std::vector<glm::vec3> stretched;
    for (const glm::vec3& p : plane.points())
        stretched.emplace_back(A * glm::dvec3(p) + move);
    const glm::dvec3 d = turn * glm::dvec3(0.12, -0.07, 0.0);  // in the stretched plane
    const double r = 0.6;
    const auto out = slideOver(plane, stretched, {handle, r}, d);
    const Falloff smooth = Falloff::smooth();
    const glm::dvec3 p0(plane.points()[handle]);
    double worst = 0.0;
    for (int32_t v = 0; v < plane.numVertices(); ++v) {
        const double f = smooth(glm::length(glm::dvec3(plane.points()[v]) - p0) / r);
        worst = std::max(worst, glm::length(glm::dvec3(out[v]) - glm::dvec3(stretched[v]) - f * d));
    }
    INFO("largest distance from A(P) + f d: " << worst);
    CHECK(worst < 2e-6);
    CHECK(glm::length(glm::dvec3(out[handle]) - glm::dvec3(stretched[handle]) - d) < 1e-6);
}
