#pragma once

#include <array>

#include <span>

#include <glm/mat3x3.hpp>
#include <glm/vec3.hpp>

#include "deformkit/warp/barr.h"
#include "deformkit/warp/profile_curve.h"

namespace deformkit::warp {

// Taper, twist and bend as DCCs parameterise them (Maya's nonLinear deformers, Blender's SimpleDeform
// modifier), mapped onto Barr's parameters (barr.h: TaperWarp, TwistWarp, BendWarp).
// The Maya mappings are the host layer's twist and bend deformers (host/deformers.h), which the Maya nodes,
// the Blender add-on and scenes use. The Blender SimpleDeform mappings reproduce Blender's own modifier;
// the Python module exposes them (blender_simple_deform_params), which the tests use to compare with Blender.
// docs/decisions.md records how each mapping was derived.

struct AxialSetup {  // for TaperWarp / TwistWarp
    AxisFrame frame;
    ProfileCurve profile = ProfileCurve::constant(0.0f);
};

struct BendSetup {  // for BendWarp
    AxisFrame frame;
    BendParams params;
};

// Maya's nonLinear bend (deformBend): bends along the handle's local Y axis towards its local +X axis,
// curvature in radians per handle-space unit along Y (the attribute is an angle; the UI shows degrees),
// bent between lowBound and highBound on handle Y, centred on the handle origin.
struct MayaBend {
    glm::vec3 handleOrigin{0.0f};         // handle translation, world units
    glm::vec3 handleX{1.0f, 0.0f, 0.0f};  // world images of the handle's unit X and Y axes (rotation x scale)
    glm::vec3 handleY{0.0f, 1.0f, 0.0f};
    double curvature = 0.0;  // radians
    double lowBound = -1.0;  // handle units, <= highBound
    double highBound = 1.0;
};
// Throws InvalidInput for zero or non-finite handle axes, X not perpendicular to Y, X and Y scaled
// differently (a handle-space circle would be an ellipse in the world, which Barr's bend cannot give),
// a non-finite curvature or bound, lowBound > highBound.
[[nodiscard]] BendSetup fromMayaBend(const MayaBend& maya);

// Maya's nonLinear twist (deformTwist): rotates about the handle's local Y axis by startAngle at lowBound
// and endAngle at highBound (radians; the UI shows degrees), linearly in between and held constant
// beyond the bounds. Right-handed about handle +Y (not checked against Maya here; see docs/decisions.md).
struct MayaTwist {
    glm::vec3 handleOrigin{0.0f};         // handle translation, world units
    glm::vec3 handleY{0.0f, 1.0f, 0.0f};  // world image of the handle's unit Y axis (rotation x scale)
    double startAngle = 0.0;              // radians, at lowBound
    double endAngle = 0.0;                // radians, at highBound
    double lowBound = -1.0;               // handle units, < highBound
    double highBound = 1.0;
};
// Throws InvalidInput for a zero or non-finite handle axis, a non-finite angle or bound, or
// lowBound >= highBound.
[[nodiscard]] AxialSetup fromMayaTwist(const MayaTwist& maya);
// The same twist's angle profile as its two samples (z in scene units along the axis, angles), for
// TwistWarp::setProfile in place; the same checks.
struct TwistSamples {
    std::array<float, 2> z, angle;
};
[[nodiscard]] TwistSamples mayaTwistSamples(const MayaTwist& maya);

// Blender's SimpleDeform modifier (twist, bend, taper modes), evaluated in the space of its origin
// object (or the modified object when there is none): `basis` columns are that space's unit x, y, z
// axes in world, `origin` its origin. The limits are fractions of the mesh's extent along the limit
// axis in that space, measured on `points` (world positions, as Blender measures the evaluated mesh).
enum class BlenderAxis { X = 0, Y = 1, Z = 2 };
struct BlenderSimpleDeform {
    glm::vec3 origin{0.0f};
    glm::mat3 basis{1.0f};  // orthonormal columns
    BlenderAxis deformAxis = BlenderAxis::Z;
    double angle = 0.0;       // twist and bend: radians over the limited range
    double factor = 0.0;      // taper: scale change per unit over the limited range
    double lowerLimit = 0.0;  // fractions in [0, 1], lower <= upper
    double upperLimit = 1.0;
};
// twist: theta(z) = angle / (L1 - L0) * clamp(z, L0, L1) about the deform axis.
[[nodiscard]] AxialSetup fromBlenderTwist(const BlenderSimpleDeform& blender,
                                          std::span<const glm::vec3> points);
// taper: f(z) = 1 + factor / (L1 - L0) * clamp(z, L0, L1) across the deform axis.
[[nodiscard]] AxialSetup fromBlenderTaper(const BlenderSimpleDeform& blender,
                                          std::span<const glm::vec3> points);
// bend: rate = angle / (L1 - L0), centre 0, range [L0, L1] along x (deform Z) or z (deform X, Y), bending
// towards y (deform X, Z) or x (deform Y). Lock axes are not supported.
// All three throw InvalidInput for limits outside [0, 1] or reversed, a non-finite angle/factor, no
// points, or a zero-length limited range (Blender divides by FLT_EPSILON there instead).
[[nodiscard]] BendSetup fromBlenderBend(const BlenderSimpleDeform& blender,
                                        std::span<const glm::vec3> points);

}  // namespace deformkit::warp
