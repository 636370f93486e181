// "twist", "bend", "taper": Barr's warps with a handle in the Maya style (warp/barr.h, warp/barr_dcc.h).

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <string>
#include <utility>

#include <glm/geometric.hpp>

#include "deformkit/error.h"
#include "deformkit/warp/barr.h"
#include "deformkit/warp/barr_dcc.h"
#include "deformkit/warp/profile_curve.h"
#include "host/deformers/families.h"
#include "host/deformers/param_values.h"

namespace deformkit::host::detail {
namespace {

// The parameters the three share: a handle origin and Y axis (the deformation axis, [bind]; the bend also
// has an X axis), and bounds in handle units along Y.
class HandleDeformer : public Deformer {
  protected:
    HandleDeformer(std::string type, std::string label) : Deformer(std::move(type), std::move(label)) {}

    void addHandle(bool withX) {
        origin_ =
            addParameter({.name = "handleOrigin", .rebinds = true, .doc = "handle translation, scene units"},
                         {0.0, 0.0, 0.0});
        if (withX) {
            x_ =
                addParameter({.name = "handleX",
                              .rebinds = true,
                              .doc = "world image of the handle's unit X axis (rotation x scale): the bend's "
                                     "direction; perpendicular to handleY and as long (checked at bind)"},
                             {1.0, 0.0, 0.0});
        }
        y_ = addParameter(
            {.name = "handleY",
             .rebinds = true,
             .doc = "world image of the handle's unit Y axis (rotation x scale): the deformation "
                    "axis, non-zero"},
            {0.0, 1.0, 0.0});
    }
    // lowBound < highBound (strict) or <= (bend), checked when used.
    void addBounds(bool strict) {
        strict_ = strict;
        low_ = addParameter({.name = "lowBound", .doc = "handle units along handle Y"}, {-1.0});
        high_ = addParameter({.name = "highBound",
                              .doc = strict ? "handle units along handle Y, above lowBound"
                                            : "handle units along handle Y, at or above lowBound"},
                             {1.0});
    }

    void validate(size_t index, std::span<const double> value) const override {
        if ((index == y_ || index == x_) && glm::length(dvec3At(value)) == 0.0)
            fail(index, "is the zero vector", "a non-degenerate handle axis");
    }

    // The bounds, checked as a parameter error on lowBound.
    [[nodiscard]] std::pair<double, double> bounds() const {
        const double lo = value(low_)[0], hi = value(high_)[0];
        if (strict_ ? !(lo < hi) : !(lo <= hi)) {
            fail(low_, "is " + numberText(lo) + ", highBound is " + numberText(hi),
                 strict_ ? "lowBound < highBound" : "lowBound <= highBound");
        }
        return {lo, hi};
    }

    size_t origin_ = 0, x_ = SIZE_MAX, y_ = 0, low_ = 0, high_ = 0;
    bool strict_ = true;
};

class TwistDeformer final : public HandleDeformer {
  public:
    explicit TwistDeformer(std::string label) : HandleDeformer("twist", std::move(label)) {
        addHandle(false);
        start_ = addParameter(
            {.name = "startAngle", .doc = "radians at lowBound, right-handed about handle +Y"}, {0.0});
        end_ = addParameter({.name = "endAngle", .doc = "radians at highBound"}, {0.0});
        addBounds(true);
    }

  protected:
    void bindRest(const geom::Mesh& rest, std::span<const float>) override {
        twist_.reset();
        const warp::AxialSetup setup = mayaSetup();
        auto twist = std::make_unique<warp::TwistWarp>(setup.frame, setup.profile);
        warp::SparseFields fields;  // the engine's fields: unused by the direct path
        twist->bind(rest.points(), fields);
        twist_ = std::move(twist);
    }
    void pushControls() override {
        // In place: an animated angle costs no allocation.
        const warp::TwistSamples samples = warp::mayaTwistSamples(mayaTwist());
        twist_->setProfile(samples.z, samples.angle, "Maya twist");
    }
    void deform(std::span<const glm::vec3> in, std::span<glm::vec3> out) override {
        twist_->evaluate(in, out);
    }

  private:
    [[nodiscard]] warp::MayaTwist mayaTwist() const {
        const auto [lo, hi] = bounds();
        warp::MayaTwist m;
        m.handleOrigin = vec3At(value(origin_));
        m.handleY = vec3At(value(y_));
        m.startAngle = value(start_)[0];
        m.endAngle = value(end_)[0];
        m.lowBound = lo;
        m.highBound = hi;
        return m;
    }
    [[nodiscard]] warp::AxialSetup mayaSetup() const { return warp::fromMayaTwist(mayaTwist()); }

    size_t start_, end_;
    std::unique_ptr<warp::TwistWarp> twist_;
};

class BendDeformer final : public HandleDeformer {
  public:
    explicit BendDeformer(std::string label) : HandleDeformer("bend", std::move(label)) {
        addHandle(true);
        curvature_ =
            addParameter({.name = "curvature",
                          .doc = "radians per handle unit along handle Y, > 0 bends towards handle +X"},
                         {0.0});
        addBounds(false);
    }

  protected:
    void bindRest(const geom::Mesh& rest, std::span<const float>) override {
        bend_.reset();
        const warp::BendSetup setup = mayaSetup();
        auto bend = std::make_unique<warp::BendWarp>(setup.frame, setup.params);
        warp::SparseFields fields;
        bend->bind(rest.points(), fields);
        bend_ = std::move(bend);
    }
    void pushControls() override { bend_->setParams(mayaSetup().params); }
    void deform(std::span<const glm::vec3> in, std::span<glm::vec3> out) override {
        bend_->evaluate(in, out);
    }

  private:
    [[nodiscard]] warp::BendSetup mayaSetup() const {
        const auto [lo, hi] = bounds();
        warp::MayaBend m;
        m.handleOrigin = vec3At(value(origin_));
        m.handleX = vec3At(value(x_));
        m.handleY = vec3At(value(y_));
        m.curvature = value(curvature_)[0];
        m.lowBound = lo;
        m.highBound = hi;
        return warp::fromMayaBend(m);
    }

    size_t curvature_;
    std::unique_ptr<warp::BendWarp> bend_;
};

// The core has no Maya taper; this is Barr's taper (its flare with equal X and Z scales and no curve) with
// a handle: the two coordinates across handle Y are scaled by startScale at lowBound and endScale at
// highBound, linearly in between, held beyond.
class TaperDeformer final : public HandleDeformer {
  public:
    explicit TaperDeformer(std::string label) : HandleDeformer("taper", std::move(label)) {
        addHandle(false);
        start_ = addParameter(
            {.name = "startScale", .doc = "scale across handle Y at lowBound; 1 = unchanged"}, {1.0});
        end_ = addParameter({.name = "endScale", .doc = "scale across handle Y at highBound"}, {1.0});
        addBounds(true);
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
    }
    void pushControls() override {
        // In place: animated scales cost no allocation (the samples are checked finite and ascending there).
        const std::array<float, 2> z = sceneBounds();
        const std::array<float, 2> scale{static_cast<float>(value(start_)[0]),
                                         static_cast<float>(value(end_)[0])};
        taper_->setProfile(z, scale, "taper profile");
    }
    void deform(std::span<const glm::vec3> in, std::span<glm::vec3> out) override {
        taper_->evaluate(in, out);
    }

  private:
    // lowBound and highBound in scene units (times handle Y's length), refused under the parameters' names
    // when that leaves float32's range (the profile would name its own z samples).
    [[nodiscard]] std::array<float, 2> sceneBounds() const {
        const auto [lo, hi] = bounds();
        const double sy = glm::length(dvec3At(value(y_)));
        std::array<float, 2> z{};
        const std::array<std::pair<double, const char*>, 2> given{{{lo, "lowBound"}, {hi, "highBound"}}};
        for (size_t k = 0; k < 2; ++k) {
            z[k] = static_cast<float>(given[k].first * sy);
            if (!std::isfinite(z[k])) {
                throw InvalidInput(formatError(context(), std::string("parameter '") + given[k].second + "'",
                                               "is " + numberText(given[k].first) +
                                                   ", times handle Y's length " + numberText(sy) +
                                                   " beyond float32's range",
                                               "bounds and a handle that keep it within float32's range"));
            }
        }
        return z;
    }
    // f(z) through (lowBound |Y|, startScale) and (highBound |Y|, endScale): the monotone cubic through two
    // samples is that line; held beyond them. z is in scene units along the unit axis from the origin.
    [[nodiscard]] warp::ProfileCurve profile() const {
        const std::array<float, 2> z = sceneBounds();
        return warp::ProfileCurve({z[0], z[1]},
                                  {static_cast<float>(value(start_)[0]), static_cast<float>(value(end_)[0])},
                                  context() + " profile");
    }

    size_t start_, end_;
    std::unique_ptr<warp::TaperWarp> taper_;
};

}  // namespace

std::unique_ptr<Deformer> makeTwistDeformer(std::string label) {
    return std::make_unique<TwistDeformer>(std::move(label));
}

std::unique_ptr<Deformer> makeBendDeformer(std::string label) {
    return std::make_unique<BendDeformer>(std::move(label));
}

std::unique_ptr<Deformer> makeTaperDeformer(std::string label) {
    return std::make_unique<TaperDeformer>(std::move(label));
}

}  // namespace deformkit::host::detail
