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

// How a deformer declares one of its parameters, with designated initialisers:
//   addParameter({.name = "radius", .rebinds = true, .doc = "support radius, scene units, > 0"}, {1.0});
// The default value given beside it sets how many values the parameter takes (unless it is resizable).
struct ParamSpec {
    std::string name;
    // True when a new value needs a new bind ("[bind]": a lattice's rest box, a slide handle's vertex or
    // radius); false for animatable controls (lattice points, angles, displacements), which never rebind.
    bool rebinds = false;
    // > 0: resizable; set() takes any positive multiple of `stride` values. 0: exactly as many values as
    // the parameter has now (an FFD's `points` follow its `divisions`).
    int32_t stride = 0;
    std::string doc;  // units, shape and range: the parameter reference and help text are made from it
};

// One parameter as hosts and the scene parser see it: its declaration and how many values it takes now.
struct ParamInfo : ParamSpec {
    int32_t components = 1;
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
// Parameters are addressed by name with double values (integers and flags as whole numbers). Setting a
// parameter to the value it already has returns at once: nothing is validated, rebound or pushed. Otherwise
// set() validates the count, finiteness (and float range: the core works in float32) and the deformer's own
// ranges, and throws InvalidInput naming context() and "parameter 'name'"; the deformer is unchanged then.
// Constraints between parameters (a low bound below a high bound) are checked when they are used, at bind
// or evaluation, so the parameters can be set one at a time in any order; parameters() lists them in a
// good setting order (bind-time inputs first: a rest-shape change resets its animated counterpart).
//
// Implementations (the built-in ones in deformers.h; a studio adds its own by deriving from this class)
// declare their parameters in their constructor with addParameter and implement three steps: bindRest
// builds the core objects from the parameters, pushControls hands the animatable controls to them (called
// before an evaluation whenever a control changed since the last push, and after every bind), and deform
// runs them.
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
    // deformers evaluate and then warp::applyEnvelope(); Native ones take them into their evaluation.
    void evaluate(std::span<const glm::vec3> in, std::span<glm::vec3> out, std::span<const float> weights,
                  double envelope);

  protected:
    Deformer(std::string type, std::string label);

    // Declares a parameter with its default value. Returns its index, which the accessors below take.
    size_t addParameter(ParamSpec spec, std::vector<double> initial);
    [[nodiscard]] const std::vector<double>& value(size_t index) const { return values_[index]; }
    // Replaces a value without validation and without marking a rebind (for a parameter that follows
    // another: FFD points reset to the rest lattice when the lattice changes); resizes the parameter.
    void assign(size_t index, std::vector<double> value);

    // The deformer's own checks of a candidate value (count and finiteness already checked): call fail()
    // to reject it.
    virtual void validate(size_t index, std::span<const double> value) const;
    // Called after parameter `index` took a new value (to reset a parameter that follows it).
    virtual void changed(size_t index);
    // The bind work: read the parameters, build the core objects from scratch, bind them to `rest`.
    virtual void bindRest(const geom::Mesh& rest, std::span<const float> weights) = 0;
    // Hands the animatable controls (parameters with rebinds = false) to the bound core objects. The
    // default does nothing, for a deformer that reads its controls in deform().
    virtual void pushControls();
    // Full deformation of in into out (sizes checked, the deformer bound, its controls pushed).
    virtual void deform(std::span<const glm::vec3> in, std::span<glm::vec3> out) = 0;
    // Native weight mode only: the deformation with weights and envelope taken in.
    virtual void deformWeighted(std::span<const glm::vec3> in, std::span<glm::vec3> out,
                                std::span<const float> weights, double envelope);

    // Throws InvalidInput: "<context>: parameter '<name>': <problem> (expected <expected>)".
    [[noreturn]] void fail(size_t index, const std::string& problem, const std::string& expected) const;
    // Checks that every value is a whole number in [lo, hi]; fails otherwise.
    void requireIntegers(size_t index, std::span<const double> value, double lo, double hi) const;

  private:
    // Checks the sizes and pushes the controls if one changed: what every evaluation starts with.
    void prepare(size_t in, size_t out);

    std::string type_, label_, context_;
    std::vector<ParamInfo> infos_;
    std::vector<std::vector<double>> values_;
    bool dirty_ = true;          // a bind is needed
    bool controlsDirty_ = true;  // a control changed since the last pushControls()
    int64_t bindCount_ = 0;
    int32_t boundVertices_ = 0;
};

}  // namespace deformkit::host
