// "beierneely" and "meshwarp": warps evaluated through the generic engine (warp/engine.h, Eq. (3)), over
// warp::WarpDeformer.

#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/vec2.hpp>

#include "deformkit/error.h"
#include "deformkit/warp/beier_neely.h"
#include "deformkit/warp/engine.h"
#include "deformkit/warp/mesh_warp.h"
#include "host/deformers/families.h"
#include "host/deformers/param_values.h"

namespace deformkit::host::detail {
namespace {

// A core Warp bound through warp::WarpDeformer: its fields are computed on the rest mesh at bind, its
// transformations again only after a control changed.
class EngineDeformer : public Deformer {
  protected:
    EngineDeformer(std::string type, std::string label) : Deformer(std::move(type), std::move(label)) {}

    // Takes the freshly built warp and binds it.
    void bindWarp(std::unique_ptr<warp::Warp> warp, const geom::Mesh& rest) {
        engine_.reset();
        warp_ = std::move(warp);
        engine_.emplace(*warp_, label().empty() ? type() : label());
        engine_->bind(rest.points());
    }
    // Hands the animatable controls to the bound warp.
    virtual void pushWarpControls() = 0;

    void pushControls() final {
        pushWarpControls();
        engine_->update();
    }
    void deform(std::span<const glm::vec3> in, std::span<glm::vec3> out) final { engine_->apply(in, out); }

  private:
    std::unique_ptr<warp::Warp> warp_;
    std::optional<warp::WarpDeformer> engine_;  // over *warp_
};

// Beier and Neely's feature-based warp in the XY plane of the scene: rest features are the destination
// segments L_i (where the weights are measured), deformed features the source segments L*_i, so a point
// on a rest feature goes onto its deformed feature.
class BeierNeelyDeformer final : public EngineDeformer {
  public:
    explicit BeierNeelyDeformer(std::string label) : EngineDeformer("beierneely", std::move(label)) {
        global_ =
            addParameter({.name = "global",
                          .rebinds = true,
                          .doc = "0 the original warp (each feature maps its perpendicular rigidly), 1 "
                                 "the global variant (perpendiculars turned by the weighted average of all "
                                 "features' rotations)"},
                         {0.0});
        rest_ =
            addParameter({.name = "restFeatures",
                          .rebinds = true,
                          .stride = 4,
                          .doc = "rest feature segments P -> Q as P.x, P.y, Q.x, Q.y in the XY plane, scene "
                                 "units, >= 1 segment, each longer than 1e-6"},
                         {0.0, 0.0, 1.0, 0.0});
        a_ = addParameter(
            {.name = "a",
             .rebinds = true,
             .doc = "scene units, > 0: the larger, the smoother and the less exact near a feature"},
            {1.0});
        b_ = addParameter({.name = "b",
                           .rebinds = true,
                           .doc = ">= 0: how fast a feature's influence falls off with distance (Beier and "
                                  "Neely use 0.5 to 2)"},
                          {2.0});
        p_ = addParameter({.name = "p",
                           .rebinds = true,
                           .doc = ">= 0: how much longer features dominate (Beier and Neely use 0 to 1)"},
                          {0.5});
        features_ =
            addParameter({.name = "features",
                          .doc = "the deformed feature segments P*, Q*, 4 values each as restFeatures, as "
                                 "many, each longer than 1e-6; reset to restFeatures when it changes"},
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
            // The core's test, on the float endpoints: a segment up to kMinSegmentLength long has no
            // direction.
            for (size_t i = 0; i < value.size(); i += 4) {
                const glm::vec2 p(static_cast<float>(value[i]), static_cast<float>(value[i + 1]));
                const glm::vec2 q(static_cast<float>(value[i + 2]), static_cast<float>(value[i + 3]));
                const float length = glm::length(q - p);
                if (!(length > warp::kMinSegmentLength)) {
                    fail(index, "feature " + std::to_string(i / 4) + " has length " + numberText(length),
                         "segments longer than " + numberText(warp::kMinSegmentLength) + " scene units");
                }
            }
        }
    }
    void changed(size_t index) override {
        if (index == rest_) assign(features_, value(rest_));
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
    void pushWarpControls() override {
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
        rest_ = addParameter({.name = "restCage",
                              .rebinds = true,
                              .stride = 3,
                              .doc = "the rest cage points, x, y, z each, >= 3 points, scene units"},
                             {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1});
        counts_ = addParameter({.name = "cageFaceCounts",
                                .rebinds = true,
                                .stride = 1,
                                .doc = "vertices per cage face, whole numbers >= 3, >= 1 face"},
                               {4, 4, 4, 4, 4, 4});
        indices_ =
            addParameter({.name = "cageFaceIndices",
                          .rebinds = true,
                          .stride = 1,
                          .doc = "cage face vertex indices into restCage, face by face, "
                                 "sum(cageFaceCounts) values; an oriented 2-manifold, boundaries "
                                 "allowed, every point on an edge of non-zero length (checked at bind)"},
                         {0, 3, 2, 1, 4, 5, 6, 7, 0, 1, 5, 4, 2, 3, 7, 6, 0, 4, 7, 3, 1, 2, 6, 5});
        alpha_ = addParameter({.name = "alpha",
                               .rebinds = true,
                               .doc = "full weight within alpha times a control vertex's longest edge, >= 0, "
                                      "below beta (checked at bind)"},
                              {0.0});
        beta_ = addParameter(
            {.name = "beta", .rebinds = true, .doc = "zero weight beyond beta times the longest edge"},
            {1.0});
        gamma_ =
            addParameter({.name = "gamma",
                          .rebinds = true,
                          .doc = "along each edge: full weight up to gamma of the edge, below mu (checked "
                                 "at bind)"},
                         {0.0});
        mu_ = addParameter(
            {.name = "mu", .rebinds = true, .doc = "along each edge: zero weight from mu of the edge on"},
            {1.0});
        cage_ = addParameter({.name = "cage",
                              .doc = "the deformed cage points, as many as restCage, scene units; reset to "
                                     "restCage when it changes"},
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
        warp::MeshWarp* raw = mesh.get();
        bindWarp(std::move(mesh), rest);
        mesh_ = raw;
    }
    void pushWarpControls() override {
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

}  // namespace

std::unique_ptr<Deformer> makeBeierNeelyDeformer(std::string label) {
    return std::make_unique<BeierNeelyDeformer>(std::move(label));
}

std::unique_ptr<Deformer> makeMeshWarpDeformer(std::string label) {
    return std::make_unique<MeshWarpDeformer>(std::move(label));
}

}  // namespace deformkit::host::detail
