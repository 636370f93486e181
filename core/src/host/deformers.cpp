#include "deformkit/host/deformers.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>
#include <glm/vec3.hpp>

#include "deformkit/error.h"
#include "deformkit/slide/falloff.h"
#include "deformkit/slide/slider.h"
#include "deformkit/warp/barr.h"
#include "deformkit/warp/barr_host.h"
#include "deformkit/warp/engine.h"
#include "deformkit/warp/ffd.h"
#include "deformkit/warp/profile_curve.h"
#include "deformkit/warp/wires.h"

namespace deformkit::host {
namespace {

glm::vec3 vec3At(std::span<const double> v, size_t first = 0) {
    return {static_cast<float>(v[first]), static_cast<float>(v[first + 1]), static_cast<float>(v[first + 2])};
}

glm::dvec3 dvec3At(std::span<const double> v, size_t first = 0) {
    return {v[first], v[first + 1], v[first + 2]};
}

std::vector<double> flatten(std::span<const glm::vec3> points) {
    std::vector<double> out;
    out.reserve(points.size() * 3);
    for (const glm::vec3& p : points)
        out.insert(out.end(), {p.x, p.y, p.z});
    return out;
}

// Points from 3k values into `out` (reused: no allocation once it has grown).
void unflatten(std::span<const double> v, std::vector<glm::vec3>& out) {
    out.resize(v.size() / 3);
    for (size_t i = 0; i < out.size(); ++i)
        out[i] = vec3At(v, 3 * i);
}

// The core's direct paths deform in place: copy first, as Deformer::evaluate has separate in and out.
void copyPoints(std::span<const glm::vec3> in, std::span<glm::vec3> out) {
    std::copy(in.begin(), in.end(), out.begin());
}

// ---- ffd ----

class FfdDeformer final : public Deformer {
  public:
    explicit FfdDeformer(std::string label) : Deformer("ffd", std::move(label)) {
        basis_ = addParameter({"basis", 1, true, "0 Bernstein (divisions <= 64), 1 uniform cubic B-spline"},
                              {0.0});
        outside_ = addParameter(
            {"outside", 1, true, "0 points outside the lattice stay put, 1 the polynomials are extrapolated"},
            {0.0});
        divisions_ =
            addParameter({"divisions", 3, true, "l, m, n: cells along X, Y, Z, whole numbers in [1, 1024]"},
                         {1.0, 1.0, 1.0});
        origin_ = addParameter({"origin", 3, true, "rest lattice corner, scene units"}, {0.0, 0.0, 0.0});
        axes_ = addParameter({"axes", 9, true,
                              "rest lattice edge vectors X, Y, Z (x, y, z of each), scene units, linearly "
                              "independent"},
                             {1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0});
        points_ =
            addParameter({"points", 0, false,
                          "deformed control points P*_ijk, x, y, z each, index (i (m+1) + j) (n+1) + k, "
                          "3 (l+1)(m+1)(n+1) values, scene units; reset to the rest lattice when "
                          "divisions, origin or axes change"},
                         flatten(restLattice().controlPoints()));
    }

  protected:
    void validate(size_t index, std::span<const double> given) const override {
        if (index == basis_ || index == outside_) requireIntegers(index, given, 0, 1);
        if (index == divisions_) requireIntegers(index, given, 1, warp::kMaxFfdDivisions);
        if (index == basis_ || index == divisions_ || index == origin_ || index == axes_) {
            // The whole lattice with the candidate value in place, through the core's own checks (axes
            // coplanar, too many controls, a Bernstein degree above 64).
            std::array<std::vector<double>, 4> candidate = {value(basis_), value(divisions_), value(origin_),
                                                            value(axes_)};
            const size_t slot = index == basis_ ? 0 : index == divisions_ ? 1 : index == origin_ ? 2 : 3;
            candidate[slot].assign(given.begin(), given.end());
            try {
                (void)warp::FfdLattice(
                    latticeFrom(candidate[1], candidate[2], candidate[3]),
                    {candidate[0][0] == 0.0 ? warp::FfdBasis::Bernstein : warp::FfdBasis::BSpline});
            } catch (const InvalidInput& e) {
                fail(index, e.what(), "a valid lattice");
            }
        }
    }

    void changed(size_t index) override {
        if (index == divisions_ || index == origin_ || index == axes_)
            assign(points_, flatten(restLattice().controlPoints()));
        if (index != basis_ && index != outside_) controlsDirty_ = true;
    }

    void bindRest(const geom::Mesh& rest, std::span<const float>) override {
        ffd_.reset();
        warp::FfdOptions options;
        options.basis = value(basis_)[0] == 0.0 ? warp::FfdBasis::Bernstein : warp::FfdBasis::BSpline;
        options.outside = value(outside_)[0] == 0.0 ? warp::FfdOutside::None : warp::FfdOutside::Extrapolate;
        auto ffd = std::make_unique<warp::Ffd>(restLattice(), options);
        unflatten(value(points_), targets_);
        ffd->setTargets(targets_);
        ffd->bind(rest.points());
        ffd_ = std::move(ffd);
        controlsDirty_ = false;
    }

    void deform(std::span<const glm::vec3> in, std::span<glm::vec3> out) override {
        if (controlsDirty_) {
            unflatten(value(points_), targets_);
            ffd_->setTargets(targets_);
            controlsDirty_ = false;
        }
        copyPoints(in, out);
        ffd_->evaluate(out);
    }

  private:
    static warp::Lattice latticeFrom(std::span<const double> divisions, std::span<const double> origin,
                                     std::span<const double> axes) {
        warp::Lattice lattice;
        lattice.divisions = glm::ivec3(static_cast<int32_t>(divisions[0]), static_cast<int32_t>(divisions[1]),
                                       static_cast<int32_t>(divisions[2]));
        lattice.origin = vec3At(origin);
        for (int c = 0; c < 3; ++c)
            lattice.axes[c] = vec3At(axes, 3 * static_cast<size_t>(c));
        return lattice;
    }
    [[nodiscard]] warp::Lattice restLattice() const {
        return latticeFrom(value(divisions_), value(origin_), value(axes_));
    }

    size_t basis_, outside_, divisions_, origin_, axes_, points_;
    std::unique_ptr<warp::Ffd> ffd_;
    std::vector<glm::vec3> targets_;
    bool controlsDirty_ = true;
};

// ---- handle-based Barr warps: twist, bend, taper ----

// The parameters the three share: a handle origin and Y axis (the deformation axis, [bind]), bounds in
// handle units along Y.
class HandleDeformer : public Deformer {
  protected:
    HandleDeformer(std::string type, std::string label) : Deformer(std::move(type), std::move(label)) {}

    void addHandle() {
        origin_ = addParameter({"handleOrigin", 3, true, "handle translation, scene units"}, {0.0, 0.0, 0.0});
        if (type() == "bend") {
            x_ = addParameter({"handleX", 3, true,
                               "world image of the handle's unit X axis (rotation x scale): the bend's "
                               "direction; perpendicular to handleY and as long"},
                              {1.0, 0.0, 0.0});
        }
        y_ =
            addParameter({"handleY", 3, true,
                          "world image of the handle's unit Y axis (rotation x scale): the deformation axis"},
                         {0.0, 1.0, 0.0});
    }
    void addBounds() {
        low_ = addParameter({"lowBound", 1, false, "handle units along handle Y"}, {-1.0});
        high_ = addParameter({"highBound", 1, false, "handle units along handle Y, above lowBound"}, {1.0});
    }

    void validate(size_t index, std::span<const double> value) const override {
        if ((index == y_ || index == x_) && glm::length(dvec3At(value)) == 0.0)
            fail(index, "is the zero vector", "a non-degenerate handle axis");
    }
    void changed(size_t index) override {
        if (!parameters()[index].rebinds) controlsDirty_ = true;
    }

    // lowBound < highBound (strict) or <= (bend), named as a parameter error.
    void requireBoundOrder(bool strict) const {
        const double lo = value(low_)[0], hi = value(high_)[0];
        if (strict ? !(lo < hi) : !(lo <= hi)) {
            fail(low_, "is " + numberText(lo) + ", highBound is " + numberText(hi),
                 strict ? "lowBound < highBound" : "lowBound <= highBound");
        }
    }
    [[nodiscard]] double bound(size_t index) const { return value(index)[0]; }

    size_t origin_ = 0, x_ = SIZE_MAX, y_ = 0, low_ = 0, high_ = 0;
    bool controlsDirty_ = true;
};

class TwistDeformer final : public HandleDeformer {
  public:
    explicit TwistDeformer(std::string label) : HandleDeformer("twist", std::move(label)) {
        addHandle();
        start_ = addParameter({"startAngle", 1, false, "radians at lowBound, right-handed about handle +Y"},
                              {0.0});
        end_ = addParameter({"endAngle", 1, false, "radians at highBound"}, {0.0});
        addBounds();
    }

  protected:
    void bindRest(const geom::Mesh& rest, std::span<const float>) override {
        twist_.reset();
        const warp::AxialSetup setup = mayaSetup();
        auto twist = std::make_unique<warp::TwistWarp>(setup.frame, setup.profile);
        warp::SparseFields fields;  // the engine's fields: unused by the direct path
        twist->bind(rest.points(), fields);
        twist_ = std::move(twist);
        controlsDirty_ = false;
    }
    void deform(std::span<const glm::vec3> in, std::span<glm::vec3> out) override {
        if (controlsDirty_) {
            twist_->setProfile(mayaSetup().profile);
            controlsDirty_ = false;
        }
        twist_->evaluate(in, out);
    }

  private:
    [[nodiscard]] warp::AxialSetup mayaSetup() const {
        requireBoundOrder(true);
        warp::MayaTwist m;
        m.handleOrigin = vec3At(value(origin_));
        m.handleY = vec3At(value(y_));
        m.startAngle = value(start_)[0];
        m.endAngle = value(end_)[0];
        m.lowBound = bound(low_);
        m.highBound = bound(high_);
        return warp::fromMayaTwist(m);
    }

    size_t start_, end_;
    std::unique_ptr<warp::TwistWarp> twist_;
};

class BendDeformer final : public HandleDeformer {
  public:
    explicit BendDeformer(std::string label) : HandleDeformer("bend", std::move(label)) {
        addHandle();
        curvature_ = addParameter(
            {"curvature", 1, false, "radians per handle unit along handle Y, > 0 bends towards handle +X"},
            {0.0});
        addBounds();
    }

  protected:
    void bindRest(const geom::Mesh& rest, std::span<const float>) override {
        bend_.reset();
        const warp::BendSetup setup = mayaSetup();
        auto bend = std::make_unique<warp::BendWarp>(setup.frame, setup.params);
        warp::SparseFields fields;
        bend->bind(rest.points(), fields);
        bend_ = std::move(bend);
        controlsDirty_ = false;
    }
    void deform(std::span<const glm::vec3> in, std::span<glm::vec3> out) override {
        if (controlsDirty_) {
            bend_->setParams(mayaSetup().params);
            controlsDirty_ = false;
        }
        bend_->evaluate(in, out);
    }

  private:
    [[nodiscard]] warp::BendSetup mayaSetup() const {
        requireBoundOrder(false);
        warp::MayaBend m;
        m.handleOrigin = vec3At(value(origin_));
        m.handleX = vec3At(value(x_));
        m.handleY = vec3At(value(y_));
        m.curvature = value(curvature_)[0];
        m.lowBound = bound(low_);
        m.highBound = bound(high_);
        return warp::fromMayaBend(m);
    }

    size_t curvature_;
    std::unique_ptr<warp::BendWarp> bend_;
};

class TaperDeformer final : public HandleDeformer {
  public:
    explicit TaperDeformer(std::string label) : HandleDeformer("taper", std::move(label)) {
        addHandle();
        start_ =
            addParameter({"startScale", 1, false, "scale across handle Y at lowBound; 1 = unchanged"}, {1.0});
        end_ = addParameter({"endScale", 1, false, "scale across handle Y at highBound"}, {1.0});
        addBounds();
    }

  protected:
    void bindRest(const geom::Mesh& rest, std::span<const float>) override {
        taper_.reset();
        const glm::vec3 origin = vec3At(value(origin_)), axis = vec3At(value(y_));
        auto taper =
            std::make_unique<warp::TaperWarp>(warp::AxisFrame{origin, axis, glm::vec3(0.0f)}, profile());
        warp::SparseFields fields;
        taper->bind(rest.points(), fields);
        taper_ = std::move(taper);
        controlsDirty_ = false;
    }
    void deform(std::span<const glm::vec3> in, std::span<glm::vec3> out) override {
        if (controlsDirty_) {
            taper_->setProfile(profile());
            controlsDirty_ = false;
        }
        taper_->evaluate(in, out);
    }

  private:
    // f(z) through (lowBound |Y|, startScale) and (highBound |Y|, endScale): the monotone cubic through two
    // samples is that line; held beyond them. z is in scene units along the unit axis from the origin.
    [[nodiscard]] warp::ProfileCurve profile() const {
        requireBoundOrder(true);
        const double sy = glm::length(dvec3At(value(y_)));
        return warp::ProfileCurve(
            {static_cast<float>(bound(low_) * sy), static_cast<float>(bound(high_) * sy)},
            {static_cast<float>(value(start_)[0]), static_cast<float>(value(end_)[0])},
            context() + " profile");
    }

    size_t start_, end_;
    std::unique_ptr<warp::TaperWarp> taper_;
};

// ---- wires ----

class WiresDeformer final : public Deformer {
  public:
    explicit WiresDeformer(std::string label) : Deformer("wires", std::move(label)) {
        smooth_ = addParameter({"smooth", 1, true, "0 the original variant, 1 the smooth variant"}, {0.0});
        rest_ = addParameter(
            {"restCurve", 0, true,
             "reference polyline, x, y, z per point, >= 2 points, non-zero length, scene units", 3},
            {0.0, 0.0, 0.0, 1.0, 0.0, 0.0});
        curve_ = addParameter({"curve", 0, false,
                               "wire polyline, as many points as restCurve, scene units; reset to restCurve "
                               "when it changes"},
                              value(rest_));
        dropoff_ = addParameter({"dropoff", 1, true, "radius r, scene units, > 0"}, {1.0});
        scale_ =
            addParameter({"scale", 1, true, "uniform scale x about the curve at full strength, > 0"}, {1.0});
    }

  protected:
    void validate(size_t index, std::span<const double> value) const override {
        if (index == smooth_) requireIntegers(index, value, 0, 1);
        if ((index == dropoff_ || index == scale_) && !(value[0] > 0.0))
            fail(index, "is " + numberText(value[0]), "a number > 0");
        if (index == rest_) {
            if (value.size() < 6)
                fail(index, "has " + std::to_string(value.size() / 3) + " point", "at least 2");
            double length = 0.0;
            for (size_t i = 3; i < value.size(); i += 3)
                length += glm::length(dvec3At(value, i) - dvec3At(value, i - 3));
            if (!(length > 0.0)) fail(index, "has length 0", "a curve of non-zero length");
        }
    }
    void changed(size_t index) override {
        if (index == rest_) assign(curve_, value(rest_));
        if (index == rest_ || index == curve_) controlsDirty_ = true;
    }

    void bindRest(const geom::Mesh& rest, std::span<const float>) override {
        wires_.reset();
        warp::Wire wire;
        unflatten(value(rest_), wire.reference);
        unflatten(value(curve_), wire.wire);
        wire.radius = static_cast<float>(value(dropoff_)[0]);
        wire.scale = static_cast<float>(value(scale_)[0]);
        warp::WiresOptions options;
        options.variant =
            value(smooth_)[0] == 0.0 ? warp::WiresVariant::Original : warp::WiresVariant::Smooth;
        std::vector<warp::Wire> wires;
        wires.push_back(std::move(wire));
        auto core = std::make_unique<warp::Wires>(std::move(wires), options);
        core->bind(rest.points());
        wires_ = std::move(core);
        controlsDirty_ = false;
    }
    void deform(std::span<const glm::vec3> in, std::span<glm::vec3> out) override {
        if (controlsDirty_) {
            unflatten(value(curve_), wire_);
            wires_->setWire(0, wire_);
            controlsDirty_ = false;
        }
        copyPoints(in, out);
        wires_->evaluate(out);
    }

  private:
    size_t smooth_, rest_, curve_, dropoff_, scale_;
    std::unique_ptr<warp::Wires> wires_;
    std::vector<glm::vec3> wire_;  // the wire curve as points, reused
    bool controlsDirty_ = true;
};

// ---- slide ----

class SlideDeformer final : public Deformer {
  public:
    explicit SlideDeformer(std::string label) : Deformer("slide", std::move(label)) {
        vertex_ = addParameter({"vertex", 1, true, "handle vertex index"}, {0.0});
        radius_ = addParameter({"radius", 1, true, "support radius, scene units, > 0"}, {1.0});
        geodesic_ = addParameter({"geodesic", 1, true, "0 Euclidean support region, 1 geodesic"}, {0.0});
        limit_ = addParameter(
            {"limitSurface", 1, true, "0 slide over the mesh, 1 over its Catmull-Clark limit surface"},
            {0.0});
        displacement_ = addParameter(
            {"displacement", 3, false, "end locator minus start locator, scene units"}, {0.0, 0.0, 0.0});
        falloff_ = addParameter({"falloff", 1, false, "0 smooth, 1 linear, 2 falloffRamp"}, {0.0});
        ramp_ = addParameter(
            {"falloffRamp", 0, false,
             "n >= 2 samples in [0, 1] at x = i / (n - 1) of distance / radius, linear between", 1},
            {1.0, 0.0});
    }

    [[nodiscard]] WeightMode weightMode() const override { return WeightMode::Native; }

  protected:
    void validate(size_t index, std::span<const double> value) const override {
        if (index == vertex_) requireIntegers(index, value, 0, std::numeric_limits<int32_t>::max());
        if (index == geodesic_ || index == limit_) requireIntegers(index, value, 0, 1);
        if (index == falloff_) requireIntegers(index, value, 0, 2);
        if (index == radius_ && !(value[0] > 0.0)) fail(index, "is " + numberText(value[0]), "a number > 0");
        if (index == ramp_) {
            try {
                (void)makeRamp(value);
            } catch (const InvalidInput& e) {
                fail(index, e.what(), "n >= 2 samples in [0, 1]");
            }
        }
    }
    void changed(size_t index) override {
        if (index == displacement_ || index == falloff_ || index == ramp_) controlsDirty_ = true;
    }

    void bindRest(const geom::Mesh& rest, std::span<const float>) override {
        slider_.reset();
        const auto vertex = static_cast<int32_t>(value(vertex_)[0]);
        if (vertex >= rest.numVertices()) {
            fail(vertex_, "is " + std::to_string(vertex),
                 "a vertex index below " + std::to_string(rest.numVertices()) +
                     ", the rest mesh's vertex count");
        }
        slide::SlideHandle handle;
        handle.vertex = vertex;
        handle.radius = value(radius_)[0];
        handle.region =
            value(geodesic_)[0] == 0.0 ? slide::RegionMetric::Euclidean : slide::RegionMetric::Geodesic;
        slide::SlideOptions options;
        options.surface = value(limit_)[0] == 0.0 ? slide::SurfaceMode::Cage : slide::SurfaceMode::Limit;
        slider_ = std::make_unique<slide::Slider>(rest, std::vector<slide::SlideHandle>{handle}, options,
                                                  context());
        controlsDirty_ = true;
    }
    void deform(std::span<const glm::vec3> in, std::span<glm::vec3> out) override {
        deformWeighted(in, out, {}, 1.0);
    }
    void deformWeighted(std::span<const glm::vec3> in, std::span<glm::vec3> out,
                        std::span<const float> weights, double envelope) override {
        if (controlsDirty_) {
            drive_[0].displacement = dvec3At(value(displacement_));
            const double kind = value(falloff_)[0];
            drive_[0].falloff = kind == 0.0   ? slide::Falloff::smooth()
                                : kind == 1.0 ? slide::Falloff::linear()
                                              : makeRamp(value(ramp_));
            controlsDirty_ = false;
        }
        copyPoints(in, out);
        slider_->evaluate(drive_, out, weights, static_cast<float>(envelope));
    }

  private:
    [[nodiscard]] slide::Falloff makeRamp(std::span<const double> samples) const {
        const std::vector<float> values(samples.begin(), samples.end());
        return slide::Falloff::ramp(values, "samples");
    }

    size_t vertex_, radius_, geodesic_, limit_, displacement_, falloff_, ramp_;
    std::unique_ptr<slide::Slider> slider_;
    std::array<slide::SlideDrive, 1> drive_;
    bool controlsDirty_ = true;
};

constexpr std::array<std::string_view, 6> kTypes = {"bend", "ffd", "slide", "taper", "twist", "wires"};

}  // namespace

std::span<const std::string_view> deformerTypes() {
    return kTypes;
}

std::unique_ptr<Deformer> makeDeformer(std::string_view type, const std::string& label) {
    if (label.empty()) {
        throw InvalidInput(
            formatError(std::string(type) + " deformer", "label", "is empty", "a non-empty label"));
    }
    if (type == "ffd") return std::make_unique<FfdDeformer>(label);
    if (type == "twist") return std::make_unique<TwistDeformer>(label);
    if (type == "bend") return std::make_unique<BendDeformer>(label);
    if (type == "taper") return std::make_unique<TaperDeformer>(label);
    if (type == "wires") return std::make_unique<WiresDeformer>(label);
    if (type == "slide") return std::make_unique<SlideDeformer>(label);
    std::string known;
    for (std::string_view t : kTypes)
        known += (known.empty() ? "" : ", ") + std::string(t);
    throw InvalidInput(formatError("deformer '" + label + "'", "type '" + std::string(type) + "'",
                                   "is unknown", "one of: " + known));
}

}  // namespace deformkit::host
