#pragma once

#include <memory>
#include <string>
#include <vector>

#include <maya/MPxNode.h>
#include <maya/MTypeId.h>

#include "maya_adapter.h"

namespace deformkit::maya {

// dkUvRedirect: the content-aware UV warp of one UDIM tile of a deformed mesh, written as a redirect map per
// frame. Inputs: the deformed mesh (inMesh, connected from the shape's worldMesh or outMesh), the rest mesh
// with UVs, the rigidity, mask and orientation map paths (UDIM patterns; #### makes a map animated, one file
// per frame), the tile, one attribute per UV-warp option (named as in scenes: resolution, iterations,
// sweepsPerLevel...) and time; on compute it solves the current frame (warm-started when it follows the last
// frame solved and warmStart is on) and writes `output` (<UDIM> and #### replaced)
// atomically. outFile holds the path written. The solver is made again only when the tile, a pattern or an
// option changes; an animated map's file is read at each frame, a still one once (RedirectNode).
class DkUvRedirect : public MPxNode {
  public:
    static void* creator() { return new DkUvRedirect; }
    static MStatus initialize();
    MStatus compute(const MPlug& plug, MDataBlock& block) override;

    static const MTypeId id;
    static MObject inMesh, restMesh, rigidity, mask, orientation, preset, tile, output, time, outFile;
    // One attribute per UV-warp option (uvwarp/options.h), in the library's order.
    static std::vector<RedirectOptionAttribute> optionSpecs;
    static std::vector<MObject> options;

  private:
    RedirectNode node_;
    std::vector<glm::vec3> points_;  // the deformed points, kept between frames
};

}  // namespace deformkit::maya
