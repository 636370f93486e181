#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <glm/vec3.hpp>

#include "deformkit/geom/mesh.h"
#include "deformkit/host/deformer.h"

namespace deformkit::host {

// The host layer every host shares (the deformkit CLI, the Python module, the Blender and Maya plugins):
// an ordered list of deformers over one rest mesh, each entry with its painted weights and envelope.
//
// - Binding. Every entry binds to the stack's rest mesh, not to the upstream entries' output at bind
//   time: a frame's result then depends only on the scene's values at that frame, never on when a bind
//   happened (a farm job evaluating frame 90 alone gets what an interactive session gets there). An
//   entry is bound when it needs it: after setRest, after a change to one of its parameters with
//   rebinds = true, after a weight change if its binding uses weights, and never otherwise. evaluate()
//   binds what it is about to run; bind() binds every entry that needs it.
// - Evaluation runs the entries in order, each on the previous one's output. An entry with envelope 0,
//   or painted weights that are all 0, is skipped (its input passes through bit for bit, and it is not
//   bound). Otherwise weights and envelope apply as the deformer's weightMode() says: Maya's
//   out = in + envelope w (deformed - in) (warp::applyEnvelope) or the deformer's own (the slide).
// - Errors are InvalidInput (or a subclass) naming the entry, "stack entry 2 (ffd 'lattice1')" (entries
//   count from 0), and the parameter or input; evaluate() writes nothing to `points` when it throws. An
//   entry whose result is not finite (parameters in float range that take a point beyond it) throws,
//   naming the point.
//
// Not thread-safe: one thread drives a stack; each entry runs in parallel inside (OpenMP), with results
// bit-identical for any thread count.
class DeformerStack {
  public:
    DeformerStack() = default;

    // The rest mesh every entry binds to, copied (positions and face arrays; the half-edge structure, built
    // on first use, is shared with `rest` and its other copies, not built again). Marks every entry for a
    // new bind.
    void setRest(const geom::Mesh& rest);
    [[nodiscard]] bool hasRest() const { return rest_.has_value(); }
    // Counts setRest() calls: a host that caches something of the rest mesh compares it to know whether
    // the rest changed (comparing meshes would cost a pass over them every frame).
    [[nodiscard]] uint64_t restVersion() const { return restVersion_; }
    // Throws InvalidInput when no rest mesh was set.
    [[nodiscard]] const geom::Mesh& rest() const;

    // Appends a deformer (envelope 1, no painted weights) and returns its index. Throws InvalidInput for a
    // null deformer or a label another entry already has.
    size_t add(std::unique_ptr<Deformer> deformer);
    [[nodiscard]] size_t size() const { return entries_.size(); }
    // Index checked; throws InvalidInput naming the index.
    [[nodiscard]] Deformer& deformer(size_t index);
    [[nodiscard]] const Deformer& deformer(size_t index) const;
    // The index of the entry labelled `label`; throws InvalidInput listing the labels when there is none.
    [[nodiscard]] size_t find(std::string_view label) const;

    // Parameters by name, as the scene parser addresses them: "envelope" (the entry's) or a parameter of
    // the entry's deformer. parameters() lists the envelope first, then the deformer's.
    [[nodiscard]] std::vector<ParamInfo> parameters(size_t index) const;
    void set(size_t index, std::string_view name, std::span<const double> value);
    void set(size_t index, std::string_view name, double value) {
        set(index, name, std::span<const double>(&value, 1));
    }
    [[nodiscard]] std::vector<double> get(size_t index, std::string_view name) const;

    // Painted weights: one per rest vertex, finite (usually in [0, 1]; not clamped), or empty for all 1.
    // Throws InvalidInput naming the entry and the first bad weight, or a count that differs from the rest
    // mesh's vertex count (checked again at evaluation if the rest mesh changes later).
    void setWeights(size_t index, std::vector<float> weights);
    [[nodiscard]] std::span<const float> weights(size_t index) const;
    // Animatable; any finite value (usually in [0, 1]; not clamped). Throws InvalidInput otherwise.
    void setEnvelope(size_t index, double envelope);
    [[nodiscard]] double envelope(size_t index) const;
    // False when the entry is skipped: envelope 0 or all painted weights 0.
    [[nodiscard]] bool isActive(size_t index) const;

    // Binds every entry that needs it. Throws InvalidInput without a rest mesh.
    void bind();
    // Deforms `points` (#V positions: the rest positions, or what an upstream stage made of them) in
    // place through every active entry. Allocates only on the first call or after a vertex count change.
    void evaluate(std::span<glm::vec3> points);
    // The same from `in` into `out` (#V each, not overlapping): the first active entry reads `in`, the last
    // writes `out`, so a host that keeps its input (a DCC's upstream geometry, the rest mesh) copies
    // nothing. When an entry throws, `out` may hold part of a result (setup errors, which are checked
    // first, leave it untouched).
    void evaluate(std::span<const glm::vec3> in, std::span<glm::vec3> out);

    // Binds done by this stack, in total and per entry.
    [[nodiscard]] int64_t bindCount() const { return bindCount_; }
    [[nodiscard]] int64_t bindCount(size_t index) const;
    // "stack entry 2 (ffd 'lattice1')".
    [[nodiscard]] std::string entryName(size_t index) const;

  private:
    struct Entry {
        std::unique_ptr<Deformer> deformer;
        std::vector<float> weights;
        double envelope = 1.0;
        bool allZero = false;  // weights non-empty and all 0
        int64_t binds = 0;
    };

    Entry& entry(size_t index);
    [[nodiscard]] const Entry& entry(size_t index) const;
    void checkWeightCount(size_t index) const;
    void bindEntry(size_t index);

    std::optional<geom::Mesh> rest_;
    std::vector<Entry> entries_;
    void prepare(std::span<const glm::vec3> in, size_t outSize);

    std::vector<glm::vec3> work_, deformed_;
    std::vector<size_t> active_;  // the active entries of the evaluation under way
    int64_t bindCount_ = 0;
    uint64_t restVersion_ = 0;
};

}  // namespace deformkit::host
