#pragma once

#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "deformkit/geom/mesh.h"
#include "deformkit/io/obj.h"
#include "deformkit/io/sampling.h"
#include "deformkit/scene/anim_curve.h"
#include "deformkit/uvwarp/shot_job.h"
#include "deformkit/uvwarp/tile_warp.h"

namespace deformkit::scene {

// The scene format version parseScene reads.
inline constexpr int kSceneVersion = 1;

// A parameter's value over time: constant, or animated with one keyframe curve per component (a vector
// parameter's keys hold arrays; component c of every key makes curve c).
struct SceneValue {
    std::vector<double> constant;   // the value when not animated
    std::vector<AnimCurve> curves;  // one per component when animated, else empty

    [[nodiscard]] bool animated() const { return !curves.empty(); }
    // The value at `frame` (the constant when not animated); one entry per component.
    [[nodiscard]] std::vector<double> at(double frame) const;
};

// One parameter of a stack entry as the scene sets it.
struct SceneParameter {
    std::string name;
    SceneValue value;
    std::string path;  // JSON path for messages: "objects[0].stack[1].params.endAngle"
};

// One entry of an object's deformer stack.
struct SceneDeformer {
    std::string type;     // a makeDeformer type (deformerTypes())
    std::string label;    // unique in the stack; default: the type followed by the entry number from 1
    SceneValue envelope;  // one component; constant 1 when the scene gives none
    // #V painted weights of the object's rest mesh (from a JSON file, sampled from maps through its UVs
    // (host/weight_maps.h), or per-vertex values of a Ptex file), or empty for all 1; and the file they came
    // from (the JSON file, weight-map pattern or Ptex file), empty when none.
    std::vector<float> weights;
    std::filesystem::path weightsFile;
    // The parameters the scene gives, in the deformer's parameters() order (bind-time inputs first), which
    // is the order hosts set them in.
    std::vector<SceneParameter> params;
    std::string path;  // "objects[0].stack[1]"
};

// The UV-warp stage of an object: a stack's last entry of type "uvwarp". It works in texture space on the
// stack's result: per UDIM tile and frame, the content-aware UV warp (uvwarp/tile_warp.h) of the rest mesh
// deformed by the stack, written as redirect maps (and bakes of a texture through them). It has no envelope
// or weights; its options are constant over the shot.
struct SceneUvWarp {
    std::string label;                                                // "uvwarp<entry number>" by default
    std::filesystem::path rigidity;                                   // UDIM pattern, resolved like meshes
    std::optional<std::filesystem::path> mask, orientation, texture;  // UDIM patterns
    std::vector<int> tiles;  // ascending; every tile of the rest mesh's UVs when the scene gives none
    // options.cells: the grid resolution (0: the rigidity map's size); every frame from the identity unless
    // the scene's params say "warmStart": true (uvwarp::shotOptions).
    uvwarp::TileWarpOptions options = uvwarp::shotOptions();
    // "preset": the library's preset ("shot", "live") instead of `options`, but for the options the scene
    // sets itself (presetOwn: its params and resolution), which keep their values.
    std::optional<uvwarp::Preset> preset;
    std::vector<std::string> presetOwn;
    io::SampleFilter filter = io::SampleFilter::Bilinear;  // of the bake
    std::string path;                                      // "objects[0].stack[2]"
};

struct SceneObject {
    std::string name;                // unique; names the output files, so letters, digits, '_', '-', '.' only
    std::filesystem::path meshFile;  // the rest OBJ, resolved against the scene file's folder
    geom::Mesh rest;
    // An animated input: each frame's positions enter the stack in place of the rest positions (a deformer
    // stack after skinning). Either the scene's "mesh" is a frame pattern such as anim.####.obj (the rest
    // mesh is then its frame restFrame), or "deformed" names an OBJ sequence or a point cache (.pc2, .mdd)
    // over the rest mesh "mesh" (io::AnimatedPositions). Empty for a static mesh.
    std::filesystem::path sequence;
    int restFrame = 0;
    std::optional<double> cacheStart;  // "cacheStart": the frame of a point cache's first sample
    std::string sequenceElement;       // the JSON path that named the input: "objects[0].mesh" or ".deformed"
    std::vector<io::FaceGroup> groups;  // of the rest OBJ, written back with every frame
    std::vector<SceneDeformer> stack;   // the geometric deformers, in order
    std::optional<SceneUvWarp> uvwarp;  // the texture-space stage after them, when the scene has one
    std::string path;                   // "objects[0]"
};

// The most frames a job takes: a scene's range, a --frames list. A typo ("frames": [1, 5000000]) is refused
// before millions of files are written or the frame list fills memory.
inline constexpr int64_t kMaxFrames = 1000000;
// Frame numbers a job takes, in a scene, a plan or --frames: -kMaxFrameNumber to kMaxFrameNumber, so a
// frame, the next one and any offset a task adds stay within int.
inline constexpr int64_t kMaxFrameNumber = 1000000000;

// A DeformKit scene (docs/scene.md): objects, each a rest mesh under a deformer stack whose parameters
// and envelopes are constant or keyframed, and a default frame range.
struct Scene {
    std::string source;  // the scene file, as named in messages
    int firstFrame = 1;  // default frame range, inclusive
    int lastFrame = 1;
    std::vector<SceneObject> objects;
};

// Weight sources that live outside the core library, provided by the application reading the scene (the
// deformkit CLI and the Python module give every one).
struct SceneReadOptions {
    // `"weights": {"ptex": file, "channel": c}`: (rest mesh, its file name, Ptex file, channel, source for
    // messages) -> #V weights (deformkit::ptex::weightsFromPtex). Unset: such a scene is refused with a
    // message saying so.
    std::function<std::vector<float>(const geom::Mesh&, const std::string&, const std::filesystem::path&,
                                     int32_t, const std::string&)>
        ptexWeights;
};

// Parses scene JSON text. `source` names the scene in messages and its folder resolves relative mesh and
// weights paths. Loads the meshes and weights files, and checks every value the way the host will set it
// (each parameter and every key value through the deformer's own set(), in parameters() order), so a
// scene that parses sets without error; constraints checked only at bind or evaluation (a low bound below a
// high bound) surface there. Throws ParseError for text that is not JSON, and InvalidInput for anything
// else, its message "<source>: <JSON path>: <what was found> (expected <what>)", e.g.
// "shot.json: objects[0].stack[1].params.endAngle.keys[2].frame: is 1, not after the previous key's 3
// (expected increasing frames)". Problems inside the mesh or weights file name that file as well.
[[nodiscard]] Scene parseScene(std::string_view text, const std::filesystem::path& source,
                               const struct SceneReadOptions& options);
[[nodiscard]] Scene parseScene(std::string_view text, const std::filesystem::path& source);

// Reads and parses a scene file. Throws IoError when it cannot be read, then as parseScene.
[[nodiscard]] Scene readScene(const std::filesystem::path& path, const struct SceneReadOptions& options);
[[nodiscard]] Scene readScene(const std::filesystem::path& path);

}  // namespace deformkit::scene
