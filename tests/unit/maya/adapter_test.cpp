// The Maya plugin's translation layer (no Maya needed): Maya matrices, ramps, each node's parameters, and
// the per-node core over the host layer.

#include <catch2/catch.hpp>

#include <cmath>

#include <glm/geometric.hpp>

#include "deformkit/error.h"
#include "deformkit/geom/primitives.h"
#include "deformkit/uvwarp/tile_warp.h"
#include "maya_adapter.h"
#include "test_support.h"

using namespace deformkit;
using maya::MayaMatrix;

namespace {

// Maya's row-vector form of "rotate 90 degrees about Z, then translate by (1, 2, 3)": the rows are the
// images of X, Y, Z and the translation.
MayaMatrix rotZThenMove() {
    MayaMatrix a;
    a.m = {{{0, 1, 0, 0}, {-1, 0, 0, 0}, {0, 0, 1, 0}, {1, 2, 3, 1}}};
    return a;
}

MayaMatrix scaleMove(double s, glm::dvec3 t) {
    MayaMatrix a;
    a.m = {{{s, 0, 0, 0}, {0, s, 0, 0}, {0, 0, s, 0}, {t.x, t.y, t.z, 1}}};
    return a;
}

bool near(const glm::dvec3& a, const glm::dvec3& b, double tol = 1e-12) {
    return glm::length(a - b) <= tol;
}

std::vector<double> param(const maya::Parameters& p, const std::string& name) {
    for (const auto& [n, v] : p)
        if (n == name) return v;
    FAIL("no parameter " << name);
    return {};
}

}  // namespace

TEST_CASE("maya adapter: row-vector matrices transform, compose and invert as Maya's", "[maya]") {
    const MayaMatrix a = rotZThenMove();
    // p M with p = (1, 0, 0, 1): the X row plus the translation row.
    CHECK(near(maya::transformPoint(a, {1, 0, 0}), {1, 3, 3}));
    CHECK(near(maya::transformPoint(a, {0, 1, 0}), {0, 2, 3}));
    CHECK(near(maya::transformVector(a, {0, 1, 0}), {-1, 0, 0}));  // no translation for vectors
    const MayaMatrix b = scaleMove(2.0, {0, 0, -1});
    const glm::dvec3 p(0.5, -0.25, 2.0);
    // "a then b": b applied to a's result.
    CHECK(near(maya::transformPoint(maya::multiply(a, b), p),
               maya::transformPoint(b, maya::transformPoint(a, p))));
    const MayaMatrix inv = maya::inverse(a, "locator1");
    CHECK(near(maya::transformPoint(inv, maya::transformPoint(a, p)), p, 1e-12));
    MayaMatrix flat = scaleMove(1.0, {0, 0, 0});
    flat.m[2] = {0, 0, 0, 0};
    CHECK_THAT(test::errorOf<InvalidInput>([&] { (void)maya::inverse(flat, "locator1"); }),
               Catch::Contains("locator1") && Catch::Contains("singular"));
}

TEST_CASE("maya adapter: ramps sample as Maya interpolates them", "[maya]") {
    const std::vector<maya::RampKey> linear{{1.0, 0.0, 1}, {0.0, 1.0, 1}};  // unsorted on purpose
    CHECK(maya::sampleRamp(linear, 5) == std::vector<double>{1.0, 0.75, 0.5, 0.25, 0.0});
    const std::vector<maya::RampKey> smooth{{0.0, 1.0, 2}, {1.0, 0.0, 2}};
    const auto s = maya::sampleRamp(smooth, 5);
    for (int i = 0; i < 5; ++i) {
        const double t = i / 4.0;
        CHECK(s[i] == Approx(1.0 - t * t * (3 - 2 * t)).margin(1e-15));
    }
    // "none" holds the key's value up to the next key; before the first and after the last key, clamp.
    const std::vector<maya::RampKey> step{{0.25, 0.5, 0}, {0.75, 1.0, 0}};
    CHECK(maya::sampleRamp(step, 5) == std::vector<double>{0.5, 0.5, 0.5, 1.0, 1.0});
    CHECK_THROWS_AS(maya::sampleRamp({}, 5), InvalidInput);
    CHECK_THROWS_AS(maya::sampleRamp(linear, 1), InvalidInput);
}

TEST_CASE("maya adapter: each node's controls become host parameters in the shape's space", "[maya]") {
    SECTION("dkSlide: the locators' difference, brought into the shape's space") {
        maya::SlideInputs in;
        in.vertex = 12;
        in.radius = 0.75;
        in.startWorld = {1, 1, 1};
        in.endWorld = {1, 3, 1};                       // 2 up in the world
        in.geometryWorld = scaleMove(2.0, {5, 0, 0});  // the shape is scaled 2x: 1 unit of its own space
        const maya::Parameters p = maya::slideParameters(in);
        CHECK(param(p, "vertex") == std::vector<double>{12});
        CHECK(param(p, "displacement") == std::vector<double>{0, 1, 0});
        CHECK(param(p, "falloff") == std::vector<double>{2});
        CHECK(param(p, "falloffRamp").size() == 33);
        CHECK(p.front().first == "vertex");  // bind-time parameters first
        CHECK(param(p, "paintedWeights") == std::vector<double>{0});
        CHECK(param(p, "foldLimit") == std::vector<double>{0});
        in.weightsAreFalloff = true;
        in.foldLimit = true;
        const maya::Parameters q = maya::slideParameters(in);
        CHECK(param(q, "paintedWeights") == std::vector<double>{1});
        CHECK(param(q, "foldLimit") == std::vector<double>{1});
    }
    SECTION("dkBarr: the handle's origin and axes") {
        maya::BarrInputs in;
        in.type = "bend";
        in.handleWorld = rotZThenMove();
        in.geometryWorld = scaleMove(1.0, {1, 0, 0});
        const maya::Parameters p = maya::barrParameters(in);
        CHECK(param(p, "handleOrigin") == std::vector<double>{0, 2, 3});
        CHECK(param(p, "handleX") == std::vector<double>{0, 1, 0});
        CHECK(param(p, "handleY") == std::vector<double>{-1, 0, 0});
        in.type = "shear";
        CHECK_THAT(test::errorOf<InvalidInput>([&] { (void)maya::barrParameters(in); }),
                   Catch::Contains("taper, twist or bend"));
    }
    SECTION("dkWire and dkMeshWarp: point counts must match their rest") {
        maya::WireInputs wire;
        wire.restWorld = {{0, 0, 0}, {1, 0, 0}};
        wire.curveWorld = {{0, 0, 0}};
        CHECK_THAT(test::errorOf<InvalidInput>([&] { (void)maya::wireParameters(wire); }),
                   Catch::Contains("dkWire") && Catch::Contains("their rest 2"));
        maya::MeshWarpInputs cage;
        cage.restCageWorld = {{0, 0, 0}};
        CHECK_THAT(test::errorOf<InvalidInput>([&] { (void)maya::meshWarpParameters(cage); }),
                   Catch::Contains("dkMeshWarp"));
    }
}

TEST_CASE("maya adapter: a frame lattice whose controls all move by t moves the mesh by t", "[maya]") {
    // The FFD's weights sum to 1 (Bernstein and B-spline both), so translating every control translates
    // every point inside the lattice exactly; at rest the FFD is the identity. Tolerance: float32 points of
    // size ~1 through the polynomial sums (a few ulps).
    const geom::Mesh mesh = geom::makeGrid({6, 6, 1.0f, 1.0f});  // [0, 1]^2, z = 0
    maya::FrameLatticeInputs in;
    in.divisions = {2, 2, 1};
    in.baseLatticeWorld = scaleMove(1.5, {0.5, 0.5, 0});  // [-0.25, 1.25]^2 x [-0.75, 0.75] around the grid
    const auto controls = [&](glm::dvec3 t) {
        std::vector<MayaMatrix> out;
        for (int i = 0; i <= 2; ++i)
            for (int j = 0; j <= 2; ++j)
                for (int k = 0; k <= 1; ++k)
                    out.push_back(
                        scaleMove(1.0, glm::dvec3(-0.25 + 0.75 * i, -0.25 + 0.75 * j, -0.75 + 1.5 * k) + t));
        return out;
    };
    maya::NodeCore core("ffdframes", "lattice1");
    core.setRest(mesh);
    in.controlsWorld = controls({0, 0, 0});
    core.set(maya::frameLatticeParameters(in));
    std::vector<glm::vec3> points(mesh.points().begin(), mesh.points().end());
    core.evaluate(points, 1.0);
    for (size_t v = 0; v < points.size(); ++v)
        CHECK(glm::length(glm::dvec3(points[v]) - glm::dvec3(mesh.points()[v])) < 1e-6);

    const glm::dvec3 t(0.25, -0.125, 0.5);
    in.controlsWorld = controls(t);
    core.set(maya::frameLatticeParameters(in));
    points.assign(mesh.points().begin(), mesh.points().end());
    core.evaluate(points, 1.0);
    for (size_t v = 0; v < points.size(); ++v)
        CHECK(glm::length(glm::dvec3(points[v]) - (glm::dvec3(mesh.points()[v]) + t)) < 1e-6);

    in.controlsWorld.pop_back();
    CHECK_THAT(test::errorOf<InvalidInput>([&] { (void)maya::frameLatticeParameters(in); }),
               Catch::Contains("18, one per lattice point"));
}

TEST_CASE("maya adapter: the node core rebinds only for new rest geometry and applies Maya's envelope rule",
          "[maya]") {
    const geom::Mesh mesh = geom::makeGrid({4, 4, 1.0f, 1.0f});
    maya::NodeCore core("twist", "twist1");
    CHECK(core.setRest(mesh));
    maya::BarrInputs in;
    in.handleWorld.m[1] = {0, 0, 1, 0};  // handle Y along Z: the twist turns the grid in its plane
    in.handleWorld.m[2] = {0, -1, 0, 0};
    in.endValue = 1.0;
    core.set(maya::barrParameters(in));
    std::vector<glm::vec3> full(mesh.points().begin(), mesh.points().end());
    core.evaluate(full, 1.0);
    CHECK(core.bindCount() == 1);
    CHECK_FALSE(core.setRest(mesh));  // the same geometry again: no rebind
    std::vector<float> w(static_cast<size_t>(mesh.numVertices()));
    for (size_t v = 0; v < w.size(); ++v)
        w[v] = static_cast<float>(v % 3) / 2.0f;
    core.setWeights(w);
    core.setWeights(w);  // unchanged: not set again
    std::vector<glm::vec3> weighted(mesh.points().begin(), mesh.points().end());
    core.evaluate(weighted, 0.5);
    CHECK(core.bindCount() == 1);  // a twist's binding does not use weights
    // Maya's rule: out = in + envelope w (deformed - in), in double, rounded once.
    for (size_t v = 0; v < w.size(); ++v) {
        const glm::dvec3 in0(mesh.points()[v]);
        const glm::dvec3 expected = in0 + 0.5 * w[v] * (glm::dvec3(full[v]) - in0);
        CHECK(glm::length(glm::dvec3(weighted[v]) - expected) < 1e-6);
    }
    geom::Mesh moved = mesh;
    moved.points()[0].z += 0.5f;
    CHECK(core.setRest(moved));
    std::vector<glm::vec3> again(moved.points().begin(), moved.points().end());
    core.evaluate(again, 1.0);
    CHECK(core.bindCount() == 2);
}

TEST_CASE("maya adapter: the redirect core warm-starts frames in order and starts cold after a jump",
          "[maya]") {
    // Reference: TileWarp driven directly. Frames 1, 2, 3 in order are one warm-started sequence; frame 7
    // after them is a jump, which must equal a fresh solver's single solve (a cold start), bit for bit.
    const geom::Mesh mesh = geom::makeGrid({8, 8, 1.0f, 1.0f});
    io::Image rigidity(32, 32, 1);
    for (int y = 0; y < 32; ++y)
        for (int x = 0; x < 32; ++x)
            rigidity.at(x, y, 0) = std::hypot(x - 15.5, y - 15.5) < 6.0 ? 1.0f : 0.0f;
    uvwarp::TileWarpOptions options;
    options.solver.iterations = 4;
    const auto pose = [&](int frame) {
        std::vector<glm::vec3> p(mesh.points().begin(), mesh.points().end());
        for (glm::vec3& q : p)
            q.x *= 1.0f + 0.05f * static_cast<float>(frame);
        return p;
    };
    maya::RedirectCore core(mesh, 1001, rigidity, {}, options, "rig");
    uvwarp::TileWarp sequence(mesh, 1001, rigidity, {}, options, {}, "rig");
    for (int frame : {1, 2, 3}) {
        const io::Image map = core.solve(frame, pose(frame));
        (void)sequence.solve(pose(frame));
        CHECK(core.warmStarted() == (frame > 1));
        CHECK(test::sameBits(map.pixels, sequence.redirect().pixels));
    }
    const io::Image jumped = core.solve(7, pose(7));
    CHECK_FALSE(core.warmStarted());
    uvwarp::TileWarp cold(mesh, 1001, rigidity, {}, options, {}, "rig");
    (void)cold.solve(pose(7));
    CHECK(test::sameBits(jumped.pixels, cold.redirect().pixels));
    CHECK_FALSE(test::sameBits(jumped.pixels, core.solve(1, pose(1)).pixels));  // the maps do change
}
