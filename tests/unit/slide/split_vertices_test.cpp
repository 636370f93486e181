#include <catch2/catch.hpp>

#include <algorithm>
#include <cstring>
#include <map>
#include <numeric>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "deformkit/error.h"
#include "deformkit/geom/half_edge.h"
#include "deformkit/geom/weld.h"
#include "deformkit/slide/slider.h"
#include "mesh_support.h"
#include "slide_real_meshes.h"
#include "test_support.h"

// Meshes as glTF, FBX and game-engine files hand them over: vertices split wherever UVs break, or every
// triangle with its own corners. The slide welds them (geom/weld.h) and must give, copy by copy, exactly the
// slide of the mesh with shared vertices.

using namespace deformkit;
using namespace deformkit::slide;
using Catch::Contains;

namespace {

struct Case {
    std::vector<SlideHandle> handles;
    std::vector<SlideDrive> drives;
    SlideOptions options;
    std::vector<float> weights;  // per original vertex, or empty
};

Case randomCase(const geom::Mesh& mesh, std::mt19937& rng) {
    const double size = test::diagonal(mesh.points());
    std::uniform_int_distribution<int32_t> vertex(0, mesh.numVertices() - 1);
    std::uniform_real_distribution<double> unit(0.0, 1.0), signedUnit(-1.0, 1.0);
    Case c;
    const int handles = unit(rng) < 0.3 ? 2 : 1;
    for (int h = 0; h < handles; ++h) {
        const RegionMetric metric = unit(rng) < 0.5 ? RegionMetric::Euclidean : RegionMetric::Geodesic;
        c.handles.push_back({vertex(rng), size * (0.05 + 0.15 * unit(rng)), metric});
        SlideDrive drive;
        drive.displacement = glm::dvec3(signedUnit(rng), signedUnit(rng), signedUnit(rng)) * (0.08 * size);
        c.drives.push_back(drive);
    }
    c.options.foldLimit = unit(rng) < 0.4;
    if (unit(rng) < 0.25) c.options.surface = SurfaceMode::Limit;
    if (unit(rng) < 0.3) {
        c.weights.resize(static_cast<size_t>(mesh.numVertices()));
        for (float& w : c.weights)
            w = static_cast<float>(unit(rng));
    }
    return c;
}

}  // namespace

TEST_CASE("slide on split vertices: every copy moves bit for bit as the shared vertex, on Spot and Bob",
          "[slide][weld]") {
    std::mt19937 rng(20261204);
    int moved = 0, cases = 0;
    for (const geom::Mesh* mesh : {&test::spot(), &test::bob()}) {
        for (const bool perCorner : {false, true}) {
            std::vector<int32_t> original;
            const geom::Mesh split = test::splitCopy(*mesh, perCorner, original);
            CAPTURE(split.numVertices(), mesh->numVertices(), perCorner);
            REQUIRE(split.numVertices() > mesh->numVertices());
            // The file's first copy of each original vertex (for handles given on the split mesh), and the
            // reference: the shared-vertex mesh numbered by first copies.
            std::vector<int32_t> firstCopy(static_cast<size_t>(mesh->numVertices()), -1), order;
            for (int32_t k = 0; k < split.numVertices(); ++k) {
                if (firstCopy[static_cast<size_t>(original[k])] < 0) {
                    firstCopy[static_cast<size_t>(original[k])] = k;
                    order.push_back(original[k]);
                }
            }
            std::vector<int32_t> newIndex;
            const geom::Mesh shared = test::renumbered(*mesh, order, newIndex);
            for (int n = 0; n < 6; ++n, ++cases) {
                Case c = randomCase(*mesh, rng);
                for (SlideHandle& h : c.handles)
                    h.vertex = newIndex[static_cast<size_t>(h.vertex)];
                if (!c.weights.empty()) {
                    std::vector<float> permuted(c.weights.size());
                    for (size_t v = 0; v < c.weights.size(); ++v)
                        permuted[static_cast<size_t>(newIndex[v])] = c.weights[v];
                    c.weights = std::move(permuted);
                }
                CAPTURE(n, c.handles[0].vertex, c.options.foldLimit, c.weights.size(),
                        c.options.surface == SurfaceMode::Limit);
                SlideResult want;
                const std::vector<glm::vec3> expected =
                    slide::slide(shared, c.handles, c.drives, c.weights, 1.0f, c.options, &want);
                Case s = c;
                for (SlideHandle& h : s.handles)
                    h.vertex = firstCopy[static_cast<size_t>(order[static_cast<size_t>(h.vertex)])];
                if (!c.weights.empty()) {
                    s.weights.resize(static_cast<size_t>(split.numVertices()));
                    for (int32_t k = 0; k < split.numVertices(); ++k)
                        s.weights[k] =
                            c.weights[static_cast<size_t>(newIndex[static_cast<size_t>(original[k])])];
                }
                SlideResult got;
                const std::vector<glm::vec3> out =
                    slide::slide(split, s.handles, s.drives, s.weights, 1.0f, s.options, &got);
                int mismatches = 0;
                for (int32_t k = 0; k < split.numVertices(); ++k) {
                    const glm::vec3& a = out[k];
                    const glm::vec3& b =
                        expected[static_cast<size_t>(newIndex[static_cast<size_t>(original[k])])];
                    mismatches += std::memcmp(&a, &b, sizeof a) != 0 ? 1 : 0;
                }
                CHECK(mismatches == 0);
                CHECK(got.moved == want.moved);
                CHECK(got.flippedTriangles == want.flippedTriangles);
                CHECK(got.unreachable == want.unreachable);
                CHECK(got.unreachable == 0);
                CHECK(got.foldScale == want.foldScale);
                CHECK(got.welded == split.numVertices() - mesh->numVertices());
                // Landings: one per moved copy, on the same face and the same corners (as the file numbers
                // them) with the same barycentric coordinates.
                size_t copiesMoved = 0;
                for (const SlideLanding& l : want.landings)
                    for (int32_t k = 0; k < split.numVertices(); ++k)
                        copiesMoved += newIndex[static_cast<size_t>(original[k])] == l.vertex ? 1 : 0;
                REQUIRE(got.landings.size() == copiesMoved);
                std::map<int32_t, const SlideLanding*> byVertex;
                for (const SlideLanding& l : want.landings)
                    byVertex[l.vertex] = &l;
                for (const SlideLanding& l : got.landings) {
                    const SlideLanding& w = *byVertex.at(newIndex[static_cast<size_t>(original[l.vertex])]);
                    CHECK(l.face == w.face);
                    for (int k = 0; k < 3; ++k) {
                        CHECK(newIndex[static_cast<size_t>(original[l.triangle[k]])] == w.triangle[k]);
                        CHECK(l.barycentric[k] == w.barycentric[k]);
                    }
                }
                moved += want.moved;
            }
        }
    }
    CHECK(cases == 24);
    CHECK(moved > 1000);  // the drags are real
}

TEST_CASE("slide on split vertices: every copy's weight counts and is checked, errors name file vertices",
          "[slide][weld]") {
    const geom::Mesh& mesh = test::spot();
    std::vector<int32_t> original;
    const geom::Mesh split = test::splitCopy(mesh, true, original);  // every face its own corners
    // A handle and its region on the split mesh: some vertex whose copies the slide moves.
    const SlideHandle handle{0, 0.15 * test::diagonal(mesh.points())};
    const SlideDrive drive{glm::dvec3(0.02, 0.01, 0.0) * test::diagonal(mesh.points()), Falloff::smooth()};
    Slider slider(split, {handle});
    const std::span<const int32_t> active = slider.activeVertices();
    REQUIRE(active.size() > 4);
    // Copies of one original vertex with other weights: the welded vertex takes their mean, as if every copy
    // had it.
    const int32_t target = original[static_cast<size_t>(active[2])];
    std::vector<int32_t> copies;
    for (int32_t k = 0; k < split.numVertices(); ++k)
        if (original[static_cast<size_t>(k)] == target) copies.push_back(k);
    REQUIRE(copies.size() >= 2);
    std::vector<float> uneven(static_cast<size_t>(split.numVertices()), 1.0f), even = uneven;
    double sum = 0.0;
    for (size_t i = 0; i < copies.size(); ++i) {
        uneven[static_cast<size_t>(copies[i])] = i == 0 ? 0.0f : 1.0f;
        sum += uneven[static_cast<size_t>(copies[i])];
    }
    for (const int32_t k : copies)
        even[static_cast<size_t>(k)] = static_cast<float>(sum / static_cast<double>(copies.size()));
    std::vector<glm::vec3> a(split.points().begin(), split.points().end()), b = a;
    slider.evaluate({&drive, 1}, a, uneven);
    slider.evaluate({&drive, 1}, b, even);
    CHECK(std::memcmp(a.data(), b.data(), a.size() * sizeof(glm::vec3)) == 0);
    CHECK(a[static_cast<size_t>(copies[0])] != split.points()[static_cast<size_t>(copies[0])]);
    // A NaN weight on a copy other than the first, and a NaN point on a handle ring's copy: named by the
    // file's index, before anything is written.
    std::vector<float> bad = even;
    bad[static_cast<size_t>(copies.back())] = std::nanf("");
    std::vector<glm::vec3> points(split.points().begin(), split.points().end());
    CHECK_THROWS_WITH(slider.evaluate({&drive, 1}, points, bad),
                      Contains("weight of vertex " + std::to_string(copies.back()) + ": not finite"));
    // The handle's ring is read whatever the radius: a slider whose region is the handle alone.
    const geom::Welding weld = geom::weldVertices(split);
    const auto welded = [&](int32_t k) { return weld.weldedOf[static_cast<size_t>(k)]; };
    int32_t ringCopy = -1;  // the first copy of a vertex sharing a face with the handle
    for (int32_t f = 0; f < split.numFaces() && ringCopy < 0; ++f) {
        const auto face = split.face(f);
        if (std::ranges::none_of(face, [&](int32_t v) { return welded(v) == welded(handle.vertex); }))
            continue;
        for (const int32_t v : face)
            if (welded(v) != welded(handle.vertex)) ringCopy = weld.firstOf[static_cast<size_t>(welded(v))];
    }
    REQUIRE(ringCopy >= 0);
    Slider tiny(split, {{handle.vertex, 1e-6 * test::diagonal(mesh.points())}});
    points[static_cast<size_t>(ringCopy)].x = std::nanf("");
    const std::vector<glm::vec3> before = points;
    CHECK_THROWS_WITH(tiny.evaluate({&drive, 1}, points),
                      Contains("point of vertex " + std::to_string(ringCopy) + ": not finite"));
    CHECK(std::memcmp(points.data(), before.data(), points.size() * sizeof(glm::vec3)) == 0);
}

TEST_CASE("slide on split vertices: without welding the split mesh tears", "[slide][weld]") {
    // What the weld prevents: the Fox-like case of every triangle on its own, the handle's triangle alone
    // moves and the others stay, a crack.
    std::vector<int32_t> original;
    const geom::Mesh split = test::splitCopy(test::spot(), true, original);
    const geom::Welding weld = geom::weldVertices(split);
    CHECK(weld.merged() == split.numVertices() - test::spot().numVertices());
    CHECK(weld.mesh.numFaces() == test::spot().numFaces());
    CHECK(weld.mesh.halfEdges().report().components == test::spot().halfEdges().report().components);
    // A tolerance joins copies a little apart; a negative one is refused.
    geom::Mesh::Data data;
    data.points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1e-4f, 1, 0}, {1, 0, 0}, {1, 1, 0}};
    data.faceCounts = {3, 3};
    data.faceIndices = {0, 1, 2, 4, 5, 3};
    const geom::Mesh apart(std::move(data), "apart");
    CHECK(geom::weldVertices(apart).merged() == 1);  // vertex 4 onto 1
    CHECK(geom::weldVertices(apart, 1e-3).merged() == 2);
    CHECK_THAT(test::errorOf<InvalidInput>([&] { (void)geom::weldVertices(apart, -1.0, "apart.obj"); }),
               Contains("apart.obj: weld tolerance: is -1"));
    // Corners of one face never weld onto each other, but a tolerance that reaches across the mesh welds
    // them through a chain of copies (0 onto 4 onto 1): the edge collapses and the mesh around it tears or
    // turns non-manifold (on Spot at 0.05, a handle's fan). Refused, naming the edge, its face and length.
    CHECK_THAT(
        test::errorOf<InvalidInput>([&] { (void)geom::weldVertices(apart, 1.5, "apart.obj"); }),
        Contains(
            "apart.obj: weld tolerance: is 1.5: it welds the two ends of edge (0, 1) of face 0, 1 long"));
    CHECK_THAT(test::errorOf<InvalidInput>([&] { (void)geom::weldVertices(test::spot(), 0.05, "spot.obj"); }),
               Contains("spot.obj: weld tolerance: is 0.05: it welds the two ends of edge") &&
                   Contains(" of face "));
    // Every copy of the split Spot within a tolerance half its shortest edge: welded as exactly.
    double shortest = 1e30;
    const geom::Mesh spot = test::spot();
    for (size_t f = 0, offset = 0; f < spot.faceCounts().size(); offset += spot.faceCounts()[f++]) {
        const auto n = static_cast<size_t>(spot.faceCounts()[f]);
        for (size_t k = 0; k < n; ++k) {
            shortest = std::min(
                shortest, glm::distance(glm::dvec3(spot.points()[spot.faceIndices()[offset + k]]),
                                        glm::dvec3(spot.points()[spot.faceIndices()[offset + (k + 1) % n]])));
        }
    }
    REQUIRE(shortest > 0.0);
    CHECK(geom::weldVertices(split, 0.5 * shortest).merged() == weld.merged());
    // An edge of zero length (a sliver of coincident points, 2-3) welded through a copy (4) is no collapse of
    // the mesh: its face goes, nothing is refused.
    geom::Mesh::Data sliver;
    sliver.points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 1, 0}, {0, 1, 0}};
    sliver.faceCounts = {3, 3, 3};
    sliver.faceIndices = {0, 1, 2, 2, 3, 0, 4, 1, 0};
    const geom::Welding welded = geom::weldVertices(geom::Mesh(std::move(sliver), "sliver"), 1e-3);
    CHECK(welded.merged() == 2);
    CHECK(welded.mesh.numFaces() == 2);
}

TEST_CASE("weld: a face whose corners weld keeps the corners left, with their UVs", "[slide][weld]") {
    // Quads on coincident points, joined through an unused copy: (a) corners 3 and 4 weld onto each other
    // (consecutive), (b) the last corner welds onto the first (cyclically). Each becomes the triangle of its
    // distinct corners; the welded mesh's counts and indices agree, and every kept corner keeps its own UV.
    const auto check = [](std::vector<glm::vec3> points, std::vector<int32_t> quad,
                          std::vector<int32_t> triangle) {
        geom::Mesh::Data data;
        data.points = std::move(points);
        data.faceCounts = {4};
        data.faceIndices = quad;
        data.uvs = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
        data.uvIndices = {0, 1, 2, 3};
        const geom::Mesh mesh(std::move(data), "quad.obj");
        const geom::Welding weld = geom::weldVertices(mesh, 0.0, "quad.obj");
        REQUIRE(weld.merged() >= 1);
        REQUIRE(weld.mesh.numFaces() == 1);
        CHECK(weld.mesh.faceCounts()[0] == 3);
        std::vector<int32_t> corners, uvCorners;
        for (size_t k = 0; k < 3; ++k) {
            corners.push_back(weld.firstOf[static_cast<size_t>(weld.mesh.faceIndices()[k])]);
            uvCorners.push_back(weld.mesh.uvIndices()[k]);
        }
        CHECK(corners == triangle);
        CHECK(weld.fileFaceOf == std::vector<int32_t>{0});
        return uvCorners;
    };
    // (a) file vertex 0 is an unused copy of vertices 3 and 4: the quad 1 2 3 4 welds to 1 2 0 0.
    CHECK(check({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 0, 0}, {0, 0, 0}}, {1, 2, 3, 4}, {1, 2, 0}) ==
          std::vector<int32_t>{0, 1, 2});
    // (b) vertex 4, unused, is a copy of vertices 0 and 3: the quad 0 1 2 3 welds to 0 1 2 0.
    CHECK(check({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 0, 0}, {0, 0, 0}}, {0, 1, 2, 3}, {0, 1, 2}) ==
          std::vector<int32_t>{0, 1, 2});
    // Corners of one face never weld onto each other directly (a collapsed edge, not a split copy).
    geom::Mesh::Data data;
    data.points = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 0, 0}};
    data.faceCounts = {4};
    data.faceIndices = {0, 1, 2, 3};
    CHECK(geom::weldVertices(geom::Mesh(std::move(data), "quad.obj")).merged() == 0);
}

TEST_CASE("weld: random meshes of coincident points give consistent welded meshes", "[slide][weld]") {
    // Invariants on any input: the welded mesh is a valid mesh (counts and indices agree), each welded face
    // comes from its file face (fileFaceOf ascending), its corners are distinct, in the file face's order,
    // and each sits where a corner of the file face sits; every file vertex maps to a welded vertex at its
    // own position. 2,000 meshes of 3 to 7 faces over a few positions, so that coincident copies, unused
    // copies and faces that collapse are common. Fixed seed.
    std::mt19937 rng(20261207);
    int collapsedCorners = 0, meshes = 0;
    for (int trial = 0; trial < 2000; ++trial) {
        const int positions = 3 + static_cast<int>(rng() % 4);
        std::vector<glm::vec3> spots;
        for (int k = 0; k < positions; ++k)
            spots.emplace_back(static_cast<float>(k % 3), static_cast<float>(k / 3),
                               static_cast<float>(k % 2));
        geom::Mesh::Data data;
        const int vertices = positions + static_cast<int>(rng() % 6);
        for (int v = 0; v < vertices; ++v)
            data.points.push_back(v < positions ? spots[v] : spots[rng() % positions]);
        const int faces = 3 + static_cast<int>(rng() % 5);
        for (int f = 0; f < faces; ++f) {
            const int n = std::min(vertices, 3 + static_cast<int>(rng() % 3));
            std::vector<int32_t> corners;
            while (static_cast<int>(corners.size()) < n) {  // distinct file vertices within a face
                const auto v = static_cast<int32_t>(rng() % vertices);
                if (std::find(corners.begin(), corners.end(), v) == corners.end()) corners.push_back(v);
            }
            data.faceCounts.push_back(n);
            data.faceIndices.insert(data.faceIndices.end(), corners.begin(), corners.end());
        }
        const geom::Mesh mesh(std::move(data), "random.obj");
        geom::Welding weld;
        try {
            weld = geom::weldVertices(mesh, 0.0, "random.obj");
        } catch (const InvalidInput& e) {
            CHECK_THAT(e.what(), Contains("every face collapses"));
            continue;
        }
        ++meshes;
        if (weld.merged() == 0) continue;
        REQUIRE(weld.mesh.faceIndices().size() ==
                static_cast<size_t>(
                    std::accumulate(weld.mesh.faceCounts().begin(), weld.mesh.faceCounts().end(), 0)));
        for (int32_t v = 0; v < mesh.numVertices(); ++v)
            CHECK(weld.mesh.points()[weld.weldedOf[v]] == mesh.points()[v]);
        REQUIRE(weld.fileFaceOf.size() == static_cast<size_t>(weld.mesh.numFaces()));
        CHECK(std::is_sorted(weld.fileFaceOf.begin(), weld.fileFaceOf.end()));
        for (int32_t f = 0; f < weld.mesh.numFaces(); ++f) {
            const auto welded = weld.mesh.face(f);
            const auto file = mesh.face(weld.fileFaceOf[f]);
            CHECK(welded.size() >= 3);
            collapsedCorners += static_cast<int>(file.size() - welded.size());
            std::vector<int32_t> sorted(welded.begin(), welded.end());
            std::sort(sorted.begin(), sorted.end());
            CHECK(std::adjacent_find(sorted.begin(), sorted.end()) == sorted.end());
            // In the file face's (cyclic) order: each welded corner is the weld of a file corner after
            // the previous one's.
            size_t k = 0;
            for (const int32_t w : welded) {
                while (k < file.size() && weld.weldedOf[file[k]] != w)
                    ++k;
                CHECK(k < file.size());
            }
        }
    }
    CHECK(meshes > 1000);
    CHECK(collapsedCorners > 0);  // the case that once broke the welded mesh is among them
}
