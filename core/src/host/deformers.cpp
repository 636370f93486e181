#include "deformkit/host/deformers.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "deformkit/error.h"
#include "deformkit/geom/mesh.h"
#include "deformkit/slide/falloff.h"
#include "deformkit/slide/slider.h"
#include "deformkit/warp/barr.h"
#include "deformkit/warp/barr_host.h"
#include "deformkit/warp/beier_neely.h"
#include "deformkit/warp/engine.h"
#include "deformkit/warp/ffd.h"
#include "deformkit/warp/ffd_frames.h"
#include "deformkit/warp/mesh_warp.h"
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

// ---- ffd, ffdframes: the lattice they share ----

// The bind-time lattice parameters of both FFD types (basis, outside, divisions, origin, axes) and their
// checks; the derived types add their controls.
class LatticeDeformer : public Deformer {
  protected:
    LatticeDeformer(std::string type, std::string label) : Deformer(std::move(type), std::move(label)) {
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
    }

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

    // True for the parameters that define the rest lattice's shape (its control points move with them).
    [[nodiscard]] bool shapesLattice(size_t index) const {
        return index == divisions_ || index == origin_ || index == axes_;
    }
    [[nodiscard]] bool isLatticeParameter(size_t index) const {
        return index == basis_ || index == outside_ || shapesLattice(index);
    }
    [[nodiscard]] warp::FfdOptions ffdOptions() const {
        warp::FfdOptions options;
        options.basis = value(basis_)[0] == 0.0 ? warp::FfdBasis::Bernstein : warp::FfdBasis::BSpline;
        options.outside = value(outside_)[0] == 0.0 ? warp::FfdOutside::None : warp::FfdOutside::Extrapolate;
        return options;
    }
    [[nodiscard]] warp::Lattice restLattice() const {
        return latticeFrom(value(divisions_), value(origin_), value(axes_));
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

    size_t basis_, outside_, divisions_, origin_, axes_;
};

class FfdDeformer final : public LatticeDeformer {
  public:
    explicit FfdDeformer(std::string label) : LatticeDeformer("ffd", std::move(label)) {
        points_ =
            addParameter({"points", 0, false,
                          "deformed control points P*_ijk, x, y, z each, index (i (m+1) + j) (n+1) + k, "
                          "3 (l+1)(m+1)(n+1) values, scene units; reset to the rest lattice when "
                          "divisions, origin or axes change"},
                         flatten(restLattice().controlPoints()));
    }

  protected:
    void changed(size_t index) override {
        if (shapesLattice(index)) assign(points_, flatten(restLattice().controlPoints()));
        if (shapesLattice(index) || index == points_) controlsDirty_ = true;
    }

    void bindRest(const geom::Mesh& rest, std::span<const float>) override {
        ffd_.reset();
        auto ffd = std::make_unique<warp::Ffd>(restLattice(), ffdOptions());
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
    size_t points_;
    std::unique_ptr<warp::Ffd> ffd_;
    std::vector<glm::vec3> targets_;
    bool controlsDirty_ = true;
};

// FFD with coordinate-frame controls: each control carries a target frame (origin = the deformed control
// point, basis = the rotation x scale of the control's neighbourhood); the source frames are the core's
// defaults, (P_ijk, identity), so T_ijk<p> = B*_ijk (p - P_ijk) + P*_ijk.
class FfdFramesDeformer final : public LatticeDeformer {
  public:
    explicit FfdFramesDeformer(std::string label) : LatticeDeformer("ffdframes", std::move(label)) {
        points_ =
            addParameter({"points", 0, false,
                          "deformed control points P*_ijk (target frame origins), x, y, z each, index "
                          "(i (m+1) + j) (n+1) + k, 3 (l+1)(m+1)(n+1) values, scene units; reset to the "
                          "rest lattice when divisions, origin or axes change"},
                         flatten(restLattice().controlPoints()));
        frames_ = addParameter({"frames", 0, false,
                                "target frame bases B*_ijk, 9 values per control in the order of points: "
                                "the images of the unit X, Y, Z axes (x, y, z of each), rotation x scale; "
                                "reset to the identity when divisions, origin or axes change"},
                               identityFrames());
    }

  protected:
    void changed(size_t index) override {
        if (shapesLattice(index)) {
            assign(points_, flatten(restLattice().controlPoints()));
            assign(frames_, identityFrames());
        }
        if (shapesLattice(index) || index == points_ || index == frames_) controlsDirty_ = true;
    }

    void bindRest(const geom::Mesh& rest, std::span<const float>) override {
        ffd_.reset();
        auto ffd = std::make_unique<warp::FfdFrames>(restLattice(), ffdOptions());
        pushTargets(*ffd);
        ffd->bind(rest.points());
        ffd_ = std::move(ffd);
        controlsDirty_ = false;
    }

    void deform(std::span<const glm::vec3> in, std::span<glm::vec3> out) override {
        if (controlsDirty_) {
            pushTargets(*ffd_);
            controlsDirty_ = false;
        }
        copyPoints(in, out);
        ffd_->evaluate(out);
    }

  private:
    [[nodiscard]] std::vector<double> identityFrames() const {
        std::vector<double> out;
        const auto controls = static_cast<size_t>(restLattice().numControls());
        out.reserve(9 * controls);
        for (size_t c = 0; c < controls; ++c)
            out.insert(out.end(), {1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0});
        return out;
    }
    void pushTargets(warp::FfdFrames& ffd) {
        const std::vector<double>& points = value(points_);
        const std::vector<double>& bases = value(frames_);
        targets_.resize(points.size() / 3);
        for (size_t c = 0; c < targets_.size(); ++c) {
            targets_[c].origin = vec3At(points, 3 * c);
            for (int a = 0; a < 3; ++a)
                targets_[c].basis[a] = vec3At(bases, 9 * c + 3 * static_cast<size_t>(a));
        }
        ffd.setTargetFrames(targets_);
    }

    size_t points_, frames_;
    std::unique_ptr<warp::FfdFrames> ffd_;
    std::vector<warp::Frame> targets_;
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
        rest_ = addParameter({"restCurve", 0, true,
                              "reference polylines, x, y, z per point, the wires one after the other as "
                              "curveSizes says, >= 2 points and non-zero length each, scene units",
                              3},
                             {0.0, 0.0, 0.0, 1.0, 0.0, 0.0});
        sizes_ = addParameter({"curveSizes", 0, true,
                               "points per wire, whole numbers >= 2 summing to restCurve's point count; a "
                               "single 0: one wire through all of restCurve",
                               1},
                              {0.0});
        curve_ = addParameter({"curve", 0, false,
                               "wire polylines, as many points as restCurve, split as it is, scene units; "
                               "reset to restCurve when it changes"},
                              value(rest_));
        dropoff_ =
            addParameter({"dropoff", 0, true,
                          "radius r per wire, scene units, > 0: one value for all wires or one per wire", 1},
                         {1.0});
        scale_ = addParameter({"scale", 0, true,
                               "uniform scale x about the curve at full strength per wire, > 0: one value "
                               "for all wires or one per wire",
                               1},
                              {1.0});
        exponent_ = addParameter(
            {"exponent", 1, true,
             "m >= 0: each wire's weight is multiplied by the length of the displacement it causes to the "
             "power m, so the wire that moves a point more dominates (only matters with several wires)"},
            {1.0});
    }

  protected:
    void validate(size_t index, std::span<const double> value) const override {
        if (index == smooth_) requireIntegers(index, value, 0, 1);
        if (index == dropoff_ || index == scale_) {
            // The core takes them as float: a positive double below float's range would become 0.
            for (size_t i = 0; i < value.size(); ++i) {
                if (!(static_cast<float>(value[i]) > 0.0f)) {
                    const std::string where =
                        value.size() == 1 ? "is " : "value " + std::to_string(i) + " is ";
                    fail(index, where + numberText(value[i]), "numbers > 0");
                }
            }
        }
        if (index == exponent_ && !(value[0] >= 0.0)) fail(index, "is " + numberText(value[0]), "m >= 0");
        if (index == sizes_) {
            requireIntegers(index, value, 0, std::numeric_limits<int32_t>::max());
            const bool automatic = value.size() == 1 && value[0] == 0.0;
            for (size_t i = 0; i < value.size() && !automatic; ++i) {
                if (value[i] < 2.0) {
                    fail(index, "value " + std::to_string(i) + " is " + numberText(value[i]),
                         "point counts >= 2, or a single 0");
                }
            }
        }
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
        const std::vector<size_t> starts = wireStarts();
        const size_t numWires = starts.size() - 1;
        for (size_t index : {dropoff_, scale_}) {
            const size_t count = value(index).size();
            if (count != 1 && count != numWires) {
                fail(index,
                     "has " + std::to_string(count) + " values for " + std::to_string(numWires) + " wires",
                     "1 value, or 1 per wire");
            }
        }
        unflatten(value(rest_), wire_);
        std::vector<warp::Wire> wires(numWires);
        for (size_t w = 0; w < numWires; ++w) {
            warp::Wire& wire = wires[w];
            wire.reference.assign(wire_.begin() + static_cast<std::ptrdiff_t>(starts[w]),
                                  wire_.begin() + static_cast<std::ptrdiff_t>(starts[w + 1]));
            double length = 0.0;
            for (size_t j = 1; j < wire.reference.size(); ++j)
                length += glm::length(glm::dvec3(wire.reference[j] - wire.reference[j - 1]));
            if (!(length > 0.0)) {
                fail(rest_,
                     "wire " + std::to_string(w) + " (points " + std::to_string(starts[w]) + " to " +
                         std::to_string(starts[w + 1] - 1) + ") has length 0",
                     "every wire of non-zero length");
            }
            wire.radius = static_cast<float>(perWire(dropoff_, w));
            wire.scale = static_cast<float>(perWire(scale_, w));
        }
        unflatten(value(curve_), wire_);
        for (size_t w = 0; w < numWires; ++w) {
            wires[w].wire.assign(wire_.begin() + static_cast<std::ptrdiff_t>(starts[w]),
                                 wire_.begin() + static_cast<std::ptrdiff_t>(starts[w + 1]));
        }
        warp::WiresOptions options;
        options.variant =
            value(smooth_)[0] == 0.0 ? warp::WiresVariant::Original : warp::WiresVariant::Smooth;
        options.exponent = static_cast<float>(value(exponent_)[0]);
        auto core = std::make_unique<warp::Wires>(std::move(wires), options);
        core->bind(rest.points());
        wires_ = std::move(core);
        starts_ = starts;
        controlsDirty_ = false;
    }
    void deform(std::span<const glm::vec3> in, std::span<glm::vec3> out) override {
        if (controlsDirty_) {
            unflatten(value(curve_), wire_);
            const std::span<const glm::vec3> all(wire_);
            for (size_t w = 0; w + 1 < starts_.size(); ++w)
                wires_->setWire(static_cast<int32_t>(w),
                                all.subspan(starts_[w], starts_[w + 1] - starts_[w]));
            controlsDirty_ = false;
        }
        copyPoints(in, out);
        wires_->evaluate(out);
    }

  private:
    // The first point of every wire in restCurve, and its point count at the end; checks curveSizes
    // against restCurve (they may disagree while being set one at a time).
    [[nodiscard]] std::vector<size_t> wireStarts() const {
        const size_t total = value(rest_).size() / 3;
        const std::vector<double>& sizes = value(sizes_);
        std::vector<size_t> starts{0};
        if (sizes.size() == 1 && sizes[0] == 0.0) {
            starts.push_back(total);
            return starts;
        }
        for (double n : sizes)
            starts.push_back(starts.back() + static_cast<size_t>(n));
        if (starts.back() != total) {
            fail(sizes_, "sums to " + std::to_string(starts.back()) + " points",
                 std::to_string(total) + ", restCurve's point count");
        }
        return starts;
    }
    [[nodiscard]] double perWire(size_t index, size_t wire) const {
        const std::vector<double>& v = value(index);
        return v.size() == 1 ? v[0] : v[wire];
    }

    size_t smooth_, rest_, sizes_, curve_, dropoff_, scale_, exponent_;
    std::unique_ptr<warp::Wires> wires_;
    std::vector<size_t> starts_;   // the bound wires' first points in restCurve, then the total
    std::vector<glm::vec3> wire_;  // the curves as points, reused
    bool controlsDirty_ = true;
};

// ---- warps evaluated through the generic engine: beierneely, meshwarp ----

// Binds a core Warp's fields on the rest mesh and evaluates Eq. (3) with warp::evaluateWarp; the
// transformations are recomputed only after a control changed.
class EngineDeformer : public Deformer {
  protected:
    EngineDeformer(std::string type, std::string label) : Deformer(std::move(type), std::move(label)) {}

    // Takes the freshly built warp (its controls already pushed) and binds it.
    void bindWarp(std::unique_ptr<warp::Warp> warp, const geom::Mesh& rest) {
        warp_.reset();
        warp->bind(rest.points(), fields_);
        warp->transformations(transforms_);
        warp_ = std::move(warp);
        controlsDirty_ = false;
    }
    // Pushes the animatable controls into the bound warp.
    virtual void pushControls() = 0;

    void deform(std::span<const glm::vec3> in, std::span<glm::vec3> out) override {
        if (controlsDirty_) {
            pushControls();
            warp_->transformations(transforms_);
            controlsDirty_ = false;
        }
        warp::evaluateWarp(in, fields_, transforms_, out, warp_->engineOptions());
    }

    bool controlsDirty_ = true;

  private:
    std::unique_ptr<warp::Warp> warp_;
    warp::SparseFields fields_;
    warp::Transformations transforms_;
};

// Beier and Neely's feature-based warp in the XY plane of the scene: rest features are the destination
// segments L_i (where the weights are measured), deformed features the source segments L*_i, so a point
// on a rest feature goes onto its deformed feature.
class BeierNeelyDeformer final : public EngineDeformer {
  public:
    explicit BeierNeelyDeformer(std::string label) : EngineDeformer("beierneely", std::move(label)) {
        global_ = addParameter({"global", 1, true,
                                "0 the original warp (each feature rigid across itself), 1 the global "
                                "variant (feature rotations averaged over all features)"},
                               {0.0});
        rest_ =
            addParameter({"restFeatures", 0, true,
                          "rest feature segments P, Q as P.x, P.y, Q.x, Q.y in the XY plane, scene units, "
                          ">= 1 segment, each of non-zero length",
                          4},
                         {0.0, 0.0, 1.0, 0.0});
        a_ = addParameter({"a", 1, true,
                           "scene units, > 0: the larger, the smoother and the less exact near "
                           "a feature"},
                          {1.0});
        b_ = addParameter({"b", 1, true, ">= 0: how fast a feature's influence falls off with distance"},
                          {2.0});
        p_ = addParameter({"p", 1, true, ">= 0: how much longer features dominate"}, {0.5});
        features_ = addParameter({"features", 0, false,
                                  "deformed feature segments P*, Q*, 4 values each as restFeatures, as many, "
                                  "non-zero lengths; reset to restFeatures when it changes"},
                                 value(rest_));
    }

  protected:
    void validate(size_t index, std::span<const double> value) const override {
        if (index == global_) requireIntegers(index, value, 0, 1);
        if (index == a_ && !(static_cast<float>(value[0]) > 0.0f))
            fail(index, "is " + numberText(value[0]), "a number > 0");
        if ((index == b_ || index == p_) && !(value[0] >= 0.0))
            fail(index, "is " + numberText(value[0]), "a number >= 0");
        if (index == rest_ || index == features_) {
            // The core's test, on the float endpoints: a segment up to 1e-6 long has no direction.
            for (size_t i = 0; i < value.size(); i += 4) {
                const glm::vec2 p(static_cast<float>(value[i]), static_cast<float>(value[i + 1]));
                const glm::vec2 q(static_cast<float>(value[i + 2]), static_cast<float>(value[i + 3]));
                const float length = glm::length(q - p);
                if (!(length > 1e-6f)) {
                    fail(index, "feature " + std::to_string(i / 4) + " has length " + numberText(length),
                         "segments longer than 1e-06 scene units");
                }
            }
        }
    }
    void changed(size_t index) override {
        if (index == rest_) assign(features_, value(rest_));
        if (index == rest_ || index == features_) controlsDirty_ = true;
    }

    void bindRest(const geom::Mesh& rest, std::span<const float>) override {
        bn_ = nullptr;
        warp::BeierNeelyOptions options;
        options.variant =
            value(global_)[0] == 0.0 ? warp::BeierNeelyVariant::Original : warp::BeierNeelyVariant::Global;
        auto bn = std::make_unique<warp::BeierNeelyWarp>(pairsFrom(value(rest_), value(features_)), options);
        warp::BeierNeelyWarp* raw = bn.get();
        bindWarp(std::move(bn), rest);
        bn_ = raw;
    }
    void pushControls() override {
        const std::vector<double>& f = value(features_);
        endpoints_.resize(f.size() / 2);
        for (size_t e = 0; e < endpoints_.size(); ++e)
            endpoints_[e] = glm::vec2(static_cast<float>(f[2 * e]), static_cast<float>(f[2 * e + 1]));
        bn_->setSourceSegments(endpoints_);
    }

  private:
    [[nodiscard]] std::vector<warp::SegmentPair> pairsFrom(std::span<const double> dst,
                                                           std::span<const double> src) const {
        std::vector<warp::SegmentPair> pairs(dst.size() / 4);
        const auto at = [](std::span<const double> v, size_t i) {
            return glm::vec2(static_cast<float>(v[i]), static_cast<float>(v[i + 1]));
        };
        for (size_t i = 0; i < pairs.size(); ++i) {
            warp::SegmentPair& s = pairs[i];
            s.dstP = at(dst, 4 * i);
            s.dstQ = at(dst, 4 * i + 2);
            s.srcP = at(src, 4 * i);
            s.srcQ = at(src, 4 * i + 2);
            s.a = static_cast<float>(value(a_)[0]);
            s.b = static_cast<float>(value(b_)[0]);
            s.p = static_cast<float>(value(p_)[0]);
        }
        return pairs;
    }

    size_t global_, rest_, features_, a_, b_, p_;
    warp::BeierNeelyWarp* bn_ = nullptr;  // the bound warp, owned by EngineDeformer
    std::vector<glm::vec2> endpoints_;
};

// The coarse-mesh warp: a control cage (any polygon mesh, boundaries allowed) whose vertices, with their
// edge stars, carry the deformation.
class MeshWarpDeformer final : public EngineDeformer {
  public:
    explicit MeshWarpDeformer(std::string label) : EngineDeformer("meshwarp", std::move(label)) {
        // The unit cube, faces oriented outwards.
        rest_ =
            addParameter({"restCage", 0, true, "rest cage points, x, y, z each, >= 3 points, scene units", 3},
                         {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1});
        counts_ = addParameter(
            {"cageFaceCounts", 0, true, "vertices per cage face, whole numbers >= 3, >= 1 face", 1},
            {4, 4, 4, 4, 4, 4});
        indices_ = addParameter({"cageFaceIndices", 0, true,
                                 "cage face vertex indices into restCage, face by face, sum(cageFaceCounts) "
                                 "values; an oriented manifold, boundaries allowed",
                                 1},
                                {0, 3, 2, 1, 4, 5, 6, 7, 0, 1, 5, 4, 2, 3, 7, 6, 0, 4, 7, 3, 1, 2, 6, 5});
        alpha_ = addParameter({"alpha", 1, true,
                               "full weight within alpha times a control vertex's longest edge, >= 0, "
                               "below beta"},
                              {0.0});
        beta_ = addParameter({"beta", 1, true, "zero weight beyond beta times the longest edge"}, {1.0});
        gamma_ = addParameter(
            {"gamma", 1, true, "along each edge: full weight up to gamma of the edge, below mu"}, {0.0});
        mu_ = addParameter({"mu", 1, true, "along each edge: zero weight from mu of the edge on"}, {1.0});
        cage_ = addParameter({"cage", 0, false,
                              "deformed cage points, as many as restCage, scene units; reset to restCage "
                              "when it changes"},
                             value(rest_));
    }

  protected:
    void validate(size_t index, std::span<const double> value) const override {
        if (index == rest_ && value.size() < 9)
            fail(index, "has " + std::to_string(value.size() / 3) + " points", "at least 3");
        if (index == counts_) requireIntegers(index, value, 3, std::numeric_limits<int32_t>::max());
        if (index == indices_) requireIntegers(index, value, 0, std::numeric_limits<int32_t>::max() - 1);
        if (index == alpha_ && !(value[0] >= 0.0)) fail(index, "is " + numberText(value[0]), "a number >= 0");
    }
    void changed(size_t index) override {
        if (index == rest_) assign(cage_, value(rest_));
        if (index == rest_ || index == cage_) controlsDirty_ = true;
    }

    void bindRest(const geom::Mesh& rest, std::span<const float>) override {
        mesh_ = nullptr;
        // Cross-parameter checks, by name (each parameter alone was checked when set).
        const warp::MeshWarpOptions options = meshOptions();
        if (!(options.alpha < options.beta)) {
            fail(alpha_, "is " + numberText(value(alpha_)[0]) + ", beta is " + numberText(value(beta_)[0]),
                 "alpha < beta");
        }
        if (!(options.gamma < options.mu)) {
            fail(gamma_, "is " + numberText(value(gamma_)[0]) + ", mu is " + numberText(value(mu_)[0]),
                 "gamma < mu");
        }
        geom::Mesh::Data data;
        unflatten(value(rest_), data.points);
        const std::vector<double>& counts = value(counts_);
        const std::vector<double>& indices = value(indices_);
        double corners = 0.0;
        for (double c : counts)
            corners += c;
        if (corners != static_cast<double>(indices.size())) {
            fail(indices_, "has " + std::to_string(indices.size()) + " values",
                 numberText(corners) + ", the sum of cageFaceCounts");
        }
        for (size_t i = 0; i < indices.size(); ++i) {
            if (indices[i] >= static_cast<double>(data.points.size())) {
                fail(indices_, "value " + std::to_string(i) + " is " + numberText(indices[i]),
                     "vertex indices below " + std::to_string(data.points.size()) +
                         ", restCage's point count");
            }
        }
        data.faceCounts.assign(counts.begin(), counts.end());
        data.faceIndices.assign(indices.begin(), indices.end());
        std::optional<geom::Mesh> cage;
        try {
            cage.emplace(std::move(data), "cage");
        } catch (const InvalidInput& e) {
            fail(indices_, e.what(), "faces without a repeated vertex");
        }
        std::unique_ptr<warp::MeshWarp> mesh;
        try {
            mesh = std::make_unique<warp::MeshWarp>(*cage, options, "cage");
        } catch (const TopologyError& e) {
            throw TopologyError(formatError(context(), "parameter 'cageFaceIndices'", e.what()));
        } catch (const InvalidInput& e) {
            fail(rest_, e.what(), "every restCage point on a cage edge, edges of non-zero length");
        }
        unflatten(value(cage_), target_);
        mesh->setTarget(target_);
        warp::MeshWarp* raw = mesh.get();
        bindWarp(std::move(mesh), rest);
        mesh_ = raw;
    }
    void pushControls() override {
        unflatten(value(cage_), target_);
        mesh_->setTarget(target_);
    }

  private:
    [[nodiscard]] warp::MeshWarpOptions meshOptions() const {
        warp::MeshWarpOptions o;
        o.alpha = static_cast<float>(value(alpha_)[0]);
        o.beta = static_cast<float>(value(beta_)[0]);
        o.gamma = static_cast<float>(value(gamma_)[0]);
        o.mu = static_cast<float>(value(mu_)[0]);
        return o;
    }

    size_t rest_, counts_, indices_, alpha_, beta_, gamma_, mu_, cage_;
    warp::MeshWarp* mesh_ = nullptr;  // the bound warp, owned by EngineDeformer
    std::vector<glm::vec3> target_;
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

constexpr std::array<std::string_view, 9> kTypes = {"beierneely", "bend",  "ffd",   "ffdframes", "meshwarp",
                                                    "slide",      "taper", "twist", "wires"};

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
    if (type == "ffdframes") return std::make_unique<FfdFramesDeformer>(label);
    if (type == "twist") return std::make_unique<TwistDeformer>(label);
    if (type == "bend") return std::make_unique<BendDeformer>(label);
    if (type == "taper") return std::make_unique<TaperDeformer>(label);
    if (type == "wires") return std::make_unique<WiresDeformer>(label);
    if (type == "slide") return std::make_unique<SlideDeformer>(label);
    if (type == "beierneely") return std::make_unique<BeierNeelyDeformer>(label);
    if (type == "meshwarp") return std::make_unique<MeshWarpDeformer>(label);
    std::string known;
    for (std::string_view t : kTypes)
        known += (known.empty() ? "" : ", ") + std::string(t);
    throw InvalidInput(formatError("deformer '" + label + "'", "type '" + std::string(type) + "'",
                                   "is unknown", "one of: " + known));
}

}  // namespace deformkit::host
