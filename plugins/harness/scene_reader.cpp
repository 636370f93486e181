#include "commands.h"
#include "deformkit/ptex/ptex_mesh.h"

namespace deformkit::harness {
namespace fs = std::filesystem;

scene::Scene readScene(const fs::path& path) {
    scene::SceneReadOptions options;
    options.ptexWeights = ptex::weightsFromPtex;
    return scene::readScene(path, options);
}

}  // namespace deformkit::harness
