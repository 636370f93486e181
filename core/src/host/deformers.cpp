#include "deformkit/host/deformers.h"

#include <array>
#include <string>

#include "deformkit/error.h"
#include "host/deformers/families.h"

namespace deformkit::host {
namespace {

constexpr std::array kTypes = {
    DeformerType{
        "beierneely",
        "Beier and Neely's feature-based warp (warp/beier_neely.h, through the generic engine) in the XY "
        "plane of the scene; z is kept. A feature is a directed segment P -> Q; a point moves with the "
        "frame of every feature, weighted by (|Q - P|^p / (a + distance to the rest feature))^b, the "
        "weights taken on the rest mesh at bind.",
        detail::makeBeierNeelyDeformer},
    DeformerType{
        "bend",
        "Maya's nonLinear bend (warp/barr_dcc.h fromMayaBend) on Barr's bend, bending along handle Y "
        "towards handle +X.",
        detail::makeBendDeformer},
    DeformerType{"ffd",
                 "Free-form deformation over a Bernstein or B-spline lattice (warp/ffd.h, the fast path).",
                 detail::makeFfdDeformer},
    DeformerType{
        "ffdframes",
        "FFD with coordinate-frame controls (warp/ffd_frames.h, the fast path): each control carries a "
        "target frame, so rotating or scaling a control turns or scales the model about it, which plain "
        "FFD cannot do. The source frames are (P_ijk, identity), hence T_ijk<p> = B*_ijk (p - P_ijk) + "
        "P*_ijk; with every basis the identity this is ffd exactly.",
        detail::makeFfdFramesDeformer},
    DeformerType{
        "meshwarp",
        "The coarse-mesh warp (warp/mesh_warp.h, through the generic engine): the vertices of a control "
        "cage (any polygon mesh near the surface, boundaries allowed) with their edge stars move the "
        "surface; a vertex's weight reaches beta times its longest edge around it and, along each edge, "
        "up to mu of the edge.",
        detail::makeMeshWarpDeformer},
    DeformerType{
        "slide",
        "Pinskiy's sliding deformer with one handle (slide/slider.h). It slides over the surface it "
        "receives (the deformed output of the deformers before it), with the displacement in that space; "
        "weights and envelope scale the tangent displacement before the walk, so slid vertices stay on "
        "that surface.",
        detail::makeSlideDeformer},
    DeformerType{
        "taper",
        "Barr's taper with a handle in the Maya style: the two coordinates across handle Y are scaled by "
        "startScale at lowBound and endScale at highBound, linearly in between, held beyond.",
        detail::makeTaperDeformer},
    DeformerType{"twist", "Maya's nonLinear twist (warp/barr_dcc.h fromMayaTwist) on Barr's twist.",
                 detail::makeTwistDeformer},
    DeformerType{"wires",
                 "Singh and Fiume's Wires (warp/wires.h, the fast path), one wire or several; curves are "
                 "polylines.",
                 detail::makeWiresDeformer},
};

}  // namespace

std::span<const DeformerType> deformerTypes() {
    return kTypes;
}

std::unique_ptr<Deformer> makeDeformer(std::string_view type, const std::string& label) {
    if (label.empty()) {
        throw InvalidInput(
            formatError(std::string(type) + " deformer", "label", "is empty", "a non-empty label"));
    }
    std::string known;
    for (const DeformerType& t : kTypes) {
        if (t.name == type) return t.make(label);
        known += (known.empty() ? "" : ", ") + std::string(t.name);
    }
    throw InvalidInput(formatError("deformer '" + label + "'", "type '" + std::string(type) + "'",
                                   "is unknown", "one of: " + known));
}

}  // namespace deformkit::host
