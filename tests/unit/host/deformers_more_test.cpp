#include <catch2/catch.hpp>

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>

#include "deformkit/error.h"
#include "deformkit/host/deformers.h"
#include "deformkit/host/stack.h"
#include "deformkit/warp/beier_neely.h"
#include "deformkit/warp/engine.h"
#include "deformkit/warp/ffd.h"
#include "deformkit/warp/ffd_frames.h"
#include "deformkit/warp/mesh_warp.h"
#include "deformkit/warp/wires.h"
#include "host/host_test_support.h"
#include "slide/slide_test_support.h"
#include "test_support.h"

// The adapters added after the first six: ffdframes, beierneely, meshwarp, and wires with several wires.
// Each is compared bit for bit with the core calls it stands for, and against a closed form where one
// exists.

using namespace deformkit;
using Catch::Contains;
using host::Deformer;
using host::makeDeformer;

using test::flatten;
using test::maxError;
using test::restOf;

namespace {

// An open tube about the z axis, radius 0.8, z in [0, 2].
geom::Mesh tube(int around = 16, int rows = 8) {
    return test::cylinder(around, rows, 0.8f, 2.0f);
}

// A 2 x 2 plane of n x n quads at z = 0.1.
geom::Mesh plane(int n = 8) {
    return test::planeGrid(n, n, 2.0f / static_cast<float>(n), glm::mat3(1.0f), glm::vec3(0.0f, 0.0f, 0.1f));
}

// Rotation by `angle` radians about the unit `axis` (Rodrigues), in double.
glm::dmat3 rotation(glm::dvec3 axis, double angle) {
    axis = glm::normalize(axis);
    const double c = std::cos(angle), s = std::sin(angle);
    const glm::dmat3 k(glm::dvec3(0, axis.z, -axis.y), glm::dvec3(-axis.z, 0, axis.x),
                       glm::dvec3(axis.y, -axis.x, 0));  // columns: k v = axis x v
    return glm::dmat3(1.0) + s * k + (1.0 - c) * k * k;
}

// The engine path the engine-based adapters stand for: fields on the rest mesh, transformations of the
// warp's current controls, Eq. (3) on `in`.
std::vector<glm::vec3> engineDirect(warp::Warp& w, const geom::Mesh& rest, const std::vector<glm::vec3>& in) {
    warp::SparseFields fields;
    w.bind(rest.points(), fields);
    warp::Transformations transforms;
    w.transformations(transforms);
    std::vector<glm::vec3> out(in.size());
    warp::evaluateWarp(in, fields, transforms, out, w.engineOptions());
    return out;
}

// Builds and sets up a deformer with 1 and then 2 OpenMP threads, binds and evaluates it each time, and
// requires the same bytes.
template <class Make>
void checkThreadCounts(const Make& make, const geom::Mesh& rest) {
    omp_set_num_threads(1);
    const auto one = make();
    const std::vector<glm::vec3> a = test::runAlone(*one, rest);
    omp_set_num_threads(2);
    const auto two = make();
    const std::vector<glm::vec3> b = test::runAlone(*two, rest);
    omp_set_num_threads(omp_get_num_procs());
    CHECK(test::sameBits(a, b));
    CHECK(maxError(a, restOf(rest)) > 0.01f);  // the comparison is of a real deformation
}

// ---- ffdframes fixture: a 2 x 1 x 2 lattice around the tube ----

struct FramesSetup {
    FramesSetup() {
        lattice.divisions = {2, 1, 2};
        lattice.origin = {-1.0f, -1.0f, -0.25f};
        lattice.axes = glm::mat3(glm::vec3(2, 0, 0), glm::vec3(0, 2, 0), glm::vec3(0, 0, 2.5f));
        const std::vector<glm::vec3> rest = lattice.controlPoints();
        frames.resize(rest.size());
        for (size_t c = 0; c < rest.size(); ++c)
            frames[c].origin = rest[c];
        warp::Frame& a = frames[lattice.index(1, 0, 1)];
        a.basis = glm::mat3(rotation({0, 0, 1}, 0.6));
        a.origin += glm::vec3(0.1f, 0.0f, 0.2f);
        frames[lattice.index(2, 1, 2)].basis =
            glm::mat3(glm::vec3(1.3f, 0, 0), glm::vec3(0, 0.8f, 0), glm::vec3(0.1f, 0, 1));
        frames[lattice.index(0, 1, 0)].origin += glm::vec3(0.0f, -0.2f, 0.1f);
    }

    [[nodiscard]] std::vector<double> points() const {
        std::vector<double> out;
        for (const warp::Frame& f : frames)
            out.insert(out.end(), {f.origin.x, f.origin.y, f.origin.z});
        return out;
    }
    [[nodiscard]] std::vector<double> bases() const {
        std::vector<double> out;
        for (const warp::Frame& f : frames)
            for (int a = 0; a < 3; ++a)
                out.insert(out.end(), {f.basis[a].x, f.basis[a].y, f.basis[a].z});
        return out;
    }
    // The adapter with this lattice and these frames.
    [[nodiscard]] std::unique_ptr<Deformer> make() const {
        auto d = makeDeformer("ffdframes", "frames1");
        d->set("divisions", std::vector<double>{2, 1, 2});
        d->set("origin", std::vector<double>{-1, -1, -0.25});
        d->set("axes", std::vector<double>{2, 0, 0, 0, 2, 0, 0, 0, 2.5});
        d->set("points", points());
        d->set("frames", bases());
        return d;
    }
    // The core calls, deforming `in` (bound to `rest`).
    [[nodiscard]] std::vector<glm::vec3> direct(const geom::Mesh& rest, std::vector<glm::vec3> in) const {
        warp::FfdFrames ffd(lattice);
        ffd.setTargetFrames(frames);
        ffd.bind(rest.points());
        ffd.evaluate(in);
        return in;
    }

    warp::Lattice lattice;
    std::vector<warp::Frame> frames;
};

// ---- meshwarp fixture: a box cage around the tube ----

// A box's 8 corners in the adapter's default order (the unit cube's: bottom face counter-clockwise from
// lo, then the top face), with its six outward quads.
struct BoxCage {
    BoxCage(glm::vec3 lo, glm::vec3 hi)
        : points{{lo.x, lo.y, lo.z}, {hi.x, lo.y, lo.z}, {hi.x, hi.y, lo.z}, {lo.x, hi.y, lo.z},
                 {lo.x, lo.y, hi.z}, {hi.x, lo.y, hi.z}, {hi.x, hi.y, hi.z}, {lo.x, hi.y, hi.z}} {}

    [[nodiscard]] geom::Mesh mesh() const {
        geom::Mesh::Data d;
        d.points = points;
        d.faceCounts.assign(counts.begin(), counts.end());
        d.faceIndices.assign(indices.begin(), indices.end());
        return geom::Mesh(std::move(d), "box cage");
    }

    std::vector<glm::vec3> points;
    std::vector<double> counts{4, 4, 4, 4, 4, 4};
    std::vector<double> indices{0, 3, 2, 1, 4, 5, 6, 7, 0, 1, 5, 4, 2, 3, 7, 6, 0, 4, 7, 3, 1, 2, 6, 5};
};

struct CageSetup {
    CageSetup() : box({-1.0f, -1.0f, -0.25f}, {1.0f, 1.0f, 2.25f}) {
        target = box.points;
        target[6] += glm::vec3(0.3f, 0.2f, 0.4f);
        target[1] += glm::vec3(-0.2f, 0.1f, 0.0f);
        target[3] += glm::vec3(0.0f, 0.0f, -0.3f);
    }
    [[nodiscard]] std::unique_ptr<Deformer> make() const {
        auto d = makeDeformer("meshwarp", "cage1");
        d->set("restCage", flatten(box.points));
        d->set("beta", 1.2);
        d->set("gamma", -0.1);
        d->set("cage", flatten(target));
        return d;
    }
    [[nodiscard]] std::vector<glm::vec3> direct(const geom::Mesh& rest,
                                                const std::vector<glm::vec3>& in) const {
        warp::MeshWarpOptions options;
        options.beta = 1.2f;
        options.gamma = -0.1f;
        warp::MeshWarp w(box.mesh(), options);
        w.setTarget(target);
        return engineDirect(w, rest, in);
    }

    BoxCage box;
    std::vector<glm::vec3> target;
};

// ---- beierneely fixture: two features over the plane ----

struct FeatureSetup {
    std::vector<double> rest{0.2, 0.3, 1.8, 0.4, 0.5, 1.6, 1.5, 1.7};
    // The first feature turns clockwise, the second anticlockwise: the variants differ.
    std::vector<double> moved{0.3, 0.5, 1.7, 0.1, 0.6, 1.4, 1.4, 1.9};

    [[nodiscard]] std::unique_ptr<Deformer> make(int global) const {
        auto d = makeDeformer("beierneely", "bn1");
        d->set("global", global);
        d->set("restFeatures", rest);
        d->set("a", 0.5);
        d->set("b", 1.5);
        d->set("p", 0.3);
        d->set("features", moved);
        return d;
    }
    [[nodiscard]] std::vector<glm::vec3> direct(int global, const geom::Mesh& mesh) const {
        std::vector<warp::SegmentPair> pairs(2);
        for (size_t i = 0; i < 2; ++i) {
            const auto at = [](const std::vector<double>& v, size_t k) {
                return glm::vec2(static_cast<float>(v[k]), static_cast<float>(v[k + 1]));
            };
            pairs[i].dstP = at(rest, 4 * i);
            pairs[i].dstQ = at(rest, 4 * i + 2);
            pairs[i].srcP = at(moved, 4 * i);
            pairs[i].srcQ = at(moved, 4 * i + 2);
            pairs[i].a = 0.5f;
            pairs[i].b = 1.5f;
            pairs[i].p = 0.3f;
        }
        warp::BeierNeelyWarp w(
            pairs, {global == 0 ? warp::BeierNeelyVariant::Original : warp::BeierNeelyVariant::Global});
        return engineDirect(w, mesh, restOf(mesh));
    }
};

// ---- wires fixture: two wires over the plane ----

struct TwoWires {
    TwoWires() {
        first.reference = {{0, 0.5f, 0.1f}, {1, 0.6f, 0.1f}, {2, 0.5f, 0.1f}};
        first.wire = {{0, 0.5f, 0.1f}, {1, 0.7f, 0.5f}, {2, 0.5f, 0.1f}};
        first.radius = 0.6f;
        second.reference = {{0.5f, 1.5f, 0.1f}, {1.5f, 1.5f, 0.1f}};
        second.wire = {{0.5f, 1.6f, 0.3f}, {1.5f, 1.4f, 0.2f}};
        second.radius = 0.5f;
        second.scale = 1.3f;
    }
    [[nodiscard]] std::unique_ptr<Deformer> make(int smooth) const {
        auto d = makeDeformer("wires", "wr");
        d->set("smooth", smooth);
        std::vector<double> rest = flatten(first.reference), curve = flatten(first.wire);
        const std::vector<double> rest2 = flatten(second.reference), curve2 = flatten(second.wire);
        rest.insert(rest.end(), rest2.begin(), rest2.end());
        curve.insert(curve.end(), curve2.begin(), curve2.end());
        d->set("restCurve", rest);
        d->set("curveSizes", std::vector<double>{3, 2});
        d->set("curve", curve);
        d->set("dropoff", std::vector<double>{0.6, 0.5});
        d->set("scale", std::vector<double>{1.0, 1.3});
        d->set("exponent", 1.5);
        return d;
    }
    [[nodiscard]] std::vector<glm::vec3> direct(int smooth, const geom::Mesh& rest) const {
        warp::WiresOptions options;
        options.variant = smooth == 0 ? warp::WiresVariant::Original : warp::WiresVariant::Smooth;
        options.exponent = 1.5f;
        warp::Wires wires({first, second}, options);
        wires.bind(rest.points());
        std::vector<glm::vec3> out = restOf(rest);
        wires.evaluate(out);
        return out;
    }

    warp::Wire first, second;
};

}  // namespace

// ---- ffdframes ----

TEST_CASE("ffdframes adapter equals warp::FfdFrames called directly", "[host][deformers][ffdframes]") {
    const geom::Mesh rest = tube();
    const FramesSetup setup;
    const auto d = makeDeformer("ffdframes", "frames1");
    // Parameters: the lattice as ffd's, then points and frames, which follow the divisions.
    const auto params = d->parameters();
    REQUIRE(params.size() == 9);
    CHECK(params[6].name == "axes");
    CHECK(params[7].name == "points");
    CHECK(params[8].name == "frames");
    CHECK_FALSE(params[8].rebinds);
    CHECK(params[8].components == 9 * 8);
    d->set("divisions", std::vector<double>{2, 1, 2});
    CHECK(d->parameter("frames").components == 9 * 3 * 2 * 3);
    CHECK(d->parameter("points").components == 3 * 3 * 2 * 3);

    const auto hosted = setup.make();
    const std::vector<glm::vec3> out = test::runAlone(*hosted, rest);
    // The same core calls on the same float values: bit-identical.
    CHECK(test::sameBits(out, setup.direct(rest, restOf(rest))));
    CHECK(maxError(out, restOf(rest)) > 0.05f);
}

TEST_CASE("ffdframes: a rigid motion of every frame moves the model rigidly, identity bases are ffd",
          "[host][deformers][ffdframes]") {
    const geom::Mesh rest = tube();
    const FramesSetup setup;
    // Every control's target frame (R P_ijk + t, R): T_ijk<p> = R (p - P_ijk) + R P_ijk + t = R p + t for
    // every control, and the weights sum to 1 inside the lattice, so the model moves by exactly R p + t.
    const glm::dmat3 r = rotation({1, 2, 3}, 0.5);
    const glm::dvec3 t(0.3, -0.2, 0.1);
    const std::vector<glm::vec3> controls = setup.lattice.controlPoints();
    std::vector<glm::vec3> moved;
    std::vector<double> bases;
    for (const glm::vec3& c : controls) {
        moved.push_back(glm::vec3(r * glm::dvec3(c) + t));
        for (int a = 0; a < 3; ++a)
            bases.insert(bases.end(), {r[a].x, r[a].y, r[a].z});
    }
    const auto d = setup.make();
    d->set("points", flatten(moved));
    d->set("frames", bases);
    const std::vector<glm::vec3> out = test::runAlone(*d, rest);
    const auto in = rest.points();
    double worst = 0.0;
    for (size_t u = 0; u < out.size(); ++u)
        worst = std::max(worst, glm::length(glm::dvec3(out[u]) - (r * glm::dvec3(in[u]) + t)));
    // Float controls, float weights summing to 1 within a few ulps, coordinates below 3 (an ulp is 2.4e-7
    // there): 2e-6.
    CHECK(worst < 2e-6);

    // Identity bases: plain FFD with the same deformed points (different float kernels: 1e-6).
    const auto frames = setup.make();
    std::vector<double> identity;
    for (size_t c = 0; c < controls.size(); ++c)
        identity.insert(identity.end(), {1, 0, 0, 0, 1, 0, 0, 0, 1});
    frames->set("frames", identity);
    const auto ffd = makeDeformer("ffd", "plain");
    ffd->set("divisions", std::vector<double>{2, 1, 2});
    ffd->set("origin", std::vector<double>{-1, -1, -0.25});
    ffd->set("axes", std::vector<double>{2, 0, 0, 0, 2, 0, 0, 0, 2.5});
    ffd->set("points", setup.points());
    const std::vector<glm::vec3> a = test::runAlone(*frames, rest), b = test::runAlone(*ffd, rest);
    CHECK(maxError(a, b) < 1e-6f);
    CHECK(maxError(a, restOf(rest)) > 0.05f);
}

TEST_CASE("ffdframes: controls do not rebind, the lattice does, and resets the controls",
          "[host][deformers][ffdframes]") {
    const geom::Mesh rest = tube();
    const FramesSetup setup;
    const auto d = setup.make();
    const std::vector<glm::vec3> first = test::runAlone(*d, rest);
    CHECK(d->bindCount() == 1);

    FramesSetup turned = setup;
    turned.frames[turned.lattice.index(1, 1, 1)].basis = glm::mat3(rotation({1, 0, 0}, -0.4));
    d->set("frames", turned.bases());
    d->set("points", turned.points());
    CHECK_FALSE(d->needsBind());
    const std::vector<glm::vec3> second = test::runAlone(*d, rest);
    CHECK(d->bindCount() == 1);
    CHECK(test::sameBits(second, turned.direct(rest, restOf(rest))));
    CHECK(maxError(first, second) > 0.01f);

    d->set("outside", 1.0);
    CHECK(d->needsBind());
    (void)test::runAlone(*d, rest);
    CHECK(d->bindCount() == 2);
    // A lattice change rebinds and puts the controls back at rest: the identity, bit for bit.
    d->set("origin", std::vector<double>{-1.5, -1, -0.25});
    warp::Lattice shifted = setup.lattice;
    shifted.origin.x = -1.5f;
    CHECK(d->get("points") == flatten(shifted.controlPoints()));
    CHECK(d->get("frames")[9 * 5 + 4] == 1.0);
    CHECK(test::sameBits(test::runAlone(*d, rest), restOf(rest)));
    CHECK(d->bindCount() == 3);
}

TEST_CASE("ffdframes: bad values are named", "[host][deformers][ffdframes][errors]") {
    const auto d = makeDeformer("ffdframes", "f");
    CHECK_THROWS_AS(d->set("frames", std::vector<double>{1, 0, 0, 0, 1, 0, 0, 0, 1}), InvalidInput);
    CHECK_THROWS_WITH(d->set("frames", std::vector<double>{1, 0, 0, 0, 1, 0, 0, 0, 1}),
                      Contains("ffdframes 'f': parameter 'frames': has 9 values (expected 72 values)"));
    std::vector<double> frames = d->get("frames");
    frames[13] = std::nan("");
    CHECK_THROWS_WITH(d->set("frames", frames), Contains("parameter 'frames': value 13 is nan"));
    CHECK_THROWS_WITH(d->set("points", std::vector<double>(24, 1e39)),
                      Contains("parameter 'points': value 0 is 1e+39") && Contains("float range"));
    CHECK_THROWS_WITH(d->set("basis", 5.0), Contains("parameter 'basis': is 5"));
    CHECK_THROWS_WITH(d->set("divisions", std::vector<double>{1, 0, 1}),
                      Contains("parameter 'divisions': value 1 is 0"));
    CHECK_THROWS_WITH(d->set("axes", std::vector<double>{1, 0, 0, 2, 0, 0, 0, 0, 1}),
                      Contains("parameter 'axes'") && Contains("coplanar"));
    CHECK(d->get("divisions") == std::vector<double>{1, 1, 1});
}

// ---- beierneely ----

TEST_CASE("beierneely adapter equals the core warp through the engine, both variants",
          "[host][deformers][beierneely]") {
    const geom::Mesh rest = plane();
    const FeatureSetup setup;
    for (int global : {0, 1}) {
        const auto d = setup.make(global);
        const std::vector<glm::vec3> out = test::runAlone(*d, rest);
        CHECK(test::sameBits(out, setup.direct(global, rest)));
        CHECK(maxError(out, restOf(rest)) > 0.05f);
        // A 2-D warp: z is kept bit for bit.
        bool zKept = true;
        for (size_t u = 0; u < out.size(); ++u)
            zKept = zKept && std::memcmp(&out[u].z, &rest.points()[u].z, sizeof(float)) == 0;
        CHECK(zKept);
    }
    // The variants differ on this input (the features turn opposite ways).
    CHECK(maxError(setup.direct(0, rest), setup.direct(1, rest)) > 1e-2f);
}

TEST_CASE("beierneely: one feature is a similarity, the closed form", "[host][deformers][beierneely]") {
    const geom::Mesh rest = plane();
    const auto d = makeDeformer("beierneely", "bn");
    const auto params = d->parameters();
    REQUIRE(params.size() == 6);
    CHECK(params[1].name == "restFeatures");
    CHECK(params[1].stride == 4);
    CHECK(params[5].name == "features");
    CHECK_FALSE(params[5].rebinds);
    // Default: one feature (0, 0) -> (1, 0); moved to (1, 1) -> (1, 2) it is a quarter turn and a shift:
    // (x, y) -> (1 - y, 1 + x), whatever the weight.
    d->set("features", std::vector<double>{1, 1, 1, 2});
    const std::vector<glm::vec3> out = test::runAlone(*d, rest);
    const auto in = rest.points();
    double worst = 0.0;
    for (size_t u = 0; u < out.size(); ++u) {
        const glm::dvec3 expected(1.0 - in[u].y, 1.0 + in[u].x, in[u].z);
        worst = std::max(worst, glm::length(glm::dvec3(out[u]) - expected));
    }
    // A float affine map of coordinates below 3 and a weight normalised to 1: a few ulps, 1e-6.
    CHECK(worst < 1e-6);
}

TEST_CASE("beierneely: deformed features do not rebind, rest features and constants do",
          "[host][deformers][beierneely]") {
    const geom::Mesh rest = plane();
    FeatureSetup setup;
    const auto d = setup.make(0);
    (void)test::runAlone(*d, rest);
    CHECK(d->bindCount() == 1);
    setup.moved[5] += 0.2;
    d->set("features", setup.moved);
    CHECK_FALSE(d->needsBind());
    CHECK(test::sameBits(test::runAlone(*d, rest), setup.direct(0, rest)));
    CHECK(d->bindCount() == 1);

    d->set("b", 1.5);  // the value it has: nothing changes
    CHECK_FALSE(d->needsBind());
    d->set("a", 0.7);
    CHECK(d->needsBind());
    (void)test::runAlone(*d, rest);
    CHECK(d->bindCount() == 2);
    d->set("global", 1.0);
    (void)test::runAlone(*d, rest);
    CHECK(d->bindCount() == 3);

    // A rest change resets the deformed features to it (the identity), with a third feature.
    const std::vector<double> three{0.2, 0.3, 1.8, 0.4, 0.5, 1.6, 1.5, 1.7, 1.0, 0.5, 1.0, 1.5};
    d->set("restFeatures", three);
    CHECK(d->get("features") == three);
    CHECK(d->parameter("features").components == 12);
    CHECK(maxError(test::runAlone(*d, rest), restOf(rest)) < 1e-6f);  // identity maps, float rounding only
    CHECK(d->bindCount() == 4);
}

TEST_CASE("beierneely: bad values are named", "[host][deformers][beierneely][errors]") {
    const auto d = makeDeformer("beierneely", "bn");
    CHECK_THROWS_AS(d->set("restFeatures", std::vector<double>{0, 0, 1}), InvalidInput);
    CHECK_THROWS_WITH(d->set("restFeatures", std::vector<double>{0, 0, 1}),
                      Contains("beierneely 'bn': parameter 'restFeatures': has 3 values") &&
                          Contains("a positive multiple of 4 values"));
    CHECK_THROWS_WITH(d->set("restFeatures", std::vector<double>{0, 0, 1, 0, 2, 2, 2, 2}),
                      Contains("parameter 'restFeatures': feature 1 has length 0"));
    CHECK_THROWS_WITH(d->set("features", std::vector<double>{0, 0, 1, 0, 0, 1, 1, 1}),
                      Contains("parameter 'features': has 8 values (expected 4 values)"));
    CHECK_THROWS_WITH(d->set("features", std::vector<double>{0.5, 0.5, 0.5, 0.5}),
                      Contains("parameter 'features': feature 0 has length 0"));
    CHECK_THROWS_WITH(
        d->set("features", std::vector<double>{0, std::numeric_limits<double>::infinity(), 1, 0}),
        Contains("parameter 'features': value 1 is inf"));
    CHECK_THROWS_WITH(d->set("global", 2.0), Contains("parameter 'global': is 2"));
    CHECK_THROWS_WITH(d->set("global", 0.5), Contains("parameter 'global': is 0.5"));
    CHECK_THROWS_WITH(d->set("a", 0.0), Contains("parameter 'a': is 0 (expected a number > 0)"));
    CHECK_THROWS_WITH(d->set("a", 1e-60), Contains("parameter 'a': is 1e-60"));  // 0 as a float
    CHECK_THROWS_WITH(d->set("b", -0.5), Contains("parameter 'b': is -0.5"));
    CHECK_THROWS_WITH(d->set("p", -1.0), Contains("parameter 'p': is -1"));
    CHECK(d->get("restFeatures") == std::vector<double>{0, 0, 1, 0});
    CHECK(d->get("a") == std::vector<double>{1});
}

// ---- meshwarp ----

TEST_CASE("meshwarp adapter equals warp::MeshWarp through the engine", "[host][deformers][meshwarp]") {
    const geom::Mesh rest = tube();
    const CageSetup setup;
    const auto d = makeDeformer("meshwarp", "cage1");
    const auto params = d->parameters();
    REQUIRE(params.size() == 8);
    CHECK(params[0].name == "restCage");
    CHECK(params[1].name == "cageFaceCounts");
    CHECK(params[2].name == "cageFaceIndices");
    CHECK(params[7].name == "cage");
    CHECK_FALSE(params[7].rebinds);
    // The default cage is the unit cube, at rest: the identity.
    const geom::Mesh small = test::planeGrid(4, 4, 0.25f, glm::mat3(1.0f), glm::vec3(0.0f, 0.0f, 0.5f));
    CHECK(maxError(test::runAlone(*d, small), restOf(small)) < 1e-6f);
    CHECK(d->get("restCage") == flatten(BoxCage({0, 0, 0}, {1, 1, 1}).points));

    const auto hosted = setup.make();
    const std::vector<glm::vec3> out = test::runAlone(*hosted, rest);
    CHECK(test::sameBits(out, setup.direct(rest, restOf(rest))));
    CHECK(maxError(out, restOf(rest)) > 0.05f);
}

TEST_CASE("meshwarp: a rigid motion of a box cage moves the tube inside rigidly",
          "[host][deformers][meshwarp]") {
    const geom::Mesh rest = tube();
    const CageSetup setup;
    // Each box corner's three edges span space, so L_i = R exactly and T_i<P> = R P + t for every corner;
    // every tube point is within reach of its nearest corner, so the result is R p + t.
    const glm::dmat3 r = rotation({1, 2, 3}, 0.5);
    const glm::dvec3 t(0.3, -0.2, 0.1);
    std::vector<glm::vec3> moved;
    for (const glm::vec3& p : setup.box.points)
        moved.push_back(glm::vec3(r * glm::dvec3(p) + t));
    const auto d = setup.make();
    d->set("cage", flatten(moved));
    const std::vector<glm::vec3> out = test::runAlone(*d, rest);
    const auto in = rest.points();
    double worst = 0.0;
    for (size_t u = 0; u < out.size(); ++u)
        worst = std::max(worst, glm::length(glm::dvec3(out[u]) - (r * glm::dvec3(in[u]) + t)));
    // Float cage targets, L_i rounded to float from a double solve, coordinates below 3 (an ulp is 2.4e-7
    // there): 2e-6.
    CHECK(worst < 2e-6);
}

TEST_CASE("meshwarp: the deformed cage does not rebind, the rest cage and weights do",
          "[host][deformers][meshwarp]") {
    const geom::Mesh rest = tube();
    CageSetup setup;
    const auto d = setup.make();
    (void)test::runAlone(*d, rest);
    CHECK(d->bindCount() == 1);
    setup.target[4] += glm::vec3(-0.2f, -0.1f, 0.1f);
    d->set("cage", flatten(setup.target));
    CHECK_FALSE(d->needsBind());
    CHECK(test::sameBits(test::runAlone(*d, rest), setup.direct(rest, restOf(rest))));
    CHECK(d->bindCount() == 1);

    d->set("mu", 1.1);
    CHECK(d->needsBind());
    (void)test::runAlone(*d, rest);
    CHECK(d->bindCount() == 2);
    // The same first face, started at another corner: new connectivity, one rebind.
    std::vector<double> indices = setup.box.indices;
    std::rotate(indices.begin(), indices.begin() + 1, indices.begin() + 4);
    d->set("cageFaceIndices", indices);
    CHECK(d->needsBind());
    (void)test::runAlone(*d, rest);
    CHECK(d->bindCount() == 3);
    // A rest cage change resets the deformed cage to it.
    const BoxCage bigger({-1.1f, -1.1f, -0.3f}, {1.1f, 1.1f, 2.3f});
    d->set("restCage", flatten(bigger.points));
    CHECK(d->get("cage") == flatten(bigger.points));
    CHECK(maxError(test::runAlone(*d, rest), restOf(rest)) < 1e-6f);  // the identity, to float rounding
    CHECK(d->bindCount() == 4);
}

TEST_CASE("meshwarp: bad values are named", "[host][deformers][meshwarp][errors]") {
    const geom::Mesh rest = tube();
    const auto d = makeDeformer("meshwarp", "m");
    CHECK_THROWS_AS(d->set("cage", std::vector<double>{0, 0, 0, 1, 0, 0, 0, 1, 0}), InvalidInput);
    CHECK_THROWS_WITH(d->set("cage", std::vector<double>{0, 0, 0, 1, 0, 0, 0, 1, 0}),
                      Contains("meshwarp 'm': parameter 'cage': has 9 values (expected 24 values)"));
    CHECK_THROWS_WITH(d->set("restCage", std::vector<double>{0, 0, 0, 1, 0, 0}),
                      Contains("parameter 'restCage': has 2 points (expected at least 3)"));
    CHECK_THROWS_WITH(d->set("restCage", std::vector<double>{0, 0, 0, 1, 0, 0, 0, 1}),
                      Contains("parameter 'restCage'") && Contains("a positive multiple of 3 values"));
    std::vector<double> cage = d->get("cage");
    cage[5] = std::nan("");
    CHECK_THROWS_WITH(d->set("cage", cage), Contains("parameter 'cage': value 5 is nan"));
    CHECK_THROWS_WITH(d->set("cageFaceCounts", std::vector<double>{4, 4, 2}),
                      Contains("parameter 'cageFaceCounts': value 2 is 2"));
    CHECK_THROWS_WITH(d->set("cageFaceIndices", std::vector<double>{0, 1, -1}),
                      Contains("parameter 'cageFaceIndices': value 2 is -1"));
    CHECK_THROWS_WITH(d->set("alpha", -0.5), Contains("parameter 'alpha': is -0.5"));

    // Cross-parameter checks at bind, by name; the deformer stays unbound.
    d->set("alpha", 1.0);
    CHECK_THROWS_WITH(d->bind(rest), Contains("meshwarp 'm': parameter 'alpha': is 1, beta is 1 (expected "
                                              "alpha < beta)"));
    d->set("alpha", 0.0);
    d->set("gamma", 2.0);
    CHECK_THROWS_WITH(d->bind(rest), Contains("parameter 'gamma': is 2, mu is 1 (expected gamma < mu)"));
    d->set("gamma", 0.0);
    d->set("cageFaceCounts", std::vector<double>{4, 4, 4, 4, 4});
    CHECK_THROWS_WITH(d->bind(rest), Contains("parameter 'cageFaceIndices': has 24 values (expected 20, the "
                                              "sum of cageFaceCounts)"));
    d->set("cageFaceCounts", std::vector<double>{4, 4, 4, 4, 4, 4});
    std::vector<double> indices = BoxCage({0, 0, 0}, {1, 1, 1}).indices;
    indices[7] = 8;
    d->set("cageFaceIndices", indices);
    CHECK_THROWS_WITH(d->bind(rest), Contains("parameter 'cageFaceIndices': value 7 is 8 (expected vertex "
                                              "indices below 8"));
    // A face turned over: not an oriented manifold, a TopologyError naming the faces.
    indices = BoxCage({0, 0, 0}, {1, 1, 1}).indices;
    std::reverse(indices.begin(), indices.begin() + 4);
    d->set("cageFaceIndices", indices);
    CHECK_THROWS_AS(d->bind(rest), TopologyError);
    CHECK_THROWS_WITH(d->bind(rest), Contains("meshwarp 'm': parameter 'cageFaceIndices'"));
    // Two cage points on top of each other: a zero-length edge.
    d->set("cageFaceIndices", BoxCage({0, 0, 0}, {1, 1, 1}).indices);
    std::vector<double> points = flatten(BoxCage({0, 0, 0}, {1, 1, 1}).points);
    points[3] = 0.0;  // point 1 onto point 0
    d->set("restCage", points);
    CHECK_THROWS_WITH(d->bind(rest), Contains("parameter 'restCage'") && Contains("zero length"));
    CHECK(d->needsBind());
    CHECK(d->bindCount() == 0);
}

// ---- wires with several wires ----

TEST_CASE("wires adapter with two wires equals warp::Wires called directly", "[host][deformers][wires]") {
    const geom::Mesh rest = plane();
    const TwoWires setup;
    for (int smooth : {0, 1}) {
        const auto d = setup.make(smooth);
        const std::vector<glm::vec3> out = test::runAlone(*d, rest);
        CHECK(test::sameBits(out, setup.direct(smooth, rest)));
        CHECK(maxError(out, restOf(rest)) > 0.1f);
    }
    // One dropoff for both wires.
    const auto d = setup.make(0);
    d->set("dropoff", 0.55);
    TwoWires same = setup;
    same.first.radius = same.second.radius = 0.55f;
    CHECK(test::sameBits(test::runAlone(*d, rest), same.direct(0, rest)));
}

TEST_CASE("wires: a second wire at rest with scale 1 has no say", "[host][deformers][wires]") {
    const geom::Mesh rest = plane();
    TwoWires setup;
    setup.second.wire = setup.second.reference;
    setup.second.scale = 1.0f;
    const auto d = setup.make(0);
    d->set("scale", 1.0);
    std::vector<double> curve = d->get("curve");
    const std::vector<double> restCurve = d->get("restCurve");
    std::copy(restCurve.begin() + 9, restCurve.end(), curve.begin() + 9);
    d->set("curve", curve);
    // The one-wire core: with m > 0 a wire's weight is scaled by the displacement it causes, 0 here (to
    // float rounding of the identity transformation), so the first wire alone decides. 1e-6 covers the
    // normalisation's rounding.
    warp::WiresOptions options;
    options.exponent = 1.5f;
    warp::Wires one({setup.first}, options);
    one.bind(rest.points());
    std::vector<glm::vec3> expected = restOf(rest);
    one.evaluate(expected);
    const std::vector<glm::vec3> out = test::runAlone(*d, rest);
    CHECK(maxError(out, expected) < 1e-6f);
    CHECK(maxError(expected, restOf(rest)) > 0.1f);
}

TEST_CASE("wires: curves do not rebind, sizes and dropoffs do", "[host][deformers][wires]") {
    const geom::Mesh rest = plane();
    TwoWires setup;
    const auto d = setup.make(0);
    CHECK(d->get("curveSizes") == std::vector<double>{3, 2});
    (void)test::runAlone(*d, rest);
    CHECK(d->bindCount() == 1);
    setup.second.wire[1] += glm::vec3(0.1f, 0.1f, 0.2f);
    std::vector<double> curve = flatten(setup.first.wire);
    const std::vector<double> second = flatten(setup.second.wire);
    curve.insert(curve.end(), second.begin(), second.end());
    d->set("curve", curve);
    CHECK_FALSE(d->needsBind());
    CHECK(test::sameBits(test::runAlone(*d, rest), setup.direct(0, rest)));
    CHECK(d->bindCount() == 1);

    d->set("dropoff", std::vector<double>{0.6, 0.45});
    CHECK(d->needsBind());
    (void)test::runAlone(*d, rest);
    CHECK(d->bindCount() == 2);
    // Five points as one wire: a different deformation, one rebind.
    d->set("curveSizes", 0.0);
    d->set("dropoff", 0.6);
    d->set("scale", 1.0);
    const std::vector<glm::vec3> joined = test::runAlone(*d, rest);
    CHECK(d->bindCount() == 3);
    CHECK(maxError(joined, setup.direct(0, rest)) > 1e-3f);
}

TEST_CASE("wires: bad sizes, counts and values are named", "[host][deformers][wires][errors]") {
    const geom::Mesh rest = plane();
    const TwoWires setup;
    const auto d = setup.make(0);
    CHECK_THROWS_AS(d->set("curveSizes", std::vector<double>{3, 1}), InvalidInput);
    CHECK_THROWS_WITH(
        d->set("curveSizes", std::vector<double>{3, 1}),
        Contains("wires 'wr': parameter 'curveSizes': value 1 is 1 (expected point counts >= 2"));
    CHECK_THROWS_WITH(d->set("curveSizes", std::vector<double>{2.5, 2.5}),
                      Contains("parameter 'curveSizes': value 0 is 2.5") && Contains("whole numbers"));
    CHECK_THROWS_WITH(d->set("curveSizes", std::vector<double>{0, 5}),
                      Contains("parameter 'curveSizes': value 0 is 0"));
    CHECK_THROWS_WITH(d->set("dropoff", std::vector<double>{0.5, 0.0}),
                      Contains("parameter 'dropoff': value 1 is 0 (expected numbers > 0)"));
    CHECK_THROWS_WITH(d->set("scale", -1.0), Contains("parameter 'scale': is -1"));
    CHECK_THROWS_WITH(d->set("exponent", -0.5), Contains("parameter 'exponent': is -0.5 (expected m >= 0)"));
    CHECK_THROWS_WITH(d->set("curve", std::vector<double>(12, 0.5)),
                      Contains("parameter 'curve': has 12 values (expected 15 values)"));
    CHECK_THROWS_WITH(d->set("smooth", 3.0), Contains("parameter 'smooth': is 3"));

    // Counts that disagree are found at bind, by name.
    d->set("curveSizes", std::vector<double>{2, 2});
    CHECK_THROWS_WITH(d->bind(rest),
                      Contains("wires 'wr': parameter 'curveSizes': sums to 4 points (expected "
                               "5, restCurve's point count)"));
    d->set("curveSizes", std::vector<double>{2, 3});
    d->set("dropoff", std::vector<double>{0.5, 0.5, 0.5});
    CHECK_THROWS_WITH(
        d->bind(rest),
        Contains("parameter 'dropoff': has 3 values for 2 wires (expected 1 value, or 1 per wire)"));
    d->set("dropoff", 0.5);
    d->set("scale", std::vector<double>{1, 1, 1});
    CHECK_THROWS_WITH(d->bind(rest), Contains("parameter 'scale': has 3 values for 2 wires"));
    d->set("scale", 1.0);
    // The second wire collapsed to a point.
    d->set("restCurve", std::vector<double>{0, 0.5, 0.1, 1, 0.5, 0.1, 1, 1, 0.1, 1, 1, 0.1, 1, 1, 0.1});
    d->set("curveSizes", std::vector<double>{2, 3});
    CHECK_THROWS_WITH(
        d->bind(rest),
        Contains("parameter 'restCurve': wire 1 (points 2 to 4) has length 0 (expected every wire "
                 "of non-zero length)"));
    CHECK(d->needsBind());
    CHECK(d->bindCount() == 0);
}

// ---- threads ----

TEST_CASE("new adapters: bit-identical output for 1 and 2 threads", "[host][deformers][determinism]") {
    const geom::Mesh dense = tube(64, 64), flat = plane(64);
    SECTION("ffdframes") {
        const FramesSetup setup;
        checkThreadCounts([&] { return setup.make(); }, dense);
    }
    SECTION("beierneely") {
        const FeatureSetup setup;
        checkThreadCounts([&] { return setup.make(0); }, flat);
        checkThreadCounts([&] { return setup.make(1); }, flat);
    }
    SECTION("meshwarp") {
        const CageSetup setup;
        checkThreadCounts([&] { return setup.make(); }, dense);
    }
    SECTION("wires, two wires") {
        const TwoWires setup;
        checkThreadCounts([&] { return setup.make(0); }, flat);
        checkThreadCounts([&] { return setup.make(1); }, flat);
    }
}

// ---- in a stack ----

TEST_CASE("a stack of ffdframes then meshwarp with weights 0.5 follows Maya's rule on the core outputs",
          "[host][deformers][stack]") {
    const geom::Mesh rest = tube();
    const FramesSetup frames;
    const CageSetup cage;
    host::DeformerStack stack;
    stack.setRest(rest);
    stack.add(frames.make());
    stack.add(cage.make());
    const std::vector<float> half(static_cast<size_t>(rest.numVertices()), 0.5f);
    stack.setWeights(0, half);
    stack.setWeights(1, half);
    std::vector<glm::vec3> points = restOf(rest);
    stack.evaluate(points);

    // Maya's rule by hand, in double and rounded once: out = in + 0.5 (deformed - in), each stage's
    // deformed positions from its core deformer bound to the rest mesh and run on the previous output.
    const auto blend = [](const std::vector<glm::vec3>& in, const std::vector<glm::vec3>& deformed) {
        std::vector<glm::vec3> out(in.size());
        for (size_t u = 0; u < in.size(); ++u)
            out[u] = glm::vec3(glm::dvec3(in[u]) + 0.5 * (glm::dvec3(deformed[u]) - glm::dvec3(in[u])));
        return out;
    };
    const std::vector<glm::vec3> first = blend(restOf(rest), frames.direct(rest, restOf(rest)));
    const std::vector<glm::vec3> expected = blend(first, cage.direct(rest, first));
    // The same float operations in the same order: bit for bit.
    CHECK(test::sameBits(points, expected));
    CHECK(maxError(points, first) > 0.02f);
    CHECK(maxError(first, restOf(rest)) > 0.02f);
    CHECK(stack.bindCount() == 2);
}
