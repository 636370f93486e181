#pragma once

#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include <glm/vec3.hpp>

namespace deformkit::warp {

// How a curve's control points define the curve. Curve warps (Wires, paper §4.4) work on polylines; a
// cubic curve is sampled into one. Two curves with the same type and control count sampled with the same
// samplesPerSpan share their parameterisation sample for sample, which is how Wires pairs a reference
// curve C(v) with its wire curve C*(v).
enum class CurveType {
    Polyline,    // the control points themselves
    CatmullRom,  // uniform Catmull-Rom spline through every control point; end tangents from phantom points
                 // reflected through the ends (P_-1 = 2 P_0 - P_1), so a straight control polygon stays
                 // straight
    Bezier,      // piecewise cubic Bezier: 3k + 1 controls, spans (P_3i, P_3i+1, P_3i+2, P_3i+3)
};

// The sampled polyline of a curve, uniform in each span's parameter: spans * samplesPerSpan + 1 points
// (the control points unchanged for CurveType::Polyline, samplesPerSpan ignored). controls: scene units.
// `name` labels the curve in error messages ("wire 1 reference curve"). Throws InvalidInput naming the
// curve for fewer than 2 controls, a Bezier control count that is not 3k + 1, samplesPerSpan outside
// [1, 4096] for a cubic type, or a non-finite control (named by index).
[[nodiscard]] std::vector<glm::vec3> sampleCurve(std::span<const glm::vec3> controls, CurveType type,
                                                 int32_t samplesPerSpan, std::string_view name = "curve");

}  // namespace deformkit::warp
