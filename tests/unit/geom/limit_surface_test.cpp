#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numbers>
#include <thread>
#include <utility>
#include <vector>

#include <glm/geometric.hpp>

#include "deformkit/error.h"
#include "deformkit/geom/limit_surface.h"

using namespace deformkit::geom;
using deformkit::InvalidInput;
using deformkit::TopologyError;

namespace {

using Faces = std::vector<std::vector<int32_t>>;
using Boundary = LimitSurfaceOptions::Boundary;

Mesh fromFaces(const std::vector<glm::dvec3>& points, const Faces& faces) {
    Mesh::Data d;
    for (const auto& p : points)
        d.points.emplace_back(p);
    for (const auto& f : faces) {
        d.faceCounts.push_back(static_cast<int32_t>(f.size()));
        d.faceIndices.insert(d.faceIndices.end(), f.begin(), f.end());
    }
    return Mesh(std::move(d));
}

// The cage positions as the surface sees them: float, widened to double.
std::vector<glm::dvec3> cagePoints(const Mesh& m) {
    return {m.points().begin(), m.points().end()};
}

std::vector<double> oneHot(int32_t n, int32_t k) {
    std::vector<double> w(n, 0.0);
    w[k] = 1.0;
    return w;
}

std::vector<double> bilinearWeights(double u, double v) {
    return {(1 - u) * (1 - v), u * (1 - v), u * v, (1 - u) * v};
}

// Corner weights of the point (u, v) of sub-face k of an n-gon: the bilinear combination of corner k, the
// midpoint of edge k (corners k, k + 1), the centre (all corners equally) and the midpoint of edge k - 1.
std::vector<double> subFaceWeights(int32_t n, int32_t k, double u, double v) {
    std::vector<double> w(n, u * v / n);
    w[k] += (1 - u) * (1 - v) + 0.5 * u * (1 - v) + 0.5 * (1 - u) * v;
    w[(k + 1) % n] += 0.5 * u * (1 - v);
    w[(k + n - 1) % n] += 0.5 * (1 - u) * v;
    return w;
}

double maxDistance(const glm::dvec3& a, const glm::dvec3& b) {
    return glm::length(a - b);
}

// ---------------------------------------------------------------------------------------------------------
// Reference Catmull-Clark, written independently of the library: one subdivision step of a manifold
// polygon mesh (with boundaries, no creases), then the closed-form limit positions of the resulting quad
// mesh's vertices: interior valence n (Halstead et al. 1993, eq. for the limit point)
//     (n^2 x + 4 sum(edge neighbours) + sum(diagonal neighbours)) / (n (n + 5)),
// boundary (a + 4 x + b) / 6 along the boundary cubic B-spline, a sharp corner stays where it is.
// ---------------------------------------------------------------------------------------------------------
struct Refined {
    std::vector<glm::dvec3> points;  // #V vertex points, then #F face points, then one point per edge
    Faces quads;
    std::vector<bool> corner;                                  // per refined point: a sharp corner
    std::map<std::pair<int32_t, int32_t>, int32_t> edgePoint;  // sorted cage edge -> refined point index

    [[nodiscard]] int32_t edge(int32_t a, int32_t b) const { return edgePoint.at(std::minmax(a, b)); }
};

Refined catmullClarkStep(const std::vector<glm::dvec3>& p, const Faces& faces, Boundary boundary) {
    const auto nv = static_cast<int32_t>(p.size());
    const auto nf = static_cast<int32_t>(faces.size());
    Refined r;
    r.points.assign(p.begin(), p.end());
    std::vector<glm::dvec3> facePoint(nf, glm::dvec3(0.0));
    for (int32_t f = 0; f < nf; ++f) {
        for (const int32_t v : faces[f])
            facePoint[f] += p[v];
        facePoint[f] /= static_cast<double>(faces[f].size());
        r.points.push_back(facePoint[f]);
    }
    std::map<std::pair<int32_t, int32_t>, std::vector<int32_t>> edgeFaces;
    for (int32_t f = 0; f < nf; ++f) {
        const auto n = static_cast<int32_t>(faces[f].size());
        for (int32_t k = 0; k < n; ++k)
            edgeFaces[std::minmax(faces[f][k], faces[f][(k + 1) % n])].push_back(f);
    }
    std::vector<std::vector<int32_t>> vertexFaces(nv);
    for (int32_t f = 0; f < nf; ++f)
        for (const int32_t v : faces[f])
            vertexFaces[v].push_back(f);
    std::vector<std::vector<int32_t>> vertexNeighbours(nv), boundaryNeighbours(nv);
    for (const auto& [e, ef] : edgeFaces) {
        const auto [a, b] = e;
        REQUIRE(ef.size() <= 2);  // the reference handles manifold meshes only
        glm::dvec3 q = 0.5 * (p[a] + p[b]);
        if (ef.size() == 2) q = 0.25 * (p[a] + p[b] + facePoint[ef[0]] + facePoint[ef[1]]);
        r.edgePoint[e] = static_cast<int32_t>(r.points.size());
        r.points.push_back(q);
        vertexNeighbours[a].push_back(b);
        vertexNeighbours[b].push_back(a);
        if (ef.size() == 1) {
            boundaryNeighbours[a].push_back(b);
            boundaryNeighbours[b].push_back(a);
        }
    }
    r.corner.assign(r.points.size(), false);
    for (int32_t v = 0; v < nv; ++v) {
        if (vertexFaces[v].empty()) continue;
        if (boundaryNeighbours[v].empty()) {
            const auto n = static_cast<double>(vertexNeighbours[v].size());
            glm::dvec3 favg(0.0), ravg(0.0);
            for (const int32_t f : vertexFaces[v])
                favg += facePoint[f];
            for (const int32_t u : vertexNeighbours[v])
                ravg += 0.5 * (p[v] + p[u]);
            favg /= static_cast<double>(vertexFaces[v].size());
            ravg /= n;
            r.points[v] = (favg + 2.0 * ravg + (n - 3.0) * p[v]) / n;
        } else {
            REQUIRE(boundaryNeighbours[v].size() == 2);
            if (vertexFaces[v].size() == 1 && boundary == Boundary::EdgesAndCorners) {
                r.corner[v] = true;  // stays put
            } else {
                r.points[v] = (p[boundaryNeighbours[v][0]] + 6.0 * p[v] + p[boundaryNeighbours[v][1]]) / 8.0;
            }
        }
    }
    for (int32_t f = 0; f < nf; ++f) {
        const auto n = static_cast<int32_t>(faces[f].size());
        for (int32_t k = 0; k < n; ++k) {
            const int32_t c = faces[f][k], next = faces[f][(k + 1) % n], prev = faces[f][(k + n - 1) % n];
            r.quads.push_back({c, r.edge(c, next), nv + f, r.edge(prev, c)});
        }
    }
    return r;
}

// Closed-form limit position of vertex x of a quad mesh (see above).
glm::dvec3 quadMeshLimit(const Refined& r, int32_t x) {
    glm::dvec3 edgeSum(0.0), diagonalSum(0.0);
    int n = 0;
    std::map<std::pair<int32_t, int32_t>, int> edgeUse;
    for (const auto& q : r.quads) {
        for (int i = 0; i < 4; ++i)
            edgeUse[std::minmax(q[i], q[(i + 1) % 4])] += 1;
    }
    std::vector<int32_t> boundary;
    for (const auto& q : r.quads) {
        for (int i = 0; i < 4; ++i) {
            if (q[i] != x) continue;
            ++n;
            edgeSum += r.points[q[(i + 1) % 4]];
            diagonalSum += r.points[q[(i + 2) % 4]];
            for (const int32_t nb : {q[(i + 1) % 4], q[(i + 3) % 4]})
                if (edgeUse[std::minmax(x, nb)] == 1) boundary.push_back(nb);
        }
    }
    REQUIRE(n > 0);
    if (boundary.empty())
        return (double(n * n) * r.points[x] + 4.0 * edgeSum + diagonalSum) / (n * (n + 5.0));
    REQUIRE(boundary.size() == 2);
    if (r.corner[x]) return r.points[x];
    return (r.points[boundary[0]] + 4.0 * r.points[x] + r.points[boundary[1]]) / 6.0;
}

// A bumpy open disc: a pentagon, a ring of four quads and two triangles around it, and an outer ring of
// quads. Interior vertices of valence 3 (pentagon corners), 4 and 5; a smooth boundary all round.
struct MixedMesh {
    std::vector<glm::dvec3> points;
    Faces faces;
};

MixedMesh mixedMesh() {
    MixedMesh m;
    for (int ring = 1; ring <= 3; ++ring) {
        for (int k = 0; k < 5; ++k) {
            const double a = 2.0 * std::numbers::pi * k / 5 + 0.1 * ring;
            const double radius = ring == 3 ? 3.2 : ring;
            m.points.emplace_back(radius * std::cos(a), radius * std::sin(a),
                                  0.3 * std::sin(1.7 * k + 2.3 * ring) + 0.1 * ring);
        }
    }
    const auto p = [](int k) { return k % 5; };
    const auto q = [](int k) { return 5 + k % 5; };
    const auto r = [](int k) { return 10 + k % 5; };
    m.faces.push_back({0, 1, 2, 3, 4});
    // Ring 1: the face between p0, q0, q1, p1 is split into two triangles.
    m.faces.push_back({p(0), q(0), q(1)});
    m.faces.push_back({p(0), q(1), p(1)});
    for (int k = 1; k < 5; ++k)
        m.faces.push_back({p(k), q(k), q(k + 1), p(k + 1)});
    for (int k = 0; k < 5; ++k)
        m.faces.push_back({q(k), r(k), r(k + 1), q(k + 1)});
    return m;
}

// Uniform cubic B-spline basis on a span, t in [0, 1]: weights of control points j - 1, j, j + 1, j + 2.
std::array<double, 4> cubicBSplineBasis(double t) {
    const double t2 = t * t, t3 = t2 * t;
    return {(1 - t) * (1 - t) * (1 - t) / 6.0, (3 * t3 - 6 * t2 + 4) / 6.0,
            (-3 * t3 + 3 * t2 + 3 * t + 1) / 6.0, t3 / 6.0};
}

// Periodic uniform cubic B-spline of the closed control polygon c, span j (from c[j] to c[j + 1]).
glm::dvec3 periodicBSpline(const std::vector<glm::dvec3>& c, int j, double t) {
    const auto n = static_cast<int>(c.size());
    const auto b = cubicBSplineBasis(t);
    glm::dvec3 p(0.0);
    for (int i = 0; i < 4; ++i)
        p += b[i] * c[((j - 1 + i) % n + n) % n];
    return p;
}

}  // namespace

TEST_CASE("limit surface of a flat uniform grid is the grid's plane, bilinear inside",
          "[geom][limit_surface]") {
    // An affine image of the integer lattice: a uniform cubic B-spline surface reproduces linear functions,
    // so the limit point of a face at (u, v) is the bilinear interpolation of its corners.
    const int nx = 9, ny = 7;
    const glm::dvec3 origin(3.0, -2.0, 1.0), e1(0.35, 0.07, 0.1), e2(-0.04, 0.3, 0.12);
    std::vector<glm::dvec3> pts;
    for (int j = 0; j <= ny; ++j)
        for (int i = 0; i <= nx; ++i)
            pts.push_back(origin + double(i) * e1 + double(j) * e2);
    Faces faces;
    const auto id = [&](int i, int j) { return j * (nx + 1) + i; };
    for (int j = 0; j < ny; ++j)
        for (int i = 0; i < nx; ++i)
            faces.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)});
    const Mesh grid = fromFaces(pts, faces);
    const auto cage = cagePoints(grid);
    const glm::dvec3 normal = glm::normalize(glm::cross(e1, e2));
    // Float cage coordinates (magnitude ~5) are rounded by ~3e-7; 1e-5 of the spacing (~3e-6) covers it.
    const double tol = 1e-5 * glm::length(e1);

    for (const Boundary boundary : {Boundary::EdgesAndCorners, Boundary::EdgesOnly}) {
        INFO("boundary " << static_cast<int>(boundary));
        const LimitSurface surface(grid, {.boundary = boundary});
        double worstPlane = 0.0, worstBilinear = 0.0, worstNormal = 0.0, worstDerivative = 0.0;
        for (int j = 0; j < ny; ++j) {
            for (int i = 0; i < nx; ++i) {
                const int32_t f = j * nx + i;
                // Interior faces: the 4x4 control net is all grid. With sharp corners the boundary rules
                // extrapolate linearly too, so every face is bilinear; rounded corners (EdgesOnly) are not.
                const bool linear =
                    boundary == Boundary::EdgesAndCorners || (i > 0 && j > 0 && i + 1 < nx && j + 1 < ny);
                for (const double u : {0.0, 0.2, 0.5, 0.9, 1.0}) {
                    for (const double v : {0.0, 0.3, 0.75, 1.0}) {
                        const auto w = bilinearWeights(u, v);
                        const LimitSample s = surface.evaluateWithDerivatives(f, w);
                        worstPlane = std::max(worstPlane, std::abs(glm::dot(s.position - origin, normal)));
                        worstNormal = std::max(worstNormal, glm::length(s.normal - normal));
                        if (!linear) continue;
                        glm::dvec3 bilinear(0.0);
                        for (int k = 0; k < 4; ++k)
                            bilinear += w[k] * cage[faces[f][k]];
                        worstBilinear = std::max(worstBilinear, maxDistance(s.position, bilinear));
                        worstDerivative =
                            std::max({worstDerivative, glm::length(s.dPdu - e1) / glm::length(e1),
                                      glm::length(s.dPdv - e2) / glm::length(e2)});
                    }
                }
            }
        }
        CHECK(worstPlane < tol);
        CHECK(worstBilinear < tol);
        // Unit normal and derivatives of the affine map: relative float rounding of the cage over a spacing.
        CHECK(worstNormal < 1e-5);
        CHECK(worstDerivative < 1e-5);

        // Cage corner (0, 0): a sharp corner is interpolated; a smooth one follows the boundary B-spline.
        const glm::dvec3 cornerExpected =
            boundary == Boundary::EdgesAndCorners
                ? cage[id(0, 0)]
                : (cage[id(1, 0)] + 4.0 * cage[id(0, 0)] + cage[id(0, 1)]) / 6.0;
        CHECK(maxDistance(surface.limitPosition(id(0, 0)), cornerExpected) < tol);
        CHECK(maxDistance(surface.evaluate(0, oneHot(4, 0)), cornerExpected) < tol);
    }
}

TEST_CASE("limit surface of a long prism tube: cross-sections are periodic cubic B-splines",
          "[geom][limit_surface]") {
    // N around, uniform straight rings: away from the open ends each face is a bicubic B-spline patch whose
    // cross-section is the closed uniform cubic B-spline of the N-gon and whose axial coordinate is linear.
    const int around = 7, rings = 9;
    const double spacing = 0.6;
    std::vector<glm::dvec3> section;
    for (int j = 0; j < around; ++j) {
        const double a = 2.0 * std::numbers::pi * j / around + 0.15 * std::sin(3.0 * j);
        const double radius = 1.0 + 0.25 * std::cos(2.0 * j) + 0.1 * j / around;
        section.emplace_back(radius * std::cos(a), radius * std::sin(a), 0.0);
    }
    std::vector<glm::dvec3> pts;
    for (int r = 0; r < rings; ++r)
        for (int j = 0; j < around; ++j)
            pts.push_back(section[j] + glm::dvec3(0.0, 0.0, r * spacing));
    Faces faces;
    const auto id = [&](int r, int j) { return r * around + (j % around); };
    for (int r = 0; r + 1 < rings; ++r)
        for (int j = 0; j < around; ++j)
            faces.push_back({id(r, j), id(r, j + 1), id(r + 1, j + 1), id(r + 1, j)});
    const Mesh tube = fromFaces(pts, faces);
    // The reference uses the float cross-section the surface sees.
    const auto cage = cagePoints(tube);
    std::vector<glm::dvec3> floatSection(cage.begin(), cage.begin() + around);
    for (auto& p : floatSection)
        p.z = 0.0;

    const LimitSurface surface(tube);
    double worst = 0.0;
    int checked = 0;
    // Faces between rings r and r + 1 with rings r - 1 and r + 2 present have a regular 4x4 control net.
    for (int r = 1; r + 2 < rings; ++r) {
        for (int j = 0; j < around; ++j) {
            const int32_t f = r * around + j;
            for (const double u : {0.0, 0.15, 0.5, 0.8, 1.0}) {
                for (const double v : {0.0, 0.4, 0.7, 1.0}) {
                    // Axially the B-spline of the rings' float z (uniform up to float rounding).
                    const auto b = cubicBSplineBasis(v);
                    double z = 0.0;
                    for (int i = 0; i < 4; ++i)
                        z += b[i] * cage[id(r - 1 + i, 0)].z;
                    const glm::dvec3 expected = periodicBSpline(floatSection, j, u) + glm::dvec3(0.0, 0.0, z);
                    worst =
                        std::max(worst, maxDistance(surface.evaluate(f, bilinearWeights(u, v)), expected));
                    ++checked;
                }
            }
        }
    }
    CHECK(checked == 6 * around * 20);
    // Exact polynomials on both sides, evaluated in double: 1e-9 of the tube's size is round-off only.
    CHECK(worst < 1e-9);
}

TEST_CASE("limit surface at vertices, edge points and face centres matches a reference Catmull-Clark",
          "[geom][limit_surface]") {
    const MixedMesh mixed = mixedMesh();
    const Mesh mesh = fromFaces(mixed.points, mixed.faces);
    const auto cage = cagePoints(mesh);
    const Refined ref = catmullClarkStep(cage, mixed.faces, Boundary::EdgesAndCorners);
    const LimitSurface surface(mesh);
    const int32_t nv = mesh.numVertices();
    // Both the patches' corners and the reference are exact limit positions (Gregory end caps interpolate
    // the limit position at their corners), computed in double from the same float cage.
    const double tol = 1e-9;
    REQUIRE(surface.numPtexFaces() == 9 + 5 + 3 + 3);  // 9 quads one each, the pentagon 5, triangles 3

    SECTION("limitPosition equals the reference and every face around the vertex at that corner") {
        for (int32_t v = 0; v < nv; ++v) {
            INFO("vertex " << v);
            CHECK(maxDistance(surface.limitPosition(v), quadMeshLimit(ref, v)) < tol);
        }
        int corners = 0;
        for (int32_t f = 0; f < mesh.numFaces(); ++f) {
            const auto n = static_cast<int32_t>(mixed.faces[f].size());
            for (int32_t k = 0; k < n; ++k) {
                INFO("face " << f << " corner " << k);
                CHECK(maxDistance(surface.evaluate(f, oneHot(n, k)),
                                  surface.limitPosition(mixed.faces[f][k])) < tol);
                ++corners;
            }
        }
        CHECK(corners == mesh.numCorners());
    }

    SECTION("Ptex orientation: sub-face and quad corners are the cage corner, edge points and centre") {
        for (int32_t f = 0; f < mesh.numFaces(); ++f) {
            const auto& face = mixed.faces[f];
            const auto n = static_cast<int32_t>(face.size());
            const int32_t first = surface.firstPtexFace(f);
            const glm::dvec3 centre = quadMeshLimit(ref, nv + f);
            for (int32_t k = 0; k < n; ++k) {
                INFO("face " << f << " corner " << k);
                const glm::dvec3 corner = quadMeshLimit(ref, face[k]);
                if (n == 4) {
                    const double u = (k == 1 || k == 2) ? 1.0 : 0.0, v = k >= 2 ? 1.0 : 0.0;
                    CHECK(maxDistance(surface.evaluateAt({first, u, v}).position, corner) < tol);
                    continue;
                }
                const glm::dvec3 nextEdge = quadMeshLimit(ref, ref.edge(face[k], face[(k + 1) % n]));
                const glm::dvec3 prevEdge = quadMeshLimit(ref, ref.edge(face[(k + n - 1) % n], face[k]));
                CHECK(maxDistance(surface.evaluateAt({first + k, 0.0, 0.0}).position, corner) < tol);
                CHECK(maxDistance(surface.evaluateAt({first + k, 1.0, 0.0}).position, nextEdge) < tol);
                CHECK(maxDistance(surface.evaluateAt({first + k, 0.0, 1.0}).position, prevEdge) < tol);
                // The face centre, the same point from every sub-face.
                CHECK(maxDistance(surface.evaluateAt({first + k, 1.0, 1.0}).position, centre) < tol);
            }
            // Equal weights are the centre too.
            CHECK(maxDistance(surface.evaluate(f, std::vector<double>(n, 1.0 / n)), centre) < tol);
        }
    }

    SECTION("points on an edge shared by two faces are the same limit point from both") {
        std::map<std::pair<int32_t, int32_t>, std::vector<std::pair<int32_t, int32_t>>>
            edges;  // -> (face, k)
        for (int32_t f = 0; f < mesh.numFaces(); ++f) {
            const auto n = static_cast<int32_t>(mixed.faces[f].size());
            for (int32_t k = 0; k < n; ++k)
                edges[std::minmax(mixed.faces[f][k], mixed.faces[f][(k + 1) % n])].emplace_back(f, k);
        }
        // Weights t on vertex a, 1 - t on vertex b, seen from one face.
        const auto onEdge = [&](int32_t f, int32_t a, int32_t b, double t) {
            const auto& face = mixed.faces[f];
            std::vector<double> w(face.size(), 0.0);
            for (size_t i = 0; i < face.size(); ++i) {
                if (face[i] == a) w[i] = t;
                if (face[i] == b) w[i] = 1.0 - t;
            }
            return surface.evaluate(f, w);
        };
        int shared = 0;
        double worst = 0.0;
        for (const auto& [e, users] : edges) {
            if (users.size() != 2) continue;
            ++shared;
            const int32_t edgePoint = ref.edgePoint.at(e);
            for (const double t : {0.1, 0.3, 0.5, 0.77}) {
                const glm::dvec3 a = onEdge(users[0].first, e.first, e.second, t);
                const glm::dvec3 b = onEdge(users[1].first, e.first, e.second, t);
                worst = std::max(worst, maxDistance(a, b));
                if (t == 0.5) {
                    INFO("edge " << e.first << "-" << e.second);
                    CHECK(maxDistance(a, quadMeshLimit(ref, edgePoint)) < tol);
                }
            }
        }
        CHECK(shared == 21);
        // Neighbouring patches share their boundary curve (the surface is watertight): round-off only.
        CHECK(worst < tol);
    }
}

TEST_CASE("limit surface with smooth corners matches the reference Catmull-Clark", "[geom][limit_surface]") {
    // A bent open strip of three quads, a triangle and a pentagon: vertices 0, 3 and 9 have one face, so
    // they are rounded off (EdgesOnly) or kept as corners (EdgesAndCorners).
    const std::vector<glm::dvec3> pts = {{0, 0, 0},       {1, 0, 0.2},    {2, 0, 0.1}, {3, 0.1, 0},
                                         {0, 1, 0.3},     {1, 1.1, 0.5},  {2, 1, 0.4}, {3, 1, 0.2},
                                         {1.5, 1.8, 0.6}, {2.5, 1.9, 0.3}};
    const Faces faces = {{0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6}, {4, 5, 8}, {5, 6, 7, 9, 8}};
    const Mesh mesh = fromFaces(pts, faces);
    const auto cage = cagePoints(mesh);
    for (const Boundary boundary : {Boundary::EdgesAndCorners, Boundary::EdgesOnly}) {
        INFO("boundary " << static_cast<int>(boundary));
        const Refined ref = catmullClarkStep(cage, faces, boundary);
        const LimitSurface surface(mesh, {.boundary = boundary});
        for (int32_t v = 0; v < mesh.numVertices(); ++v) {
            INFO("vertex " << v);
            // Exact limit positions on both sides, double arithmetic: round-off only.
            CHECK(maxDistance(surface.limitPosition(v), quadMeshLimit(ref, v)) < 1e-9);
        }
        for (int32_t f = 0; f < mesh.numFaces(); ++f) {
            const auto n = static_cast<int32_t>(faces[f].size());
            CHECK(maxDistance(surface.evaluate(f, std::vector<double>(n, 1.0 / n)),
                              quadMeshLimit(ref, mesh.numVertices() + f)) < 1e-9);
        }
    }
}

TEST_CASE("ptexLocation inverts the corner weights of quad and sub-face points", "[geom][limit_surface]") {
    const MixedMesh mixed = mixedMesh();
    const Mesh mesh = fromFaces(mixed.points, mixed.faces);
    const LimitSurface surface(mesh);
    for (int32_t f = 0; f < mesh.numFaces(); ++f) {
        const auto n = static_cast<int32_t>(mixed.faces[f].size());
        for (int32_t k = 0; k < (n == 4 ? 1 : n); ++k) {
            for (const double u : {0.0, 0.1, 0.45, 0.9, 1.0}) {
                for (const double v : {0.0, 0.3, 0.6, 0.95}) {
                    INFO("face " << f << " sub-face " << k << " u " << u << " v " << v);
                    const auto w = n == 4 ? bilinearWeights(u, v) : subFaceWeights(n, k, u, v);
                    const LimitSurface::PtexLocation at = surface.ptexLocation(f, w);
                    // Closed-form weights mapped back: round-off only. At u = 1 or v = 1 the point lies on
                    // the sub-face's border with a neighbour, so only the location is compared there.
                    if (n != 4 && (u == 1.0 || v == 1.0)) {
                        CHECK(maxDistance(surface.evaluateAt(at).position,
                                          surface.evaluateAt({surface.firstPtexFace(f) + k, u, v}).position) <
                              1e-9);
                        continue;
                    }
                    CHECK(at.ptexFace == surface.firstPtexFace(f) + k);
                    CHECK(at.u == Approx(u).margin(1e-12));
                    CHECK(at.v == Approx(v).margin(1e-12));
                }
            }
        }
    }
    // A fan-triangle barycentric point of the pentagon (corners 0, 2, 3) spread onto its corners: on the
    // regular reference pentagon it lies at ~175 degrees, within 36 degrees of corner 2 (144): sub-face 2.
    const std::vector<double> fan = {0.1, 0.0, 0.5, 0.4, 0.0};
    const auto at = surface.ptexLocation(0, fan);
    CHECK(at.ptexFace == surface.firstPtexFace(0) + 2);
}

TEST_CASE("limit surface derivatives match finite differences in the Ptex parameters",
          "[geom][limit_surface]") {
    const MixedMesh mixed = mixedMesh();
    const Mesh mesh = fromFaces(mixed.points, mixed.faces);
    const LimitSurface surface(mesh);
    const double h = 1e-5;
    double worst = 0.0;
    for (int32_t p = 0; p < surface.numPtexFaces(); ++p) {
        for (const double u : {0.2, 0.5, 0.7}) {
            for (const double v : {0.25, 0.6}) {
                const LimitSample s = surface.evaluateAt({p, u, v});
                const glm::dvec3 du = (surface.evaluateAt({p, u + h, v}).position -
                                       surface.evaluateAt({p, u - h, v}).position) /
                                      (2 * h);
                const glm::dvec3 dv = (surface.evaluateAt({p, u, v + h}).position -
                                       surface.evaluateAt({p, u, v - h}).position) /
                                      (2 * h);
                worst = std::max({worst, glm::length(s.dPdu - du), glm::length(s.dPdv - dv)});
                CHECK(glm::length(s.normal) == Approx(1.0).margin(1e-12));
                CHECK(glm::dot(s.normal, glm::cross(du, dv)) > 0.0);
            }
        }
    }
    // Central differences of a piecewise bicubic at h = 1e-5: truncation ~h^2 |P'''| plus round-off
    // ~1e-16 / h, both well below 1e-6 for this unit-sized cage (a factor-2 scale error would be ~1).
    CHECK(worst < 1e-6);
}

TEST_CASE("limit surface on a non-manifold edge stays consistent", "[geom][limit_surface]") {
    // Three quads share the edge 0-1: OpenSubdiv makes it infinitely sharp, so along it the surface is
    // the edge's own curve, the same from all three faces.
    const std::vector<glm::dvec3> pts = {{0, 0, 0},  {1, 0, 0},  {1, 1, 0}, {0, 1, 0},
                                         {1, -1, 0}, {0, -1, 0}, {1, 0, 1}, {0, 0, 1}};
    const Faces faces = {{0, 1, 2, 3}, {1, 0, 5, 4}, {0, 1, 6, 7}};
    const Mesh mesh = fromFaces(pts, faces);
    const LimitSurface surface(mesh);
    for (const double t : {0.0, 0.25, 0.5, 1.0}) {
        const glm::dvec3 a = surface.evaluate(0, std::vector<double>{1 - t, t, 0, 0});
        const glm::dvec3 b = surface.evaluate(1, std::vector<double>{t, 1 - t, 0, 0});
        const glm::dvec3 c = surface.evaluate(2, std::vector<double>{1 - t, t, 0, 0});
        // A sharp edge between two sharp corner-like ends is the straight segment: (t, 0, 0).
        CHECK(maxDistance(a, b) < 1e-12);
        CHECK(maxDistance(a, c) < 1e-12);
        CHECK(maxDistance(a, glm::dvec3(t, 0.0, 0.0)) < 1e-9);
    }
}

TEST_CASE("limit surface queries from several threads give the serial results", "[geom][limit_surface]") {
    const MixedMesh mixed = mixedMesh();
    const Mesh mesh = fromFaces(mixed.points, mixed.faces);
    const LimitSurface surface(mesh);
    const int samples = 33;
    const auto location = [&](int i) {
        return LimitSurface::PtexLocation{i % surface.numPtexFaces(), (i % samples) / (samples - 1.0),
                                          ((i / samples) % samples) / (samples - 1.0)};
    };
    const int count = surface.numPtexFaces() * samples * samples;
    std::vector<glm::dvec3> serial(count), parallel(count);
    for (int i = 0; i < count; ++i)
        serial[i] = surface.evaluateAt(location(i)).normal;
    std::vector<std::thread> threads;
    for (int t = 0; t < 4; ++t) {
        threads.emplace_back([&, t] {
            for (int i = t; i < count; i += 4)
                parallel[i] = surface.evaluateAt(location(i)).normal;
        });
    }
    for (auto& t : threads)
        t.join();
    // Const queries share no mutable state: bit-identical results.
    CHECK(parallel == serial);
}

TEST_CASE("limit surface: errors", "[geom][limit_surface][errors]") {
    const MixedMesh mixed = mixedMesh();
    const Mesh mesh = fromFaces(mixed.points, mixed.faces);
    const LimitSurface surface(mesh, {}, "cage 'body'");
    const std::vector<double> quad = {0.25, 0.25, 0.25, 0.25};

    CHECK_THROWS_WITH(surface.evaluate(-1, quad),
                      Catch::Contains("cage 'body'") && Catch::Contains("face -1"));
    CHECK_THROWS_AS(surface.evaluate(mesh.numFaces(), quad), InvalidInput);
    CHECK_THROWS_WITH(surface.ptexLocation(mesh.numFaces(), quad), Catch::Contains("out of range"));
    // Face 0 is the pentagon: 4 weights are one too few.
    CHECK_THROWS_WITH(surface.evaluate(0, quad), Catch::Contains("4 corner weights") && Catch::Contains("5"));
    CHECK_THROWS_AS(surface.evaluate(3, std::vector<double>{}), InvalidInput);
    CHECK_THROWS_AS(surface.evaluate(3, std::vector<double>{0.5, 0.5, 0.5, -0.5}), InvalidInput);
    CHECK_THROWS_AS(surface.evaluate(3, std::vector<double>{0.5, 0.5, 0.5, 0.5}), InvalidInput);
    CHECK_THROWS_AS(surface.evaluate(3, std::vector<double>{NAN, 0.5, 0.5, 0.0}), InvalidInput);
    CHECK_THROWS_AS(surface.evaluateWithDerivatives(3, std::vector<double>{1.0, 0.0}), InvalidInput);
    // Round-off in the weights is accepted.
    CHECK_NOTHROW(surface.evaluate(3, std::vector<double>{0.5 + 1e-7, 0.5, -1e-7, 0.0}));

    CHECK_THROWS_AS(surface.limitPosition(-1), InvalidInput);
    CHECK_THROWS_AS(surface.limitPosition(mesh.numVertices()), InvalidInput);
    CHECK_THROWS_AS(surface.evaluateAt({surface.numPtexFaces(), 0.5, 0.5}), InvalidInput);
    CHECK_THROWS_AS(surface.evaluateAt({0, 1.5, 0.5}), InvalidInput);
    CHECK_THROWS_AS(surface.evaluateAt({0, 0.5, NAN}), InvalidInput);
    CHECK_THROWS_AS(surface.firstPtexFace(-1), InvalidInput);

    CHECK_THROWS_WITH(LimitSurface(mesh, {.isolationLevel = 0}, "cage"), Catch::Contains("isolation level"));
    CHECK_THROWS_AS(LimitSurface(mesh, {.isolationLevel = 11}), InvalidInput);
    CHECK_THROWS_AS(LimitSurface(Mesh()), InvalidInput);
}

TEST_CASE("limit surface rejects a vertex beyond OpenSubdiv's valence limit",
          "[geom][limit_surface][errors]") {
    // An open fan of 65535 triangles around vertex 0 gives it 65536 edges, one more than OpenSubdiv
    // refines; a TopologyError names the vertex (OpenSubdiv's own failure would not).
    const int n = 65535;
    Mesh::Data d;
    d.points.emplace_back(0.0f, 0.0f, 0.0f);
    for (int k = 0; k <= n; ++k) {
        const double a = 1.9 * std::numbers::pi * k / n;
        d.points.emplace_back(std::cos(a), std::sin(a), 0.0);
    }
    for (int k = 0; k < n; ++k) {
        d.faceCounts.push_back(3);
        d.faceIndices.insert(d.faceIndices.end(), {0, 1 + k, 2 + k});
    }
    const Mesh fan(std::move(d));
    CHECK_THROWS_AS(LimitSurface(fan, {}, "fan"), TopologyError);
    CHECK_THROWS_WITH(LimitSurface(fan, {}, "fan"), Catch::Contains("fan") && Catch::Contains("vertex 0"));
}

TEST_CASE("limit surface over moved points equals a surface built from them", "[geom][limit_surface]") {
    // withPoints() reuses the patches and recomputes the control points: it must give what a fresh build
    // from the moved cage gives, bit for bit (the same refinement in the same order).
    const MixedMesh mixed = mixedMesh();
    const Mesh mesh = fromFaces(mixed.points, mixed.faces);
    LimitSurfaceOptions options;
    options.deformable = true;
    const LimitSurface rest(mesh, options);
    std::vector<glm::dvec3> movedPoints;
    for (const glm::dvec3& p : mixed.points)
        movedPoints.push_back(p +
                              glm::dvec3(0.2 * std::sin(3.0 * p.y), 0.1 * p.x * p.y, 0.3 * std::cos(p.x)));
    const Mesh movedMesh = fromFaces(movedPoints, mixed.faces);
    const LimitSurface fresh(movedMesh);
    const LimitSurface moved = rest.withPoints(movedMesh.points());
    for (int32_t f = 0; f < LimitSurface(mesh).numPtexFaces(); ++f) {
        for (const double u : {0.0, 0.3, 1.0}) {
            for (const double v : {0.0, 0.6, 1.0}) {
                const LimitSample a = moved.evaluateAt({f, u, v}), b = fresh.evaluateAt({f, u, v});
                CHECK(a.position == b.position);
                CHECK(a.dPdu == b.dPdu);
            }
        }
    }
    for (int32_t v = 0; v < mesh.numVertices(); ++v)
        CHECK(moved.limitPosition(v) == fresh.limitPosition(v));
    // The rest surface is unchanged, a surface not built deformable refuses, a wrong count is named.
    CHECK(rest.limitPosition(0) == LimitSurface(mesh).limitPosition(0));
    CHECK_THROWS_AS((void)fresh.withPoints(movedMesh.points()), deformkit::Error);
    const std::vector<glm::vec3> tooFew(3);
    CHECK_THROWS_WITH((void)rest.withPoints(tooFew), Catch::Contains("3 given"));
}

TEST_CASE("limit surface with holes: the other faces keep their limit exactly", "[geom][limit_surface]") {
    // The outer ring of quads made holes: the pentagon and the inner ring, whose one-rings the holes still
    // complete, evaluate exactly as without holes; evaluating a hole is an error naming it.
    const MixedMesh mixed = mixedMesh();
    const Mesh mesh = fromFaces(mixed.points, mixed.faces);
    const LimitSurface whole(mesh);
    LimitSurfaceOptions options;
    for (int32_t f = 7; f < 12; ++f)
        options.holes.push_back(f);
    const LimitSurface holed(mesh, options);
    for (int32_t f = 0; f < 7; ++f) {
        const int32_t n = static_cast<int32_t>(mixed.faces[f].size());
        for (int32_t k = 0; k < n; ++k) {
            std::vector<double> w(n, 0.5 / (n - 1));
            w[k] = 0.5;
            CHECK(maxDistance(holed.evaluate(f, w), whole.evaluate(f, w)) < 1e-12);
        }
    }
    CHECK_THROWS_WITH((void)holed.evaluate(8, std::vector<double>(4, 0.25)), Catch::Contains("hole"));
    options.holes = {40};
    CHECK_THROWS_WITH((void)LimitSurface(mesh, options), Catch::Contains("hole face 40"));
}
