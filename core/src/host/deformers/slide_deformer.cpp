// "slide": Pinskiy's sliding deformer with one handle (slide/slider.h).

#include <algorithm>
#include <array>
#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "deformkit/error.h"
#include "deformkit/slide/falloff.h"
#include "deformkit/slide/slider.h"
#include "host/deformers/families.h"
#include "host/deformers/param_values.h"

namespace deformkit::host::detail {
namespace {

// Weights and envelope scale the tangent displacement before the walk (WeightMode::Native), so slid
// vertices stay on the surface; the incoming points are the surface the slide moves over, and the
// displacement is read in their space (slide/slider.h).
class SlideDeformer final : public Deformer {
  public:
    explicit SlideDeformer(std::string label) : Deformer("slide", std::move(label)) {
        vertex_ =
            addParameter({.name = "vertex",
                          .rebinds = true,
                          .doc = "the handle vertex, below the rest mesh's vertex count (checked at bind)"},
                         {0.0});
        radius_ = addParameter({.name = "radius", .rebinds = true, .doc = "support radius, scene units, > 0"},
                               {1.0});
        geodesic_ = addParameter(
            {.name = "geodesic", .rebinds = true, .doc = "0 Euclidean support region, 1 geodesic"}, {0.0});
        limit_ = addParameter({.name = "limitSurface",
                               .rebinds = true,
                               .doc = "0 slide over the mesh, 1 over its Catmull-Clark limit surface"},
                              {0.0});
        painted_ = addParameter({.name = "paintedWeights",
                                 .rebinds = true,
                                 .doc = "0 weights scale the falloff, 1 the weights are the falloff (the "
                                        "paper's rule; the radius only bounds the region)"},
                                {0.0});
        foldLimit_ = addParameter({.name = "foldLimit",
                                   .rebinds = true,
                                   .doc = "1 scales the drag down so that no triangle of the region flips"},
                                  {0.0});
        weld_ =
            addParameter({.name = "weldTolerance",
                          .rebinds = true,
                          .doc = "split vertices within this distance (scene units, >= 0) are one vertex; 0 "
                                 "welds exactly coincident ones"},
                         {0.0});
        displacement_ = addParameter(
            {.name = "displacement", .doc = "end locator minus start locator, scene units"}, {0.0, 0.0, 0.0});
        falloff_ = addParameter({.name = "falloff", .doc = "0 smooth, 1 linear, 2 falloffRamp"}, {0.0});
        ramp_ =
            addParameter({.name = "falloffRamp",
                          .stride = 1,
                          .doc = "n >= 2 samples in [0, 1] at x = i / (n - 1) of distance / radius, linear "
                                 "between"},
                         {1.0, 0.0});
    }

    [[nodiscard]] WeightMode weightMode() const override { return WeightMode::Native; }

  protected:
    void validate(size_t index, std::span<const double> value) const override {
        if (index == vertex_) requireIntegers(index, value, 0, std::numeric_limits<int32_t>::max());
        if (index == geodesic_ || index == limit_ || index == painted_ || index == foldLimit_)
            requireIntegers(index, value, 0, 1);
        if (index == falloff_) requireIntegers(index, value, 0, 2);
        if (index == radius_ && !(value[0] > 0.0)) fail(index, "is " + numberText(value[0]), "a number > 0");
        if (index == weld_ && !(value[0] >= 0.0))
            fail(index, "is " + numberText(value[0]), "a distance >= 0");
        if (index == ramp_) {
            try {
                (void)makeRamp(value);
            } catch (const InvalidInput& e) {
                fail(index, e.what(), "");  // the ramp's message says what it expected
            }
        }
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
        options.weights = value(painted_)[0] == 0.0 ? slide::PaintedWeights::ScaleFalloff
                                                    : slide::PaintedWeights::AreFalloff;
        options.foldLimit = value(foldLimit_)[0] != 0.0;
        options.weldTolerance = value(weld_)[0];
        slider_ = std::make_unique<slide::Slider>(rest, std::vector<slide::SlideHandle>{handle}, options,
                                                  context());
    }
    void pushControls() override {
        drive_[0].displacement = dvec3At(value(displacement_));
        // The falloff is made again only when its kind or ramp changed: dragging the handle changes the
        // displacement alone, and such a frame allocates nothing.
        const double kind = value(falloff_)[0];
        const std::vector<double>& ramp = value(ramp_);
        if (kind == falloffKind_ && (kind != 2.0 || ramp == falloffRamp_)) return;
        drive_[0].falloff = kind == 0.0   ? slide::Falloff::smooth()
                            : kind == 1.0 ? slide::Falloff::linear()
                                          : makeRamp(ramp);
        falloffKind_ = kind;
        falloffRamp_.assign(ramp.begin(), ramp.end());
    }
    void deform(std::span<const glm::vec3> in, std::span<glm::vec3> out) override {
        deformWeighted(in, out, {}, 1.0);
    }
    void deformWeighted(std::span<const glm::vec3> in, std::span<glm::vec3> out,
                        std::span<const float> weights, double envelope) override {
        std::copy(in.begin(), in.end(), out.begin());  // the slider moves points in place
        slider_->evaluate(drive_, out, weights, static_cast<float>(envelope));
    }

  private:
    [[nodiscard]] slide::Falloff makeRamp(std::span<const double> samples) const {
        const std::vector<float> values(samples.begin(), samples.end());
        return slide::Falloff::ramp(values, "samples");
    }

    size_t vertex_, radius_, geodesic_, limit_, painted_, foldLimit_, weld_, displacement_, falloff_, ramp_;
    std::unique_ptr<slide::Slider> slider_;
    std::array<slide::SlideDrive, 1> drive_;
    double falloffKind_ = -1.0;  // the falloff drive_ holds: its kind and ramp (-1: none yet)
    std::vector<double> falloffRamp_;
};

}  // namespace

std::unique_ptr<Deformer> makeSlideDeformer(std::string label) {
    return std::make_unique<SlideDeformer>(std::move(label));
}

}  // namespace deformkit::host::detail
