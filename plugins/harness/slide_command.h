#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <glm/vec3.hpp>

#include "deformkit/slide/slider.h"

// `deformkit slide MESH --handle I --from X,Y,Z --to X,Y,Z --radius R --out OUT.obj`: the slide (Pinskiy,
// "Sliding deformation") as a CLI command, one handle dragged from a start locator to an end locator.
// Options:
// --falloff smooth|linear|v0,v1,... (ramp samples at x = i / (n - 1) of distance / radius), --weights FILE
// (a JSON array of one number per vertex) or --weights-ptex FILE [--weights-channel C] (a Ptex map painted on
// the mesh: per-vertex values, docs/ptex.md), --envelope E, --region euclidean|geodesic, --surface
// cage|limit,
// --max-walk N. UVs and groups of MESH are kept; only positions change.
namespace deformkit::harness {

struct SlideCommand {
    std::filesystem::path mesh;     // OBJ
    std::filesystem::path out;      // OBJ, written atomically
    slide::SlideHandle handle;      // vertex, radius (scene units), region metric
    glm::dvec3 from{0.0}, to{0.0};  // start and end locators: the displacement is to - from
    slide::Falloff falloff = slide::Falloff::smooth();
    std::optional<std::filesystem::path> weights;      // JSON array, one number per vertex
    std::optional<std::filesystem::path> weightsPtex;  // or a Ptex map of the mesh (its per-vertex values)
    int32_t weightsChannel = 0;                        // the Ptex map's channel
    double envelope = 1.0;
    slide::SlideOptions options;
};

// Reads MESH (and the weights), slides, writes OUT atomically; returns the evaluation's counts. Throws
// IoError / ParseError / InvalidInput (deformkit::Error) before anything is written.
slide::SlideResult slideCommand(const SlideCommand& command);

// The one summary line the CLI prints: "wrote OUT: moved M, limited L (boundary-stopped B,
// walk-limit-stopped S), flipped triangles T, unreachable U, without a tangent plane N, degenerate triangles
// D", then ", fold limit: drag scaled
// to K" when it applied and "; W split vertices welded onto a coincident vertex ..." when the mesh had some.
[[nodiscard]] std::string slideSummary(const std::filesystem::path& out, const slide::SlideResult& result);

// "x,y,z" (three finite numbers) for the option `option` (e.g. "--from"); InvalidInput naming it otherwise.
[[nodiscard]] glm::dvec3 parsePoint(std::string_view text, const std::string& option);

// "smooth", "linear", or comma-separated ramp samples "1,0.5,0"; InvalidInput naming `option` and the
// sample otherwise.
[[nodiscard]] slide::Falloff parseFalloff(std::string_view text, const std::string& option = "--falloff");

}  // namespace deformkit::harness
