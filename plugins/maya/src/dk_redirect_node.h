#pragma once

#include <map>
#include <memory>
#include <string>

#include <maya/MPxNode.h>
#include <maya/MTypeId.h>

#include "maya_adapter.h"

namespace deformkit::maya {

// dkUvRedirect: the content-aware UV warp of one UDIM tile of a deformed mesh, written as a redirect map per
// frame. Inputs: the deformed mesh (inMesh, connected from the shape's worldMesh or outMesh), the rest mesh
// with UVs, the rigidity (and optional mask) map paths (UDIM patterns), the tile, the grid resolution and
// time; on compute it solves the current frame (warm-started when it follows the last frame solved) and
// writes `output` (<UDIM> and #### replaced) atomically. outFile holds the path written.
class DkUvRedirect : public MPxNode {
  public:
    static void* creator() { return new DkUvRedirect; }
    static MStatus initialize();
    MStatus compute(const MPlug& plug, MDataBlock& block) override;

    static const MTypeId id;
    static MObject inMesh, restMesh, rigidity, mask, tile, resolution, output, time, outFile;

  private:
    std::unique_ptr<RedirectCore> core_;
    std::string coreKey_;  // the inputs the core was built for
};

}  // namespace deformkit::maya
