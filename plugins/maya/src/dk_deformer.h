#pragma once

// DeformKit's Maya deformer nodes: one MPxDeformerNode per deformer, each a thin translation between Maya's
// attributes and the host layer (maya_adapter.h). Written against the documented API of Maya 2024.

#include <initializer_list>
#include <memory>
#include <vector>

#include <maya/MDataBlock.h>
#include <maya/MFloatArray.h>
#include <maya/MFnNumericData.h>
#include <maya/MFnUnitAttribute.h>
#include <maya/MIntArray.h>
#include <maya/MItGeometry.h>
#include <maya/MMatrix.h>
#include <maya/MPointArray.h>
#include <maya/MPxDeformerNode.h>
#include <maya/MTypeId.h>

#include "maya_adapter.h"

namespace deformkit::maya {

// What every node shares: each geometry the node deforms (input[i]) has its own state (NodeGeometry): its
// rest is its input mesh, captured at the first evaluation and again when its topology changes or `rebind`
// is toggled (Maya deformers bind to their input when created); painted weights come from the deformer's
// weightList (paintable); the envelope is Maya's (0 leaves the input as it is). A deformer set of some of
// the mesh's vertices deforms those, the deformer seeing the whole mesh. A node only says which host type
// it is and reads its own attributes into host parameters.
class DkDeformer : public MPxDeformerNode {
  public:
    MStatus deform(MDataBlock& block, MItGeometry& iter, const MMatrix& geometryWorld,
                   unsigned int multiIndex) override;

    // Adds a node class's `rebind` attribute (toggled by the user to take the current input as the new rest).
    static MStatus addRebindAttribute(MObject& attribute);

  protected:
    // Attribute helpers for the node classes' initialize() (MPxNode's addAttribute is theirs to call).
    static MStatus addNumeric(MObject& attribute, const char* name, const char* shortName,
                              MFnNumericData::Type type, double value, bool keyable = true);
    static MStatus addMatrix(MObject& attribute, const char* name, const char* shortName, bool array = false);
    // An angle (shown in the scene's angle unit, read in radians) or a distance (shown in the scene's linear
    // unit, read in Maya's internal centimetres, as the geometry's points are): Maya converts what is
    // typed or connected (a joint's rotate), as for its own deformers.
    static MStatus addUnit(MObject& attribute, const char* name, const char* shortName,
                           MFnUnitAttribute::Type type, double value);
    static void affectsOutput(std::initializer_list<MObject*> attributes);

    // The host type, read from the node's attributes where it depends on them (a dkBarr's kind).
    [[nodiscard]] virtual const char* hostType(MDataBlock& block) = 0;
    [[nodiscard]] virtual const MObject& rebindAttribute() const = 0;
    // The host parameters from the node's attributes, written into `out` (kept by the node between calls,
    // so a warm deform() allocates nothing); throws deformkit::Error for bad values.
    virtual void parameters(MDataBlock& block, const MayaMatrix& geometryWorld, Parameters& out) = 0;

  private:
    NodeGeometries geometries_;
    Parameters parameters_;       // the last parameters, rewritten in place each deform()
    MPointArray positions_;       // the input's positions, read and written in bulk
    MIntArray counts_, indices_;  // the input's polygons, for the topology check
    std::vector<int32_t> faceCounts_, faceIndices_;
    // A deformer set of some vertices: the whole mesh's positions, the members and their results.
    std::vector<glm::vec3> all_, moved_;
    std::vector<int32_t> members_;
    std::vector<float> memberWeights_;
};

[[nodiscard]] MayaMatrix toMaya(const MMatrix& m);

class DkSlide : public DkDeformer {
  public:
    static void* creator() { return new DkSlide; }
    static MStatus initialize();
    MStatus accessoryNodeSetup(MDagModifier& modifier) override;
    MObject& accessoryAttribute() const override { return endMatrix; }
    static const MTypeId id;
    static MObject rebind;
    static MObject vertex, radius, geodesic, limitSurface, weightsAreFalloff, foldLimit, falloff, startMatrix,
        endMatrix;

  protected:
    const MObject& rebindAttribute() const override { return rebind; }
    const char* hostType(MDataBlock&) override { return "slide"; }
    void parameters(MDataBlock& block, const MayaMatrix& geometryWorld, Parameters& out) override;

  private:
    SlideInputs in_;  // kept: its falloff keys reuse their storage
    MIntArray rampIndices_, rampInterpolations_;
    MFloatArray rampPositions_, rampValues_;
};

class DkBarr : public DkDeformer {
  public:
    static void* creator() { return new DkBarr; }
    static MStatus initialize();
    MStatus accessoryNodeSetup(MDagModifier& modifier) override;
    MObject& accessoryAttribute() const override { return handleMatrix; }
    static const MTypeId id;
    static MObject rebind;
    static MObject kind, handleMatrix, startValue, endValue, startAngle, endAngle, curvature, lowBound,
        highBound;

  protected:
    const MObject& rebindAttribute() const override { return rebind; }
    // The host type follows the `kind` attribute (the geometries' cores are made again when it changes).
    const char* hostType(MDataBlock& block) override;
    void parameters(MDataBlock& block, const MayaMatrix& geometryWorld, Parameters& out) override;

  private:
    BarrInputs in_;
};

class DkFrameLattice : public DkDeformer {
  public:
    static void* creator() { return new DkFrameLattice; }
    static MStatus initialize();
    static const MTypeId id;
    static MObject rebind;
    static MObject divisions, basis, baseMatrix, controlMatrix;

  protected:
    const MObject& rebindAttribute() const override { return rebind; }
    const char* hostType(MDataBlock&) override { return "ffdframes"; }
    void parameters(MDataBlock& block, const MayaMatrix& geometryWorld, Parameters& out) override;

  private:
    FrameLatticeInputs in_;
};

class DkWire : public DkDeformer {
  public:
    static void* creator() { return new DkWire; }
    static MStatus initialize();
    static const MTypeId id;
    static MObject rebind;
    static MObject restCurve, curve, samples, dropoff, scale, smooth;

  protected:
    const MObject& rebindAttribute() const override { return rebind; }
    const char* hostType(MDataBlock&) override { return "wires"; }
    void parameters(MDataBlock& block, const MayaMatrix& geometryWorld, Parameters& out) override;

  private:
    WireInputs in_;
};

class DkMeshWarp : public DkDeformer {
  public:
    static void* creator() { return new DkMeshWarp; }
    static MStatus initialize();
    static const MTypeId id;
    static MObject rebind;
    static MObject restCage, cage;

  protected:
    const MObject& rebindAttribute() const override { return rebind; }
    const char* hostType(MDataBlock&) override { return "meshwarp"; }
    void parameters(MDataBlock& block, const MayaMatrix& geometryWorld, Parameters& out) override;

  private:
    MeshWarpInputs in_;
    MPointArray points_;
    MIntArray counts_, indices_;
};

}  // namespace deformkit::maya
