#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

#include <glm/geometric.hpp>

#include "deformkit/error.h"
#include "deformkit/host/deformers.h"
#include "deformkit/slide/slider.h"
#include "deformkit/warp/barr.h"
#include "deformkit/warp/barr_dcc.h"
#include "deformkit/warp/ffd.h"
#include "deformkit/warp/wires.h"
#include "host/host_test_support.h"
#include "slide/slide_test_support.h"
#include "test_support.h"

using namespace deformkit;
using Catch::Contains;
using host::Deformer;
using host::makeDeformer;

using test::maxError;
using test::restOf;

namespace {

// A 2 x 2 plane of 8 x 8 quads, lifted to z = 0.1 so no coordinate is exactly 0.
geom::Mesh testPlane() {
    return test::planeGrid(8, 8, 0.25f, glm::mat3(1.0f), glm::vec3(0.0f, 0.0f, 0.1f));
}

}  // namespace

TEST_CASE("the factory knows nine types and names the unknown ones", "[host][deformers]") {
    const auto types = host::deformerTypes();
    REQUIRE(types.size() == 9);
    CHECK(std::is_sorted(
        types.begin(), types.end(),
        [](const host::DeformerType& a, const host::DeformerType& b) { return a.name < b.name; }));
    for (const host::DeformerType& type : types) {
        const std::string_view t = type.name;
        CHECK(!type.summary.empty());
        const auto d = makeDeformer(t, "a");
        CHECK(d->type() == t);
        CHECK(d->label() == "a");
        CHECK(d->context() == std::string(t) + " 'a'");
        CHECK(d->needsBind());
        CHECK(d->bindCount() == 0);
    }
    CHECK_THROWS_AS(makeDeformer("lattice", "l1"), InvalidInput);
    CHECK_THROWS_WITH(makeDeformer("lattice", "l1"),
                      Contains("type 'lattice'") &&
                          Contains("beierneely, bend, ffd, ffdframes, meshwarp, slide, taper, twist, wires"));
    CHECK_THROWS_WITH(makeDeformer("ffd", ""), Contains("label") && Contains("is empty"));
}

TEST_CASE("ffd adapter equals warp::Ffd called directly, and its points follow the divisions",
          "[host][deformers][ffd]") {
    const geom::Mesh rest = testPlane();
    const auto d = makeDeformer("ffd", "lattice1");
    // Parameters as listed: bind-time inputs first, then the controls; points follow the divisions.
    const auto params = d->parameters();
    REQUIRE(params.size() == 8);
    CHECK(params[0].name == "basis");
    CHECK(params[2].name == "ends");
    CHECK(params[3].name == "evaluateAt");
    CHECK(params[3].rebinds);  // back at 0 the lattice coordinates are the rest points' again
    CHECK(params[4].name == "divisions");
    CHECK(params[4].rebinds);
    CHECK(params[7].name == "points");
    CHECK_FALSE(params[7].rebinds);
    CHECK(params[7].components == 3 * 8);  // one cell: (1+1)^3 controls

    d->set("divisions", std::vector<double>{2, 1, 3});
    CHECK(d->parameter("points").components == 3 * 3 * 2 * 4);
    const std::vector<double> origin{-0.2, -0.3, -0.5}, axes{2.4, 0, 0, 0, 2.5, 0, 0, 0, 1.2};
    d->set("origin", origin);
    d->set("axes", axes);

    warp::Lattice lattice;
    lattice.divisions = {2, 1, 3};
    lattice.origin = {-0.2f, -0.3f, -0.5f};
    lattice.axes = glm::mat3(glm::vec3(2.4f, 0, 0), glm::vec3(0, 2.5f, 0), glm::vec3(0, 0, 1.2f));
    // Points reset to the rest lattice when the lattice changes: compare with the core's control points.
    std::vector<glm::vec3> targets = lattice.controlPoints();
    const std::vector<double> resetPoints = d->get("points");
    REQUIRE(resetPoints.size() == targets.size() * 3);
    for (size_t c = 0; c < targets.size(); ++c) {
        CHECK(resetPoints[3 * c] == targets[c].x);
        CHECK(resetPoints[3 * c + 1] == targets[c].y);
        CHECK(resetPoints[3 * c + 2] == targets[c].z);
    }
    // At rest the lattice is the identity, bit for bit (every translation is 0).
    CHECK(test::sameBits(test::runAlone(*d, rest), restOf(rest)));

    targets[lattice.index(1, 1, 2)] += glm::vec3(0.3f, -0.2f, 0.5f);
    targets[lattice.index(2, 0, 1)] += glm::vec3(-0.1f, 0.4f, 0.2f);
    std::vector<double> flat;
    for (const glm::vec3& t : targets)
        flat.insert(flat.end(), {t.x, t.y, t.z});
    d->set("points", flat);
    const std::vector<glm::vec3> hosted = test::runAlone(*d, rest);

    warp::Ffd ffd(lattice);
    ffd.setTargets(targets);
    ffd.bind(rest.points());
    std::vector<glm::vec3> direct = restOf(rest);
    ffd.evaluate(direct);
    // The adapter makes the same core calls on the same float values: bit-identical.
    CHECK(test::sameBits(hosted, direct));
    CHECK(maxError(direct, restOf(rest)) > 0.05f);  // the lattice moved something
}

TEST_CASE("twist adapter: Maya's twist, equal to the core and to the closed form",
          "[host][deformers][twist]") {
    const geom::Mesh rest = testPlane();
    const auto d = makeDeformer("twist", "tw");
    d->set("handleOrigin", std::vector<double>{1, 1, 0});
    d->set("handleY", std::vector<double>{2, 0, 0});  // axis along +x, scale 2: bounds -1..1 are x in [-1, 3]
    d->set("startAngle", 0.0);
    d->set("endAngle", std::numbers::pi);
    const std::vector<glm::vec3> hosted = test::runAlone(*d, rest);

    warp::MayaTwist maya;
    maya.handleOrigin = {1, 1, 0};
    maya.handleY = {2, 0, 0};
    maya.endAngle = std::numbers::pi;
    const warp::AxialSetup setup = warp::fromMayaTwist(maya);
    warp::TwistWarp twist(setup.frame, setup.profile);
    warp::SparseFields fields;
    twist.bind(rest.points(), fields);
    std::vector<glm::vec3> direct(hosted.size());
    twist.evaluate(rest.points(), direct);
    CHECK(test::sameBits(hosted, direct));

    // Closed form: theta(x) = pi (x + 1) / 4 on [-1, 3], a right-handed turn about +x through (1, 1, 0):
    // (y - 1, z) -> ((y - 1) cos - z sin, (y - 1) sin + z cos). Float trigonometry and the profile's
    // float evaluation round to a few ulps of coordinates below 2: 1e-5.
    const auto points = rest.points();
    for (size_t u = 0; u < points.size(); ++u) {
        const glm::dvec3 p(points[u]);
        const double t = std::numbers::pi * (p.x + 1.0) / 4.0, c = std::cos(t), s = std::sin(t);
        const glm::dvec3 expected(p.x, 1.0 + (p.y - 1.0) * c - p.z * s, (p.y - 1.0) * s + p.z * c);
        CHECK(glm::length(glm::dvec3(hosted[u]) - expected) < 1e-5);
    }
}

TEST_CASE("taper adapter: scales across the handle axis linearly between the bounds, held beyond",
          "[host][deformers][taper]") {
    geom::Mesh::Data data;
    data.points = {{1, 0, 0}, {1, 5, 1}, {0.5f, -4, -2}, {2, 1, 0}, {0, 0.5f, 3}};
    data.faceCounts = {3, 3};
    data.faceIndices = {0, 1, 2, 2, 3, 4};
    const geom::Mesh rest(std::move(data), "points");
    const auto d = makeDeformer("taper", "tp");
    d->set("handleY", std::vector<double>{0, 2, 0});  // bounds -1..1 are y in [-2, 2]
    d->set("startScale", 1.0);
    d->set("endScale", 3.0);
    const std::vector<glm::vec3> out = test::runAlone(*d, rest);
    // f(y) = 2 + y / 2 on [-2, 2], 1 below, 3 above; x and z multiplied by f. Hand values; the profile is
    // a float cubic that is exactly linear here, so 1e-6 covers its rounding.
    const std::vector<glm::vec3> expected = {
        {2, 0, 0}, {3, 5, 3}, {0.5f, -4, -2}, {5, 1, 0}, {0, 0.5f, 6.75f}};
    for (size_t u = 0; u < expected.size(); ++u)
        CHECK(glm::length(out[u] - expected[u]) < 1e-6f);

    warp::TaperWarp taper({glm::vec3(0), glm::vec3(0, 2, 0), glm::vec3(0)},
                          warp::ProfileCurve({-2.0f, 2.0f}, {1.0f, 3.0f}));
    warp::SparseFields fields;
    taper.bind(rest.points(), fields);
    std::vector<glm::vec3> direct(out.size());
    taper.evaluate(rest.points(), direct);
    CHECK(test::sameBits(out, direct));

    // Bounds beyond float32's range once in scene units (3e38 times handle Y's length 2): named as the
    // parameter, not as the profile's z sample that became inf.
    const auto far = makeDeformer("taper", "tp");
    far->set("handleY", std::vector<double>{0, 2, 0});
    far->set("highBound", 3e38);
    CHECK_THROWS_WITH(
        test::runAlone(*far, rest),
        Contains("taper 'tp': parameter 'highBound': is 3e+38, times handle Y's length 2 beyond "
                 "float32's range"));
}

TEST_CASE("bend, wires and slide adapters equal their core deformers", "[host][deformers]") {
    const geom::Mesh rest = testPlane();

    SECTION("bend") {
        const auto d = makeDeformer("bend", "bd");
        d->set("handleOrigin", std::vector<double>{1, 1, 0});
        d->set("handleX", std::vector<double>{0, 0, 1});
        d->set("handleY", std::vector<double>{1, 0, 0});
        d->set("curvature", 0.8);
        d->set("lowBound", -0.5);
        const std::vector<glm::vec3> hosted = test::runAlone(*d, rest);
        warp::MayaBend maya;
        maya.handleOrigin = {1, 1, 0};
        maya.handleX = {0, 0, 1};
        maya.handleY = {1, 0, 0};
        maya.curvature = 0.8;
        maya.lowBound = -0.5;
        const warp::BendSetup setup = warp::fromMayaBend(maya);
        warp::BendWarp bend(setup.frame, setup.params);
        warp::SparseFields fields;
        bend.bind(rest.points(), fields);
        std::vector<glm::vec3> direct(hosted.size());
        bend.evaluate(rest.points(), direct);
        CHECK(test::sameBits(hosted, direct));
        CHECK(maxError(direct, restOf(rest)) > 0.05f);
    }
    SECTION("wires") {
        const auto d = makeDeformer("wires", "wr");
        const std::vector<double> restCurve{0, 1, 0.1, 1, 1.1, 0.1, 2, 1, 0.1};
        d->set("restCurve", restCurve);
        CHECK(d->get("curve") == restCurve);  // reset to the rest curve
        d->set("curve", std::vector<double>{0, 1, 0.1, 1, 1.2, 0.5, 2, 1, 0.1});
        d->set("dropoff", 0.6);
        const std::vector<glm::vec3> hosted = test::runAlone(*d, rest);
        warp::Wire wire;
        wire.reference = {{0, 1, 0.1f}, {1, 1.1f, 0.1f}, {2, 1, 0.1f}};
        wire.wire = {{0, 1, 0.1f}, {1, 1.2f, 0.5f}, {2, 1, 0.1f}};
        wire.radius = 0.6f;
        warp::Wires wires({wire});
        wires.bind(rest.points());
        std::vector<glm::vec3> direct = restOf(rest);
        wires.evaluate(direct);
        CHECK(test::sameBits(hosted, direct));
        CHECK(maxError(direct, restOf(rest)) > 0.1f);
    }
    SECTION("slide") {
        const auto d = makeDeformer("slide", "sl");
        CHECK(d->weightMode() == host::WeightMode::Native);
        d->set("vertex", 40.0);  // (4, 4), the centre (1, 1)
        d->set("radius", 0.7);
        d->set("displacement", std::vector<double>{0.2, 0.1, 0.0});
        d->set("falloff", 2.0);
        d->set("falloffRamp", std::vector<double>{1, 0.5, 0});
        const std::vector<glm::vec3> hosted = test::runAlone(*d, rest);
        slide::Slider slider(rest, {{40, 0.7}});
        const std::vector<float> ramp{1, 0.5f, 0};
        const std::vector<slide::SlideDrive> drives{{glm::dvec3(0.2, 0.1, 0.0), slide::Falloff::ramp(ramp)}};
        std::vector<glm::vec3> direct = restOf(rest);
        slider.evaluate(drives, direct);
        CHECK(test::sameBits(hosted, direct));
        // On a plane the slide is a translation by falloff x displacement: the handle moves by all of it.
        CHECK(glm::length(hosted[40] - (rest.points()[40] + glm::vec3(0.2f, 0.1f, 0.0f))) < 1e-6f);
    }
}

TEST_CASE("parameters are validated and named", "[host][deformers][errors]") {
    const auto ffd = makeDeformer("ffd", "lattice1");
    CHECK_THROWS_WITH(ffd->set("point", std::vector<double>{1, 2, 3}),
                      Contains("ffd 'lattice1': parameter 'point': does not exist") && Contains("points"));
    CHECK_THROWS_WITH(ffd->get("pts"), Contains("parameter 'pts'"));
    CHECK_THROWS_WITH(ffd->set("points", std::vector<double>{1, 2, 3}),
                      Contains("parameter 'points': has 3 values (expected 24 values)"));
    CHECK_THROWS_WITH(ffd->set("origin", std::vector<double>{0, std::nan(""), 0}),
                      Contains("parameter 'origin': value 1 is nan"));
    CHECK_THROWS_WITH(ffd->set("origin", std::vector<double>{0, 1e300, 0}), Contains("within float range"));
    CHECK_THROWS_WITH(ffd->set("divisions", std::vector<double>{2, 0, 1}),
                      Contains("parameter 'divisions': value 1 is 0"));
    CHECK_THROWS_WITH(ffd->set("divisions", std::vector<double>{2, 1.5, 1}), Contains("whole numbers"));
    // Bernstein: degree at most 64; the core's message is kept.
    CHECK_THROWS_WITH(ffd->set("divisions", std::vector<double>{65, 1, 1}),
                      Contains("parameter 'divisions'") && Contains("B-spline"));
    CHECK_THROWS_WITH(ffd->set("axes", std::vector<double>{1, 0, 0, 0, 1, 0, 2, 3, 0}),
                      Contains("parameter 'axes'") && Contains("coplanar"));
    CHECK_THROWS_WITH(ffd->set("basis", 5.0), Contains("parameter 'basis': is 5"));
    CHECK_THROWS_WITH(ffd->set("basis", std::vector<double>{1, 1}),
                      Contains("parameter 'basis': has 2 values (expected 1 value, or 3 (X, Y, Z))"));
    CHECK_THROWS_WITH(ffd->set("basis", std::vector<double>{1, 0.5, 1}),
                      Contains("parameter 'basis': value 1 is 0.5"));
    CHECK_THROWS_WITH(ffd->set("ends", 2.0), Contains("parameter 'ends': is 2"));
    // Rejected values leave the deformer as it was.
    CHECK(ffd->get("divisions") == std::vector<double>{1, 1, 1});
    CHECK(ffd->get("origin") == std::vector<double>{0, 0, 0});

    const auto slide = makeDeformer("slide", "s");
    CHECK_THROWS_WITH(slide->set("radius", 0.0), Contains("slide 's': parameter 'radius': is 0"));
    // The ramp's own message, once: what it expected, not a second "(expected ...)".
    const std::string ramp = test::errorOf<InvalidInput>([&] {
        slide->set("falloffRamp", std::vector<double>{1, 1.5, 0});
    });
    CHECK_THAT(ramp,
               Contains("parameter 'falloffRamp': samples: sample 1: is 1.5 (expected a finite value in "
                        "[0, 1])"));
    CHECK(ramp.find("(expected", ramp.find("(expected") + 1) == std::string::npos);
    CHECK_THROWS_WITH(slide->set("falloffRamp", std::vector<double>{1}), Contains("parameter 'falloffRamp'"));
    slide->set("vertex", 500.0);  // checked against the mesh at bind
    const geom::Mesh rest = testPlane();
    CHECK_THROWS_WITH(slide->bind(rest), Contains("slide 's': parameter 'vertex': is 500 (expected a vertex "
                                                  "index below 81"));
    CHECK(slide->needsBind());
    CHECK(slide->bindCount() == 0);
    std::vector<glm::vec3> out(81);
    CHECK_THROWS_WITH(slide->evaluate(restOf(rest), out),
                      Contains("slide 's': evaluate: called before a needed bind"));

    const auto wires = makeDeformer("wires", "w");
    CHECK_THROWS_WITH(wires->set("restCurve", std::vector<double>{0, 0, 0, 0, 0, 0}),
                      Contains("parameter 'restCurve': has length 0"));
    CHECK_THROWS_WITH(wires->set("restCurve", std::vector<double>{0, 0, 0, 1}),
                      Contains("a positive multiple of 3 values"));
    CHECK_THROWS_WITH(wires->set("curve", std::vector<double>{0, 0, 0, 1, 0, 0, 2, 0, 0}),
                      Contains("parameter 'curve': has 9 values (expected 6 values)"));

    // Bounds may pass each other while being set; they are checked, by name, when used.
    const auto twist = makeDeformer("twist", "t");
    twist->set("lowBound", 2.0);
    CHECK_THROWS_WITH(
        twist->bind(rest),
        Contains("twist 't': parameter 'lowBound': is 2, highBound is 1 (expected lowBound < highBound)"));
    twist->set("highBound", 3.0);
    twist->bind(rest);
    CHECK(twist->bindCount() == 1);
    twist->set("lowBound", 4.0);  // animatable: no rebind, the evaluation reports it
    CHECK_FALSE(twist->needsBind());
    std::vector<glm::vec3> twisted(81);
    CHECK_THROWS_WITH(twist->evaluate(restOf(rest), twisted),
                      Contains("twist 't': parameter 'lowBound': is 4"));
    CHECK_THROWS_WITH(twist->set("handleY", std::vector<double>{0, 0, 0}),
                      Contains("parameter 'handleY': is the zero vector"));

    // Cross-parameter checks the core makes at bind arrive with the deformer's name in front.
    const auto bend = makeDeformer("bend", "b");
    bend->set("handleX", std::vector<double>{2, 0, 0});
    CHECK_THROWS_WITH(bend->bind(rest), Contains("bend 'b': bend handle frame: handle scale"));
}

namespace {

// Counts what the host layer asks of a deformer: validations, control pushes and binds.
class CountingDeformer final : public Deformer {
  public:
    CountingDeformer() : Deformer("counting", "c") {
        size_ = addParameter({.name = "size", .rebinds = true, .doc = "bind-time"}, {1.0});
        gain_ = addParameter({.name = "gain", .doc = "a control"}, {1.0});
    }
    mutable int validations = 0;  // validate() is const
    int pushes = 0, binds = 0;
    double pushedGain = 0.0;

  protected:
    void validate(size_t, std::span<const double>) const override { ++validations; }
    void bindRest(const geom::Mesh&, std::span<const float>) override { ++binds; }
    void pushControls() override {
        ++pushes;
        pushedGain = value(gain_)[0];
    }
    void deform(std::span<const glm::vec3> in, std::span<glm::vec3> out) override {
        for (size_t u = 0; u < in.size(); ++u)
            out[u] = in[u] * static_cast<float>(pushedGain);
    }

  private:
    size_t size_, gain_;
};

}  // namespace

TEST_CASE("set: an unchanged value returns before validation; changed controls are pushed once",
          "[host][deformers]") {
    const geom::Mesh plane = testPlane();
    const std::vector<glm::vec3> rest = restOf(plane);
    std::vector<glm::vec3> out(rest.size());
    CountingDeformer d;
    d.set("gain", 1.0);  // the default: nothing happens
    d.set("size", 1.0);
    CHECK(d.validations == 0);
    CHECK(d.needsBind());
    d.bind(plane);
    CHECK(d.binds == 1);
    d.evaluate(rest, out);  // a bind is followed by one push
    d.evaluate(rest, out);
    CHECK(d.pushes == 1);
    d.set("gain", 2.0);
    CHECK(d.validations == 1);
    CHECK(!d.needsBind());  // a control never rebinds
    d.set("gain", 2.0);     // unchanged again
    CHECK(d.validations == 1);
    d.evaluate(rest, out);
    d.evaluate(rest, out);
    CHECK(d.pushes == 2);
    CHECK(out[5] == rest[5] * 2.0f);
    d.set("size", 3.0);  // bind-time: a new bind, then the controls again
    CHECK(d.needsBind());
    d.bind(plane);
    d.evaluate(rest, out);
    CHECK(d.binds == 2);
    CHECK(d.pushes == 3);
}

TEST_CASE("an FFD does not rebuild its lattice to validate an unchanged value", "[host][deformers]") {
    // divisions (4, 4, 4) with the Bernstein basis is valid; setting the same value again must not run the
    // lattice check, so it stays cheap for hosts that push every parameter every frame.
    const auto ffd = makeDeformer("ffd", "lattice");
    const std::vector<double> divisions = {4, 4, 4};
    ffd->set("divisions", divisions);
    const std::vector<double> points = ffd->get("points");
    const std::vector<double> moved = [&] {
        std::vector<double> p = points;
        p[0] += 0.25;
        return p;
    }();
    ffd->set("points", moved);
    ffd->set("divisions", divisions);  // unchanged: the moved points are kept (a change would reset them)
    CHECK(ffd->get("points") == moved);
}
