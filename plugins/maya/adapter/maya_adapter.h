#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include <glm/vec3.hpp>

#include "deformkit/geom/mesh.h"
#include "deformkit/host/stack.h"
#include "deformkit/io/image.h"
#include "deformkit/uvwarp/tile_warp.h"

// The Maya plugin's translation layer, free of Maya headers so it is built and tested everywhere: Maya's
// conventions (row-vector matrices, ramp attributes, world-space controls) turned into host-layer
// parameters, and the per-node state every DeformKit deformer node keeps. The nodes in plugins/maya/src only
// read attributes into these structures and write the points back.
namespace deformkit::maya {

// A Maya matrix as MMatrix::get() fills it: row-major, row vectors (p' = p M): rows 0..2 are the images
// of the X, Y, Z axes, row 3 the translation.
struct MayaMatrix {
    std::array<std::array<double, 4>, 4> m{{{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}, {0, 0, 0, 1}}};
};

[[nodiscard]] MayaMatrix multiply(const MayaMatrix& a, const MayaMatrix& b);  // a then b: p a b
// Throws InvalidInput naming `what` for a singular matrix.
[[nodiscard]] MayaMatrix inverse(const MayaMatrix& a, const std::string& what);
[[nodiscard]] glm::dvec3 transformPoint(const MayaMatrix& a, const glm::dvec3& p);
[[nodiscard]] glm::dvec3 transformVector(const MayaMatrix& a, const glm::dvec3& v);

// Host-layer parameters a node sets on its deformer, bind-time ones first (the order hosts set them in).
using Parameters = std::vector<std::pair<std::string, std::vector<double>>>;

// A key of a Maya ramp attribute (MRampAttribute): position and value in [0, 1], interpolation as Maya
// numbers it: 0 none (hold the value to the next key), 1 linear, 2 smooth, 3 spline (sampled as smooth).
struct RampKey {
    double position = 0.0;
    double value = 0.0;
    int interpolation = 1;
};

// The ramp sampled at x = i / (samples - 1), as the slide's falloffRamp takes it. Before the first key the
// first value, after the last the last one. Throws InvalidInput for no keys or samples < 2.
[[nodiscard]] std::vector<double> sampleRamp(std::span<const RampKey> keys, int samples);

// dkSlide: the handle vertex and its support, the falloff ramp, and the start and end locators (world
// positions) whose difference, in the deformed geometry's space, is the displacement.
struct SlideInputs {
    int vertex = 0;
    double radius = 1.0;
    bool geodesic = true;
    bool limitSurface = false;
    bool weightsAreFalloff = false;  // the paper's rule: the painted weights are the falloff
    bool foldLimit = false;          // scale the drag down so no triangle of the region flips
    std::vector<RampKey> falloff{{0.0, 1.0, 2}, {1.0, 0.0, 2}};
    int rampSamples = 33;
    glm::dvec3 startWorld{0.0};
    glm::dvec3 endWorld{0.0};
    MayaMatrix geometryWorld;  // the deformed shape's world matrix
};
[[nodiscard]] Parameters slideParameters(const SlideInputs& in);

// dkBarr: "taper", "twist" or "bend" about a handle transform (its world matrix: the frame's origin and
// axes, scaled), in the deformed geometry's space.
struct BarrInputs {
    std::string type = "twist";
    MayaMatrix handleWorld;
    MayaMatrix geometryWorld;
    double startValue = 0.0;  // scale (taper) or angle in radians (twist)
    double endValue = 0.0;
    double curvature = 0.5;  // bend: radians per handle unit
    double lowBound = -1.0;
    double highBound = 1.0;
};
[[nodiscard]] Parameters barrParameters(const BarrInputs& in);

// dkFrameLattice: FFD with frames. The rest lattice is the unit cube [-0.5, 0.5]^3 under the base
// lattice's world matrix (as Maya's ffd baseLattice); each control is a transform (a locator) whose world
// matrix gives the control's position (translation) and frame (axis images). Controls in the host's order:
// (i (m + 1) + j) (n + 1) + k, i along the lattice's X.
struct FrameLatticeInputs {
    std::array<int, 3> divisions{1, 1, 1};
    MayaMatrix baseLatticeWorld;
    std::vector<MayaMatrix> controlsWorld;
    MayaMatrix geometryWorld;
    int basis = 0;  // 0 Bernstein, 1 uniform cubic B-spline
};
[[nodiscard]] Parameters frameLatticeParameters(const FrameLatticeInputs& in);

// dkWire: the wires' rest and current curve points (world; the node samples each NURBS curve at its CVs or
// evenly), one after the other as curveSizes says, in the deformed geometry's space.
struct WireInputs {
    std::vector<glm::dvec3> restWorld;
    std::vector<glm::dvec3> curveWorld;
    std::vector<int> curveSizes;  // points per wire
    std::vector<double> dropoff{1.0};
    std::vector<double> scale{1.0};
    bool smooth = true;
    MayaMatrix geometryWorld;
};
[[nodiscard]] Parameters wireParameters(const WireInputs& in);

// dkMeshWarp: a cage mesh's rest and current points (world) and its faces, in the deformed geometry's space.
struct MeshWarpInputs {
    std::vector<glm::dvec3> restCageWorld;
    std::vector<glm::dvec3> cageWorld;
    std::vector<int> faceCounts;
    std::vector<int> faceIndices;
    MayaMatrix geometryWorld;
};
[[nodiscard]] Parameters meshWarpParameters(const MeshWarpInputs& in);

// What every DeformKit deformer node keeps between evaluations: a host DeformerStack of one entry (so the
// envelope, painted weights and bind rules are the host layer's) over the node's rest geometry.
// setRest rebinds only when the geometry differs from the current rest (vertex count, faces or points);
// parameters and weights rebind only as the host layer decides.
class NodeCore {
  public:
    // `type`: a host deformer type ("slide", "ffdframes", "taper", "twist", "bend", "wires", "meshwarp").
    explicit NodeCore(const std::string& type, const std::string& label);

    // Returns true when the rest changed (and the entry will rebind).
    bool setRest(const geom::Mesh& rest);
    [[nodiscard]] bool hasRest() const { return stack_.hasRest(); }
    void set(const Parameters& parameters);
    // Maya's painted weights (one per vertex; empty: all 1). Set on the stack only when they changed.
    void setWeights(std::span<const float> weights);
    // Deforms `points` in place (the node's input geometry) with the node's envelope.
    void evaluate(std::span<glm::vec3> points, double envelope);

    [[nodiscard]] const host::DeformerStack& stack() const { return stack_; }
    [[nodiscard]] int64_t bindCount() const { return stack_.bindCount(); }

  private:
    host::DeformerStack stack_;
    std::vector<float> weights_;
};

// What the dkUvRedirect node keeps: one UDIM tile's UV-warp solver over the rest mesh. Frames solved in
// order warm-start from the previous one; any other frame (a jump, scrubbing backwards, the first one)
// starts cold, so a frame's map depends only on the frames played before it in order, as in
// `deformkit eval` runs that start at that frame.
class RedirectCore {
  public:
    RedirectCore(const geom::Mesh& rest, int tile, const io::Image& rigidity, const io::Image& mask,
                 const uvwarp::TileWarpOptions& options, const std::string& source);
    // The redirect map (T x T x 2) for `frame` with the deformed points.
    [[nodiscard]] io::Image solve(int frame, std::span<const glm::vec3> deformedPoints);
    [[nodiscard]] bool warmStarted() const { return warm_; }

  private:
    uvwarp::TileWarp warp_;
    std::optional<int> last_;
    bool warm_ = false;
};

}  // namespace deformkit::maya
