#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <glm/vec3.hpp>

#include "deformkit/geom/mesh.h"

namespace deformkit::host {

// One named parameter of a deformer, as hosts and the scene parser address it.
struct ParamInfo {
    std::string name;
    // How many values set() takes now. It can change: an FFD's `points` follows its `divisions`, and a
    // resizable parameter (stride > 0) takes the length of the last value set.
    int32_t components = 1;
    // True when a new value needs a new bind (a lattice's rest box, a slide handle's vertex or radius);
    // false for animatable controls (lattice points, angles, displacements), which never rebind.
    bool rebinds = false;
    std::string doc;  // units, shape and range, for help text
    // > 0: resizable; set() takes any positive multiple of `stride` values (the doc gives the minimum).
    int32_t stride = 0;
};

// How a deformer takes painted weights and the envelope.
enum class WeightMode {
    // Maya's rule, applied by the host layer after the deformer: out = in + envelope w (deformed - in).
    Blend,
    // The deformer scales its own displacement before it is applied. The slide does: a weighted
    // displacement is still a walk over the rest surface, so slid vertices stay on it, where a linear
    // blend would cut the chord between in and deformed.
    Native,
};

// A deformer in Maya's model, host-neutral: bound to a rest mesh (precomputation), then evaluated many
// times with new controls. The host layer (DeformerStack) binds it only when needsBind() says so: before
// the first evaluation, after a rest mesh change, and after a change to a parameter with rebinds = true.
//
// Parameters are addressed by name with double values (integers and flags as whole numbers). set()
// validates the count, finiteness (and float range: the core works in float32) and the deformer's own
// ranges, and throws InvalidInput naming context() and "parameter 'name'"; the deformer is unchanged
// then. Setting a parameter to the value it already has changes nothing (no rebind). Constraints between
// parameters (a low bound below a high bound) are checked when they are used, at bind or evaluation, so
// the parameters can be set one at a time in any order; parameters() lists them in a good setting order
// (bind-time inputs first: a rest-shape change resets its animated counterpart, see deformers.h).
//
// Implementations (deformers.h; a studio adds its own by deriving from this class) declare their
// parameters in their constructor with addParameter and implement bindRest and deform.
class Deformer {
  public:
    virtual ~Deformer() = default;
    Deformer(const Deformer&) = delete;
    Deformer& operator=(const Deformer&) = delete;

    [[nodiscard]] const std::string& type() const { return type_; }
    [[nodiscard]] const std::string& label() const { return label_; }
    // How error messages name this deformer: "ffd 'lattice1'" by default; a stack sets
    // "stack entry 2 (ffd 'lattice1')".
    [[nodiscard]] const std::string& context() const { return context_; }
    void setContext(std::string context) { context_ = std::move(context); }

    [[nodiscard]] std::span<const ParamInfo> parameters() const { return infos_; }
    // The parameter called `name`; throws InvalidInput listing the known names when there is none.
    [[nodiscard]] const ParamInfo& parameter(std::string_view name) const;
    [[nodiscard]] bool hasParameter(std::string_view name) const;
    void set(std::string_view name, std::span<const double> value);
    void set(std::string_view name, double value) { set(name, std::span<const double>(&value, 1)); }
    [[nodiscard]] std::vector<double> get(std::string_view name) const;

    [[nodiscard]] virtual WeightMode weightMode() const { return WeightMode::Blend; }
    // True when the binding depends on the painted weights (none of the built-in deformers), so a weight
    // change needs a new bind.
    [[nodiscard]] virtual bool weightsAffectBinding() const { return false; }

    [[nodiscard]] bool needsBind() const { return dirty_; }
    // Marks the binding stale (the host's rest mesh or, where weightsAffectBinding(), the weights changed).
    void markForBind() { dirty_ = true; }
    // Binds to `rest` (its positions and connectivity); weights: #V painted weights, or empty for all 1,
    // used only where weightsAffectBinding(). On failure the deformer stays unbound and the error, whatever
    // the core said, is prefixed with context().
    void bind(const geom::Mesh& rest, std::span<const float> weights = {});
    // Completed binds since construction.
    [[nodiscard]] int64_t bindCount() const { return bindCount_; }
    // Vertex count of the bound rest mesh (0 before the first bind).
    [[nodiscard]] int32_t boundVertices() const { return boundVertices_; }

    // The fully deformed positions, no weights or envelope: in and out hold #V positions of the bound
    // mesh (the rest positions or an upstream deformer's output) and must not overlap. Throws InvalidInput
    // naming context() if the deformer needs a bind or a size differs.
    void evaluate(std::span<const glm::vec3> in, std::span<glm::vec3> out);
    // With painted weights (#V, or empty for all 1) and the envelope applied as weightMode() says: Blend
    // deformers evaluate and then blendDeformation(); Native ones take them into their evaluation.
    void evaluate(std::span<const glm::vec3> in, std::span<glm::vec3> out, std::span<const float> weights,
                  double envelope);

  protected:
    Deformer(std::string type, std::string label);

    // Declares a parameter with its default value (info.components is set from it). Returns its index,
    // which the accessors below take.
    size_t addParameter(ParamInfo info, std::vector<double> initial);
    [[nodiscard]] const std::vector<double>& value(size_t index) const { return values_[index]; }
    // Replaces a value without validation and without marking a rebind (for a parameter that follows
    // another: FFD points reset to the rest lattice when the lattice changes); resizes the parameter.
    void assign(size_t index, std::vector<double> value);

    // The deformer's own checks of a candidate value (count and finiteness already checked): call fail()
    // to reject it.
    virtual void validate(size_t index, std::span<const double> value) const;
    // Called after parameter `index` took a new value.
    virtual void changed(size_t index);
    // The bind work: read the parameters, build the core objects from scratch, bind them to `rest`.
    virtual void bindRest(const geom::Mesh& rest, std::span<const float> weights) = 0;
    // Full deformation of in into out (sizes checked, the deformer bound).
    virtual void deform(std::span<const glm::vec3> in, std::span<glm::vec3> out) = 0;
    // Native weight mode only: the deformation with weights and envelope taken in.
    virtual void deformWeighted(std::span<const glm::vec3> in, std::span<glm::vec3> out,
                                std::span<const float> weights, double envelope);

    // Throws InvalidInput: "<context>: parameter '<name>': <problem> (expected <expected>)".
    [[noreturn]] void fail(size_t index, const std::string& problem, const std::string& expected) const;
    // Checks that every value is a whole number in [lo, hi]; fails otherwise.
    void requireIntegers(size_t index, std::span<const double> value, double lo, double hi) const;

  private:
    void checkSizes(size_t in, size_t out) const;

    std::string type_, label_, context_;
    std::vector<ParamInfo> infos_;
    std::vector<std::vector<double>> values_;
    bool dirty_ = true;
    int64_t bindCount_ = 0;
    int32_t boundVertices_ = 0;
};

// Maya's painted-weight and envelope rule, per vertex u with k = envelope w_u (w_u = 1 when weights is
// empty): out_u = in_u + k (deformed_u - in_u), computed in double and rounded to float once. k = 1 gives
// deformed_u and k = 0 gives in_u bit for bit. in, deformed, out: #V positions; out may alias deformed.
// OpenMP over vertices, bit-identical for any thread count. Sizes are the caller's to check.
void blendDeformation(std::span<const glm::vec3> in, std::span<const glm::vec3> deformed,
                      std::span<const float> weights, double envelope, std::span<glm::vec3> out);

}  // namespace deformkit::host
