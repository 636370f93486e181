#include "deformkit/scene/evaluator.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <utility>

#include "deformkit/error.h"
#include "deformkit/host/deformers.h"
#include "deformkit/io/obj.h"

namespace deformkit::scene {
namespace {

std::string frameText(double frame) {
    return "frame " + numberText(frame);
}

// Runs `read`, naming the scene and `element` in front of any error's message: an IoError stays one when
// `keepIoErrors`, everything else is InvalidInput.
template <class F>
void namedBy(const std::string& source, const std::string& element, const std::string& prefix, F&& read,
             bool keepIoErrors = true) {
    try {
        read();
    } catch (const IoError& e) {
        if (keepIoErrors) throw IoError(formatError(source, element, prefix + e.what()));
        throw InvalidInput(formatError(source, element, prefix + e.what()));
    } catch (const Error& e) {
        throw InvalidInput(formatError(source, element, prefix + e.what()));
    }
}

}  // namespace

SceneEvaluator::SceneEvaluator(Scene scene) : scene_(std::move(scene)) {
    objects_.resize(scene_.objects.size());
    for (size_t o = 0; o < scene_.objects.size(); ++o) {
        const SceneObject& so = scene_.objects[o];
        Object& ob = objects_[o];
        ob.deformed = so.rest;
        ob.stack.setRest(so.rest);
        ob.restVersion = ob.sceneRestVersion = ob.stack.restVersion();
        if (!so.sequence.empty()) {
            namedBy(scene_.source, so.sequenceElement, "", [&] {
                ob.sequence =
                    std::make_unique<io::AnimatedPositions>(so.sequence, so.sequenceElement, so.cacheStart);
                ob.sequence->setReference(so.rest, so.meshFile.string());
            });
        }
        for (size_t i = 0; i < so.stack.size(); ++i) {
            const SceneDeformer& sd = so.stack[i];
            try {
                const size_t index = ob.stack.add(host::makeDeformer(sd.type, sd.label));
                if (!sd.weights.empty()) ob.stack.setWeights(index, sd.weights);
            } catch (const Error& e) {
                throw InvalidInput(formatError(scene_.source, sd.path, e.what()));
            }
            bool animatedBind = false;
            const host::Deformer& d = ob.stack.deformer(i);
            for (const SceneParameter& p : sd.params)
                animatedBind = animatedBind || (p.value.animated() && d.parameter(p.name).rebinds);
            ob.setAll.push_back(animatedBind);
        }
        // Constants once, at the first frame (animated values there too; the frame evaluated first sets
        // them again).
        setFrame(o, scene_.firstFrame, true);
    }
}

void SceneEvaluator::setFrame(size_t object, double frame, bool all) {
    const SceneObject& so = scene_.objects[object];
    Object& ob = objects_[object];
    for (size_t i = 0; i < so.stack.size(); ++i) {
        const SceneDeformer& sd = so.stack[i];
        const bool setAll = all || ob.setAll[i];
        try {
            if (setAll || sd.envelope.animated()) ob.stack.setEnvelope(i, sd.envelope.at(frame)[0]);
        } catch (const Error& e) {
            throw InvalidInput(
                formatError(scene_.source, sd.path + ".envelope", frameText(frame) + ": " + e.what()));
        }
        for (const SceneParameter& p : sd.params) {
            if (!setAll && !p.value.animated()) continue;
            try {
                ob.stack.set(i, p.name, p.value.at(frame));
            } catch (const Error& e) {
                throw InvalidInput(formatError(scene_.source, p.path, frameText(frame) + ": " + e.what()));
            }
        }
    }
}

const geom::Mesh& SceneEvaluator::evaluate(size_t object, double frame) {
    if (object >= objects_.size()) {
        throw InvalidInput(formatError(scene_.source, "object " + std::to_string(object), "does not exist",
                                       "an index below " + std::to_string(objects_.size())));
    }
    // Frames as a scene or --frames takes them (fractions allowed): a NaN frame would reach the curves as a
    // bad parameter value, an infinite one their end values without a word.
    if (!(std::abs(frame) <= static_cast<double>(kMaxFrameNumber))) {
        throw InvalidInput(formatError(
            scene_.source, "frame", "is " + numberText(frame),
            "a frame from -" + std::to_string(kMaxFrameNumber) + " to " + std::to_string(kMaxFrameNumber)));
    }
    setFrame(object, frame, false);
    Object& ob = objects_[object];
    ++ob.evaluations;
    const geom::Mesh& rest = ob.stack.rest();
    std::span<glm::vec3> points = ob.deformed.points();
    if (ob.restVersion != ob.stack.restVersion()) {
        ob.deformed = rest;  // a host gave the stack a new rest mesh
        ob.restVersion = ob.stack.restVersion();
        points = ob.deformed.points();
    }
    std::span<const glm::vec3> input = rest.points();
    // The input sequence drives the scene's rest mesh only, not one a host set since.
    if (ob.sequence && ob.restVersion == ob.sceneRestVersion) {
        readInput(object, frame);
        input = ob.input;
    }
    try {
        ob.stack.evaluate(input, points);
    } catch (const Error& e) {
        throw InvalidInput(formatError(scene_.source, scene_.objects[object].path + ".stack",
                                       frameText(frame) + ": " + e.what()));
    }
    return ob.deformed;
}

void SceneEvaluator::check(std::span<const int> frames) {
    if (frames.empty()) return;
    for (size_t o = 0; o < objects_.size(); ++o) {
        const SceneObject& so = scene_.objects[o];
        Object& ob = objects_[o];
        // Every frame's values set (a key between frames may overshoot, a stepped key reach a bad value)
        // and bound where a bind-time value changed: the stack binds only entries whose bind-time values
        // changed, as evaluating the frames does.
        for (size_t k = 0; k < frames.size(); ++k) {
            setFrame(o, frames[k], k == 0);
            try {
                ob.stack.bind();
            } catch (const Error& e) {
                throw InvalidInput(
                    formatError(scene_.source, so.path + ".stack", frameText(frames[k]) + ": " + e.what()));
            }
        }
        if (!ob.sequence) continue;
        for (const int frame : frames) {
            // The input's errors name the frame (a cache's "frame 4", a sequence's file of frame 4).
            namedBy(scene_.source, so.sequenceElement, "",
                    [&] { ob.sequence->requireFrames(std::span<const int>(&frame, 1)); });
        }
    }
}

void SceneEvaluator::readInput(size_t object, double frame) {
    const SceneObject& so = scene_.objects[object];
    Object& ob = objects_[object];
    const std::string& element = so.sequenceElement;
    if (frame != std::floor(frame) || std::abs(frame) > 1.0e9) {
        throw InvalidInput(formatError(scene_.source, element,
                                       frameText(frame) + " of the animated input " + so.sequence.string(),
                                       "whole frames for an object with an animated input"));
    }
    const int whole = static_cast<int>(frame);
    namedBy(
        scene_.source, element, "", [&] { ob.sequence->read(whole, ob.input); }, false);
}

host::DeformerStack& SceneEvaluator::stack(size_t object) {
    if (object >= objects_.size()) {
        throw InvalidInput(formatError(scene_.source, "object " + std::to_string(object), "does not exist",
                                       "an index below " + std::to_string(objects_.size())));
    }
    return objects_[object].stack;
}

const host::DeformerStack& SceneEvaluator::stack(size_t object) const {
    return const_cast<SceneEvaluator&>(*this).stack(object);
}

}  // namespace deformkit::scene
