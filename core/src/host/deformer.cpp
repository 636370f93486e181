#include "deformkit/host/deformer.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <utility>

#include <glm/vec3.hpp>

#include "deformkit/error.h"
#include "deformkit/geom/finite.h"
#include "deformkit/warp/envelope.h"

namespace deformkit::host {
namespace {

std::string withContext(const std::string& context, const char* message) {
    const std::string text(message);
    if (text.starts_with(context)) return text;
    return context + ": " + text;
}

// Called inside a catch block: rethrows the Error in flight as the same kind, its message prefixed with
// `context` (unless it already starts with it).
[[noreturn]] void rethrowWithContext(const std::string& context) {
    try {
        throw;
    } catch (const TopologyError& e) {
        throw TopologyError(withContext(context, e.what()));
    } catch (const InvalidInput& e) {
        throw InvalidInput(withContext(context, e.what()));
    } catch (const ParseError& e) {
        throw ParseError(withContext(context, e.what()));
    } catch (const IoError& e) {
        throw IoError(withContext(context, e.what()));
    } catch (const Error& e) {
        throw Error(withContext(context, e.what()));
    }
}

}  // namespace

Deformer::Deformer(std::string type, std::string label)
    : type_(std::move(type)), label_(std::move(label)), context_(type_ + " '" + label_ + "'") {}

size_t Deformer::addParameter(ParamSpec spec, std::vector<double> initial) {
    ParamInfo info;
    static_cast<ParamSpec&>(info) = std::move(spec);
    info.components = static_cast<int32_t>(initial.size());
    infos_.push_back(std::move(info));
    values_.push_back(std::move(initial));
    return infos_.size() - 1;
}

bool Deformer::hasParameter(std::string_view name) const {
    for (const ParamInfo& info : infos_)
        if (info.name == name) return true;
    return false;
}

const ParamInfo& Deformer::parameter(std::string_view name) const {
    for (const ParamInfo& info : infos_)
        if (info.name == name) return info;
    std::string known;
    for (const ParamInfo& info : infos_)
        known += (known.empty() ? "" : ", ") + info.name;
    throw InvalidInput(
        formatError(context_, "parameter '" + std::string(name) + "'", "does not exist", "one of: " + known));
}

void Deformer::set(std::string_view name, std::span<const double> value) {
    const size_t index = static_cast<size_t>(&parameter(name) - infos_.data());
    const ParamInfo& info = infos_[index];
    const size_t count = value.size();
    // An unchanged value changes nothing: no validation (an FFD validates a whole lattice), no rebind.
    std::vector<double>& current = values_[index];
    if (current.size() == count && std::equal(current.begin(), current.end(), value.begin())) return;
    if (info.stride > 0) {
        if (count == 0 || count % static_cast<size_t>(info.stride) != 0) {
            fail(index, "has " + std::to_string(count) + " values",
                 "a positive multiple of " + std::to_string(info.stride) + " values");
        }
    } else if (count != static_cast<size_t>(info.components)) {
        fail(index, "has " + std::to_string(count) + " values", std::to_string(info.components) + " values");
    }
    // The core computes in float32: a double beyond its range would become infinite there.
    constexpr double kMax = std::numeric_limits<float>::max();
    for (size_t i = 0; i < count; ++i) {
        if (!std::isfinite(value[i]) || std::abs(value[i]) > kMax) {
            fail(index, "value " + std::to_string(i) + " is " + numberText(value[i]),
                 "finite numbers within float range");
        }
    }
    validate(index, value);
    current.assign(value.begin(), value.end());
    infos_[index].components = static_cast<int32_t>(count);
    if (info.rebinds) dirty_ = true;
    controlsDirty_ = true;
    changed(index);
}

std::vector<double> Deformer::get(std::string_view name) const {
    return values_[static_cast<size_t>(&parameter(name) - infos_.data())];
}

void Deformer::assign(size_t index, std::vector<double> value) {
    infos_[index].components = static_cast<int32_t>(value.size());
    values_[index] = std::move(value);
}

void Deformer::validate(size_t, std::span<const double>) const {}

void Deformer::changed(size_t) {}

void Deformer::pushControls() {}

void Deformer::deformWeighted(std::span<const glm::vec3>, std::span<glm::vec3>, std::span<const float>,
                              double) {
    throw InvalidInput(formatError(context_, "weighted evaluation", "is not implemented by this deformer",
                                   "deformWeighted() in a deformer whose weight mode is Native"));
}

void Deformer::fail(size_t index, const std::string& problem, const std::string& expected) const {
    throw InvalidInput(formatError(context_, "parameter '" + infos_[index].name + "'", problem, expected));
}

void Deformer::requireIntegers(size_t index, std::span<const double> value, double lo, double hi) const {
    for (size_t i = 0; i < value.size(); ++i) {
        const double v = value[i];
        if (v != std::floor(v) || v < lo || v > hi) {
            const std::string where = value.size() == 1 ? "is " : "value " + std::to_string(i) + " is ";
            fail(index, where + numberText(v),
                 "whole numbers in [" + numberText(lo) + ", " + numberText(hi) + "]");
        }
    }
}

void Deformer::bind(const geom::Mesh& rest, std::span<const float> weights) {
    dirty_ = true;
    boundVertices_ = 0;
    if (!weights.empty() && weights.size() != static_cast<size_t>(rest.numVertices())) {
        throw InvalidInput(formatError(context_, "weights",
                                       "has " + std::to_string(weights.size()) + " values",
                                       std::to_string(rest.numVertices()) + ", one per rest vertex"));
    }
    try {
        bindRest(rest, weights);
    } catch (const Error&) {
        rethrowWithContext(context_);
    }
    dirty_ = false;
    controlsDirty_ = true;
    boundVertices_ = rest.numVertices();
    ++bindCount_;
}

void Deformer::prepare(size_t in, size_t out) {
    if (dirty_) {
        throw InvalidInput(formatError(context_, "evaluate", "called before a needed bind",
                                       "bind() after the rest mesh or a bind-time parameter changed"));
    }
    const size_t n = static_cast<size_t>(boundVertices_);
    if (in != n || out != n) {
        throw InvalidInput(
            formatError(context_, "points",
                        "has " + std::to_string(in) + " inputs and " + std::to_string(out) + " outputs",
                        std::to_string(n) + " each, the bound mesh's vertex count"));
    }
    if (controlsDirty_) {
        try {
            pushControls();
        } catch (const Error&) {
            rethrowWithContext(context_);
        }
        controlsDirty_ = false;
    }
}

void Deformer::evaluate(std::span<const glm::vec3> in, std::span<glm::vec3> out) {
    prepare(in.size(), out.size());
    try {
        deform(in, out);
    } catch (const Error&) {
        rethrowWithContext(context_);
    }
    // Parameters within float range can still take a point beyond it (an envelope of 3e38, a bend of 3e38
    // radians a unit): refused here, naming the point, rather than handed on as NaN or infinity. The input
    // is finite (the stack checks it), so the message gives the point before and after.
    warp::requireFiniteResult(context_, in, out, static_cast<int64_t>(geom::firstNonFinite(out)));
}

void Deformer::evaluate(std::span<const glm::vec3> in, std::span<glm::vec3> out,
                        std::span<const float> weights, double envelope) {
    prepare(in.size(), out.size());
    if (!weights.empty() && weights.size() != in.size()) {
        throw InvalidInput(formatError(context_, "weights",
                                       "has " + std::to_string(weights.size()) + " values",
                                       std::to_string(in.size()) + ", one per vertex"));
    }
    if (!std::isfinite(envelope)) {
        throw InvalidInput(
            formatError(context_, "envelope", "is " + numberText(envelope), "a finite number"));
    }
    int64_t bad = -1;  // the first point whose output is not finite, once known
    try {
        if (weightMode() == WeightMode::Native) {
            deformWeighted(in, out, weights, envelope);
        } else {
            deform(in, out);
            // k = 1 everywhere gives the deformed positions bit for bit: no pass needed. The blend finds
            // its first point that is not finite as it writes.
            if (!weights.empty() || envelope != 1.0)
                bad = warp::applyEnvelope(in, out, weights, envelope, out);
        }
    } catch (const Error&) {
        rethrowWithContext(context_);
    }
    if (bad < 0) bad = static_cast<int64_t>(geom::firstNonFinite(out));
    warp::requireFiniteResult(context_, in, out, bad);
}

}  // namespace deformkit::host
