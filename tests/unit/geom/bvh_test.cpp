#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <random>

#include <glm/geometric.hpp>

#include "deformkit/error.h"
#include "deformkit/geom/bvh.h"
#include "deformkit/geom/primitives.h"
#include "deformkit/geom/triangulation.h"

using namespace deformkit::geom;

namespace {

struct Soup {
    std::vector<glm::vec3> points;
    std::vector<std::array<int32_t, 3>> triangles;
};

Soup soupOf(const Mesh& m) {
    return {{m.points().begin(), m.points().end()}, triangleVertices(m, triangulate(m))};
}

// Random triangles of size ~0.1 in the unit cube; every 25th has collinear corners and every 30th and 40th
// two coincident corners: closest points lie on their edges, and rays never hit them.
Soup randomSoup(int count, uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f), offset(-0.08f, 0.08f);
    Soup s;
    for (int t = 0; t < count; ++t) {
        const glm::vec3 c(unit(rng), unit(rng), unit(rng));
        glm::vec3 a = c + glm::vec3(offset(rng), offset(rng), offset(rng));
        glm::vec3 b = c + glm::vec3(offset(rng), offset(rng), offset(rng));
        glm::vec3 d = c + glm::vec3(offset(rng), offset(rng), offset(rng));
        if (t % 25 == 0) {
            b = c + glm::vec3(0.04f, 0.02f, -0.01f);
            d = c + glm::vec3(-0.08f, -0.04f, 0.02f);
            a = c;
        }
        if (t % 30 == 0) b = a;
        if (t % 40 == 0) d = b;
        const auto base = static_cast<int32_t>(s.points.size());
        s.points.insert(s.points.end(), {a, b, d});
        s.triangles.push_back({base, base + 1, base + 2});
    }
    return s;
}

// Independent references: project onto the triangle's plane and test the barycentric signs, otherwise take
// the nearest of the three edges; a ray meets the plane, then the same inside test.
double segmentDistance2(const glm::dvec3& p, const glm::dvec3& a, const glm::dvec3& b) {
    const glm::dvec3 ab = b - a;
    const double len2 = glm::dot(ab, ab);
    const double t = len2 > 0.0 ? std::clamp(glm::dot(p - a, ab) / len2, 0.0, 1.0) : 0.0;
    const glm::dvec3 q = a + t * ab;
    return glm::dot(p - q, p - q);
}

double referenceDistance2(const glm::dvec3& p, const glm::dvec3& a, const glm::dvec3& b,
                          const glm::dvec3& c) {
    const glm::dvec3 n = glm::cross(b - a, c - a);
    const double nn = glm::dot(n, n);
    if (nn > 0.0) {
        const glm::dvec3 q = p - glm::dot(p - a, n) / nn * n;
        const double wa = glm::dot(glm::cross(b - q, c - q), n), wb = glm::dot(glm::cross(c - q, a - q), n),
                     wc = glm::dot(glm::cross(a - q, b - q), n);
        if (wa >= 0.0 && wb >= 0.0 && wc >= 0.0) return glm::dot(p - q, p - q);
    }
    return std::min({segmentDistance2(p, a, b), segmentDistance2(p, b, c), segmentDistance2(p, c, a)});
}

std::optional<double> referenceRay(const glm::dvec3& o, const glm::dvec3& d, const glm::dvec3& a,
                                   const glm::dvec3& b, const glm::dvec3& c) {
    const glm::dvec3 n = glm::cross(b - a, c - a);
    const double denom = glm::dot(n, d);
    if (denom == 0.0) return std::nullopt;
    const double t = glm::dot(n, a - o) / denom;
    const glm::dvec3 q = o + t * d;
    if (glm::dot(glm::cross(b - a, q - a), n) < 0.0 || glm::dot(glm::cross(c - b, q - b), n) < 0.0 ||
        glm::dot(glm::cross(a - c, q - c), n) < 0.0) {
        return std::nullopt;
    }
    return t;
}

struct Corners {
    glm::dvec3 a, b, c;
};
Corners cornersOf(const Soup& s, int32_t t) {
    const auto& tri = s.triangles[t];
    return {glm::dvec3(s.points[tri[0]]), glm::dvec3(s.points[tri[1]]), glm::dvec3(s.points[tri[2]])};
}

double bruteForceDistance(const Soup& s, const glm::vec3& query) {
    double best = std::numeric_limits<double>::infinity();
    for (int32_t t = 0; t < static_cast<int32_t>(s.triangles.size()); ++t) {
        const Corners k = cornersOf(s, t);
        best = std::min(best, referenceDistance2(glm::dvec3(query), k.a, k.b, k.c));
    }
    return std::sqrt(best);
}

std::optional<double> bruteForceRay(const Soup& s, const glm::vec3& origin, const glm::vec3& direction,
                                    float tMin, float tMax) {
    std::optional<double> best;
    for (int32_t t = 0; t < static_cast<int32_t>(s.triangles.size()); ++t) {
        const Corners k = cornersOf(s, t);
        const auto hit = referenceRay(glm::dvec3(origin), glm::dvec3(direction), k.a, k.b, k.c);
        if (hit && *hit >= tMin && *hit <= tMax && (!best || *hit < *best)) best = hit;
    }
    return best;
}

glm::dvec3 fromBarycentric(const Soup& s, int32_t t, const glm::vec3& b) {
    const Corners k = cornersOf(s, t);
    return double(b.x) * k.a + double(b.y) * k.b + double(b.z) * k.c;
}

void checkBarycentric(const glm::vec3& b) {
    CHECK(b.x + b.y + b.z == Approx(1.0f).margin(1e-6));
    CHECK(std::min({b.x, b.y, b.z}) >= -1e-6f);
}

// Compares closestPoint with the brute-force reference; `scale` is the size of the model.
void checkClosestPoint(const Bvh& bvh, const Soup& s, const glm::vec3& query, double scale) {
    const double expected = bruteForceDistance(s, query);
    const Bvh::ClosestPoint r = bvh.closestPoint(query);
    INFO("query (" << query.x << ", " << query.y << ", " << query.z << ")");
    REQUIRE(r.triangle >= 0);
    CHECK(r.face == r.triangle);
    CHECK(r.distance == Approx(expected).epsilon(1e-5).margin(1e-7 * scale));
    // The reported triangle really is that close (a tie may pick another triangle than the reference).
    const Corners k = cornersOf(s, r.triangle);
    CHECK(std::sqrt(referenceDistance2(glm::dvec3(query), k.a, k.b, k.c)) ==
          Approx(expected).epsilon(1e-5).margin(1e-7 * scale));
    CHECK(glm::length(fromBarycentric(s, r.triangle, r.barycentric) - glm::dvec3(r.point)) < 1e-6 * scale);
    CHECK(glm::length(glm::dvec3(query) - glm::dvec3(r.point)) ==
          Approx(expected).epsilon(1e-5).margin(1e-7 * scale));
    checkBarycentric(r.barycentric);
}

void checkRay(const Bvh& bvh, const Soup& s, const glm::vec3& origin, const glm::vec3& direction, float tMin,
              float tMax, double scale) {
    const auto expected = bruteForceRay(s, origin, direction, tMin, tMax);
    const auto hit = bvh.intersectRay(origin, direction, tMin, tMax);
    INFO("ray (" << origin.x << ", " << origin.y << ", " << origin.z << ") + t (" << direction.x << ", "
                 << direction.y << ", " << direction.z << "), t in [" << tMin << ", " << tMax << "]");
    REQUIRE(hit.has_value() == expected.has_value());
    if (!hit) return;
    CHECK(hit->t == Approx(*expected).epsilon(1e-5).margin(1e-7 * scale));
    CHECK(hit->t >= tMin);
    CHECK(hit->t <= tMax);
    CHECK(hit->face == hit->triangle);
    const glm::dvec3 onRay = glm::dvec3(origin) + double(hit->t) * glm::dvec3(direction);
    CHECK(glm::length(onRay - glm::dvec3(hit->point)) < 1e-5 * scale);
    CHECK(glm::length(fromBarycentric(s, hit->triangle, hit->barycentric) - glm::dvec3(hit->point)) <
          1e-5 * scale);
    checkBarycentric(hit->barycentric);
}

struct Scene {
    const char* name;
    Soup soup;
    Box3 queryBox;  // where query points and ray origins are drawn
};

std::vector<Scene> scenes() {
    std::vector<Scene> out;
    out.push_back({"sphere", soupOf(makeSphere({1.0f, 48, 24})), {glm::vec3(-2.0f), glm::vec3(2.0f)}});
    out.push_back({"capped tube",
                   soupOf(makeCappedTube({1.0f, 4.0f, 64, 48, 6})),
                   {glm::vec3(-2.0f, -1.0f, -2.0f), glm::vec3(2.0f, 5.0f, 2.0f)}});
    out.push_back({"triangle soup", randomSoup(1500, 3), {glm::vec3(-0.25f), glm::vec3(1.25f)}});
    return out;
}

glm::vec3 randomIn(const Box3& box, std::mt19937& rng) {
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    return box.min + glm::vec3(u(rng), u(rng), u(rng)) * box.extent();
}

}  // namespace

TEST_CASE("bvh closestPoint matches a brute-force search", "[geom][bvh]") {
    for (const Scene& scene : scenes()) {
        SECTION(scene.name) {
            const Bvh bvh(scene.soup.points, scene.soup.triangles);
            CHECK(bvh.numTriangles() == static_cast<int32_t>(scene.soup.triangles.size()));
            const double scale = glm::length(scene.queryBox.extent());
            std::mt19937 rng(42);
            for (int q = 0; q < 2000; ++q)
                checkClosestPoint(bvh, scene.soup, randomIn(scene.queryBox, rng), scale);
            // Queries on the surface: distance ~0, where relative precision matters most.
            std::uniform_real_distribution<float> u(0.0f, 1.0f);
            for (int q = 0; q < 200; ++q) {
                const auto t = static_cast<int32_t>(rng() % scene.soup.triangles.size());
                const float b1 = u(rng) * 0.5f, b2 = u(rng) * 0.5f;
                const glm::vec3 p =
                    glm::vec3(fromBarycentric(scene.soup, t, glm::vec3(1.0f - b1 - b2, b1, b2)));
                CHECK(bvh.closestPoint(p).distance <= 1e-6 * scale);
            }
        }
    }
}

TEST_CASE("bvh intersectRay matches a brute-force search", "[geom][bvh]") {
    for (const Scene& scene : scenes()) {
        SECTION(scene.name) {
            const Bvh bvh(scene.soup.points, scene.soup.triangles);
            Box3 modelBox;
            for (const auto& p : scene.soup.points)
                modelBox.extend(p);
            const double scale = glm::length(scene.queryBox.extent());
            std::mt19937 rng(43);
            std::uniform_real_distribution<float> u(0.0f, 1.0f);
            int hits = 0;
            for (int q = 0; q < 2000; ++q) {
                const glm::vec3 origin = randomIn(scene.queryBox, rng);
                // Aimed at the model so most rays hit; unnormalised directions.
                const glm::vec3 direction = (randomIn(modelBox, rng) - origin) * (0.5f + 2.0f * u(rng));
                float tMin = 0.0f, tMax = std::numeric_limits<float>::infinity();
                if (q % 4 == 1) tMin = u(rng);
                if (q % 4 == 2) tMax = 0.2f + u(rng);
                checkRay(bvh, scene.soup, origin, direction, tMin, tMax, scale);
                hits += bvh.intersectRay(origin, direction, tMin, tMax).has_value() ? 1 : 0;
            }
            CHECK(hits > 500);
        }
    }
}

TEST_CASE("bvh closestPoint on a sphere mesh: closed-form bounds", "[geom][bvh]") {
    const float r = 1.3f;
    const int32_t segments = 48, rings = 24;
    const Mesh sphere = makeSphere({r, segments, rings});
    const Bvh bvh(sphere);
    // Every face lies in a cap around one of its corners of angular radius at most D (one latitude step plus
    // one longitude step), so every surface point has r cos D <= |x| <= r: a sagitta of r (1 - cos D).
    const double D = std::numbers::pi / rings + 2.0 * std::numbers::pi / segments;
    const double sagitta = r * (1.0 - std::cos(D));
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    for (int q = 0; q < 2000; ++q) {
        glm::vec3 dir(u(rng), u(rng), u(rng));
        if (glm::length(dir) < 0.1f) continue;
        dir = glm::normalize(dir);
        const double radius =
            q % 2 == 0 ? r * (1.0 + 2.0 * std::abs(u(rng))) : r * std::cos(D) * std::abs(u(rng));
        const glm::vec3 p = dir * static_cast<float>(radius);
        const double len = glm::length(glm::dvec3(p));
        const double d = bvh.closestPoint(p).distance;
        if (len > r) {
            CHECK(d >= len - r - 1e-5);
            CHECK(d <= len - r + sagitta + 1e-5);
        } else {
            CHECK(d >= r * std::cos(D) - len - 1e-5);
            CHECK(d <= r - len + 1e-5);
        }
    }
    // Beyond a vertex v, at p = 1.5 v, the closest point is v itself: every surface point x has |x| <= r,
    // so (p - v) . (v - x) >= 0 and |p - x| >= |p - v|.
    for (int32_t v = 0; v < sphere.numVertices(); ++v) {
        const glm::vec3 vertex = sphere.points()[v];
        const auto c = bvh.closestPoint(1.5f * vertex);
        CHECK(c.distance == Approx(0.5 * glm::length(glm::dvec3(vertex))).epsilon(1e-6));
        CHECK(glm::length(c.point - vertex) < 1e-5f);
    }
}

TEST_CASE("bvh rays along an axis hit a grid at the exact parameter, from both sides", "[geom][bvh]") {
    const Mesh grid = makeGrid({10, 10, 2.0f, 2.0f});
    const Bvh bvh(grid);
    CHECK(bvh.numTriangles() == 200);
    // Cell (1, 2) of size 0.2 holds (0.31, 0.47): quad 2 * 10 + 1.
    auto down = bvh.intersectRay({0.31f, 0.47f, 3.0f}, {0.0f, 0.0f, -2.0f});
    REQUIRE(down);
    CHECK(down->t == 1.5f);
    CHECK(down->point == glm::vec3(0.31f, 0.47f, 0.0f));
    CHECK(down->face == 21);
    auto up = bvh.intersectRay({0.31f, 0.47f, -1.0f}, {0.0f, 0.0f, 0.5f});
    REQUIRE(up);
    CHECK(up->t == 2.0f);
    CHECK(up->face == 21);
    CHECK_FALSE(bvh.intersectRay({0.31f, 0.47f, 3.0f}, {0.0f, 0.0f, -2.0f}, 0.0f, 1.4f));
    CHECK_FALSE(bvh.intersectRay({0.31f, 0.47f, 3.0f}, {0.0f, 0.0f, -2.0f}, 1.6f));
    CHECK_FALSE(bvh.intersectRay({0.31f, 0.47f, 3.0f}, {0.0f, 0.0f, 1.0f}));
    CHECK_FALSE(bvh.intersectRay({2.5f, 0.47f, 3.0f}, {0.0f, 0.0f, -1.0f}));
    // Through a grid vertex shared by six triangles: still one hit.
    auto vertex = bvh.intersectRay({0.4f, 0.6f, 1.0f}, {0.0f, 0.0f, -1.0f});
    REQUIRE(vertex);
    CHECK(vertex->t == 1.0f);

    // Closest points project straight down onto the grid.
    const auto c = bvh.closestPoint({1.13f, 0.71f, 0.25f});
    CHECK(c.distance == Approx(0.25f));
    CHECK(c.face == 3 * 10 + 5);
    CHECK(c.point.x == Approx(1.13f));
    CHECK(c.point.y == Approx(0.71f));
    CHECK(c.point.z == 0.0f);
    CHECK(bvh.bounds().min == grid.bounds().min);
    CHECK(bvh.bounds().max == grid.bounds().max);

    // A sphere seen from its centre along +z: the ray passes exactly through the pole vertex.
    const Bvh sphere(makeSphere({0.75f, 16, 8}));
    auto pole = sphere.intersectRay(glm::vec3(0.0f), {0.0f, 0.0f, 1.0f});
    REQUIRE(pole);
    CHECK(pole->t == 0.75f);
}

TEST_CASE("bvh closestPoint prunes by maxDistance", "[geom][bvh]") {
    const Bvh bvh(makeSphere({1.0f, 32, 16}));
    // The closest point to (0, 0, 1.5) is the pole vertex, at 0.5.
    const auto none = bvh.closestPoint({0.0f, 0.0f, 1.5f}, 0.4f);
    CHECK(none.triangle == -1);
    CHECK(none.face == -1);
    CHECK(std::isinf(none.distance));
    const auto within = bvh.closestPoint({0.0f, 0.0f, 1.5f}, 0.6f);
    CHECK(within.triangle >= 0);
    CHECK(within.distance == 0.5f);
    CHECK(bvh.closestPoint({0.0f, 0.0f, 1.5f}, 0.5f).triangle >= 0);  // the bound is inclusive
    CHECK(bvh.closestPoint({0.0f, 0.0f, 1.5f}, 0.0f).triangle == -1);
    CHECK(bvh.closestPoint({0.0f, 0.0f, 1.0f}, 0.0f).triangle >= 0);
}

TEST_CASE("bvh refit after a deformation answers like a rebuild", "[geom][bvh]") {
    const Mesh sphere = makeSphere({1.0f, 40, 20});
    Soup rest = soupOf(sphere);
    Bvh refitted(rest.points, rest.triangles);
    std::mt19937 rng(9);
    std::uniform_real_distribution<float> noise(-0.05f, 0.05f);
    for (int step = 0; step < 3; ++step) {
        Soup deformed = rest;
        for (auto& p : deformed.points) {
            // A bulge, a shear and noise; the last step scrambles far more than the tree was built for.
            const float bulge = 1.0f + 0.4f * std::sin(2.0f * p.x + static_cast<float>(step));
            p = glm::vec3(p.x * bulge + 0.3f * p.z * p.z, p.y * bulge, p.z * (2.0f - bulge)) +
                glm::vec3(noise(rng), noise(rng), noise(rng)) * (step == 2 ? 10.0f : 1.0f);
        }
        refitted.refit(deformed.points);
        const Bvh rebuilt(deformed.points, deformed.triangles);
        CHECK(refitted.bounds().min == rebuilt.bounds().min);
        CHECK(refitted.bounds().max == rebuilt.bounds().max);
        const Box3 box{glm::vec3(-2.0f), glm::vec3(2.0f)};
        for (int q = 0; q < 300; ++q) {
            const glm::vec3 p = randomIn(box, rng);
            const auto a = refitted.closestPoint(p), b = rebuilt.closestPoint(p);
            CHECK(a.distance == Approx(b.distance).epsilon(1e-6));
            CHECK(a.distance == Approx(bruteForceDistance(deformed, p)).epsilon(1e-5));
            const glm::vec3 direction = randomIn(box, rng) - p;
            const auto ha = refitted.intersectRay(p, direction), hb = rebuilt.intersectRay(p, direction);
            REQUIRE(ha.has_value() == hb.has_value());
            if (ha) CHECK(ha->t == Approx(hb->t).epsilon(1e-6));
        }
    }
}

TEST_CASE("bvh: empty input and errors", "[geom][bvh][errors]") {
    const Bvh empty(std::span<const glm::vec3>{}, std::span<const std::array<int32_t, 3>>{});
    CHECK(empty.numTriangles() == 0);
    CHECK(empty.bounds().empty());
    CHECK(empty.closestPoint(glm::vec3(0.0f)).triangle == -1);
    CHECK_FALSE(empty.intersectRay(glm::vec3(0.0f), {1.0f, 0.0f, 0.0f}));

    const std::vector<glm::vec3> points{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    std::vector<std::array<int32_t, 3>> triangles{{0, 1, 2}, {0, 2, 4}};
    CHECK_THROWS_WITH(Bvh(points, triangles), Catch::Contains("triangle 1 corner 2") &&
                                                  Catch::Contains("vertex index 4 is out of range") &&
                                                  Catch::Contains("[0, 4)"));
    triangles[1] = {0, -1, 3};
    CHECK_THROWS_AS(Bvh(points, triangles), deformkit::InvalidInput);
    triangles[1] = {0, 1, 3};
    Bvh bvh(points, triangles);
    const std::vector<glm::vec3> fewer(3);
    CHECK_THROWS_WITH(bvh.refit(fewer), Catch::Contains("got 3 positions") && Catch::Contains("4 positions"));
    std::vector<glm::vec3> nan = points;
    nan[2].y = std::numeric_limits<float>::quiet_NaN();
    CHECK_THROWS_WITH(bvh.refit(nan), Catch::Contains("vertex 2"));
    CHECK_THROWS_AS(Bvh(nan, triangles), deformkit::InvalidInput);
    CHECK_THROWS_AS(bvh.closestPoint(glm::vec3(std::numeric_limits<float>::quiet_NaN())),
                    deformkit::InvalidInput);
    CHECK_THROWS_AS(bvh.closestPoint(glm::vec3(0.0f), -1.0f), deformkit::InvalidInput);
    CHECK_THROWS_AS(bvh.intersectRay(glm::vec3(0.0f), glm::vec3(0.0f)), deformkit::InvalidInput);
    // Still usable after the failed refits.
    CHECK(bvh.closestPoint({0.2f, 0.2f, -1.0f}).distance == Approx(1.0f));
}
