// Ptex faces of meshes: OpenSubdiv face ids and adjacency checked against the geometry of the faces,
// filtered look-ups against linear paintings, per-vertex values, baking, and UDIM conversions.

#include <catch2/catch.hpp>

#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <random>
#include <set>

#include <glm/geometric.hpp>

#include "deformkit/error.h"
#include "deformkit/io/obj.h"
#include "deformkit/ptex/half.h"
#include "deformkit/ptex/ptex_mesh.h"

#include "../test_support.h"
#include "ptex_mesh_support.h"

using namespace deformkit;
using deformkit::ptex::PtexMesh;

namespace {

// A planar mesh mixing quads, triangles and a pentagon (with a straight-angle corner):
//
//   8 ------ 9 ---- 10          T  = (4, 5, 8),  T2 = (5, 9, 8)
//   | T  /T2  \  P   |          P  = (5, 6, 7, 10, 9)
//   4 ----- 5 ---- 6 ---- 7     Q0 = (0, 1, 5, 4), Q1 = (1, 2, 6, 5), Q2 = (2, 3, 7, 6)
//   |  Q0   |  Q1  |  Q2  |
//   0 ----- 1 ---- 2 ---- 3
geom::Mesh mixedMesh() {
    geom::Mesh::Data d;
    d.points = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0},    {3, 0, 0},    {0, 1, 0}, {1, 1, 0},
                {2, 1, 0}, {3, 1, 0}, {0.5f, 2, 0}, {2, 2.2f, 0}, {3, 2, 0}};
    d.faceCounts = {4, 4, 4, 3, 3, 5};
    d.faceIndices = {0, 1, 5, 4, 1, 2, 6, 5, 2, 3, 7, 6, 4, 5, 8, 5, 9, 8, 5, 6, 7, 10, 9};
    for (const glm::vec3& p : d.points)
        d.uvs.emplace_back(0.1f + 0.25f * p.x, 0.1f + 0.3f * p.y);
    d.uvIndices = d.faceIndices;
    return geom::Mesh(std::move(d), "mixed.obj");
}

// An n x n grid of unit quads in the plane z = 0 (UVs = position / n squeezed into [0.1, 0.9] of tile
// 1001, or spread over `tilesU` tiles along u); face k's corner list is rotated by k % 4 so that the Ptex
// (u, v) axes of neighbours point every which way.
geom::Mesh grid(int n, bool rotate, int tilesU = 1) {
    geom::Mesh::Data d;
    for (int j = 0; j <= n; ++j)
        for (int i = 0; i <= n; ++i) {
            d.points.emplace_back(i, j, 0);
            d.uvs.emplace_back(tilesU * (0.1f + 0.8f * i / n), 0.1f + 0.8f * j / n);
        }
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            const int v0 = j * (n + 1) + i;
            std::array<int, 4> c{v0, v0 + 1, v0 + n + 2, v0 + n + 1};
            if (rotate) std::rotate(c.begin(), c.begin() + (j * n + i) % 4, c.end());
            d.faceCounts.push_back(4);
            d.faceIndices.insert(d.faceIndices.end(), c.begin(), c.end());
        }
    d.uvIndices = d.faceIndices;
    return geom::Mesh(std::move(d), "grid.obj");
}

// The four corners of a Ptex face in 3D, written from the convention (quad corners; sub-face k: corner k,
// midpoint of edge k, centre, midpoint of edge k - 1), independently of PtexMesh::cornerWeights.
std::array<glm::dvec3, 4> ptexCorners(const geom::Mesh& mesh, const PtexMesh& pm, int32_t p) {
    const auto face = mesh.face(pm.meshFace(p));
    const auto P = [&](size_t k) { return glm::dvec3(mesh.points()[face[k % face.size()]]); };
    if (face.size() == 4) return {P(0), P(1), P(2), P(3)};
    const size_t n = face.size(), k = static_cast<size_t>(pm.subFace(p));
    glm::dvec3 centre(0.0);
    for (size_t c = 0; c < n; ++c)
        centre += P(c) / static_cast<double>(n);
    return {P(k), 0.5 * (P(k) + P(k + 1)), centre, 0.5 * (P(k + n - 1) + P(k))};
}

glm::dvec3 ptexPoint(const std::array<glm::dvec3, 4>& c, double u, double v) {
    return (1 - u) * (1 - v) * c[0] + u * (1 - v) * c[1] + u * v * c[2] + (1 - u) * v * c[3];
}

// A linear painting of the plane.
double paint(const glm::dvec3& p) {
    return 0.3 + 0.2 * p.x - 0.15 * p.y;
}
const double kPaintGradient = std::hypot(0.2, 0.15);

// The three meshes' paintings baked at 2^log2 texels per side.
ptex::PtexFile bakePaint(const geom::Mesh& mesh, const PtexMesh& pm, int8_t log2) {
    std::vector<float> values;
    for (const glm::vec3& p : mesh.points())
        values.push_back(static_cast<float>(paint(glm::dvec3(p))));
    return ptex::bakeVertexValues(pm, values, 1, {log2, log2, ptex::DataType::Float});
}

float floatAt(const ptex::PtexFile& file, int32_t face, size_t index) {
    float value = 0.0f;
    std::memcpy(&value, file.texels[face].data() + index * 4, 4);
    return value;
}

}  // namespace

TEST_CASE("ptex mesh: one Ptex face per quad and N per N-gon, in face order", "[ptex][mesh]") {
    const geom::Mesh mesh = mixedMesh();
    const PtexMesh pm(mesh, "mixed.obj");
    CHECK(pm.numPtexFaces() == 3 + 3 + 3 + 5);
    CHECK(pm.numMeshFaces() == 6);
    const std::vector<int32_t> first{0, 1, 2, 3, 6, 9};
    for (int32_t f = 0; f < 6; ++f)
        CHECK(pm.firstPtexFace(f) == first[f]);
    CHECK(pm.meshFace(4) == 3);
    CHECK(pm.subFace(4) == 1);
    CHECK(pm.subFace(1) == -1);
    CHECK(pm.meshFace(13) == 5);
    CHECK(pm.subFace(13) == 4);
    const auto infos = pm.faceInfos(3, 2);
    CHECK(infos[0].subface == false);
    CHECK(infos[10].subface == true);
    CHECK(infos[10].ures() == 8);
    CHECK(infos[10].vres() == 4);
}

TEST_CASE("ptex mesh: adjacency joins faces along the same segment of the surface", "[ptex][mesh]") {
    // Independent check of OpenSubdiv's adjacency: edge e of face p runs from corner e to corner e + 1 of
    // the Ptex face; its neighbour's edge must run along the same line the other way, over the same
    // segment (equal kinds) or over a half of it (a quad edge next to a sub-face's half edge).
    for (const geom::Mesh& mesh : {mixedMesh(), grid(3, true)}) {
        const PtexMesh pm(mesh);
        int shared = 0, boundary = 0;
        for (int32_t p = 0; p < pm.numPtexFaces(); ++p) {
            const auto c = ptexCorners(mesh, pm, p);
            for (int e = 0; e < 4; ++e) {
                const int32_t g = pm.adjFaces(p)[e];
                if (g < 0) {
                    ++boundary;
                    continue;
                }
                ++shared;
                const int ge = pm.adjEdges(p)[e];
                const auto d = ptexCorners(mesh, pm, g);
                const glm::dvec3 a0 = c[e], a1 = c[(e + 1) % 4], b0 = d[ge], b1 = d[(ge + 1) % 4];
                const bool pSub = pm.subFace(p) >= 0, gSub = pm.subFace(g) >= 0;
                const bool outer = [&](int edge, bool sub) { return !sub || edge == 0 || edge == 3; }(e,
                                                                                                      pSub);
                if (pSub == gSub || !outer) {
                    // The same segment, reversed; and the neighbour points back.
                    CHECK(glm::length(a0 - b1) < 1e-6);
                    CHECK(glm::length(a1 - b0) < 1e-6);
                    CHECK(pm.adjFaces(g)[ge] == p);
                    CHECK(pm.adjEdges(g)[ge] == e);
                } else {
                    // Quad edge and a half of it: the shorter lies on the longer, in the opposite direction.
                    const glm::dvec3 L0 = pSub ? b0 : a0, L1 = pSub ? b1 : a1, S0 = pSub ? a0 : b0,
                                     S1 = pSub ? a1 : b1;
                    const glm::dvec3 dir = L1 - L0;
                    for (const glm::dvec3& s : {S0, S1}) {
                        const double t = glm::dot(s - L0, dir) / glm::dot(dir, dir);
                        CHECK(glm::length(L0 + t * dir - s) < 1e-6);
                        CHECK(t > -1e-9);
                        CHECK(t < 1 + 1e-9);
                    }
                    CHECK(glm::dot(S1 - S0, dir) < 0.0);
                    CHECK(glm::length(S1 - S0) == Approx(0.5 * glm::length(dir)).epsilon(1e-6));
                }
            }
        }
        // Boundary Ptex edges, counted from the mesh: a quad's edge with no twin is one, an N-gon's two.
        int boundaryHalfEdges = 0;
        for (int32_t f = 0; f < mesh.numFaces(); ++f) {
            const auto face = mesh.face(f);
            for (size_t k = 0; k < face.size(); ++k) {
                const int32_t a = face[k], b = face[(k + 1) % face.size()];
                bool found = false;
                for (int32_t g = 0; g < mesh.numFaces() && !found; ++g) {
                    const auto other = mesh.face(g);
                    for (size_t m = 0; m < other.size(); ++m)
                        found = found || (other[m] == b && other[(m + 1) % other.size()] == a);
                }
                if (!found) boundaryHalfEdges += face.size() == 4 ? 1 : 2;
            }
        }
        CHECK(boundary == boundaryHalfEdges);
        CHECK(shared + boundary == 4 * pm.numPtexFaces());
    }
}

TEST_CASE("ptex mesh: corner weights place (u, v) bilinearly on the quad or sub-face", "[ptex][mesh]") {
    const geom::Mesh mesh = mixedMesh();
    const PtexMesh pm(mesh);
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    for (int32_t p = 0; p < pm.numPtexFaces(); ++p) {
        const auto face = mesh.face(pm.meshFace(p));
        const auto c = ptexCorners(mesh, pm, p);
        std::vector<double> w(face.size());
        for (int s = 0; s < 20; ++s) {
            const double u = unit(rng), v = unit(rng);
            pm.cornerWeights(p, u, v, w);
            glm::dvec3 at(0.0);
            double sum = 0.0;
            for (size_t k = 0; k < face.size(); ++k) {
                at += w[k] * glm::dvec3(mesh.points()[face[k]]);
                sum += w[k];
                CHECK(w[k] >= 0.0);
            }
            CHECK(sum == Approx(1.0).margin(1e-12));
            CHECK(glm::length(at - ptexPoint(c, u, v)) < 1e-12 * 10);
        }
    }
}

TEST_CASE("ptex mesh: baking a linear painting stores its value at every texel centre", "[ptex][mesh]") {
    const geom::Mesh mesh = mixedMesh();
    const PtexMesh pm(mesh);
    const ptex::PtexFile file = bakePaint(mesh, pm, 3);
    REQUIRE(file.faces.size() == static_cast<size_t>(pm.numPtexFaces()));
    // A linear painting interpolated over the corners equals the painting at the interpolated point; the
    // texels are float, so within float rounding of values below 1.
    double worst = 0.0;
    for (int32_t p = 0; p < pm.numPtexFaces(); ++p) {
        const auto c = ptexCorners(mesh, pm, p);
        for (int j = 0; j < 8; ++j)
            for (int i = 0; i < 8; ++i)
                worst = std::max(worst, std::abs(floatAt(file, p, static_cast<size_t>(j * 8 + i)) -
                                                 paint(ptexPoint(c, (i + 0.5) / 8, (j + 0.5) / 8))));
    }
    CHECK(worst < 1e-6);

    SECTION("8-bit texels round to the nearest 1/255") {
        std::vector<float> values;
        for (const glm::vec3& p : mesh.points())
            values.push_back(static_cast<float>(paint(glm::dvec3(p))));
        const auto u8 = ptex::bakeVertexValues(pm, values, 1, {1, 1, ptex::DataType::UInt8});
        const auto c = ptexCorners(mesh, pm, 5);
        const double expected = paint(ptexPoint(c, 0.75, 0.25));
        CHECK(std::abs(u8.texels[5][1] / 255.0 - expected) <= 0.5 / 255 + 1e-7);
    }
    SECTION("bad inputs name the problem") {
        std::vector<float> values(static_cast<size_t>(mesh.numVertices()), 0.5f);
        CHECK_THAT(test::errorOf<InvalidInput>([&] { (void)ptex::bakeVertexValues(pm, values, 2); }),
                   Catch::Contains("11 vertices x 2 channels"));
        values[7] = std::nanf("");
        CHECK_THAT(test::errorOf<InvalidInput>([&] { (void)ptex::bakeVertexValues(pm, values, 1); }),
                   Catch::Contains("vertex 7"));
        values[7] = 0.0f;
        CHECK_THAT(test::errorOf<InvalidInput>([&] {
                       (void)ptex::bakeVertexValues(pm, values, 1, {16, 1});
                   }),
                   Catch::Contains("[0, 15]"));
    }
}

TEST_CASE("ptex sampler: bilinear look-ups reproduce a linear painting across face edges", "[ptex][mesh]") {
    // On a grid of unit squares every face maps affinely to the plane, so the painting is linear in each
    // face's (u, v) and bilinear filtering reproduces it exactly, also beyond edges and corners where texels
    // come from neighbours whose axes are rotated. Tolerance: float texels of values below 1 (1e-6).
    const geom::Mesh mesh = grid(4, true);
    const PtexMesh pm(mesh);
    const ptex::PtexFile file = bakePaint(mesh, pm, 2);
    const ptex::PtexSampler sampler(file, "paint.ptx");
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    double worstInside = 0.0;
    for (int32_t p = 0; p < pm.numPtexFaces(); ++p) {
        const auto c = ptexCorners(mesh, pm, p);
        bool interior = true;  // all four neighbours exist: no clamping at the mesh boundary
        for (int e = 0; e < 4; ++e)
            interior = interior && pm.adjFaces(p)[e] >= 0;
        if (!interior) continue;
        for (int s = 0; s < 200; ++s) {
            const double u = unit(rng), v = unit(rng);
            float value = 0.0f;
            sampler.sample(p, u, v, std::span<float>(&value, 1));
            worstInside = std::max(worstInside, std::abs(value - paint(ptexPoint(c, u, v))));
        }
    }
    CHECK(worstInside < 1e-6);
}

TEST_CASE("ptex sampler: constant faces of any declared size cost one pixel and read across edges",
          "[ptex][mesh]") {
    // Faces 0 and 2 constant and declared 32768 x 32768 (float RGBA: 16 GiB each expanded), face 1 painted
    // (2 x 2) between them: face 0's edge 1 meets face 1's edge 3, face 1's edge 1 meets face 2's edge 3.
    ptex::PtexFile file;
    file.dataType = ptex::DataType::Float;
    file.channels = 4;
    file.faces.resize(3);
    file.texels.resize(3);
    for (const int f : {0, 2}) {
        file.faces[f].ulog2 = file.faces[f].vlog2 = 15;
        file.faces[f].constant = true;
    }
    file.faces[1].ulog2 = file.faces[1].vlog2 = 1;
    file.faces[0].adjFaces[1] = 1, file.faces[0].adjEdges[1] = 3;
    file.faces[1].adjFaces[3] = 0, file.faces[1].adjEdges[3] = 1;
    file.faces[1].adjFaces[1] = 2, file.faces[1].adjEdges[1] = 3;
    file.faces[2].adjFaces[3] = 1, file.faces[2].adjEdges[3] = 1;
    const std::array<float, 4> left{0.1f, 0.2f, 0.3f, 0.4f}, right{0.9f, 0.8f, 0.7f, 0.6f};
    std::vector<float> painted(2 * 2 * 4);
    for (size_t k = 0; k < painted.size(); ++k)
        painted[k] = 0.05f * static_cast<float>(k);
    file.texels[1].resize(painted.size() * sizeof(float));
    std::memcpy(file.texels[1].data(), painted.data(), file.texels[1].size());
    file.constData.resize(3 * file.pixelSize());
    std::memcpy(file.constData.data(), left.data(), sizeof left);
    std::memcpy(file.constData.data() + 2 * file.pixelSize(), right.data(), sizeof right);
    const ptex::PtexSampler sampler(file, "constant.ptx");  // 64 bytes of values, not 32 GiB
    std::array<float, 4> out{};
    sampler.sample(0, 0.3, 0.7, out);  // inside a constant face: its value
    CHECK(out == left);
    CHECK(sampler.texel(2, 32767, 32767, 2) == right[2]);
    // Face 1 at u = 0 (texel centres at u = 0.25, 0.75): half its first column, half the ghost column read
    // from face 0 across the edge, on row j = 0 (v = 0.25, a texel centre).
    sampler.sample(1, 0.0, 0.25, out);
    for (int c = 0; c < 4; ++c)
        CHECK(out[c] == static_cast<float>(left[c] + 0.5 * (static_cast<double>(painted[c]) - left[c])));
    // And at u = 1 towards face 2.
    sampler.sample(1, 1.0, 0.25, out);
    for (int c = 0; c < 4; ++c) {
        const float last = painted[4 + c];  // texel (1, 0)
        CHECK(out[c] == static_cast<float>(last + 0.5 * (static_cast<double>(right[c]) - last)));
    }
}

TEST_CASE("ptex sampler: continuous across quad, triangle and pentagon edges", "[ptex][mesh]") {
    // Mixed mesh: the painting is reproduced to first order everywhere (within the gradient times one
    // texel's diagonal, the resolution of the map), and a point on a shared edge reads the same value from
    // both faces where both have the same kind (an exact ghost texel), to float rounding.
    const geom::Mesh mesh = mixedMesh();
    const PtexMesh pm(mesh);
    const ptex::PtexFile file = bakePaint(mesh, pm, 3);
    const ptex::PtexSampler sampler(file, "paint.ptx");
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    double worstRatio = 0.0;
    for (int32_t p = 0; p < pm.numPtexFaces(); ++p) {
        const auto c = ptexCorners(mesh, pm, p);
        const double texelDiagonal = std::max(glm::length(c[2] - c[0]), glm::length(c[3] - c[1])) / 8.0;
        for (int s = 0; s < 100; ++s) {
            const double u = unit(rng), v = unit(rng);
            float value = 0.0f;
            sampler.sample(p, u, v, std::span<float>(&value, 1));
            worstRatio = std::max(
                worstRatio, std::abs(value - paint(ptexPoint(c, u, v))) / (kPaintGradient * texelDiagonal));
        }
        for (int e = 0; e < 4; ++e) {
            const int32_t g = pm.adjFaces(p)[e];
            if (g < 0 || (pm.subFace(p) >= 0) != (pm.subFace(g) >= 0)) continue;
            const int ge = pm.adjEdges(p)[e];
            for (double t : {0.3, 0.5, 0.7}) {
                // Edge parameter t on p's edge e is 1 - t on g's edge ge.
                const auto onEdge = [](int edge, double s) {
                    return edge == 0   ? glm::dvec2(s, 0)
                           : edge == 1 ? glm::dvec2(1, s)
                           : edge == 2 ? glm::dvec2(1 - s, 1)
                                       : glm::dvec2(0, 1 - s);
                };
                const glm::dvec2 a = onEdge(e, t), b = onEdge(ge, 1 - t);
                REQUIRE(glm::length(ptexPoint(c, a.x, a.y) - ptexPoint(ptexCorners(mesh, pm, g), b.x, b.y)) <
                        1e-6);
                float va = 0.0f, vb = 0.0f;
                sampler.sample(p, a.x, a.y, std::span<float>(&va, 1));
                sampler.sample(g, b.x, b.y, std::span<float>(&vb, 1));
                CHECK(va == Approx(vb).margin(2e-6));
            }
        }
    }
    CHECK(worstRatio < 1.0);
}

TEST_CASE("ptex mesh: per-vertex values average the corner texels of the incident faces", "[ptex][mesh]") {
    const geom::Mesh mesh = mixedMesh();
    const PtexMesh pm(mesh);
    // Constant faces: face p holds p + 1 in channel 0 and 10 (p + 1) in channel 1. The value at a vertex
    // is the mean over the Ptex faces touching it at a corner (a sub-face touches only its own corner).
    const ptex::PtexFile file = test::constantFaces(
        pm, 2, 2, [](int32_t p, int32_t c) { return c == 0 ? p + 1.0f : 10.0f * (p + 1); });
    std::map<int32_t, std::vector<double>> touching;
    for (int32_t f = 0; f < mesh.numFaces(); ++f) {
        const auto face = mesh.face(f);
        for (size_t k = 0; k < face.size(); ++k)
            touching[face[k]].push_back(face.size() == 4
                                            ? pm.firstPtexFace(f) + 1.0
                                            : pm.firstPtexFace(f) + static_cast<double>(k) + 1.0);
    }
    const std::vector<float> values = ptex::vertexValues(pm, file, "const.ptx");
    REQUIRE(values.size() == 2 * 11u);
    for (const auto& [vertex, list] : touching) {
        double mean = 0.0;
        for (double x : list)
            mean += x / static_cast<double>(list.size());
        CHECK(values[2 * vertex] == Approx(mean).epsilon(1e-6));
        CHECK(values[2 * vertex + 1] == Approx(10 * mean).epsilon(1e-6));
    }

    SECTION("a quad's corner k reads texel (0,0), (u max, 0), (u max, v max), (0, v max)") {
        ptex::PtexFile one = bakePaint(mesh, pm, 2);
        // Overwrite every texel with a code of its face and position; vertex 0 is corner 0 of Q0 alone,
        // vertex 3 corner 1 of Q2 alone, vertex 7 corner 2 of Q2 and corner 2 of the pentagon (sub-face 2).
        for (int32_t p = 0; p < pm.numPtexFaces(); ++p)
            for (int j = 0; j < 4; ++j)
                for (int i = 0; i < 4; ++i) {
                    const float code = 100.0f * p + 10.0f * j + i;
                    std::memcpy(one.texels[p].data() + 4 * (j * 4 + i), &code, 4);
                }
        const auto v = ptex::vertexValues(pm, one, "codes.ptx");
        CHECK(v[0] == 0.0f);
        CHECK(v[3] == 200.0f + 3.0f);
        CHECK(v[7] == Approx(0.5 * ((200 + 33) + 100 * (pm.firstPtexFace(5) + 2))));
        CHECK(v[10] == Approx(100.0 * (pm.firstPtexFace(5) + 3)));

        // A NaN at a corner texel is refused, naming the file, the face, the texel and the channel (it
        // averaged into a NaN weight, written to JSON as "nan"); one inside the face is not read.
        const float nan = std::numeric_limits<float>::quiet_NaN();
        ptex::PtexFile inside = one;
        std::memcpy(inside.texels[2].data() + 4 * (1 * 4 + 1), &nan, 4);  // texel (1, 1): not a corner
        CHECK(ptex::vertexValues(pm, inside, "inside.ptx") == v);
        std::memcpy(one.texels[2].data() + 4 * (0 * 4 + 3), &nan, 4);  // texel (3, 0): Q2's corner 1
        CHECK_THAT(test::errorOf<InvalidInput>([&] { (void)ptex::vertexValues(pm, one, "codes.ptx"); }),
                   Catch::Contains("codes.ptx: face 2 texel (3, 0) channel 0: is nan"));
    }
}

TEST_CASE("ptex mesh: a face beyond OpenSubdiv's limit is named, not printed by OpenSubdiv", "[ptex][mesh]") {
    // A 65536-gon: OpenSubdiv's limit is 65535 corners (it printed its own error on stdout and the message
    // named no face).
    const int32_t n = 65536;
    geom::Mesh::Data data;
    for (int32_t k = 0; k < n; ++k) {
        const double a = 2.0 * 3.14159265358979323846 * k / n;
        data.points.emplace_back(static_cast<float>(std::cos(a)), static_cast<float>(std::sin(a)), 0.0f);
    }
    data.faceCounts = {n};
    for (int32_t k = 0; k < n; ++k)
        data.faceIndices.push_back(k);
    const geom::Mesh disc(std::move(data), "disc.obj");
    CHECK_THROWS_AS(PtexMesh(disc, "disc.obj"), TopologyError);
    CHECK_THROWS_WITH(PtexMesh(disc, "disc.obj"),
                      Catch::Contains("disc.obj: face 0: has 65536 corners (expected at most 65535"));
}

TEST_CASE("ptex mesh: a file of another mesh is refused, naming the file and both counts", "[ptex][mesh]") {
    const geom::Mesh mesh = mixedMesh();
    const PtexMesh pm(mesh, "mixed.obj");
    const geom::Mesh other = grid(2, false);
    const ptex::PtexFile file = bakePaint(other, PtexMesh(other), 1);
    const std::string message =
        test::errorOf<InvalidInput>([&] { (void)ptex::vertexValues(pm, file, "paint.ptx"); });
    CHECK_THAT(message, Catch::Contains("paint.ptx"));
    CHECK_THAT(message, Catch::Contains("has 4 faces"));
    CHECK_THAT(message, Catch::Contains("14 Ptex faces"));
    CHECK_THAT(message, Catch::Contains("mixed.obj"));
    // As many faces, other kinds (no mesh metadata to tell): a quad and a triangle (4 Ptex faces, 3 of them
    // sub-faces) against a file of 4 quads, whose texels would land on the wrong faces.
    geom::Mesh::Data d;
    d.points = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {2, 0.5f, 0}};
    d.faceCounts = {4, 3};
    d.faceIndices = {0, 1, 2, 3, 1, 4, 2};
    const geom::Mesh quadTriangle(std::move(d), "qt.obj");
    const PtexMesh qt(quadTriangle, "qt.obj");
    REQUIRE(qt.numPtexFaces() == 4);
    CHECK_THAT(test::errorOf<InvalidInput>([&] { (void)ptex::vertexValues(qt, file, "paint.ptx"); }),
               Catch::Contains(
                   "paint.ptx: face 1: is a whole quad, where mesh qt.obj has sub-face 0 of its 3-gon 1"));

    ptex::PtexFile bad = bakePaint(mesh, pm, 1);
    bad.faces[3].adjFaces[1] = 99;
    CHECK_THAT(test::errorOf<InvalidInput>([&] { (void)ptex::PtexSampler(bad, "bad.ptx"); }),
               Catch::Contains("face 3 edge 1"));
    // A non-finite texel: filtered look-ups would spread it (a UDIM image made from it held 256 NaN
    // pixels for one NaN texel, inf became NaN). Named where it is.
    ptex::PtexFile holed = bakePaint(mesh, pm, 1);
    REQUIRE(holed.dataType == ptex::DataType::Float);
    const float nan = std::nanf("");
    const size_t at =
        (static_cast<size_t>(1) * holed.faces[5].ures() + 1) * holed.pixelSize();  // texel (1, 1)
    std::memcpy(holed.texels[5].data() + at, &nan, sizeof nan);
    CHECK_THAT(test::errorOf<InvalidInput>([&] { (void)ptex::PtexSampler(holed, "holed.ptx"); }),
               Catch::Contains("holed.ptx: face 5 texel (1, 1) channel 0: is nan (expected finite values"));
    // The float copy counts against the reading cap with the texels as stored. In a float file each face's
    // copy is its texels as stored, or its one constant value: the cap fits both and not one byte fewer.
    const ptex::PtexFile paint = bakePaint(mesh, pm, 2);
    REQUIRE(paint.dataType == ptex::DataType::Float);
    uint64_t stored = paint.constData.size(), floats = 0;
    for (const auto& texels : paint.texels) {
        stored += texels.size();
        floats += texels.empty() ? paint.pixelSize() : texels.size();
    }
    REQUIRE(floats > 0);
    CHECK_NOTHROW(ptex::PtexSampler(paint, "paint.ptx", stored + floats));
    CHECK_THAT(test::errorOf<InvalidInput>(
                   [&] { (void)ptex::PtexSampler(paint, "paint.ptx", stored + floats - 1); }),
               Catch::Contains("paint.ptx: texels: " + std::to_string(stored) + " bytes as stored and " +
                               std::to_string(floats) + " as floats for filtering (expected at most " +
                               std::to_string(stored + floats - 1)));
}

TEST_CASE("ptex mesh: a file whose mesh metadata lists other polygons, or these in another order, is refused",
          "[ptex][mesh]") {
    const geom::Mesh mesh = mixedMesh();
    const PtexMesh pm(mesh, "mixed.obj");
    const std::vector<int32_t> counts(mesh.faceCounts().begin(), mesh.faceCounts().end());
    const std::vector<int32_t> indices(mesh.faceIndices().begin(), mesh.faceIndices().end());
    const auto painted = [&](const std::vector<int32_t>& c, const std::vector<int32_t>& i) {
        ptex::PtexFile file = bakePaint(mesh, pm, 1);
        file.metadata.push_back(ptex::MetaValue::ofInt32("PtexFaceVertCounts", c));
        file.metadata.push_back(ptex::MetaValue::ofInt32("PtexFaceVertIndices", i));
        return file;
    };
    const std::vector<float> reference = ptex::vertexValues(pm, bakePaint(mesh, pm, 1), "paint.ptx");
    // Its own polygons, and the same with the vertices numbered otherwise (one-to-one): read alike.
    CHECK(ptex::vertexValues(pm, painted(counts, indices), "paint.ptx") == reference);
    std::vector<int32_t> renumbered = indices;
    for (int32_t& v : renumbered)
        v = (v * 7 + 3) % mesh.numVertices();  // 7 is prime to 11 vertices: a permutation
    CHECK(ptex::vertexValues(pm, painted(counts, renumbered), "paint.ptx") == reference);
    // The same polygons in another order (Q0 and Q1 swapped: the same face count and sizes), as a mesh
    // exported again would list them: every face's texels would land on another face.
    geom::Mesh::Data swapped;
    swapped.points.assign(mesh.points().begin(), mesh.points().end());
    swapped.faceCounts = counts;
    swapped.faceIndices = indices;
    std::swap_ranges(swapped.faceIndices.begin(), swapped.faceIndices.begin() + 4,
                     swapped.faceIndices.begin() + 4);
    const geom::Mesh reordered(std::move(swapped), "reordered");
    const PtexMesh other(reordered, "reordered.obj");
    CHECK_THAT(
        test::errorOf<InvalidInput>(
            [&] { (void)ptex::vertexValues(other, painted(counts, indices), "paint.ptx"); }),
        Catch::Contains(
            "paint.ptx: metadata: polygon 1: corner 0 pairs file vertex 1 with mesh vertex 0, but in "
            "the polygons before it file vertex 1 was mesh vertex 2: ") &&
            Catch::Contains("the file was painted on another mesh, or on its polygons in another order "
                            "(expected the polygons of mesh reordered.obj, in its order"));
    std::vector<int32_t> triangleFirst = counts;
    triangleFirst[0] = 3;
    CHECK_THAT(test::errorOf<InvalidInput>(
                   [&] { (void)ptex::vertexValues(pm, painted(triangleFirst, indices), "paint.ptx"); }),
               Catch::Contains("paint.ptx: metadata: polygon 0: has 3 corners where mesh polygon 0 has 4"));
    CHECK_THAT(test::errorOf<InvalidInput>([&] {
                   (void)ptex::vertexValues(pm, painted({4, 4}, {0, 1, 5, 4, 1, 2, 6, 5}), "paint.ptx");
               }),
               Catch::Contains("paint.ptx: metadata PtexFaceVertCounts: lists 2 polygons (expected 6: "));
    // A triangle-mesh file is named as one, whatever its face count.
    ptex::PtexFile triangles = bakePaint(mesh, pm, 1);
    triangles.meshType = ptex::MeshType::Triangle;
    triangles.faces.pop_back();
    CHECK_THAT(test::errorOf<InvalidInput>([&] { (void)ptex::vertexValues(pm, triangles, "tri.ptx"); }),
               Catch::Contains("tri.ptx: header: is a triangle-mesh Ptex file"));
}

TEST_CASE("ptex mesh: split vertices (glTF, FBX) are one vertex: faces across a seam are neighbours",
          "[ptex][mesh]") {
    // mixedMesh with every face on its own copies of its corners, as a glTF splits a mesh at every seam.
    const geom::Mesh shared = mixedMesh();
    geom::Mesh::Data d;
    for (int32_t f = 0; f < shared.numFaces(); ++f) {
        d.faceCounts.push_back(static_cast<int32_t>(shared.face(f).size()));
        for (const int32_t v : shared.face(f)) {
            d.faceIndices.push_back(static_cast<int32_t>(d.points.size()));
            d.points.push_back(shared.points()[static_cast<size_t>(v)]);
        }
    }
    const geom::Mesh split(std::move(d), "split.gltf");
    const PtexMesh a(shared, "mixed.obj"), b(split, "split.gltf");
    REQUIRE(a.numPtexFaces() == b.numPtexFaces());
    for (int32_t p = 0; p < a.numPtexFaces(); ++p) {
        CHECK(a.adjFaces(p) == b.adjFaces(p));
        CHECK(a.adjEdges(p) == b.adjEdges(p));
    }
    // A file painted on the shared-vertex mesh (its metadata: that mesh's polygons) belongs to the split one,
    // whose per-vertex values are each copy's vertex's.
    ptex::PtexFile painted = bakePaint(shared, a, 1);
    const ptex::MeshData metadata = ptex::meshData(shared);
    painted.metadata.push_back(ptex::MetaValue::ofInt32("PtexFaceVertCounts", metadata.faceVertCounts));
    painted.metadata.push_back(ptex::MetaValue::ofInt32("PtexFaceVertIndices", metadata.faceVertIndices));
    const std::vector<float> onShared = ptex::vertexValues(a, painted, "paint.ptx");
    const std::vector<float> onSplit = ptex::vertexValues(b, painted, "paint.ptx");
    for (int32_t f = 0, corner = 0; f < shared.numFaces(); ++f)
        for (const int32_t v : shared.face(f))
            CHECK(onSplit[static_cast<size_t>(corner++)] ==
                  Approx(onShared[static_cast<size_t>(v)]).margin(1e-6));
    // The split mesh's own metadata lists the shared polygons, their 11 vertices numbered by first use (one
    // to one with the shared mesh's, at the same positions), not 23 copies.
    const ptex::MeshData own = ptex::meshData(split);
    REQUIRE(own.faceVertIndices.size() == metadata.faceVertIndices.size());
    CHECK(own.vertPositions.size() == 3u * 11);
    std::map<int32_t, int32_t> sharedOf;
    for (size_t c = 0; c < own.faceVertIndices.size(); ++c) {
        const int32_t mine = own.faceVertIndices[c], theirs = metadata.faceVertIndices[c];
        CHECK(sharedOf.try_emplace(mine, theirs).first->second == theirs);
        for (size_t k = 0; k < 3; ++k)
            CHECK(own.vertPositions[3 * static_cast<size_t>(mine) + k] ==
                  metadata.vertPositions[3 * static_cast<size_t>(theirs) + k]);
    }
    CHECK(sharedOf.size() == 11u);
    // Metadata that lists the split vertices themselves (a tool writing the split mesh as it is) belongs too.
    ptex::PtexFile asSplit = bakePaint(shared, a, 1);
    asSplit.metadata.push_back(ptex::MetaValue::ofInt32("PtexFaceVertCounts", metadata.faceVertCounts));
    asSplit.metadata.push_back(ptex::MetaValue::ofInt32(
        "PtexFaceVertIndices", std::vector<int32_t>(split.faceIndices().begin(), split.faceIndices().end())));
    CHECK(ptex::vertexValues(b, asSplit, "split.ptx") == onSplit);
    // and not to the shared mesh, two of whose corners it numbers apart.
    CHECK_THROWS_WITH(
        ptex::vertexValues(a, asSplit, "split.ptx"),
        Catch::Contains("split.ptx: metadata: polygon 1: corner 0 pairs file vertex 4 with mesh vertex 1"));
}

TEST_CASE("ptex mesh: UDIM and Ptex convert both ways through the mesh UVs", "[ptex][mesh][udim]") {
    // UVs are an affine image of the positions, so a painting linear in UV is linear on every face. From
    // UDIM: each texel is the bilinear image sample at its UV, exact for a linear image away from the tile
    // border (1e-5: float pixel coordinates). To UDIM: each covered pixel samples the Ptex map at the
    // (u, v) interpolated over a grid of cells on the face; exact for the linear map up to float (1e-4:
    // the raster's float (u, v) and the sampler's float texels).
    const geom::Mesh mesh = grid(4, true, 2);  // columns of faces end at u = 1: none crosses a tile
    const PtexMesh pm(mesh);
    const auto uvPaint = [](double u, double v) { return 0.2 + 0.15 * u + 0.4 * v; };  // u over both tiles
    const int res = 64;
    std::vector<ptex::UdimTile> tiles;
    for (int tile : {1001, 1002}) {
        ptex::UdimTile t{tile, io::Image(res, res, 1)};
        for (int y = 0; y < res; ++y)
            for (int x = 0; x < res; ++x)
                t.image.at(x, y, 0) =
                    static_cast<float>(uvPaint(tile - 1001 + (x + 0.5) / res, 1.0 - (y + 0.5) / res));
        tiles.push_back(std::move(t));
    }
    const ptex::PtexFile file = ptex::udimToPtex(pm, mesh, tiles, {3, 3, ptex::DataType::Float});
    double worst = 0.0;
    for (int32_t p = 0; p < pm.numPtexFaces(); ++p) {
        std::array<glm::dvec2, 4> uv;
        for (int k = 0; k < 4; ++k)
            uv[k] = glm::dvec2(mesh.uvs()[mesh.faceUVIndices(pm.meshFace(p))[k]]);
        for (int j = 0; j < 8; ++j)
            for (int i = 0; i < 8; ++i) {
                const double u = (i + 0.5) / 8, v = (j + 0.5) / 8;
                const glm::dvec2 at =
                    (1 - u) * (1 - v) * uv[0] + u * (1 - v) * uv[1] + u * v * uv[2] + (1 - u) * v * uv[3];
                worst = std::max(
                    worst, std::abs(floatAt(file, p, static_cast<size_t>(j * 8 + i)) - uvPaint(at.x, at.y)));
            }
    }
    CHECK(worst < 1e-5);

    SECTION("automatic face resolution follows the face's size in texels") {
        const ptex::PtexFile autoRes = ptex::udimToPtex(pm, mesh, tiles);
        // Each face spans 0.4 of a tile in u (the mesh is stretched over two tiles) and 0.2 in v: 25.6
        // and 12.8 texels -> 32 x 16 (nearest powers of two in log scale), whichever way its axes turn.
        for (const auto& info : autoRes.faces) {
            CHECK(std::set<int>{info.ures(), info.vres()} == std::set<int>{32, 16});
        }
    }

    const auto back = ptex::ptexToUdim(pm, mesh, file, "paint.ptx", {res, {}, true});
    REQUIRE(back.size() == 2);
    double worstBack = 0.0, worstNearBoundary = 0.0;
    int covered = 0, expectedCovered = 0;
    for (const auto& tile : back) {
        for (int y = 0; y < res; ++y)
            for (int x = 0; x < res; ++x) {
                const double u = (x + 0.5) / res, v = 1.0 - (y + 0.5) / res;
                // The mesh covers u = 2 (0.1 + 0.8 i / 4) in [0.2, 1.8] and v in [0.1, 0.9].
                const double globalU = u + (tile.tile - 1001);
                const bool inside = globalU > 0.2 && globalU < 1.8 && v > 0.1 && v < 0.9;
                expectedCovered += inside ? 1 : 0;
                if (tile.image.at(x, y, 1) != 1.0f) continue;
                ++covered;
                // Within one Ptex texel (0.05 of a tile) of the mesh boundary the sampler repeats the edge
                // texels (clamp), which is first-order there: gradient x texel.
                const double error = std::abs(tile.image.at(x, y, 0) - uvPaint(globalU, v));
                const bool nearBoundary = globalU < 0.25 || globalU > 1.75 || v < 0.15 || v > 0.85;
                if (nearBoundary)
                    worstNearBoundary = std::max(worstNearBoundary, error);
                else
                    worstBack = std::max(worstBack, error);
            }
    }
    CHECK(covered == expectedCovered);
    CHECK(worstBack < 1e-4);
    CHECK(worstNearBoundary < std::hypot(0.15, 0.4) * 0.05);

    SECTION("errors: no UVs, a tile without an image") {
        geom::Mesh::Data d;
        d.points = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
        d.faceCounts = {4};
        d.faceIndices = {0, 1, 2, 3};
        const geom::Mesh bare(std::move(d), "bare.obj");
        const PtexMesh barePm(bare, "bare.obj");
        CHECK_THAT(test::errorOf<InvalidInput>([&] { (void)ptex::udimToPtex(barePm, bare, tiles); }),
                   Catch::Contains("bare.obj") && Catch::Contains("no UVs"));
        const std::vector<ptex::UdimTile> oneTile(tiles.begin(), tiles.begin() + 1);
        CHECK_THAT(test::errorOf<InvalidInput>([&] { (void)ptex::udimToPtex(pm, mesh, oneTile); }),
                   Catch::Contains("UDIM tile 1002"));
    }
    SECTION("errors: values a texel of the type cannot hold, named where they are read") {
        // u8 and u16 hold [0, 1] (clamped before), half +-65504 (inf before): 2.0 and 1e5 are refused.
        std::vector<ptex::UdimTile> bright = tiles;
        bright[1].image.at(40, 20, 0) = 2.0f;
        CHECK_THAT(test::errorOf<InvalidInput>([&] {
                       (void)ptex::udimToPtex(pm, mesh, bright, {3, 3, ptex::DataType::UInt8});
                   }),
                   Catch::Contains("UDIM tile 1002: pixel (") && Catch::Contains(": is ") &&
                       Catch::Contains("(expected values in [0, 1] for u8 texels"));
        std::fill(bright[1].image.pixels.begin(), bright[1].image.pixels.end(), 1e5f);
        CHECK_THAT(test::errorOf<InvalidInput>([&] {
                       (void)ptex::udimToPtex(pm, mesh, bright, {3, 3, ptex::DataType::Half});
                   }),
                   Catch::Contains("(expected values within +-65504 for half texels"));
        CHECK_NOTHROW(ptex::udimToPtex(pm, mesh, bright, {3, 3, ptex::DataType::Float}));
        std::vector<float> values(static_cast<size_t>(mesh.numVertices()), 0.5f);
        values[7] = -0.5f;
        CHECK_THAT(test::errorOf<InvalidInput>([&] {
                       (void)ptex::bakeVertexValues(pm, values, 1, {2, 2, ptex::DataType::UInt16});
                   }),
                   Catch::Contains("vertex 7: has value -0.5 (expected values in [0, 1] for u16"));
        values[7] = 7e4f;
        CHECK_THAT(test::errorOf<InvalidInput>([&] {
                       (void)ptex::bakeVertexValues(pm, values, 1, {2, 2, ptex::DataType::Half});
                   }),
                   Catch::Contains("vertex 7: has value 70000 (expected values within +-65504"));
    }
    SECTION("errors: a face off the UDIM tiles or across two, both ways, naming it") {
        // The layout shifted left by a tile (u in [-0.8, 0.8]): its left faces lie off the tiles (u < 0),
        // where tile 1001's image was written blank and read from its clamped edge. Shifted right by 0.4 (u
        // in [0.6, 2.2]): the last column of faces, u in [1.8, 2.2], lies in tile 1003 and 0.2 into tile
        // 1002.
        for (const auto& [shift, tile, where] :
             {std::tuple{-1.0f, 1001, "off the UDIM tiles"}, std::tuple{0.4f, 1003, "in tile 1002"}}) {
            geom::Mesh::Data d;
            d.points.assign(mesh.points().begin(), mesh.points().end());
            for (const glm::vec2& uv : mesh.uvs())
                d.uvs.push_back(uv + glm::vec2(shift, 0.0f));
            d.faceCounts.assign(mesh.faceCounts().begin(), mesh.faceCounts().end());
            d.faceIndices.assign(mesh.faceIndices().begin(), mesh.faceIndices().end());
            d.uvIndices.assign(mesh.uvIndices().begin(), mesh.uvIndices().end());
            const geom::Mesh shifted(std::move(d), "shifted.obj");
            const PtexMesh shiftedPm(shifted, "shifted.obj");
            INFO("shift " << shift);
            for (const std::string& what :
                 {test::errorOf<InvalidInput>([&] { (void)ptex::udimToPtex(shiftedPm, shifted, tiles); }),
                  test::errorOf<InvalidInput>([&] {
                      (void)ptex::ptexToUdim(shiftedPm, shifted, file, "paint.ptx", {res, {tile}});
                  })}) {
                CHECK_THAT(what,
                           Catch::Contains("shifted.obj, UDIM tile " + std::to_string(tile) + ": face ") &&
                               Catch::Contains(": overhangs the tile by ") && Catch::Contains(where));
            }
        }
    }
}

TEST_CASE(
    "ptex mesh: to-udim covers every chart texel and pads chart edges, so a UDIM round trip keeps seams",
    "[ptex][mesh][udim]") {
    // Real layouts: Spot (quads) and Bob (triangles: three Ptex sub-faces each), tests/data.
    const auto name = GENERATE(as<std::string>{}, "spot/spot_quadrangulated.obj", "bob/bob_tri.obj");
    INFO(name);
    const geom::Mesh mesh = io::readObj(std::string(DEFORMKIT_TEST_DATA) + "/" + name).mesh;
    const PtexMesh pm(mesh, name);
    // A smooth painting in [0.1, 0.9] of the rest positions, baked at 8 × 8 texels a face.
    std::vector<float> values(static_cast<size_t>(mesh.numVertices()));
    for (size_t v = 0; v < values.size(); ++v) {
        const glm::vec3 p = mesh.points()[v];
        values[v] = 0.5f + 0.4f * std::sin(4.0f * p.x + 1.0f) * std::cos(3.0f * p.y + 2.0f * p.z);
    }
    const ptex::PtexFile file = ptex::bakeVertexValues(pm, values, 1, {3, 3, ptex::DataType::Float});
    const int res = 1024;
    const auto tiles = ptex::ptexToUdim(pm, mesh, file, name, {res, {}, true, 8});

    // The charts, found here: texel centres inside a UV face of the tile (fanned from its first corner),
    // by edge functions in double. Every one must hold a value (the painting is never 0 there), and so
    // must every texel touching a chart (the padding).
    size_t chartTexels = 0, uncovered = 0, unpadded = 0;
    for (const auto& tile : tiles) {
        const int tu = (tile.tile - 1001) % 10, tv = (tile.tile - 1001) / 10;
        std::vector<uint8_t> chart(static_cast<size_t>(res) * res, 0);
        for (int32_t f = 0; f < mesh.numFaces(); ++f) {
            const auto corners = mesh.faceUVIndices(f);
            if (mesh.faceUdimTile(f) != tile.tile) continue;
            std::vector<glm::dvec2> p;
            for (const int32_t c : corners)
                p.emplace_back((mesh.uvs()[c].x - tu) * res, (1.0 - (mesh.uvs()[c].y - tv)) * res);
            for (size_t k = 1; k + 1 < p.size(); ++k) {
                const glm::dvec2 a = p[0], b = p[k], c = p[k + 1];
                const double area = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
                if (area == 0.0) continue;
                const int x0 = std::max(0, static_cast<int>(std::floor(std::min({a.x, b.x, c.x}))));
                const int x1 = std::min(res - 1, static_cast<int>(std::ceil(std::max({a.x, b.x, c.x}))));
                const int y0 = std::max(0, static_cast<int>(std::floor(std::min({a.y, b.y, c.y}))));
                const int y1 = std::min(res - 1, static_cast<int>(std::ceil(std::max({a.y, b.y, c.y}))));
                for (int y = y0; y <= y1; ++y)
                    for (int x = x0; x <= x1; ++x) {
                        const glm::dvec2 q(x + 0.5, y + 0.5);
                        const auto side = [&](glm::dvec2 s, glm::dvec2 t) {
                            return ((t.x - s.x) * (q.y - s.y) - (t.y - s.y) * (q.x - s.x)) / area;
                        };
                        if (side(a, b) >= 0 && side(b, c) >= 0 && side(c, a) >= 0) chart[y * res + x] = 1;
                    }
            }
        }
        for (int y = 0; y < res; ++y)
            for (int x = 0; x < res; ++x) {
                if (!chart[y * res + x]) continue;
                ++chartTexels;
                if (tile.image.at(x, y, 0) == 0.0f) ++uncovered;
                for (int dy = -1; dy <= 1; ++dy)
                    for (int dx = -1; dx <= 1; ++dx) {
                        const int nx = x + dx, ny = y + dy;
                        if (nx >= 0 && ny >= 0 && nx < res && ny < res && tile.image.at(nx, ny, 0) == 0.0f)
                            ++unpadded;
                    }
            }
    }
    CHECK(chartTexels > 100000);
    CHECK(uncovered == 0);
    CHECK(unpadded == 0);

    // Ptex → UDIM → Ptex at the same face resolution: per-vertex values (a vertex on a seam reads texels at
    // the chart's edge in every chart it belongs to) stay within 0.05 of the original everywhere; without
    // padding, bilinear look-ups at seams mix in the 0 outside the charts (hundreds of vertices off).
    const ptex::PtexFile back = ptex::udimToPtex(pm, mesh, tiles, {3, 3, ptex::DataType::Float});
    const std::vector<float> before = ptex::vertexValues(pm, file, "paint.ptx");
    const std::vector<float> after = ptex::vertexValues(pm, back, "back.ptx");
    int off = 0;
    double worst = 0.0;
    for (size_t v = 0; v < before.size(); ++v) {
        const double d = std::abs(after[2 * v] - before[v]);  // channel 0 of (value, coverage)
        worst = std::max(worst, d);
        off += d > 0.05 ? 1 : 0;
    }
    INFO("worst " << worst);
    CHECK(off == 0);
}
