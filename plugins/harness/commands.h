#pragma once

#include <filesystem>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "deformkit/io/preview.h"
#include "deformkit/scene/scene.h"

// The deformkit CLI's subcommands as plain functions, so tests call them in-process. Each throws
// deformkit::Error on bad input; main() turns that into one line on stderr and exit code 2.
namespace deformkit::harness {

// `deformkit info FILE`: a mesh (.obj), an image, or a UDIM pattern. Writes a human-readable report.
void describe(const std::filesystem::path& file, std::ostream& out);

// Reads a scene the way every command does: all weight sources, Ptex files included.
[[nodiscard]] scene::Scene readScene(const std::filesystem::path& path);

struct PreviewCommand {
    std::filesystem::path mesh;
    std::optional<std::filesystem::path> texture;  // image or UDIM pattern
    // Painted weights shown as colours (io::weightColor): a JSON weights file, or a Ptex map of the mesh
    // (its per-vertex values of channel weightsChannel). At most one.
    std::optional<std::filesystem::path> weights;
    std::optional<std::filesystem::path> weightsPtex;
    int32_t weightsChannel = 0;
    std::filesystem::path out;  // PNG (or any image format by extension)
    io::PreviewOptions options;
};
// `deformkit preview`: renders and writes atomically.
void preview(const PreviewCommand& command);

struct DemoCommand {
    std::filesystem::path outDir = "demo-out";
    int32_t resolution = 1024;
};
// `deformkit demo`: writes the demo assets and a preview into outDir, the warps into outDir/warps and the
// slide into outDir/slide, the Ptex-painted slide into outDir/ptex; returns the files written.
std::vector<std::filesystem::path> demo(const DemoCommand& command);

}  // namespace deformkit::harness
