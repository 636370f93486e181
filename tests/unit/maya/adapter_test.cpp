// The Maya plugin's translation layer (no Maya needed): Maya matrices, ramps, each node's parameters, and
// the per-node core over the host layer.

#include <catch2/catch.hpp>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <new>

#include <glm/geometric.hpp>

#include "deformkit/error.h"
#include "deformkit/geom/primitives.h"
#include "deformkit/uvwarp/options.h"
#include "maya_adapter.h"
#include "test_support.h"

using namespace deformkit;
using maya::MayaMatrix;

// Every allocation of this test program, counted: a deform() cycle of a warm node core must not add one.
namespace {
std::atomic<int64_t> allocations{0};
}  // namespace

void* operator new(size_t size) {
    allocations.fetch_add(1, std::memory_order_relaxed);
    if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
    throw std::bad_alloc();
}
void operator delete(void* p) noexcept {
    std::free(p);
}
void operator delete(void* p, size_t) noexcept {
    std::free(p);
}

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

TEST_CASE("maya adapter: each geometry of a node keeps its own rest, binding once; a topology change rebinds",
          "[maya]") {
    // One dkSlide on two meshes of different sizes (input[0] and input[3]), evaluated in turn for 10 frames,
    // as Maya calls deform() once per geometry: each binds once, and gives what a node of its own gives.
    const geom::Mesh small = geom::makeGrid({6, 6, 1.0f, 1.0f}), large = geom::makeGrid({8, 8, 1.0f, 1.0f});
    maya::SlideInputs in;
    in.vertex = 10;
    in.radius = 0.6;
    in.endWorld = {0.0, 0.1, 0.0};
    const maya::Parameters parameters = maya::slideParameters(in);
    const auto topology = [](const geom::Mesh& m) {
        return std::pair(std::vector<int32_t>(m.faceCounts().begin(), m.faceCounts().end()),
                         std::vector<int32_t>(m.faceIndices().begin(), m.faceIndices().end()));
    };
    const auto run = [&](maya::NodeGeometry& geometry, const geom::Mesh& mesh) {
        maya::NodeCore& core = geometry.core("slide", "dkSlide1");
        const auto [counts, indices] = topology(mesh);
        if (geometry.takesRest(false, counts, indices)) core.setRest(mesh);
        core.set(parameters);
        std::vector<glm::vec3> points(mesh.points().begin(), mesh.points().end());
        core.evaluate(points, 1.0);
        return points;
    };
    maya::NodeGeometries node;
    maya::NodeGeometry alone;
    std::vector<glm::vec3> shared, own;
    for (int frame = 0; frame < 10; ++frame) {
        (void)run(node.at(0), small);
        shared = run(node.at(3), large);
        own = run(alone, large);
    }
    CHECK(node.size() == 2);
    CHECK(node.at(0).core("slide", "dkSlide1").bindCount() == 1);
    CHECK(node.at(3).core("slide", "dkSlide1").bindCount() == 1);
    CHECK(test::sameBits(shared, own));
    // A topology change with as many vertices (a row of faces deleted upstream) takes the input as the new
    // rest; the same topology does not, whatever the positions; a rebind toggle does, once.
    maya::NodeGeometry& g = node.at(0);
    auto [counts, indices] = topology(small);
    CHECK_FALSE(g.takesRest(false, counts, indices));
    counts.resize(counts.size() - 6);
    indices.resize(indices.size() - 24);
    CHECK(g.core("slide", "dkSlide1").restTopologyDiffers(counts, indices));
    CHECK(g.takesRest(false, counts, indices));
    // The rest keeps the grid's polygons (the caller did not take the reduced input): no change.
    const auto [same, sameIndices] = topology(small);
    CHECK_FALSE(g.takesRest(false, same, sameIndices));
    CHECK(g.takesRest(true, same, sameIndices));
    CHECK_FALSE(g.takesRest(true, same, sameIndices));
    // Another host type (a dkBarr's kind changed) makes a new core, which takes the rest again.
    maya::NodeGeometry barr;
    barr.core("twist", "dkBarr1").setRest(small);
    CHECK_FALSE(barr.takesRest(false, same, sameIndices));
    CHECK_FALSE(barr.core("taper", "dkBarr1").hasRest());
    CHECK(barr.takesRest(false, same, sameIndices));
}

TEST_CASE(
    "maya adapter: a deformer set of some vertices moves those as the whole mesh with weight 0 elsewhere",
    "[maya]") {
    const geom::Mesh mesh = geom::makeGrid({6, 6, 1.0f, 1.0f});
    maya::BarrInputs in;
    in.type = "twist";
    in.handleWorld.m[1] = {0, 0, 1, 0};
    in.handleWorld.m[2] = {0, -1, 0, 0};
    in.endValue = 1.0;
    const std::vector<glm::vec3> all(mesh.points().begin(), mesh.points().end());
    // Members in the iterator's order (not sorted), with painted weights.
    const std::vector<int32_t> members{20, 3, 7, 48, 5, 33};
    const std::vector<float> memberWeights{1.0f, 0.5f, 0.25f, 1.0f, 0.75f, 0.1f};
    maya::NodeCore subset("twist", "dkBarr1"), whole("twist", "dkBarr1");
    for (maya::NodeCore* core : {&subset, &whole}) {
        core->setRest(mesh);
        core->set(maya::barrParameters(in));
    }
    std::vector<glm::vec3> moved(members.size());
    subset.evaluateMembers(all, members, memberWeights, 0.8, moved);
    // The reference: the whole mesh with those weights on the members and 0 elsewhere.
    std::vector<float> weights(all.size(), 0.0f);
    for (size_t k = 0; k < members.size(); ++k)
        weights[members[k]] = memberWeights[k];
    whole.setWeights(weights);
    std::vector<glm::vec3> reference = all;
    whole.evaluate(reference, 0.8);
    for (size_t k = 0; k < members.size(); ++k) {
        INFO("member " << k);
        CHECK(moved[k] == reference[members[k]]);
        CHECK(moved[k] != all[members[k]]);
    }
    const std::vector<int32_t> outside{3, 99};
    const std::vector<float> two{1.0f, 1.0f};
    std::vector<glm::vec3> out(2);
    CHECK_THROWS_WITH(
        subset.evaluateMembers(all, outside, two, 1.0, out),
        Catch::Contains("deformer set member 1: is vertex 99 (expected a vertex of the mesh's 49)"));
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

namespace {

// One deform() as the Maya node makes it: parameters rebuilt in place into the node's kept record, pushed
// where they changed, the input positions copied into the core's buffer, evaluated.
template <class Inputs, class Fill>
void deformCycle(maya::NodeCore& core, maya::Parameters& kept, const Inputs& in, Fill fill,
                 std::span<const glm::vec3> input) {
    fill(in, kept);
    core.set(kept);
    const std::span<glm::vec3> points = core.points(input.size());
    std::copy(input.begin(), input.end(), points.begin());
    const std::span<float> weights = core.weights(input.size());
    std::fill(weights.begin(), weights.end(), 1.0f);
    core.evaluateBuffers(1.0, false);
}

}  // namespace

TEST_CASE("maya adapter: a warm deform cycle allocates nothing, pushes only what changed, binds once",
          "[maya]") {
    const geom::Mesh mesh = geom::makeGrid({24, 24, 2.0f, 2.0f});
    const std::vector<glm::vec3> input(mesh.points().begin(), mesh.points().end());

    SECTION("slide driven by its end locator") {
        maya::NodeCore core("slide", "slide1");
        core.setRest(mesh);
        maya::SlideInputs in;
        in.vertex = 12 * 25 + 12;
        in.radius = 0.8;
        maya::Parameters kept;
        const auto fill = [](const maya::SlideInputs& i, maya::Parameters& out) {
            maya::slideParameters(i, out);
        };
        int64_t warm = 0;
        for (int frame = 0; frame < 12; ++frame) {
            in.endWorld = {0.02 * frame, 0.01 * frame, 0.0};  // the animator drags the end locator
            const int64_t before = allocations.load();
            const int64_t pushedBefore = core.pushCount();
            deformCycle(core, kept, in, fill, input);
            if (frame >= 2) warm += allocations.load() - before;
            // The first cycle pushes all 9 parameters; after it only the displacement changes.
            CHECK(core.pushCount() - pushedBefore == (frame == 0 ? 9 : 1));
        }
        CHECK(warm == 0);
        CHECK(core.bindCount() == 1);  // bound once, driven by the locator
        const std::span<glm::vec3> out = core.points(input.size());
        CHECK(glm::length(out[in.vertex] - input[in.vertex]) > 0.1f);  // the handle did slide
        // Nothing moved: nothing pushed.
        maya::slideParameters(in, kept);
        CHECK(core.set(kept) == 0);
        // A new radius is a bind-time change: pushed (and validated) once, and the slide binds again.
        in.radius = 0.5;
        deformCycle(core, kept, in, fill, input);
        CHECK(core.bindCount() == 2);
    }

    SECTION("twist and frame lattice") {
        maya::NodeCore twist("twist", "twist1");
        twist.setRest(mesh);
        maya::BarrInputs barr;
        barr.handleWorld.m[1] = {0, 0, 1, 0};
        barr.handleWorld.m[2] = {0, -1, 0, 0};
        maya::NodeCore lattice("ffdframes", "lattice1");
        lattice.setRest(mesh);
        maya::FrameLatticeInputs frames;
        frames.divisions = {1, 1, 1};
        frames.baseLatticeWorld.m[0] = {2.2, 0, 0, 0};
        frames.baseLatticeWorld.m[1] = {0, 2.2, 0, 0};
        frames.baseLatticeWorld.m[2] = {0, 0, 1, 0};
        for (int c = 0; c < 8; ++c) {
            MayaMatrix control;
            control.m[3] = {c & 4 ? 1.1 : -1.1, c & 2 ? 1.1 : -1.1, c & 1 ? 0.5 : -0.5, 1};
            frames.controlsWorld.push_back(control);
        }
        maya::Parameters keptTwist, keptLattice;
        const auto fillTwist = [](const maya::BarrInputs& i, maya::Parameters& out) {
            maya::barrParameters(i, out);
        };
        const auto fillLattice = [](const maya::FrameLatticeInputs& i, maya::Parameters& out) {
            maya::frameLatticeParameters(i, out);
        };
        int64_t warmTwist = 0, warmLattice = 0;
        for (int frame = 0; frame < 8; ++frame) {
            barr.endValue = 0.1 * frame;
            frames.controlsWorld[7].m[3][2] = 0.5 + 0.05 * frame;
            const int64_t before = allocations.load();
            deformCycle(twist, keptTwist, barr, fillTwist, input);
            const int64_t between = allocations.load();
            deformCycle(lattice, keptLattice, frames, fillLattice, input);
            if (frame >= 2) {
                warmTwist += between - before;
                warmLattice += allocations.load() - between;
            }
        }
        CHECK(warmLattice == 0);
        CHECK(warmTwist == 0);  // the new angle updates the twist's profile in place
        for (const char* type : {"taper", "bend"}) {
            maya::NodeCore core(type, "barr1");
            core.setRest(mesh);
            maya::BarrInputs other = barr;
            other.type = type;
            maya::Parameters kept;
            int64_t warm = 0;
            for (int frame = 0; frame < 6; ++frame) {
                other.endValue = 1.0 + 0.1 * frame;    // the taper's end scale
                other.curvature = 0.1 + 0.05 * frame;  // the bend's curvature
                const int64_t before = allocations.load();
                deformCycle(core, kept, other, fillTwist, input);
                if (frame >= 2) warm += allocations.load() - before;
            }
            INFO(type);
            CHECK(warm == 0);
            CHECK(core.bindCount() == 1);
        }
        CHECK(twist.bindCount() == 1);
        CHECK(lattice.bindCount() == 1);
        // Per frame after the first: the twist's end angle, the lattice's points (frames unchanged).
        CHECK(twist.pushCount() == 6 + 7);
        CHECK(lattice.pushCount() == 6 + 7);
    }
}

TEST_CASE("maya adapter: parameters written in place equal the returned ones, and a shorter list shrinks",
          "[maya]") {
    maya::BarrInputs bend;
    bend.type = "bend";
    maya::BarrInputs twist;
    twist.type = "twist";
    maya::Parameters kept;
    maya::barrParameters(bend, kept);
    CHECK(kept == maya::barrParameters(bend));
    maya::barrParameters(twist, kept);  // one entry fewer (no handleX), names in another order
    CHECK(kept == maya::barrParameters(twist));
    maya::SlideInputs slide;
    slide.falloff = {{0.6, 0.2, 1}, {0.0, 1.0, 2}, {0.6, 0.4, 1}, {1.0, 0.0, 0}};  // unsorted, a tie at 0.6
    maya::slideParameters(slide, kept);
    CHECK(kept == maya::slideParameters(slide));
}

namespace {

io::Image diskMap(int texels, double cx, double cy, double radius) {
    io::Image image(texels, texels, 1);
    for (int y = 0; y < texels; ++y)
        for (int x = 0; x < texels; ++x)
            image.at(x, y, 0) =
                std::hypot((x + 0.5) / texels - cx, (y + 0.5) / texels - cy) < radius ? 1.0f : 0.0f;
    return image;
}

}  // namespace

TEST_CASE(
    "maya adapter: the redirect node reads animated maps per frame, still ones once, and rebuilds on "
    "an option change",
    "[maya]") {
    const test::TempDir dir;
    const geom::Mesh mesh = geom::makeGrid({8, 8, 1.0f, 1.0f});
    const auto pose = [&](int frame) {
        std::vector<glm::vec3> p(mesh.points().begin(), mesh.points().end());
        for (glm::vec3& q : p)
            q.x *= 1.0f + 0.05f * static_cast<float>(frame);
        return p;
    };
    // An animated rigidity map: the disk moves between frames 1 and 2. A still orientation map.
    const io::Image rig1 = diskMap(32, 0.4, 0.5, 0.15), rig2 = diskMap(32, 0.6, 0.5, 0.15);
    io::Image orientation(32, 32, 1);
    for (int y = 0; y < 32; ++y)
        for (int x = 0; x < 32; ++x)
            orientation.at(x, y, 0) = x < 16 ? 1.0f : 0.0f;
    io::writeImage(dir.path() / "rig.1001.0001.exr", rig1, {io::PixelType::Float, {}});
    io::writeImage(dir.path() / "rig.1001.0002.exr", rig2, {io::PixelType::Float, {}});
    io::writeImage(dir.path() / "ori.1001.exr", orientation, {io::PixelType::Float, {}});
    maya::RedirectInputs in;
    in.rigidity = (dir.path() / "rig.<UDIM>.####.exr").string();
    in.orientation = (dir.path() / "ori.<UDIM>.exr").string();
    in.options.solver.iterations = 3;
    in.options.solver.orientationPreservation = 0.3f;
    CHECK(maya::redirectFilesAt(in, 2).rigidity == (dir.path() / "rig.1001.0002.exr").string());
    CHECK(maya::redirectFilesAt(in, 2).mask.empty());

    maya::RedirectNode node;
    REQUIRE(node.needsBuild(in));
    node.build(mesh, in, 1, "rig");
    CHECK(node.mapReads() == 2);  // frame 1's rigidity, the orientation
    const io::Image first = node.solve(in, 1, pose(1));
    const io::Image second = node.solve(in, 2, pose(2));
    CHECK(node.warmStarted());
    CHECK(node.mapReads() == 4);  // frame 2's rigidity, and the orientation with it (one setMaps)
    // The reference: TileWarp driven directly, its maps changed between the frames.
    uvwarp::TileWarp direct(mesh, 1001, rig1, {}, in.options, orientation, "rig");
    (void)direct.solve(pose(1));
    CHECK(test::sameBits(first.pixels, direct.redirect().pixels));
    direct.setMaps(rig2, {}, orientation);
    (void)direct.solve(pose(2));
    CHECK(test::sameBits(second.pixels, direct.redirect().pixels));
    // The orientation map is used: without it the same frames give other bytes.
    uvwarp::TileWarp plain(mesh, 1001, rig1, {}, in.options, {}, "rig");
    (void)plain.solve(pose(1));
    CHECK_FALSE(test::sameBits(first.pixels, plain.redirect().pixels));

    // A still rigidity map is read once over a whole run of frames.
    maya::RedirectInputs still = in;
    still.rigidity = (dir.path() / "rig.<UDIM>.0001.exr").string();
    REQUIRE(node.needsBuild(still));
    node.build(mesh, still, 1, "rig");
    const int64_t reads = node.mapReads();
    for (int frame = 1; frame <= 5; ++frame)
        (void)node.solve(still, frame, pose(frame));
    CHECK(node.mapReads() == reads);
    CHECK(node.builds() == 2);
    // An option change needs a new solver; the same inputs do not.
    CHECK_FALSE(node.needsBuild(still));
    maya::RedirectInputs changed = still;
    changed.options.solver.sweepsPerLevel = {1, 4, 8};
    CHECK(node.needsBuild(changed));
    CHECK_THROWS_WITH(node.solve(changed, 6, pose(6)), Catch::Contains("not built for these inputs"));
    // The rest mesh built over, given again, needs nothing; another one (a new restMesh), or this one with
    // its UVs edited, needs a new solver.
    CHECK_FALSE(node.needsBuild(still, &mesh));
    geom::Mesh::Data edited{std::vector<glm::vec3>(mesh.points().begin(), mesh.points().end()),
                            std::vector<int32_t>(mesh.faceCounts().begin(), mesh.faceCounts().end()),
                            std::vector<int32_t>(mesh.faceIndices().begin(), mesh.faceIndices().end()),
                            std::vector<glm::vec2>(mesh.uvs().begin(), mesh.uvs().end()),
                            std::vector<int32_t>(mesh.uvIndices().begin(), mesh.uvIndices().end())};
    edited.uvs[0].x += 0.01f;
    const geom::Mesh uvEdited(std::move(edited), "edited");
    CHECK(node.needsBuild(still, &uvEdited));
    const geom::Mesh other = geom::makeGrid({12, 12, 1.0f, 1.0f});
    CHECK(node.needsBuild(still, &other));
    node.build(other, still, 1, "rig");
    CHECK_FALSE(node.needsBuild(still, &other));
    // A missing frame of an animated map names the file.
    maya::RedirectNode fresh;
    fresh.build(mesh, in, 1, "rig");
    CHECK_THROWS_WITH(fresh.solve(in, 3, pose(3)), Catch::Contains("rig.1001.0003.exr"));
}

TEST_CASE("maya adapter: the redirect node reads a map of several channels from channel 0, said once",
          "[maya][uvwarp]") {
    const test::TempDir dir;
    const geom::Mesh mesh = geom::makeGrid({8, 8, 1.0f, 1.0f});
    const io::Image disk = diskMap(32, 0.5, 0.5, 0.2);
    io::Image rgba(32, 32, 4, 0.5f);
    for (int y = 0; y < 32; ++y)
        for (int x = 0; x < 32; ++x)
            rgba.at(x, y, 0) = disk.at(x, y, 0);
    io::writeImage(dir.path() / "rig.1001.exr", rgba, {io::PixelType::Float, {}});
    io::writeImage(dir.path() / "one.1001.exr", disk, {io::PixelType::Float, {}});
    std::vector<glm::vec3> stretched(mesh.points().begin(), mesh.points().end());
    for (glm::vec3& p : stretched)
        p.x *= 1.4f;
    maya::RedirectInputs colour, plain;
    colour.rigidity = (dir.path() / "rig.<UDIM>.exr").string();
    plain.rigidity = (dir.path() / "one.<UDIM>.exr").string();
    maya::RedirectNode a, b;
    a.build(mesh, colour, 1, "dkUvRedirect1");
    b.build(mesh, plain, 1, "dkUvRedirect2");
    CHECK(test::sameBits(a.solve(colour, 1, stretched).pixels, b.solve(plain, 1, stretched).pixels));
    const std::vector<std::string> notes = a.takeNotes();
    REQUIRE(notes.size() == 1);
    CHECK_THAT(notes[0], Catch::Contains("rig.1001.exr' has 4 channels: channel 0 (red) is read"));
    (void)a.solve(colour, 2, stretched);
    a.build(mesh, colour, 3, "dkUvRedirect1");  // read again: the note was said
    CHECK(a.takeNotes().empty());
    CHECK(b.takeNotes().empty());
}

TEST_CASE("maya adapter: the redirect node's preset replaces every option but the resolution",
          "[maya][uvwarp]") {
    const test::TempDir dir;
    const geom::Mesh mesh = geom::makeGrid({8, 8, 1.0f, 1.0f});
    const io::Image disk = diskMap(32, 0.5, 0.5, 0.2);
    io::writeImage(dir.path() / "rig.1001.exr", disk, {io::PixelType::Float, {}});
    std::vector<glm::vec3> stretched(mesh.points().begin(), mesh.points().end());
    for (glm::vec3& p : stretched)
        p.x *= 1.4f;
    maya::RedirectInputs in;
    in.rigidity = (dir.path() / "rig.<UDIM>.exr").string();
    in.options.solver.iterations = 7;  // replaced by the preset
    in.options.cells = 16;             // kept: the live schedule is chosen by it
    in.preset = "live";
    maya::RedirectNode node;
    node.build(mesh, in, 1, "dkUvRedirect1");
    const io::Image first = node.solve(in, 1, stretched);
    uvwarp::TileWarp direct(mesh, 1001, disk, {}, uvwarp::presetOptions(uvwarp::Preset::Live, 16), {},
                            "direct");
    (void)direct.solve(stretched);
    CHECK(test::sameBits(first.pixels, direct.redirect().pixels));
    CHECK(direct.stats().iterations == uvwarp::liveOptions(16).coldIterations);
    maya::RedirectInputs shot = in;
    shot.preset = "shot";
    CHECK(node.needsBuild(shot));
    shot.preset = "fast";
    CHECK_THROWS_WITH(node.build(mesh, shot, 1, "dkUvRedirect1"),
                      Catch::Contains("dkUvRedirect: preset: is 'fast' (expected shot or live)"));
}

TEST_CASE("maya adapter: dkUvRedirect has an attribute per UV-warp option, named and ranged as declared",
          "[maya][uvwarp]") {
    // Walks the declaration (uvwarp/options.h): every option has an attribute of its own name and type with
    // the library's default; a value in range reaches the node's options (and makes the node rebuild), values
    // just outside it are refused naming the node, the attribute and the range.
    using Kind = maya::RedirectOptionAttribute::Kind;
    const std::vector<maya::RedirectOptionAttribute> attributes = maya::redirectOptionAttributes();
    const std::span<const uvwarp::OptionSpec> specs = uvwarp::optionSpecs();
    REQUIRE(attributes.size() == specs.size());
    const uvwarp::TileWarpOptions defaults;
    maya::RedirectNode node;
    const geom::Mesh mesh = geom::makeGrid({4, 4, 1.0f, 1.0f});
    const test::TempDir dir;
    io::writeImage(dir.path() / "rig.1001.exr", diskMap(16, 0.5, 0.5, 0.2), {io::PixelType::Float, {}});
    maya::RedirectInputs base;
    base.rigidity = (dir.path() / "rig.<UDIM>.exr").string();
    node.build(mesh, base, 1, "dkUvRedirect1");
    for (size_t i = 0; i < specs.size(); ++i) {
        const maya::RedirectOptionAttribute& a = attributes[i];
        const uvwarp::OptionSpec& spec = specs[i];
        const std::string name(spec.name);
        CAPTURE(name);
        REQUIRE(a.spec == &spec);
        const std::vector<double> value = spec.get(defaults);
        const double first =
            value.empty() ? 0.0 : value.front();  // empty: sweepsPerLevel's automatic schedule
        // A value in range other than the default, and values just outside the range.
        double inRange = 0.0, above = spec.high + 1.0, below = spec.lowOpen ? spec.low : spec.low - 1.0;
        std::string text;
        switch (spec.type) {
            case uvwarp::OptionType::Flag:
                CHECK(a.kind == Kind::Boolean);
                CHECK(a.number == first);
                CHECK((!a.minimum && !a.maximum));
                inRange = first != 0 ? 0.0 : 1.0;
                break;
            case uvwarp::OptionType::Integer:
                CHECK(a.kind == Kind::Int);
                CHECK(a.number == first);
                CHECK(a.minimum == std::optional<double>(spec.low));
                CHECK(a.maximum == std::optional<double>(spec.high));
                inRange = spec.powerOfTwo ? 8.0 : first < spec.high ? first + 1.0 : first - 1.0;
                break;
            case uvwarp::OptionType::Number:
                CHECK(a.kind == Kind::Double);
                CHECK(a.number == first);
                CHECK(a.minimum == (spec.lowOpen ? std::nullopt : std::optional<double>(spec.low)));
                CHECK(a.maximum == std::optional<double>(spec.high));
                inRange = first < spec.high ? (first + spec.high) / 2 : (spec.low + spec.high) / 2;
                above = spec.high + 0.5;
                if (!spec.lowOpen) below = spec.low - 0.5;
                break;
            case uvwarp::OptionType::IntegerList:
                CHECK(a.kind == Kind::Text);
                CHECK(a.text.empty());  // sweepsPerLevel: the library's schedule by the grid's size
                text = "2, 3 5";
                break;
        }
        maya::RedirectInputs in = base;
        maya::setRedirectOption(in, a, inRange, text);
        const std::vector<double> got = spec.get(in.options);
        if (spec.type == uvwarp::OptionType::IntegerList) {
            CHECK(got == std::vector<double>{2, 3, 5});
        } else {
            CHECK(got.front() == (spec.type == uvwarp::OptionType::Number
                                      ? static_cast<double>(static_cast<float>(inRange))
                                      : inRange));
        }
        CHECK(node.needsBuild(in));
        const auto refused = [&](double number, const std::string& listText) {
            maya::RedirectInputs bad = base;
            CHECK_THROWS_WITH(maya::setRedirectOption(bad, a, number, listText),
                              Catch::StartsWith("dkUvRedirect: " + name + ": is ") &&
                                  Catch::EndsWith("(expected " + uvwarp::expectedValue(spec) + ")"));
        };
        if (spec.type == uvwarp::OptionType::IntegerList) {
            refused(0, "4 1001");
            refused(0, "4 -1");
            refused(0, "0 0");
            refused(0, "4 x 8");
            maya::RedirectInputs automatic = base;  // no number: the library's schedule, as the default
            maya::setRedirectOption(automatic, a, 0, "  ");
            CHECK(spec.get(automatic.options).empty());
        } else if (spec.type != uvwarp::OptionType::Flag) {
            refused(above, "");
            refused(below, "");
        }
    }
    CHECK_FALSE(node.needsBuild(base));
}

TEST_CASE("uv warp: a warm solve allocates nothing, on one thread or two", "[maya][uvwarp]") {
    // What dkUvRedirect runs per frame, with this program's allocation counter: the UV-warp solver on a
    // 128-cell plane stretched 1.4x along u, rigid disks on a lattice, the border fixed; the live preset's
    // schedule, so that every level's sweeps and regularisations run (levels over 32 rows on the parallel
    // wavefront with two threads).
    const int32_t n = 128, side = n + 1;
    const auto plane = [&](int32_t channels, const auto& value) {
        uvwarp::PointField f;
        f.cells = n;
        f.channels = channels;
        f.values.resize(static_cast<size_t>(side) * side * channels);
        for (int32_t j = 0; j < side; ++j)
            for (int32_t i = 0; i < side; ++i)
                value(static_cast<float>(i) / n, static_cast<float>(j) / n, f.values.data() + f.index(i, j));
        return f;
    };
    const uvwarp::PointField rest =
        plane(3, [](float u, float v, float* p) { p[0] = u, p[1] = v, p[2] = 0; });
    const uvwarp::PointField deformed =
        plane(3, [](float u, float v, float* p) { p[0] = 1.4f * u, p[1] = v, p[2] = 0; });
    const uvwarp::PointField rigidity = plane(1, [](float u, float v, float* p) {
        const float du = u - (std::floor(u * 8.0f) + 0.5f) / 8.0f,
                    dv = v - (std::floor(v * 8.0f) + 0.5f) / 8.0f;
        p[0] = du * du + dv * dv < 0.04f * 0.04f ? 1.0f : 0.0f;
    });
    const uvwarp::PointField mask = plane(1, [](float u, float v, float* p) {
        p[0] = u > 0.0f && v > 0.0f && u < 1.0f && v < 1.0f ? 1.0f : 0.0f;
    });
    for (const int32_t threads : {1, 2}) {
        uvwarp::SolverOptions options;
        options.iterations = 1;
        options.sweepsPerLevel = {1, 2, 10};
        options.coarseRelaxation = 1.4f;
        options.threads = threads;
        options.levels = 3;
        uvwarp::Solver solver(rest, rigidity, mask, options);
        solver.solve(deformed);  // the first frame may size its buffers
        const int64_t before = allocations.load();
        for (int frame = 0; frame < 3; ++frame)
            solver.solve(deformed);
        const int64_t allocated = allocations.load() - before;  // read before INFO, which allocates
        INFO(threads << " threads");
        CHECK(allocated == 0);
        CHECK(solver.stats().remainingFolds == 0);
    }
}
