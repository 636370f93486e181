#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <glm/vec3.hpp>

#include "deformkit/geom/mesh.h"
#include "deformkit/host/stack.h"
#include "deformkit/io/image.h"
#include "deformkit/uvwarp/options.h"

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
[[nodiscard]] MayaMatrix inverse(const MayaMatrix& a, std::string_view what);
[[nodiscard]] glm::dvec3 transformPoint(const MayaMatrix& a, const glm::dvec3& p);
[[nodiscard]] glm::dvec3 transformVector(const MayaMatrix& a, const glm::dvec3& v);

// Host-layer parameters a node sets on its deformer, bind-time ones first (the order hosts set them in).
using Parameters = std::vector<std::pair<std::string, std::vector<double>>>;

// Writes a node's parameters into `out` in order, reusing each entry's storage (its name and values): a node
// that keeps its Parameters between deform() calls builds them again without allocating. The destructor
// drops entries left from a longer previous list.
class ParameterWriter {
  public:
    explicit ParameterWriter(Parameters& out) : out_(out) {}
    ParameterWriter(const ParameterWriter&) = delete;
    ParameterWriter& operator=(const ParameterWriter&) = delete;
    ~ParameterWriter() { out_.resize(next_); }

    // The next entry, named `name`, its values cleared (capacity kept).
    std::vector<double>& next(std::string_view name);
    void scalar(std::string_view name, double value) { next(name).push_back(value); }
    void vector(std::string_view name, const glm::dvec3& v);

  private:
    Parameters& out_;
    size_t next_ = 0;
};

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
void sampleRamp(std::span<const RampKey> keys, int samples, std::vector<double>& out);  // into out, reused

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
void slideParameters(const SlideInputs& in, Parameters& out);  // into out, reusing its storage

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
void barrParameters(const BarrInputs& in, Parameters& out);  // into out, reusing its storage

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
void frameLatticeParameters(const FrameLatticeInputs& in, Parameters& out);  // into out, reusing its storage

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
void wireParameters(const WireInputs& in, Parameters& out);  // into out, reusing its storage

// dkMeshWarp: a cage mesh's rest and current points (world) and its faces, in the deformed geometry's space.
struct MeshWarpInputs {
    std::vector<glm::dvec3> restCageWorld;
    std::vector<glm::dvec3> cageWorld;
    std::vector<int> faceCounts;
    std::vector<int> faceIndices;
    MayaMatrix geometryWorld;
};
[[nodiscard]] Parameters meshWarpParameters(const MeshWarpInputs& in);
void meshWarpParameters(const MeshWarpInputs& in, Parameters& out);  // into out, reusing its storage

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
    // Pushes to the deformer only the parameters whose values differ from the last ones pushed (a locator
    // that did not move costs a comparison; the host layer validates a value only when it is set). Returns
    // how many were pushed.
    size_t set(const Parameters& parameters);
    // Maya's painted weights (one per vertex; empty: all 1). Set on the stack only when they changed.
    void setWeights(std::span<const float> weights);
    // Deforms `points` in place (the node's input geometry) with the node's envelope.
    void evaluate(std::span<glm::vec3> points, double envelope);

    // The node's buffers, kept between deform() calls: the node reads Maya's positions in bulk
    // (MItGeometry::allPositions) into points(n) and its painted weights into weights(n), calls
    // evaluateBuffers, and writes points(n) back (setAllPositions). A warm call allocates nothing.
    std::span<glm::vec3> points(size_t n);
    std::span<float> weights(size_t n);
    // Deforms points(n) in place; `painted` false ignores the weights buffer (all 1).
    void evaluateBuffers(double envelope, bool painted);

    // Whether a mesh of these polygons (Maya's MFnMesh::getVertices) is not the rest's: another topology
    // with as many vertices (faces deleted upstream) rebinds too. True without a rest.
    [[nodiscard]] bool restTopologyDiffers(std::span<const int32_t> counts,
                                           std::span<const int32_t> indices) const;
    // A deformer set of some of the mesh's vertices (Edit Membership, `deformer pCube1.vtx[0:19]`): the
    // deformer sees the whole mesh as bound, `all` its every position, with weight 0 off the set and
    // `memberWeights` (painted) on it; the members' new positions, in `members`' order, go to `out`.
    void evaluateMembers(std::span<const glm::vec3> all, std::span<const int32_t> members,
                         std::span<const float> memberWeights, double envelope, std::span<glm::vec3> out);

    [[nodiscard]] const host::DeformerStack& stack() const { return stack_; }
    [[nodiscard]] int64_t bindCount() const { return stack_.bindCount(); }
    [[nodiscard]] int64_t pushCount() const { return pushCount_; }  // parameters pushed since construction

  private:
    host::DeformerStack stack_;
    std::vector<float> weights_;  // the weights set on the stack
    Parameters pushed_;           // the values last pushed, per name, in the order first seen
    int64_t pushCount_ = 0;
    std::vector<glm::vec3> pointBuffer_;
    std::vector<float> weightBuffer_;
};

// One geometry a deformer node deforms (Maya's input[i] and outputGeometry[i]: a node on several meshes
// deforms each in its own deform() call): its core, with its own rest, weights and parameters pushed, and
// the rebind toggle it last saw.
class NodeGeometry {
  public:
    // The core, made for `type` (again when the type changes: a dkBarr's kind). `label` names the node.
    NodeCore& core(const std::string& type, const std::string& label);
    // Whether the input (its polygons) must become the rest: no rest yet, `rebind` toggled since the last
    // bind, or another topology (NodeCore::restTopologyDiffers). Call after core().
    [[nodiscard]] bool takesRest(bool rebind, std::span<const int32_t> counts,
                                 std::span<const int32_t> indices);

  private:
    std::unique_ptr<NodeCore> core_;
    bool rebindSeen_ = false;
};

// A node's geometries by Maya's multi index, each kept apart.
class NodeGeometries {
  public:
    [[nodiscard]] NodeGeometry& at(unsigned index) { return geometries_[index]; }
    [[nodiscard]] size_t size() const { return geometries_.size(); }

  private:
    std::map<unsigned, NodeGeometry> geometries_;
};

// dkUvRedirect's attributes: the maps as file patterns (<UDIM> for the tile; #### for the frame, 4 digits,
// in an animated map: one file per frame), the tile, and one attribute per UV-warp option
// (redirectOptionAttributes).
struct RedirectInputs {
    int tile = 1001;
    std::string rigidity;     // required
    std::string mask;         // empty: derived from the UVs
    std::string orientation;  // empty: none (or the density heuristic)
    // "shot" or "live": the library's preset replaces every option but `resolution`; empty: the options.
    std::string preset;
    uvwarp::TileWarpOptions options;
};

// The attribute of one UV-warp option (uvwarp/options.h): named as declared (camelCase, the short name the
// same), an int, double or boolean attribute with the library's default, or for a list a string of whole
// numbers separated by spaces or commas ("4 8 16"; empty: the library's choice).
struct RedirectOptionAttribute {
    enum class Kind { Int, Double, Boolean, Text };
    const uvwarp::OptionSpec* spec = nullptr;
    Kind kind = Kind::Int;
    double number = 0.0;  // the default of Int, Double and Boolean attributes
    std::string text;     // the default of a Text attribute
    // The declared range of an Int or Double attribute, for its slider and Maya's own clamping (a value
    // below or above it never reaches compute); a range open at its low end gets no minimum there (the
    // option's check names such a value at compute). Unset for Boolean and Text attributes.
    std::optional<double> minimum, maximum;
};
[[nodiscard]] std::vector<RedirectOptionAttribute> redirectOptionAttributes();

// Sets the option of `attribute` in `in` from the attribute's value: `number` for Int, Double and Boolean
// attributes, `text` for Text ones. The library checks it; InvalidInput names dkUvRedirect and the attribute.
void setRedirectOption(RedirectInputs& in, const RedirectOptionAttribute& attribute, double number,
                       std::string_view text);

// A file pattern at a tile and frame: <UDIM> replaced by the tile, a frame token in the file name (####,
// %04d; io::ObjSequence) by the frame; an empty pattern stays empty.
[[nodiscard]] std::string fileAt(const std::string& pattern, int tile, int frame);

// The map files of `frame` (empty patterns stay empty).
struct RedirectFiles {
    std::string rigidity, mask, orientation;
    bool operator==(const RedirectFiles&) const = default;
};
[[nodiscard]] RedirectFiles redirectFilesAt(const RedirectInputs& in, int frame);

// What the dkUvRedirect node keeps: one UDIM tile's UV-warp solver over the rest mesh. Frames solved in
// order warm-start from the previous one; any other frame (a jump, scrubbing backwards, the first one)
// starts cold, so a frame's map depends only on the frames played before it in order, as in
// `deformkit eval` runs that start at that frame.
class RedirectCore {
  public:
    RedirectCore(const geom::Mesh& rest, int tile, const io::Image& rigidity, const io::Image& mask,
                 const uvwarp::TileWarpOptions& options, const std::string& source,
                 const io::Image& orientation = {});
    // The redirect map (T x T x 2) for `frame` with the deformed points.
    [[nodiscard]] io::Image solve(int frame, std::span<const glm::vec3> deformedPoints);
    [[nodiscard]] bool warmStarted() const { return warm_; }

    // New maps for the frames that follow (an animated map's next file); the solver's hierarchy is rebuilt
    // only where a map changed.
    void setMaps(const io::Image& rigidity, const io::Image& mask, const io::Image& orientation);

  private:
    uvwarp::TileWarp warp_;
    std::optional<int> last_;
    bool warm_ = false;
};

// The dkUvRedirect node's state over its evaluations: the solver is made again only when the tile, a map
// pattern or an option changes (needsBuild); per frame, only the map files that changed are read (an
// animated map reads its frame's file; a still one is read once).
class RedirectNode {
  public:
    // True before the first build and after a change of tile, map pattern or option; with `rest`, also when
    // it is not the rest mesh built over (a new restMesh, or its UVs or points edited).
    [[nodiscard]] bool needsBuild(const RedirectInputs& in, const geom::Mesh* rest = nullptr) const;
    // A new solver over `rest` with the maps of `frame`. `source` names the node in errors and headers.
    void build(const geom::Mesh& rest, const RedirectInputs& in, int frame, const std::string& source);
    // The redirect map of `frame` (build first when needsBuild): warm-started when `frame` follows the last
    // one solved, cold otherwise (RedirectCore).
    [[nodiscard]] io::Image solve(const RedirectInputs& in, int frame,
                                  std::span<const glm::vec3> deformedPoints);
    [[nodiscard]] int64_t builds() const { return builds_; }
    [[nodiscard]] int64_t mapReads() const { return mapReads_; }  // map files read so far
    [[nodiscard]] bool warmStarted() const { return core_ && core_->warmStarted(); }
    // What the user should hear once (a map of several channels, read from channel 0), since the last call.
    [[nodiscard]] std::vector<std::string> takeNotes();

  private:
    struct Maps {
        io::Image rigidity, mask, orientation;
    };
    Maps read(const RedirectFiles& files);

    std::unique_ptr<RedirectCore> core_;
    std::optional<geom::Mesh> rest_;  // the rest mesh built over
    RedirectInputs built_;
    RedirectFiles loaded_;
    int64_t builds_ = 0;
    int64_t mapReads_ = 0;
    std::vector<std::string> notes_;
    std::set<std::string> noted_;  // the files a note was made for
};

}  // namespace deformkit::maya
