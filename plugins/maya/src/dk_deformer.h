#pragma once

// DeformKit's Maya deformer nodes: one MPxDeformerNode per deformer, each a thin translation between Maya's
// attributes and the host layer (maya_adapter.h). Written against the documented API of Maya 2024.

#include <initializer_list>
#include <memory>

#include <maya/MDataBlock.h>
#include <maya/MFloatArray.h>
#include <maya/MFnNumericData.h>
#include <maya/MIntArray.h>
#include <maya/MItGeometry.h>
#include <maya/MMatrix.h>
#include <maya/MPointArray.h>
#include <maya/MPxDeformerNode.h>
#include <maya/MTypeId.h>

#include "maya_adapter.h"

namespace deformkit::maya {

// What every node shares: the rest geometry is the node's input mesh, captured at the first evaluation and
// again when its topology changes or `rebind` is toggled (Maya deformers bind to their input when created);
// painted weights come from the deformer's weightList (paintable); the envelope is Maya's. A node only says
// which host type it is and reads its own attributes into host parameters.
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
    static void affectsOutput(std::initializer_list<MObject*> attributes);

    [[nodiscard]] virtual const char* hostType() const = 0;
    [[nodiscard]] virtual const MObject& rebindAttribute() const = 0;
    // The host parameters from the node's attributes, written into `out` (kept by the node between calls,
    // so a warm deform() allocates nothing); throws deformkit::Error for bad values.
    virtual void parameters(MDataBlock& block, const MayaMatrix& geometryWorld, Parameters& out) = 0;

  private:
    std::unique_ptr<NodeCore> core_;
    bool rebindSeen_ = false;
    Parameters parameters_;  // the last parameters, rewritten in place each deform()
    MPointArray positions_;  // the input's positions, read and written in bulk
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
    const char* hostType() const override { return "slide"; }
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
    static MObject kind, handleMatrix, startValue, endValue, curvature, lowBound, highBound;

  protected:
    const MObject& rebindAttribute() const override { return rebind; }
    // The host type follows the `kind` attribute (the node's core is rebuilt when it changes).
    const char* hostType() const override;
    void parameters(MDataBlock& block, const MayaMatrix& geometryWorld, Parameters& out) override;

  private:
    short kind_ = 1;
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
    const char* hostType() const override { return "ffdframes"; }
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
    const char* hostType() const override { return "wires"; }
    void parameters(MDataBlock& block, const MayaMatrix& geometryWorld, Parameters& out) override;

  private:
    WireInputs in_;
    MPointArray cvs_;
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
    const char* hostType() const override { return "meshwarp"; }
    void parameters(MDataBlock& block, const MayaMatrix& geometryWorld, Parameters& out) override;

  private:
    MeshWarpInputs in_;
    MPointArray points_;
    MIntArray counts_, indices_;
};

}  // namespace deformkit::maya
