#include "maya_adapter.h"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>
#include <glm/mat4x4.hpp>
#include <glm/matrix.hpp>

#include "deformkit/error.h"
#include "deformkit/host/deformers.h"

namespace deformkit::maya {

namespace {

// Maya's row-vector matrix as glm's column-vector one: M_glm = M_maya^T, so glm's [c][r] is Maya's [c][r]
// read as column c.
glm::dmat4 toGlm(const MayaMatrix& a) {
    glm::dmat4 g(1.0);
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c)
            g[r][c] = a.m[r][c];  // glm column r = Maya row r (the image of axis r, or the translation)
    return g;
}

MayaMatrix fromGlm(const glm::dmat4& g) {
    MayaMatrix a;
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c)
            a.m[r][c] = g[r][c];
    return a;
}

std::vector<double> flat(const glm::dvec3& v) {
    return {v.x, v.y, v.z};
}

void append(std::vector<double>& out, const glm::dvec3& v) {
    out.insert(out.end(), {v.x, v.y, v.z});
}

std::vector<double> flatPoints(std::span<const glm::dvec3> points, const MayaMatrix& toGeometry) {
    std::vector<double> out;
    out.reserve(points.size() * 3);
    for (const glm::dvec3& p : points)
        append(out, transformPoint(toGeometry, p));
    return out;
}

double smooth(double t) {
    return t * t * (3.0 - 2.0 * t);
}

}  // namespace

MayaMatrix multiply(const MayaMatrix& a, const MayaMatrix& b) {
    // p a b = p (a b): with row vectors the product is a times b; in glm's column form (a b)^T = b^T a^T.
    return fromGlm(toGlm(b) * toGlm(a));
}

MayaMatrix inverse(const MayaMatrix& a, const std::string& what) {
    const glm::dmat4 g = toGlm(a);
    const double det = glm::determinant(g);
    if (!std::isfinite(det) || std::abs(det) < 1e-300) {
        throw InvalidInput(formatError(what, "world matrix",
                                       "is singular (determinant " + numberText(det) + ")",
                                       "an invertible transform"));
    }
    return fromGlm(glm::inverse(g));
}

glm::dvec3 transformPoint(const MayaMatrix& a, const glm::dvec3& p) {
    return glm::dvec3(toGlm(a) * glm::dvec4(p, 1.0));
}

glm::dvec3 transformVector(const MayaMatrix& a, const glm::dvec3& v) {
    return glm::dvec3(toGlm(a) * glm::dvec4(v, 0.0));
}

std::vector<double> sampleRamp(std::span<const RampKey> keys, int samples) {
    if (keys.empty()) {
        throw InvalidInput(formatError("falloff ramp", "", "has no keys", "at least one key"));
    }
    if (samples < 2) {
        throw InvalidInput(formatError("falloff ramp", "samples", "is " + std::to_string(samples), ">= 2"));
    }
    std::vector<RampKey> sorted(keys.begin(), keys.end());
    std::stable_sort(sorted.begin(), sorted.end(),
                     [](const RampKey& a, const RampKey& b) { return a.position < b.position; });
    std::vector<double> out(static_cast<size_t>(samples));
    for (int i = 0; i < samples; ++i) {
        const double x = static_cast<double>(i) / (samples - 1);
        size_t k = 0;
        while (k + 1 < sorted.size() && sorted[k + 1].position <= x)
            ++k;
        const RampKey& a = sorted[k];
        if (x <= sorted.front().position) {
            out[i] = sorted.front().value;
        } else if (k + 1 == sorted.size()) {
            out[i] = sorted.back().value;
        } else {
            const RampKey& b = sorted[k + 1];
            const double t = b.position > a.position ? (x - a.position) / (b.position - a.position) : 1.0;
            const double s = a.interpolation == 0 ? 0.0 : a.interpolation == 1 ? t : smooth(t);
            out[i] = a.value + s * (b.value - a.value);
        }
    }
    return out;
}

Parameters slideParameters(const SlideInputs& in) {
    const MayaMatrix toGeometry = inverse(in.geometryWorld, "dkSlide: the deformed shape");
    const glm::dvec3 d = transformVector(toGeometry, in.endWorld - in.startWorld);
    return {{"vertex", {static_cast<double>(in.vertex)}},
            {"radius", {in.radius}},
            {"geodesic", {in.geodesic ? 1.0 : 0.0}},
            {"limitSurface", {in.limitSurface ? 1.0 : 0.0}},
            {"paintedWeights", {in.weightsAreFalloff ? 1.0 : 0.0}},
            {"foldLimit", {in.foldLimit ? 1.0 : 0.0}},
            {"falloff", {2.0}},
            {"falloffRamp", sampleRamp(in.falloff, in.rampSamples)},
            {"displacement", flat(d)}};
}

Parameters barrParameters(const BarrInputs& in) {
    if (in.type != "taper" && in.type != "twist" && in.type != "bend") {
        throw InvalidInput(formatError("dkBarr", "type", "is '" + in.type + "'", "taper, twist or bend"));
    }
    const MayaMatrix local =
        multiply(in.handleWorld, inverse(in.geometryWorld, "dkBarr: the deformed shape"));
    Parameters p{{"handleOrigin", flat(transformPoint(local, glm::dvec3(0.0)))}};
    if (in.type == "bend") p.push_back({"handleX", flat(transformVector(local, {1.0, 0.0, 0.0}))});
    p.push_back({"handleY", flat(transformVector(local, {0.0, 1.0, 0.0}))});
    if (in.type == "taper") {
        p.push_back({"startScale", {in.startValue}});
        p.push_back({"endScale", {in.endValue}});
    } else if (in.type == "twist") {
        p.push_back({"startAngle", {in.startValue}});
        p.push_back({"endAngle", {in.endValue}});
    } else {
        p.push_back({"curvature", {in.curvature}});
    }
    p.push_back({"lowBound", {in.lowBound}});
    p.push_back({"highBound", {in.highBound}});
    return p;
}

Parameters frameLatticeParameters(const FrameLatticeInputs& in) {
    const size_t controls = static_cast<size_t>(in.divisions[0] + 1) * (in.divisions[1] + 1) *
                            static_cast<size_t>(in.divisions[2] + 1);
    if (in.divisions[0] < 1 || in.divisions[1] < 1 || in.divisions[2] < 1 ||
        in.controlsWorld.size() != controls) {
        throw InvalidInput(
            formatError("dkFrameLattice", "controls",
                        "has " + std::to_string(in.controlsWorld.size()) + " control transforms",
                        std::to_string(controls) + ", one per lattice point ((l+1)(m+1)(n+1) for "
                                                   "divisions of at least 1)"));
    }
    const MayaMatrix toGeometry = inverse(in.geometryWorld, "dkFrameLattice: the deformed shape");
    const MayaMatrix base = multiply(in.baseLatticeWorld, toGeometry);
    std::vector<double> axes;
    for (int a = 0; a < 3; ++a) {
        glm::dvec3 axis(0.0);
        axis[a] = 1.0;
        append(axes, transformVector(base, axis));
    }
    std::vector<double> points, frames;
    points.reserve(controls * 3);
    frames.reserve(controls * 9);
    for (const MayaMatrix& control : in.controlsWorld) {
        const MayaMatrix local = multiply(control, toGeometry);
        append(points, transformPoint(local, glm::dvec3(0.0)));
        for (int a = 0; a < 3; ++a) {
            glm::dvec3 axis(0.0);
            axis[a] = 1.0;
            append(frames, transformVector(local, axis));
        }
    }
    return {{"basis", {static_cast<double>(in.basis)}},
            {"divisions",
             {static_cast<double>(in.divisions[0]), static_cast<double>(in.divisions[1]),
              static_cast<double>(in.divisions[2])}},
            {"origin", flat(transformPoint(base, {-0.5, -0.5, -0.5}))},
            {"axes", axes},
            {"points", points},
            {"frames", frames}};
}

Parameters wireParameters(const WireInputs& in) {
    if (in.restWorld.size() != in.curveWorld.size()) {
        throw InvalidInput(formatError("dkWire", "curves",
                                       "have " + std::to_string(in.curveWorld.size()) +
                                           " points, their rest " + std::to_string(in.restWorld.size()),
                                       "as many points as the rest curves"));
    }
    const MayaMatrix toGeometry = inverse(in.geometryWorld, "dkWire: the deformed shape");
    std::vector<double> sizes(in.curveSizes.begin(), in.curveSizes.end());
    if (sizes.empty()) sizes = {0.0};
    return {{"smooth", {in.smooth ? 1.0 : 0.0}},
            {"restCurve", flatPoints(in.restWorld, toGeometry)},
            {"curveSizes", sizes},
            {"dropoff", in.dropoff},
            {"scale", in.scale},
            {"curve", flatPoints(in.curveWorld, toGeometry)}};
}

Parameters meshWarpParameters(const MeshWarpInputs& in) {
    if (in.restCageWorld.size() != in.cageWorld.size()) {
        throw InvalidInput(formatError("dkMeshWarp", "cage",
                                       "has " + std::to_string(in.cageWorld.size()) + " points, its rest " +
                                           std::to_string(in.restCageWorld.size()),
                                       "as many points as the rest cage"));
    }
    const MayaMatrix toGeometry = inverse(in.geometryWorld, "dkMeshWarp: the deformed shape");
    return {{"restCage", flatPoints(in.restCageWorld, toGeometry)},
            {"cageFaceCounts", std::vector<double>(in.faceCounts.begin(), in.faceCounts.end())},
            {"cageFaceIndices", std::vector<double>(in.faceIndices.begin(), in.faceIndices.end())},
            {"cage", flatPoints(in.cageWorld, toGeometry)}};
}

NodeCore::NodeCore(const std::string& type, const std::string& label) {
    stack_.add(host::makeDeformer(type, label));
}

bool NodeCore::setRest(const geom::Mesh& rest) {
    if (stack_.hasRest()) {
        const geom::Mesh& current = stack_.rest();
        const auto same = [](auto a, auto b) { return std::ranges::equal(a, b); };
        if (same(current.faceCounts(), rest.faceCounts()) &&
            same(current.faceIndices(), rest.faceIndices()) && same(current.points(), rest.points())) {
            return false;
        }
    }
    stack_.setRest(rest);
    return true;
}

void NodeCore::set(const Parameters& parameters) {
    for (const auto& [name, value] : parameters)
        stack_.set(0, name, value);
}

void NodeCore::setWeights(std::span<const float> weights) {
    if (std::ranges::equal(weights, weights_)) return;
    weights_.assign(weights.begin(), weights.end());
    stack_.setWeights(0, weights_);
}

void NodeCore::evaluate(std::span<glm::vec3> points, double envelope) {
    stack_.setEnvelope(0, envelope);
    stack_.evaluate(points);
}

RedirectCore::RedirectCore(const geom::Mesh& rest, int tile, const io::Image& rigidity, const io::Image& mask,
                           const uvwarp::TileWarpOptions& options, const std::string& source)
    : warp_(rest, tile, rigidity, mask, options, {}, source) {}

io::Image RedirectCore::solve(int frame, std::span<const glm::vec3> deformedPoints) {
    warm_ = last_ && frame == *last_ + 1;
    if (!warm_) warp_.reset();
    (void)warp_.solve(deformedPoints);
    last_ = frame;
    return warp_.redirect();
}

}  // namespace deformkit::maya
