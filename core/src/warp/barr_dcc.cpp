#include "deformkit/warp/barr_dcc.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include <glm/geometric.hpp>

#include "deformkit/error.h"

namespace deformkit::warp {
namespace {

void requireFinite(double v, const char* source, const char* name) {
    if (!std::isfinite(v)) throw InvalidInput(formatError(source, name, "is not finite", "a number"));
}

struct Range {
    double lo, hi;
};

// `v` as a float, or InvalidInput naming what it is (`element`, made from the DCC's `from`) when it is beyond
// float32's range: it would become inf and be refused later under a name the DCC user never typed.
float floatOf(double v, const char* source, const char* element, const char* from) {
    const auto f = static_cast<float>(v);
    if (!std::isfinite(f)) {
        throw InvalidInput(formatError(source, element, "is " + numberText(v) + ", beyond float32's range",
                                       std::string(from) + " giving a value within float32's range"));
    }
    return f;
}

// Blender's limits: fractions of the [min, max] extent of the points along `axis` of the origin space.
Range blenderLimits(const BlenderSimpleDeform& b, std::span<const glm::vec3> points, int axis,
                    const char* source) {
    requireFinite(b.lowerLimit, source, "lower limit");
    requireFinite(b.upperLimit, source, "upper limit");
    if (b.lowerLimit < 0.0 || b.upperLimit > 1.0 || b.lowerLimit > b.upperLimit) {
        throw InvalidInput(
            formatError(source, "limits",
                        "are [" + std::to_string(b.lowerLimit) + ", " + std::to_string(b.upperLimit) + "]",
                        "0 <= lower <= upper <= 1"));
    }
    if (points.empty()) throw InvalidInput(formatError(source, "points", "is empty", "the mesh's points"));
    // The mapping measures and rotates in the origin space's unit axes: a scaled or sheared basis would
    // silently change the result, so it is refused (an origin object's scale is Blender's, not ours to
    // guess).
    constexpr const char* kAxisNames[3] = {"x", "y", "z"};
    for (int a = 0; a < 3; ++a) {
        const glm::dvec3 column(b.basis[a]);
        const double length = glm::length(column);
        if (!(std::abs(length - 1.0) <= 1e-4)) {
            throw InvalidInput(formatError(source, std::string("basis ") + kAxisNames[a] + " axis",
                                           "has length " + numberText(length),
                                           "unit, orthogonal axes (the origin's rotation, without scale)"));
        }
        for (int c = a + 1; c < 3; ++c) {
            const double d = glm::dot(column, glm::dvec3(b.basis[c]));
            if (!(std::abs(d) <= 1e-4)) {
                throw InvalidInput(formatError(
                    source, std::string("basis ") + kAxisNames[a] + " and " + kAxisNames[c] + " axes",
                    "are not orthogonal (dot product " + numberText(d) + ")",
                    "unit, orthogonal axes (the origin's rotation, without shear)"));
            }
        }
    }
    for (int a = 0; a < 3; ++a) {
        if (!std::isfinite(b.origin[a])) {
            throw InvalidInput(formatError(source, "origin",
                                           "is (" + numberText(b.origin.x) + ", " + numberText(b.origin.y) +
                                               ", " + numberText(b.origin.z) + ")",
                                           "finite coordinates"));
        }
    }
    double lower = std::numeric_limits<double>::infinity(), upper = -lower;
    const glm::dvec3 dir(b.basis[axis]);
    for (size_t i = 0; i < points.size(); ++i) {
        const double c = glm::dot(glm::dvec3(points[i]) - glm::dvec3(b.origin), dir);
        if (!std::isfinite(c)) {
            throw InvalidInput(
                formatError(source, "point " + std::to_string(i), "is not finite", "finite coordinates"));
        }
        lower = std::min(lower, c);
        upper = std::max(upper, c);
    }
    const Range r{lower + (upper - lower) * b.lowerLimit, lower + (upper - lower) * b.upperLimit};
    if (!(r.hi > r.lo)) {
        throw InvalidInput(formatError(source, "limits", "span zero length along the limit axis",
                                       "a limited range of positive length"));
    }
    return r;
}

AxisFrame blenderFrame(const BlenderSimpleDeform& b, int along, int up) {
    return {b.origin, b.basis[along], b.basis[up]};
}

// Linear profile a * clamp(z, lo, hi) + offset, exactly as two samples with constant extension.
// `value` names the DCC's parameter the values come from ("angle", "factor").
ProfileCurve linearProfile(const Range& r, double slope, double offset, const char* name, const char* value) {
    const char* limits = "limits and points";
    return ProfileCurve({floatOf(r.lo, name, "lower limit's position", limits),
                         floatOf(r.hi, name, "upper limit's position", limits)},
                        {floatOf(offset + slope * r.lo, name, "value at the lower limit", value),
                         floatOf(offset + slope * r.hi, name, "value at the upper limit", value)},
                        name);
}

}  // namespace

BendSetup fromMayaBend(const MayaBend& m) {
    const char* source = "bend handle frame";  // Maya's and Blender's bend handles alike
    for (int i = 0; i < 3; ++i) {
        requireFinite(m.handleOrigin[i], source, "handle origin");
        requireFinite(m.handleX[i], source, "handle X axis");
        requireFinite(m.handleY[i], source, "handle Y axis");
    }
    requireFinite(m.curvature, source, "curvature");
    requireFinite(m.lowBound, source, "lowBound");
    requireFinite(m.highBound, source, "highBound");
    const double sx = glm::length(glm::dvec3(m.handleX)), sy = glm::length(glm::dvec3(m.handleY));
    if (!(sx > 0.0) || !(sy > 0.0)) {
        throw InvalidInput(
            formatError(source, "handle axes", "include a zero vector", "a non-degenerate handle"));
    }
    if (std::abs(glm::dot(glm::dvec3(m.handleX), glm::dvec3(m.handleY))) > 1e-5 * sx * sy) {
        throw InvalidInput(
            formatError(source, "handle axes", "X and Y are not perpendicular", "an unsheared handle"));
    }
    if (std::abs(sx - sy) > 1e-5 * std::max(sx, sy)) {
        throw InvalidInput(formatError(source, "handle scale",
                                       "X is " + std::to_string(sx) + " and Y is " + std::to_string(sy),
                                       "equal X and Y scale (a circular arc)"));
    }
    if (m.lowBound > m.highBound) {
        throw InvalidInput(formatError(source, "lowBound", "is above highBound", "lowBound <= highBound"));
    }
    BendSetup out;
    out.frame = {m.handleOrigin, m.handleY, m.handleX};
    // Handle units -> world units: lengths times sy, a rate (angle per length) divided by sy.
    out.params = {floatOf(m.curvature / sy, "Maya bend", "rate (curvature over the handle's scale)",
                          "a curvature and handle scale"),
                  0.0f, floatOf(m.lowBound * sy, "Maya bend", "lowBound times the handle's scale", "bounds"),
                  floatOf(m.highBound * sy, "Maya bend", "highBound times the handle's scale", "bounds")};
    return out;
}

AxialSetup fromMayaTwist(const MayaTwist& m) {
    const TwistSamples samples = mayaTwistSamples(m);
    return {{m.handleOrigin, m.handleY, glm::vec3(0.0f)},
            ProfileCurve({samples.z[0], samples.z[1]}, {samples.angle[0], samples.angle[1]}, "Maya twist")};
}

TwistSamples mayaTwistSamples(const MayaTwist& m) {
    const char* source = "Maya twist";
    for (int i = 0; i < 3; ++i) {
        requireFinite(m.handleOrigin[i], source, "handle origin");
        requireFinite(m.handleY[i], source, "handle Y axis");
    }
    requireFinite(m.startAngle, source, "startAngle");
    requireFinite(m.endAngle, source, "endAngle");
    requireFinite(m.lowBound, source, "lowBound");
    requireFinite(m.highBound, source, "highBound");
    const double sy = glm::length(glm::dvec3(m.handleY));
    if (!(sy > 0.0)) {
        throw InvalidInput(
            formatError(source, "handle Y axis", "is a zero vector", "a non-degenerate handle"));
    }
    if (!(m.lowBound < m.highBound)) {
        throw InvalidInput(formatError(source, "lowBound", "is not below highBound", "lowBound < highBound"));
    }
    // Handle units -> world units along the axis: times the handle's Y scale.
    const Range r{m.lowBound * sy, m.highBound * sy};
    const double slope = (m.endAngle - m.startAngle) / (r.hi - r.lo);
    const double offset = m.startAngle - slope * r.lo;  // as linearProfile computes its samples
    return {{floatOf(r.lo, source, "lowBound times the handle's scale", "bounds"),
             floatOf(r.hi, source, "highBound times the handle's scale", "bounds")},
            {floatOf(offset + slope * r.lo, source, "angle at lowBound", "angles"),
             floatOf(offset + slope * r.hi, source, "angle at highBound", "angles")}};
}

AxialSetup fromBlenderTwist(const BlenderSimpleDeform& b, std::span<const glm::vec3> points) {
    requireFinite(b.angle, "Blender twist", "angle");
    const int axis = static_cast<int>(b.deformAxis);
    const Range r = blenderLimits(b, points, axis, "Blender twist");
    return {blenderFrame(b, axis, (axis + 1) % 3),
            linearProfile(r, b.angle / (r.hi - r.lo), 0.0, "Blender twist", "an angle")};
}

AxialSetup fromBlenderTaper(const BlenderSimpleDeform& b, std::span<const glm::vec3> points) {
    requireFinite(b.factor, "Blender taper", "factor");
    const int axis = static_cast<int>(b.deformAxis);
    const Range r = blenderLimits(b, points, axis, "Blender taper");
    return {blenderFrame(b, axis, (axis + 1) % 3),
            linearProfile(r, b.factor / (r.hi - r.lo), 1.0, "Blender taper", "a factor")};
}

BendSetup fromBlenderBend(const BlenderSimpleDeform& b, std::span<const glm::vec3> points) {
    requireFinite(b.angle, "Blender bend", "angle");
    // Blender bends about the deform axis: along z towards y (X), along z towards x (Y), along x towards y
    // (Z).
    int along = 0, up = 1;
    if (b.deformAxis == BlenderAxis::X) along = 2, up = 1;
    if (b.deformAxis == BlenderAxis::Y) along = 2, up = 0;
    const Range r = blenderLimits(b, points, along, "Blender bend");
    BendSetup out;
    out.frame = blenderFrame(b, along, up);
    out.params = {floatOf(b.angle / (r.hi - r.lo), "Blender bend", "rate (angle over the limited length)",
                          "an angle and limits"),
                  0.0f, floatOf(r.lo, "Blender bend", "lower limit's position", "limits and points"),
                  floatOf(r.hi, "Blender bend", "upper limit's position", "limits and points")};
    return out;
}

}  // namespace deformkit::warp
