#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include <glm/vec3.hpp>

#include "deformkit/geom/mesh.h"
#include "deformkit/host/stack.h"
#include "deformkit/io/animated_positions.h"
#include "deformkit/scene/scene.h"

namespace deformkit::scene {

// Evaluates a scene frame after frame the way a DCC does: one DeformerStack per object, built once (rest
// mesh, deformers, painted weights, constant parameters), then at each frame every animated parameter and
// envelope is set from its curves and the stack evaluated. Setting an animatable parameter never rebinds;
// the stacks bind on the first evaluation and again only after a rest or bind-time change (an animated
// [bind] parameter whose value moves, or a host's stack(o).setRest()), as DeformerStack says. A frame's
// result depends only on the scene at that frame, not on the frames evaluated before it.
//
// Errors at evaluation (a constraint checked at bind, such as lowBound < highBound, or an interpolated key
// value a deformer rejects) are InvalidInput naming the scene, the object's or parameter's JSON path and
// the frame. Not thread-safe: one thread drives an evaluator.
class SceneEvaluator {
  public:
    // Builds the stacks; throws InvalidInput as above for a value the deformers reject.
    explicit SceneEvaluator(Scene scene);

    [[nodiscard]] const Scene& scene() const { return scene_; }
    [[nodiscard]] size_t numObjects() const { return objects_.size(); }

    // Object `object`'s deformed mesh at `frame` (frames may be fractional; curves hold their end values
    // outside their keys): the rest mesh's connectivity with the stack's output positions. The stack's
    // input is the rest positions, or for an object with an animated input that frame's positions (whole
    // frames only; an OBJ must exist and have the rest mesh's connectivity, a point cache the rest mesh's
    // vertex count and the frame). The reference stays valid until the next evaluate() of that object.
    // Throws InvalidInput for an object index out of range, a frame not finite or beyond +-kMaxFrameNumber,
    // and naming the scene, the object's "mesh" (or
    // "deformed") and the file for an input frame that is missing, fractional or of another connectivity.
    const geom::Mesh& evaluate(size_t object, double frame);

    // Checks, before any work, what evaluating `frames` would find wrong that does not depend on the frame's
    // deformation: every object's stack set at every frame and bound where its bind-time values change (a
    // slide vertex out of range, a key that overshoots to a value a deformer rejects: as costly as the
    // binds evaluating the frames does), and for an object with an animated input, that each frame is
    // there (an OBJ of the sequence, a sample of the cache). Throws InvalidInput / IoError as evaluate()
    // names them. No evaluation is counted.
    void check(std::span<const int> frames);

    // evaluate() calls for the object so far: a host feeding one evaluation to several consumers (a mesh
    // writer and every UV-warp tile) shows with it that a frame is evaluated once.
    [[nodiscard]] int64_t evaluations(size_t object) const { return objects_.at(object).evaluations; }

    // The object's stack, for inspection (bind counts) and host changes (setRest, setWeights).
    [[nodiscard]] host::DeformerStack& stack(size_t object);
    [[nodiscard]] const host::DeformerStack& stack(size_t object) const;

  private:
    struct Object {
        host::DeformerStack stack;
        geom::Mesh deformed;
        // Per stack entry: set every parameter each frame (an animated [bind] parameter can reset an
        // animated counterpart that the scene holds constant), or only the animated ones.
        std::vector<bool> setAll;
        // The object's animated input (SceneObject::sequence: an OBJ sequence or a point cache), when it has
        // one.
        std::unique_ptr<io::AnimatedPositions> sequence;
        std::vector<glm::vec3> input;   // the sequence's positions at the frame evaluated
        uint64_t restVersion = 0;       // the stack's rest version `deformed` was copied from
        uint64_t sceneRestVersion = 0;  // the stack's rest version holding the scene's rest mesh
        int64_t evaluations = 0;
    };

    void setFrame(size_t object, double frame, bool all);
    // The input sequence's positions at `frame` into the object's `input` (#V: the reference checked the
    // count); errors as evaluate() says.
    void readInput(size_t object, double frame);

    Scene scene_;
    std::vector<Object> objects_;
};

}  // namespace deformkit::scene
