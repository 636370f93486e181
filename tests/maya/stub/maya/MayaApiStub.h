#pragma once
// Declarations of the Maya API calls the DeformKit plugin makes, with the signatures Autodesk documents for
// Maya 2024, written for a compile-only check of plugins/maya/src where no devkit is installed. Nothing here
// is Maya's code or headers; nothing links against it.
class MStatus {
  public:
    enum MStatusCode { kSuccess, kFailure, kUnknownParameter };
    MStatus(MStatusCode c = kSuccess) : c_(c) {}
    explicit operator bool() const { return c_ == kSuccess; }
    bool operator!() const { return c_ != kSuccess; }
    MStatusCode c_;
};
namespace MS {
constexpr MStatus::MStatusCode kSuccess = MStatus::kSuccess, kFailure = MStatus::kFailure,
                               kUnknownParameter = MStatus::kUnknownParameter;
}
class MString {
  public:
    MString();
    MString(const char*);
    const char* asChar() const;
    MString operator+(const char*) const;
    MString operator+(const MString&) const;
};
inline MString operator+(const char*, const MString&);
class MObject {
  public:
    static MObject kNullObj;
    bool hasFn(int) const;
};
namespace MFn {
enum Type { kNurbsCurve, kMesh };
}
class MIntArray {
  public:
    unsigned length() const;
    int operator[](unsigned) const;
};
class MFloatArray {
  public:
    unsigned length() const;
    float operator[](unsigned) const;
};
struct MPoint {
    double x, y, z;
    MPoint(double, double, double, double w = 1);
    MPoint();
};
class MPointArray {
  public:
    unsigned length() const;
    MPoint operator[](unsigned) const;
    MPoint& operator[](unsigned);
    MStatus setLength(unsigned);
    MStatus clear();
};
class MMatrix {
  public:
    void get(double[4][4]) const;
};
namespace MSpace {
enum Space { kObject, kWorld };
}
class MTime {
  public:
    enum Unit { k24FPS };
    static Unit uiUnit();
    double as(Unit) const;
};
typedef int int3[3];
class MAngle {
  public:
    double asRadians() const;
};
class MDistance {
  public:
    double asCentimeters() const;
};
class MDataHandle {
  public:
    MAngle asAngle() const;
    MDistance asDistance() const;
    float asFloat() const;
    double asDouble() const;
    int asInt() const;
    short asShort() const;
    bool asBool() const;
    const MMatrix& asMatrix() const;
    MObject asMesh() const;
    MObject asNurbsCurve() const;
    int3& asInt3();
    MString asString() const;
    MTime asTime() const;
    MDataHandle child(const MObject&);
    void set(const MString&);
};
class MArrayDataHandle {
  public:
    MStatus jumpToElement(unsigned);
    MDataHandle outputValue();
    MDataHandle inputValue();
    unsigned elementCount();
    MStatus next();
};
class MPlug {
  public:
    MPlug();
    MPlug(const MObject&, const MObject&);
    MPlug elementByLogicalIndex(unsigned) const;
    bool operator!=(const MObject&) const;
};
class MDataBlock {
  public:
    MDataHandle inputValue(const MObject&);
    MDataHandle outputValue(const MObject&);
    MArrayDataHandle outputArrayValue(const MObject&);
    MArrayDataHandle inputArrayValue(const MObject&);
    MStatus setClean(const MPlug&);
};
class MItGeometry {
  public:
    int count() const;
    MStatus reset();
    bool isDone() const;
    MStatus next();
    MPoint position() const;
    MStatus setPosition(const MPoint&);
    int index() const;
    MStatus allPositions(MPointArray&, MSpace::Space = MSpace::kObject) const;
    MStatus setAllPositions(const MPointArray&, MSpace::Space = MSpace::kObject);
};
class MTypeId {
  public:
    MTypeId(unsigned);
};
class MDagModifier {
  public:
    MObject createNode(const MString&, const MObject& parent = MObject::kNullObj, MStatus* = nullptr);
    MStatus renameNode(const MObject&, const MString&);
    MStatus connect(const MPlug&, const MPlug&);
};
class MPxNode {
  public:
    enum Type { kDependNode, kDeformerNode };
    virtual ~MPxNode();
    MString name() const;
    MObject thisMObject() const;
    virtual MStatus compute(const MPlug&, MDataBlock&);

  protected:
    static MStatus addAttribute(const MObject&);
    static MStatus attributeAffects(const MObject&, const MObject&);
};
class MPxGeometryFilter : public MPxNode {
  public:
    static MObject input, inputGeom, outputGeom, envelope;
    virtual MStatus deform(MDataBlock&, MItGeometry&, const MMatrix&, unsigned int);
    virtual MStatus accessoryNodeSetup(MDagModifier&);
    virtual MObject& accessoryAttribute() const;
};
class MPxDeformerNode : public MPxGeometryFilter {
  public:
    float weightValue(MDataBlock&, unsigned int, unsigned int);
};
class MFnData {
  public:
    enum Type { kMesh, kNurbsCurve, kString };
};
class MFnNumericData {
  public:
    enum Type { kInt, kDouble, kBoolean, k3Int };
};
class MFnAttribute {
  public:
    MStatus setKeyable(bool);
    MStatus setArray(bool);
    MStatus setUsesArrayDataBuilder(bool);
    MStatus setWritable(bool);
    MStatus setStorable(bool);
};
class MFnNumericAttribute : public MFnAttribute {
  public:
    MObject create(const MString&, const MString&, MFnNumericData::Type, double = 0, MStatus* = nullptr);
    MStatus setDefault(int, int, int);
    MStatus setMin(double);
    MStatus setMax(double);
};
class MFnMatrixAttribute : public MFnAttribute {
  public:
    MObject create(const MString&, const MString&);
};
class MFnEnumAttribute : public MFnAttribute {
  public:
    MObject create(const MString&, const MString&, short);
    MStatus addField(const MString&, short);
};
class MFnTypedAttribute : public MFnAttribute {
  public:
    MObject create(const MString&, const MString&, MFnData::Type, const MObject& = MObject::kNullObj,
                   MStatus* = nullptr);
};
class MFnStringData {
  public:
    MObject create(const MString&, MStatus* = nullptr);
};
class MFnUnitAttribute : public MFnAttribute {
  public:
    enum Type { kAngle, kDistance, kTime };
    MObject create(const MString&, const MString&, Type, double);
};
class MRampAttribute {
  public:
    MRampAttribute(const MObject&, const MObject&);
    static MObject createCurveRamp(const MString&, const MString&);
    void getEntries(MIntArray&, MFloatArray&, MFloatArray&, MIntArray&, MStatus* = nullptr);
};
class MFnDependencyNode {
  public:
    MFnDependencyNode(const MObject&);
    MPlug findPlug(const MString&, bool) const;
};
class MFnMesh {
  public:
    MFnMesh(const MObject&);
    MStatus getPoints(MPointArray&, MSpace::Space) const;
    MStatus getVertices(MIntArray&, MIntArray&) const;
    MStatus getUVs(MFloatArray&, MFloatArray&) const;
    MStatus getAssignedUVs(MIntArray&, MIntArray&) const;
};
class MFnNurbsCurve {
  public:
    MFnNurbsCurve(const MObject&);
    MStatus getCVs(MPointArray&, MSpace::Space) const;
    int numCVs(MStatus* = nullptr) const;
    MStatus getKnotDomain(double&, double&) const;
    MStatus getPointAtParam(double, MPoint&, MSpace::Space = MSpace::kObject) const;
};
class MGlobal {
  public:
    static void displayError(const MString&);
    static void displayWarning(const MString&);
    static MStatus executeCommand(const MString&);
    static MStatus executePythonCommand(const MString&);
};
typedef void* (*MCreatorFunction)();
typedef MStatus (*MInitializeFunction)();
class MFnPlugin {
  public:
    MFnPlugin(MObject, const char* = "", const char* = "", const char* = "");
    MStatus registerNode(const MString&, const MTypeId&, MCreatorFunction, MInitializeFunction,
                         MPxNode::Type = MPxNode::kDependNode);
    MStatus deregisterNode(const MTypeId&);
};
