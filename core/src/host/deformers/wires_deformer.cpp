// "wires": Singh and Fiume's Wires, one wire or several (warp/wires.h, the fast path).

#include <algorithm>
#include <cstddef>
#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <glm/geometric.hpp>

#include "deformkit/error.h"
#include "deformkit/warp/wires.h"
#include "host/deformers/families.h"
#include "host/deformers/param_values.h"

namespace deformkit::host::detail {
namespace {

class WiresDeformer final : public Deformer {
  public:
    explicit WiresDeformer(std::string label) : Deformer("wires", std::move(label)) {
        smooth_ = addParameter(
            {.name = "smooth", .rebinds = true, .doc = "0 the original variant, 1 the smooth variant"},
            {0.0});
        rest_ = addParameter({.name = "restCurve",
                              .rebinds = true,
                              .stride = 3,
                              .doc = "the reference polylines (sample a cubic curve with warp::sampleCurve "
                                     "first), x, y, z per point, the wires one after the other as curveSizes "
                                     "says, >= 2 points and non-zero length each, scene units"},
                             {0.0, 0.0, 0.0, 1.0, 0.0, 0.0});
        sizes_ =
            addParameter({.name = "curveSizes",
                          .rebinds = true,
                          .stride = 1,
                          .doc = "points per wire, whole numbers >= 2 summing to restCurve's point count "
                                 "(checked at bind); a single 0: one wire through all of restCurve"},
                         {0.0});
        curve_ = addParameter({.name = "curve",
                               .doc = "the wire polylines, as many points as restCurve and split as it is, "
                                      "scene units; reset to restCurve when it changes"},
                              value(rest_));
        dropoff_ =
            addParameter({.name = "dropoff",
                          .rebinds = true,
                          .stride = 1,
                          .doc = "the radius r per wire, scene units, > 0: one value for every wire or "
                                 "one per wire"},
                         {1.0});
        scale_ = addParameter({.name = "scale",
                               .rebinds = true,
                               .stride = 1,
                               .doc = "the uniform scale x about the curve at full strength, > 0 (the core "
                                      "fixes it at construction, hence [bind]): one value or one per wire"},
                              {1.0});
        exponent_ =
            addParameter({.name = "exponent",
                          .rebinds = true,
                          .doc = "m >= 0: each wire's weight at a point is multiplied by the length of "
                                 "the displacement it gives the point to the power m, so where wires "
                                 "overlap the one that moves a point more dominates"},
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
    }
    void pushControls() override {
        unflatten(value(curve_), wire_);
        const std::span<const glm::vec3> all(wire_);
        for (size_t w = 0; w + 1 < starts_.size(); ++w)
            wires_->setWire(static_cast<int32_t>(w), all.subspan(starts_[w], starts_[w + 1] - starts_[w]));
    }
    void deform(std::span<const glm::vec3> in, std::span<glm::vec3> out) override {
        std::copy(in.begin(), in.end(), out.begin());  // the fast path deforms in place
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
};

}  // namespace

std::unique_ptr<Deformer> makeWiresDeformer(std::string label) {
    return std::make_unique<WiresDeformer>(std::move(label));
}

}  // namespace deformkit::host::detail
