#include "maya_adapter.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <string_view>
#include <utility>

#include <glm/geometric.hpp>
#include <glm/mat4x4.hpp>
#include <glm/matrix.hpp>

#include "deformkit/error.h"
#include "deformkit/host/deformers.h"
#include "deformkit/io/obj_sequence.h"
#include "deformkit/io/udim.h"
#include "deformkit/uvwarp/options.h"

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

void append(std::vector<double>& out, const glm::dvec3& v) {
    out.insert(out.end(), {v.x, v.y, v.z});
}

void appendPoints(std::vector<double>& out, std::span<const glm::dvec3> points,
                  const MayaMatrix& toGeometry) {
    out.reserve(out.size() + points.size() * 3);
    for (const glm::dvec3& p : points)
        append(out, transformPoint(toGeometry, p));
}

double smooth(double t) {
    return t * t * (3.0 - 2.0 * t);
}

}  // namespace

MayaMatrix multiply(const MayaMatrix& a, const MayaMatrix& b) {
    // p a b = p (a b): with row vectors the product is a times b; in glm's column form (a b)^T = b^T a^T.
    return fromGlm(toGlm(b) * toGlm(a));
}

MayaMatrix inverse(const MayaMatrix& a, std::string_view what) {
    const glm::dmat4 g = toGlm(a);
    const double det = glm::determinant(g);
    if (!std::isfinite(det) || std::abs(det) < 1e-300) {
        throw InvalidInput(formatError(std::string(what), "world matrix",
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

std::vector<double>& ParameterWriter::next(std::string_view name) {
    if (next_ == out_.size()) out_.emplace_back();
    auto& [entryName, values] = out_[next_++];
    if (entryName != name) entryName.assign(name);
    values.clear();
    return values;
}

void ParameterWriter::vector(std::string_view name, const glm::dvec3& v) {
    append(next(name), v);
}

void sampleRamp(std::span<const RampKey> keys, int samples, std::vector<double>& out) {
    if (keys.empty()) {
        throw InvalidInput(formatError("falloff ramp", "", "has no keys", "at least one key"));
    }
    if (samples < 2) {
        throw InvalidInput(formatError("falloff ramp", "samples", "is " + std::to_string(samples), ">= 2"));
    }
    // Keys in position order without sorting a copy (no allocation): the first key is the lowest position
    // (the earliest of equal ones), the last the highest (the latest of equal ones), as a stable sort has
    // them.
    const RampKey* first = &keys[0];
    const RampKey* last = &keys[0];
    for (const RampKey& k : keys) {
        if (k.position < first->position) first = &k;
        if (k.position >= last->position) last = &k;
    }
    out.resize(static_cast<size_t>(samples));
    for (int i = 0; i < samples; ++i) {
        const double x = static_cast<double>(i) / (samples - 1);
        if (x <= first->position) {
            out[i] = first->value;
            continue;
        }
        // a: the key at or before x (the latest of equal positions); b: the first key after x.
        const RampKey* a = nullptr;
        const RampKey* b = nullptr;
        for (const RampKey& k : keys) {
            if (k.position <= x) {
                if (a == nullptr || k.position >= a->position) a = &k;
            } else if (b == nullptr || k.position < b->position) {
                b = &k;
            }
        }
        if (b == nullptr) {
            out[i] = last->value;
            continue;
        }
        const double t = b->position > a->position ? (x - a->position) / (b->position - a->position) : 1.0;
        const double sm = a->interpolation == 0 ? 0.0 : a->interpolation == 1 ? t : smooth(t);
        out[i] = a->value + sm * (b->value - a->value);
    }
}

std::vector<double> sampleRamp(std::span<const RampKey> keys, int samples) {
    std::vector<double> out;
    sampleRamp(keys, samples, out);
    return out;
}

void slideParameters(const SlideInputs& in, Parameters& out) {
    const MayaMatrix toGeometry = inverse(in.geometryWorld, "dkSlide: the deformed shape");
    const glm::dvec3 d = transformVector(toGeometry, in.endWorld - in.startWorld);
    ParameterWriter w(out);
    w.scalar("vertex", static_cast<double>(in.vertex));
    w.scalar("radius", in.radius);
    w.scalar("geodesic", in.geodesic ? 1.0 : 0.0);
    w.scalar("limitSurface", in.limitSurface ? 1.0 : 0.0);
    w.scalar("paintedWeights", in.weightsAreFalloff ? 1.0 : 0.0);
    w.scalar("foldLimit", in.foldLimit ? 1.0 : 0.0);
    w.scalar("falloff", 2.0);
    sampleRamp(in.falloff, in.rampSamples, w.next("falloffRamp"));
    w.vector("displacement", d);
}

void barrParameters(const BarrInputs& in, Parameters& out) {
    if (in.type != "taper" && in.type != "twist" && in.type != "bend") {
        throw InvalidInput(formatError("dkBarr", "type", "is '" + in.type + "'", "taper, twist or bend"));
    }
    const MayaMatrix local =
        multiply(in.handleWorld, inverse(in.geometryWorld, "dkBarr: the deformed shape"));
    ParameterWriter w(out);
    w.vector("handleOrigin", transformPoint(local, glm::dvec3(0.0)));
    if (in.type == "bend") w.vector("handleX", transformVector(local, {1.0, 0.0, 0.0}));
    w.vector("handleY", transformVector(local, {0.0, 1.0, 0.0}));
    if (in.type == "taper") {
        w.scalar("startScale", in.startValue);
        w.scalar("endScale", in.endValue);
    } else if (in.type == "twist") {
        w.scalar("startAngle", in.startValue);
        w.scalar("endAngle", in.endValue);
    } else {
        w.scalar("curvature", in.curvature);
    }
    w.scalar("lowBound", in.lowBound);
    w.scalar("highBound", in.highBound);
}

void frameLatticeParameters(const FrameLatticeInputs& in, Parameters& out) {
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
    ParameterWriter w(out);
    w.scalar("basis", static_cast<double>(in.basis));
    std::vector<double>& divisions = w.next("divisions");
    for (int a = 0; a < 3; ++a)
        divisions.push_back(static_cast<double>(in.divisions[a]));
    w.vector("origin", transformPoint(base, {-0.5, -0.5, -0.5}));
    std::vector<double>& axes = w.next("axes");
    for (int a = 0; a < 3; ++a) {
        glm::dvec3 axis(0.0);
        axis[a] = 1.0;
        append(axes, transformVector(base, axis));
    }
    std::vector<double>& points = w.next("points");
    for (const MayaMatrix& control : in.controlsWorld)
        append(points, transformPoint(multiply(control, toGeometry), glm::dvec3(0.0)));
    std::vector<double>& frames = w.next("frames");
    for (const MayaMatrix& control : in.controlsWorld) {
        const MayaMatrix local = multiply(control, toGeometry);
        for (int a = 0; a < 3; ++a) {
            glm::dvec3 axis(0.0);
            axis[a] = 1.0;
            append(frames, transformVector(local, axis));
        }
    }
}

void wireParameters(const WireInputs& in, Parameters& out) {
    if (in.restWorld.size() != in.curveWorld.size()) {
        throw InvalidInput(formatError("dkWire", "curves",
                                       "have " + std::to_string(in.curveWorld.size()) +
                                           " points, their rest " + std::to_string(in.restWorld.size()),
                                       "as many points as the rest curves"));
    }
    const MayaMatrix toGeometry = inverse(in.geometryWorld, "dkWire: the deformed shape");
    ParameterWriter w(out);
    w.scalar("smooth", in.smooth ? 1.0 : 0.0);
    appendPoints(w.next("restCurve"), in.restWorld, toGeometry);
    std::vector<double>& sizes = w.next("curveSizes");
    sizes.assign(in.curveSizes.begin(), in.curveSizes.end());
    if (sizes.empty()) sizes.push_back(0.0);
    w.next("dropoff").assign(in.dropoff.begin(), in.dropoff.end());
    w.next("scale").assign(in.scale.begin(), in.scale.end());
    appendPoints(w.next("curve"), in.curveWorld, toGeometry);
}

void meshWarpParameters(const MeshWarpInputs& in, Parameters& out) {
    if (in.restCageWorld.size() != in.cageWorld.size()) {
        throw InvalidInput(formatError("dkMeshWarp", "cage",
                                       "has " + std::to_string(in.cageWorld.size()) + " points, its rest " +
                                           std::to_string(in.restCageWorld.size()),
                                       "as many points as the rest cage"));
    }
    const MayaMatrix toGeometry = inverse(in.geometryWorld, "dkMeshWarp: the deformed shape");
    ParameterWriter w(out);
    appendPoints(w.next("restCage"), in.restCageWorld, toGeometry);
    w.next("cageFaceCounts").assign(in.faceCounts.begin(), in.faceCounts.end());
    w.next("cageFaceIndices").assign(in.faceIndices.begin(), in.faceIndices.end());
    appendPoints(w.next("cage"), in.cageWorld, toGeometry);
}

// The value-returning forms, for callers that do not keep their parameters.
#define DEFORMKIT_RETURNING(function, Inputs) \
    Parameters function(const Inputs& in) {   \
        Parameters out;                       \
        function(in, out);                    \
        return out;                           \
    }
DEFORMKIT_RETURNING(slideParameters, SlideInputs)
DEFORMKIT_RETURNING(barrParameters, BarrInputs)
DEFORMKIT_RETURNING(frameLatticeParameters, FrameLatticeInputs)
DEFORMKIT_RETURNING(wireParameters, WireInputs)
DEFORMKIT_RETURNING(meshWarpParameters, MeshWarpInputs)
#undef DEFORMKIT_RETURNING

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

size_t NodeCore::set(const Parameters& parameters) {
    size_t pushed = 0;
    for (const auto& [name, value] : parameters) {
        auto last = std::ranges::find_if(pushed_, [&](const auto& entry) { return entry.first == name; });
        if (last != pushed_.end() && last->second == value) continue;
        stack_.set(0, name, value);  // throws for a bad value: nothing is recorded as pushed
        if (last == pushed_.end()) {
            pushed_.emplace_back(name, value);
        } else {
            last->second.assign(value.begin(), value.end());
        }
        ++pushed;
    }
    pushCount_ += static_cast<int64_t>(pushed);
    return pushed;
}

std::span<glm::vec3> NodeCore::points(size_t n) {
    pointBuffer_.resize(n);
    return pointBuffer_;
}

std::span<float> NodeCore::weights(size_t n) {
    weightBuffer_.resize(n);
    return weightBuffer_;
}

void NodeCore::evaluateBuffers(double envelope, bool painted) {
    setWeights(painted ? std::span<const float>(weightBuffer_) : std::span<const float>());
    evaluate(pointBuffer_, envelope);
}

bool NodeCore::restTopologyDiffers(std::span<const int32_t> counts, std::span<const int32_t> indices) const {
    if (!stack_.hasRest()) return true;
    const geom::Mesh& rest = stack_.rest();
    return !std::ranges::equal(rest.faceCounts(), counts) || !std::ranges::equal(rest.faceIndices(), indices);
}

void NodeCore::evaluateMembers(std::span<const glm::vec3> all, std::span<const int32_t> members,
                               std::span<const float> memberWeights, double envelope,
                               std::span<glm::vec3> out) {
    if (memberWeights.size() != members.size() || out.size() != members.size()) {
        throw InvalidInput(formatError(stack_.entryName(0), "deformer set",
                                       "has " + std::to_string(members.size()) + " members, " +
                                           std::to_string(memberWeights.size()) + " weights and " +
                                           std::to_string(out.size()) + " outputs",
                                       "as many of each"));
    }
    pointBuffer_.assign(all.begin(), all.end());
    weightBuffer_.assign(all.size(), 0.0f);
    for (size_t k = 0; k < members.size(); ++k) {
        const int32_t v = members[k];
        if (v < 0 || static_cast<size_t>(v) >= all.size()) {
            throw InvalidInput(formatError(stack_.entryName(0), "deformer set member " + std::to_string(k),
                                           "is vertex " + std::to_string(v),
                                           "a vertex of the mesh's " + std::to_string(all.size())));
        }
        weightBuffer_[v] = memberWeights[k];
    }
    evaluateBuffers(envelope, true);
    for (size_t k = 0; k < members.size(); ++k)
        out[k] = pointBuffer_[members[k]];
}

NodeCore& NodeGeometry::core(const std::string& type, const std::string& label) {
    if (!core_ || core_->stack().deformer(0).type() != type) {
        core_ = std::make_unique<NodeCore>(type, label);
        rebindSeen_ = false;
    }
    return *core_;
}

bool NodeGeometry::takesRest(bool rebind, std::span<const int32_t> counts, std::span<const int32_t> indices) {
    if (core_->hasRest() && rebind == rebindSeen_ && !core_->restTopologyDiffers(counts, indices))
        return false;
    rebindSeen_ = rebind;
    return true;
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
                           const uvwarp::TileWarpOptions& options, const std::string& source,
                           const io::Image& orientation)
    : warp_(rest, tile, rigidity, mask, options, orientation, source) {}

void RedirectCore::setMaps(const io::Image& rigidity, const io::Image& mask, const io::Image& orientation) {
    warp_.setMaps(rigidity, mask, orientation);
}

namespace {

// Every option equal (the derived mask's label only names the mesh in errors).
bool sameOptions(const uvwarp::TileWarpOptions& a, const uvwarp::TileWarpOptions& b) {
    const auto specs = uvwarp::optionSpecs();
    return std::all_of(specs.begin(), specs.end(),
                       [&](const uvwarp::OptionSpec& spec) { return spec.get(a) == spec.get(b); });
}

}  // namespace

namespace {

// 'text', for messages.
std::string quoted(std::string_view text) {
    std::string out(text.size() + 2, '\'');
    std::copy(text.begin(), text.end(), out.begin() + 1);
    return out;
}

}  // namespace

std::vector<RedirectOptionAttribute> redirectOptionAttributes() {
    std::vector<RedirectOptionAttribute> out;
    const uvwarp::TileWarpOptions defaults;
    for (const uvwarp::OptionSpec& spec : uvwarp::optionSpecs()) {
        RedirectOptionAttribute a;
        a.spec = &spec;
        const std::vector<double> value = spec.get(defaults);
        switch (spec.type) {
            case uvwarp::OptionType::Integer:
                a.kind = RedirectOptionAttribute::Kind::Int;
                break;
            case uvwarp::OptionType::Number:
                a.kind = RedirectOptionAttribute::Kind::Double;
                break;
            case uvwarp::OptionType::Flag:
                a.kind = RedirectOptionAttribute::Kind::Boolean;
                break;
            case uvwarp::OptionType::IntegerList:
                a.kind = RedirectOptionAttribute::Kind::Text;
                a.text = uvwarp::valueText(spec, value);
                break;
        }
        if (a.kind != RedirectOptionAttribute::Kind::Text) a.number = value.front();
        if (a.kind == RedirectOptionAttribute::Kind::Int || a.kind == RedirectOptionAttribute::Kind::Double) {
            if (!spec.lowOpen) a.minimum = spec.low;
            a.maximum = spec.high;
        }
        out.push_back(std::move(a));
    }
    return out;
}

void setRedirectOption(RedirectInputs& in, const RedirectOptionAttribute& attribute, double number,
                       std::string_view text) {
    using Kind = uvwarp::OptionValue::Kind;
    uvwarp::OptionValue value;
    value.numbers = {number};
    if (attribute.kind == RedirectOptionAttribute::Kind::Boolean) {
        value.kind = Kind::Boolean;
        value.numbers = {number != 0 ? 1.0 : 0.0};
    } else if (attribute.kind == RedirectOptionAttribute::Kind::Text) {
        // Whole numbers separated by spaces, commas or tabs; the library checks their range.
        value.kind = Kind::List;
        value.numbers.clear();
        size_t i = 0;
        while (i < text.size() && value.kind == Kind::List) {
            if (text[i] == ' ' || text[i] == ',' || text[i] == '\t') {
                ++i;
                continue;
            }
            size_t end = i;
            while (end < text.size() && text[end] != ' ' && text[end] != ',' && text[end] != '\t')
                ++end;
            double x = 0.0;
            const auto [ptr, ec] = std::from_chars(text.data() + i, text.data() + end, x);
            if (ec != std::errc() || ptr != text.data() + end) {
                value.kind = Kind::Other;
                value.shown = quoted(text);
            }
            value.numbers.push_back(x);
            i = end;
        }
        // No number (the default, ""): the library's choice, as an empty list anywhere.
    }
    uvwarp::setOption(in.options, *attribute.spec, value, "dkUvRedirect", attribute.spec->name);
}

std::string fileAt(const std::string& pattern, int tile, int frame) {
    if (pattern.empty()) return {};
    // The library's rule for per-tile maps (and scenes' animated maps): a frame token is one in the file
    // name, as io::ObjSequence reads them (####, %04d).
    const std::string path = io::expandUdim(pattern, tile);
    return io::ObjSequence::isPattern(path) ? io::ObjSequence(path).framePath(frame).string() : path;
}

RedirectFiles redirectFilesAt(const RedirectInputs& in, int frame) {
    return {fileAt(in.rigidity, in.tile, frame), fileAt(in.mask, in.tile, frame),
            fileAt(in.orientation, in.tile, frame)};
}

bool RedirectNode::needsBuild(const RedirectInputs& in, const geom::Mesh* rest) const {
    if (!core_ || in.tile != built_.tile || in.rigidity != built_.rigidity || in.mask != built_.mask ||
        in.orientation != built_.orientation || in.preset != built_.preset ||
        !sameOptions(in.options, built_.options)) {
        return true;
    }
    if (rest == nullptr || !rest_) return false;
    const auto same = [](auto a, auto b) { return std::ranges::equal(a, b); };
    return !same(rest->points(), rest_->points()) || !same(rest->faceCounts(), rest_->faceCounts()) ||
           !same(rest->faceIndices(), rest_->faceIndices()) || !same(rest->uvs(), rest_->uvs()) ||
           !same(rest->uvIndices(), rest_->uvIndices());
}

RedirectNode::Maps RedirectNode::read(const RedirectFiles& files) {
    if (files.rigidity.empty()) {
        throw InvalidInput(
            formatError("dkUvRedirect", "rigidity", "is empty", "a rigidity map file pattern"));
    }
    // A map of several channels (an RGB or RGBA export): channel 0 is used, said once per file.
    const auto readMap = [&](const std::string& file, const char* role) {
        io::Image image = io::readImage(file, {0, role});
        ++mapReads_;
        if (image.channels > 1 && noted_.insert(file).second) {
            notes_.push_back(std::string(role) + " '" + file + "' has " + std::to_string(image.channels) +
                             " channels: channel 0 (red) is read");
        }
        return image;
    };
    Maps maps;
    maps.rigidity = readMap(files.rigidity, "rigidity map");
    if (!files.mask.empty()) maps.mask = readMap(files.mask, "warp mask");
    if (!files.orientation.empty()) maps.orientation = readMap(files.orientation, "orientation map");
    return maps;
}

std::vector<std::string> RedirectNode::takeNotes() {
    return std::exchange(notes_, {});
}

void RedirectNode::build(const geom::Mesh& rest, const RedirectInputs& in, int frame,
                         const std::string& source) {
    const RedirectFiles files = redirectFilesAt(in, frame);
    const Maps maps = read(files);
    // A preset replaces every option but the grid resolution, which the live schedule is chosen by.
    static const std::vector<std::string> kOwn = {"resolution"};
    const uvwarp::TileWarpOptions options =
        in.preset.empty() ? in.options
                          : uvwarp::withPreset(uvwarp::presetNamed(in.preset, "dkUvRedirect", "preset"),
                                               in.options.cells != 0 ? in.options.cells : maps.rigidity.width,
                                               in.options, kOwn);
    core_ = std::make_unique<RedirectCore>(rest, in.tile, maps.rigidity, maps.mask, options, source,
                                           maps.orientation);
    rest_ = rest;
    built_ = in;
    loaded_ = files;
    ++builds_;
}

io::Image RedirectNode::solve(const RedirectInputs& in, int frame,
                              std::span<const glm::vec3> deformedPoints) {
    if (needsBuild(in)) {
        throw InvalidInput(formatError("dkUvRedirect", "solver", "is not built for these inputs",
                                       "build() after a change of tile, map pattern or option"));
    }
    const RedirectFiles files = redirectFilesAt(in, frame);
    if (!(files == loaded_)) {  // an animated map: this frame's files
        const Maps maps = read(files);
        core_->setMaps(maps.rigidity, maps.mask, maps.orientation);
        loaded_ = files;
    }
    return core_->solve(frame, deformedPoints);
}

io::Image RedirectCore::solve(int frame, std::span<const glm::vec3> deformedPoints) {
    warm_ = last_ && frame == *last_ + 1;
    if (!warm_) warp_.reset();
    (void)warp_.solve(deformedPoints);
    last_ = frame;
    return warp_.redirect();
}

}  // namespace deformkit::maya
