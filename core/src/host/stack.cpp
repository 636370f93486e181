#include "deformkit/host/stack.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "deformkit/error.h"
#include "deformkit/geom/finite.h"

namespace deformkit::host {
namespace {

constexpr const char* kEnvelope = "envelope";

}  // namespace

void DeformerStack::setRest(const geom::Mesh& rest) {
    ++restVersion_;
    rest_ = rest;
    for (Entry& e : entries_)
        e.deformer->markForBind();
}

const geom::Mesh& DeformerStack::rest() const {
    if (!rest_) throw InvalidInput(formatError("stack", "rest mesh", "is not set", "setRest() first"));
    return *rest_;
}

size_t DeformerStack::add(std::unique_ptr<Deformer> deformer) {
    const std::string name = "stack entry " + std::to_string(entries_.size());
    if (!deformer) throw InvalidInput(formatError(name, "deformer", "is null", "a deformer"));
    for (size_t i = 0; i < entries_.size(); ++i) {
        if (entries_[i].deformer->label() == deformer->label()) {
            throw InvalidInput(formatError(name, "label '" + deformer->label() + "'",
                                           "is already used by " + entryName(i),
                                           "a label unique in the stack"));
        }
    }
    Entry e;
    e.deformer = std::move(deformer);
    entries_.push_back(std::move(e));
    const size_t index = entries_.size() - 1;
    entries_[index].deformer->setContext(entryName(index));
    return index;
}

DeformerStack::Entry& DeformerStack::entry(size_t index) {
    return const_cast<Entry&>(std::as_const(*this).entry(index));
}

const DeformerStack::Entry& DeformerStack::entry(size_t index) const {
    if (index >= entries_.size()) {
        throw InvalidInput(formatError("stack", "entry " + std::to_string(index), "does not exist",
                                       "an index below " + std::to_string(entries_.size())));
    }
    return entries_[index];
}

Deformer& DeformerStack::deformer(size_t index) {
    return *entry(index).deformer;
}

const Deformer& DeformerStack::deformer(size_t index) const {
    return *entry(index).deformer;
}

size_t DeformerStack::find(std::string_view label) const {
    std::string known;
    for (size_t i = 0; i < entries_.size(); ++i) {
        if (entries_[i].deformer->label() == label) return i;
        known += (known.empty() ? "'" : ", '") + entries_[i].deformer->label() + "'";
    }
    throw InvalidInput(formatError("stack", "deformer '" + std::string(label) + "'", "does not exist",
                                   known.empty() ? "a deformer added to the stack" : "one of: " + known));
}

std::string DeformerStack::entryName(size_t index) const {
    const Deformer& d = *entry(index).deformer;
    return "stack entry " + std::to_string(index) + " (" + d.type() + " '" + d.label() + "')";
}

std::vector<ParamInfo> DeformerStack::parameters(size_t index) const {
    const Deformer& d = deformer(index);
    std::vector<ParamInfo> out;
    ParamInfo envelope;
    envelope.name = kEnvelope;
    envelope.doc = "scales this entry's displacement: 0 = off (skipped), 1 = full; animatable, not clamped";
    envelope.components = 1;
    out.push_back(std::move(envelope));
    out.insert(out.end(), d.parameters().begin(), d.parameters().end());
    return out;
}

void DeformerStack::set(size_t index, std::string_view name, std::span<const double> value) {
    Entry& e = entry(index);
    if (name == kEnvelope && !e.deformer->hasParameter(name)) {
        if (value.size() != 1) {
            throw InvalidInput(formatError(entryName(index), "parameter 'envelope'",
                                           "has " + std::to_string(value.size()) + " values", "1 value"));
        }
        setEnvelope(index, value[0]);
        return;
    }
    if (!e.deformer->hasParameter(name)) {
        std::string known = kEnvelope;
        for (const ParamInfo& info : e.deformer->parameters())
            known += ", " + info.name;
        throw InvalidInput(formatError(entryName(index), "parameter '" + std::string(name) + "'",
                                       "does not exist", "one of: " + known));
    }
    e.deformer->set(name, value);
}

std::vector<double> DeformerStack::get(size_t index, std::string_view name) const {
    const Entry& e = entry(index);
    if (name == kEnvelope && !e.deformer->hasParameter(name)) return {e.envelope};
    return e.deformer->get(name);
}

void DeformerStack::setWeights(size_t index, std::vector<float> weights) {
    Entry& e = entry(index);
    if (!weights.empty()) {
        if (!rest_) {
            throw InvalidInput(formatError(entryName(index), "weights", "given before the rest mesh",
                                           "setRest() before painted weights"));
        }
        const auto n = static_cast<size_t>(rest_->numVertices());
        if (weights.size() != n) {
            throw InvalidInput(formatError(entryName(index), "weights",
                                           "has " + std::to_string(weights.size()) + " values",
                                           std::to_string(n) + ", one per rest vertex"));
        }
        for (size_t i = 0; i < weights.size(); ++i) {
            if (!std::isfinite(weights[i])) {
                throw InvalidInput(formatError(entryName(index), "weight of vertex " + std::to_string(i),
                                               "is " + numberText(weights[i]), "a finite number"));
            }
        }
    }
    e.allZero =
        !weights.empty() && std::all_of(weights.begin(), weights.end(), [](float w) { return w == 0.0f; });
    e.weights = std::move(weights);
    if (e.deformer->weightsAffectBinding()) e.deformer->markForBind();
}

std::span<const float> DeformerStack::weights(size_t index) const {
    return entry(index).weights;
}

void DeformerStack::setEnvelope(size_t index, double envelope) {
    Entry& e = entry(index);
    // Applied in float32, as every parameter: a double beyond float range would become infinite there.
    if (!std::isfinite(envelope) || std::abs(envelope) > std::numeric_limits<float>::max()) {
        throw InvalidInput(formatError(entryName(index), "parameter 'envelope'", "is " + numberText(envelope),
                                       "a finite number within float range, usually in [0, 1]"));
    }
    e.envelope = envelope;
}

double DeformerStack::envelope(size_t index) const {
    return entry(index).envelope;
}

bool DeformerStack::isActive(size_t index) const {
    const Entry& e = entry(index);
    return e.envelope != 0.0 && !e.allZero;
}

int64_t DeformerStack::bindCount(size_t index) const {
    return entry(index).binds;
}

void DeformerStack::checkWeightCount(size_t index) const {
    const Entry& e = entries_[index];
    const auto n = static_cast<size_t>(rest_->numVertices());
    if (!e.weights.empty() && e.weights.size() != n) {
        throw InvalidInput(formatError(entryName(index), "weights",
                                       "has " + std::to_string(e.weights.size()) + " values",
                                       std::to_string(n) + ", one per vertex of the current rest mesh"));
    }
}

void DeformerStack::bindEntry(size_t index) {
    Entry& e = entries_[index];
    checkWeightCount(index);
    e.deformer->bind(*rest_, e.weights);
    ++e.binds;
    ++bindCount_;
}

void DeformerStack::bind() {
    (void)rest();
    for (size_t i = 0; i < entries_.size(); ++i)
        if (entries_[i].deformer->needsBind()) bindEntry(i);
}

// Checks sizes and finiteness, and binds what the active entries need: everything that can fail on the
// entries' setup fails here, before any work.
void DeformerStack::prepare(std::span<const glm::vec3> in, size_t outSize) {
    const geom::Mesh& mesh = rest();
    const auto n = static_cast<size_t>(mesh.numVertices());
    if (in.size() != n || outSize != n) {
        throw InvalidInput(formatError(
            "stack", "points", "has " + std::to_string(in.size() != n ? in.size() : outSize) + " positions",
            std::to_string(n) + ", one per rest vertex"));
    }
    // The rest mesh's own positions are finite (geom::Mesh checks them); anything else is scanned, in one
    // branch-free pass (vectorised) before looking for the first bad point.
    if (in.data() != mesh.points().data()) {
        const size_t u = geom::firstNonFinite(in);
        if (u < n) {
            throw InvalidInput(
                formatError("stack", "point " + std::to_string(u), "is not finite", "finite coordinates"));
        }
    }
    active_.clear();
    for (size_t i = 0; i < entries_.size(); ++i) {
        if (!isActive(i)) continue;
        checkWeightCount(i);
        if (entries_[i].deformer->needsBind()) bindEntry(i);
        active_.push_back(i);
    }
}

void DeformerStack::evaluate(std::span<glm::vec3> points) {
    prepare(points, points.size());
    if (active_.empty()) return;
    // In place: the entries ping-pong between two buffers, read `points` first and are copied back last,
    // so `points` is untouched when an entry throws.
    const size_t n = points.size();
    work_.resize(n);
    deformed_.resize(n);
    std::span<const glm::vec3> in = points;
    for (size_t a = 0; a < active_.size(); ++a) {
        Entry& e = entries_[active_[a]];
        const std::span<glm::vec3> out(a % 2 == 0 ? work_ : deformed_);
        e.deformer->evaluate(in, out, e.weights, e.envelope);
        in = out;
    }
    std::copy(in.begin(), in.end(), points.begin());
}

void DeformerStack::evaluate(std::span<const glm::vec3> in, std::span<glm::vec3> out) {
    prepare(in, out.size());
    const std::vector<size_t>& active = active_;
    if (active.empty()) {
        std::copy(in.begin(), in.end(), out.begin());
        return;
    }
    const size_t n = in.size();
    if (active.size() > 1) work_.resize(n);
    if (active.size() > 2) deformed_.resize(n);
    std::span<const glm::vec3> from = in;
    for (size_t a = 0; a < active.size(); ++a) {
        Entry& e = entries_[active[a]];
        const bool last = a + 1 == active.size();
        std::span<glm::vec3> to = last ? out : std::span<glm::vec3>(a % 2 == 0 ? work_ : deformed_);
        e.deformer->evaluate(from, to, e.weights, e.envelope);
        from = to;
    }
}

}  // namespace deformkit::host
