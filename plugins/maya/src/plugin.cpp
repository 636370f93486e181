// The deformkit Maya plugin: registers the deformer nodes and the UV redirect node, makes the deformers'
// weights paintable, and loads the Python commands that create each set-up on the selection.

#include <maya/MFnPlugin.h>
#include <maya/MGlobal.h>

#include "dk_deformer.h"
#include "dk_redirect_node.h"

using namespace deformkit::maya;

namespace {

struct NodeType {
    const char* name;
    MTypeId id;
    MCreatorFunction creator;
    MInitializeFunction initialize;
};

const NodeType kDeformers[] = {
    {"dkSlide", DkSlide::id, DkSlide::creator, DkSlide::initialize},
    {"dkBarr", DkBarr::id, DkBarr::creator, DkBarr::initialize},
    {"dkFrameLattice", DkFrameLattice::id, DkFrameLattice::creator, DkFrameLattice::initialize},
    {"dkWire", DkWire::id, DkWire::creator, DkWire::initialize},
    {"dkMeshWarp", DkMeshWarp::id, DkMeshWarp::creator, DkMeshWarp::initialize},
};

}  // namespace

MStatus initializePlugin(MObject object) {
    MFnPlugin plugin(object, "DeformKit", "0.1", "Any");
    MStatus status;
    for (const NodeType& node : kDeformers) {
        status =
            plugin.registerNode(node.name, node.id, node.creator, node.initialize, MPxNode::kDeformerNode);
        if (!status) return status;
        MGlobal::executeCommand(MString("makePaintable -attrType multiFloat -sm deformer ") + node.name +
                                " weights;");
    }
    status = plugin.registerNode("dkUvRedirect", DkUvRedirect::id, DkUvRedirect::creator,
                                 DkUvRedirect::initialize);
    if (!status) return status;
    MGlobal::executePythonCommand("import deformkit_maya; deformkit_maya.install_menu()");
    return MS::kSuccess;
}

MStatus uninitializePlugin(MObject object) {
    MFnPlugin plugin(object);
    MGlobal::executePythonCommand("import deformkit_maya; deformkit_maya.remove_menu()");
    plugin.deregisterNode(DkUvRedirect::id);
    for (const NodeType& node : kDeformers) {
        MGlobal::executeCommand(MString("makePaintable -remove -attrType multiFloat ") + node.name +
                                " weights;");
        plugin.deregisterNode(node.id);
    }
    return MS::kSuccess;
}
