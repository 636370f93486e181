#pragma once

// A Maya mesh (MFnMesh on a mesh data object) as DeformKit mesh data, shared by the plugin's nodes.

#include <maya/MFloatArray.h>
#include <maya/MFnMesh.h>
#include <maya/MFnTypedAttribute.h>
#include <maya/MIntArray.h>
#include <maya/MPointArray.h>

#include "deformkit/geom/mesh.h"

namespace deformkit::maya {

// A mesh input attribute (a rest mesh, a cage, the deformed mesh), for the node to add.
inline MObject meshAttribute(const char* name, const char* shortName) {
    MFnTypedAttribute typed;
    return typed.create(name, shortName, MFnData::kMesh);
}

// Points (the data's object space), faces, and with `withUVs` the current UV set per face corner.
inline geom::Mesh::Data meshDataOf(const MObject& data, bool withUVs) {
    MFnMesh fn(data);
    MPointArray points;
    fn.getPoints(points, MSpace::kObject);
    MIntArray counts, indices;
    fn.getVertices(counts, indices);
    geom::Mesh::Data d;
    d.points.reserve(points.length());
    for (unsigned i = 0; i < points.length(); ++i)
        d.points.emplace_back(static_cast<float>(points[i].x), static_cast<float>(points[i].y),
                              static_cast<float>(points[i].z));
    for (unsigned i = 0; i < counts.length(); ++i)
        d.faceCounts.push_back(counts[i]);
    for (unsigned i = 0; i < indices.length(); ++i)
        d.faceIndices.push_back(indices[i]);
    if (withUVs) {
        MFloatArray us, vs;
        fn.getUVs(us, vs);
        MIntArray uvCounts, uvIds;
        fn.getAssignedUVs(uvCounts, uvIds);
        for (unsigned i = 0; i < us.length(); ++i)
            d.uvs.emplace_back(us[i], vs[i]);
        for (unsigned i = 0; i < uvIds.length(); ++i)
            d.uvIndices.push_back(uvIds[i]);
    }
    return d;
}

}  // namespace deformkit::maya
