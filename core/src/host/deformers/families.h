#pragma once

// The built-in deformer families, one source each; deformers.cpp lists them in its table of types.

#include <memory>
#include <string>

#include "deformkit/host/deformer.h"

namespace deformkit::host::detail {

std::unique_ptr<Deformer> makeFfdDeformer(std::string label);         // lattice_deformers.cpp
std::unique_ptr<Deformer> makeFfdFramesDeformer(std::string label);   // lattice_deformers.cpp
std::unique_ptr<Deformer> makeTwistDeformer(std::string label);       // barr_deformers.cpp
std::unique_ptr<Deformer> makeBendDeformer(std::string label);        // barr_deformers.cpp
std::unique_ptr<Deformer> makeTaperDeformer(std::string label);       // barr_deformers.cpp
std::unique_ptr<Deformer> makeWiresDeformer(std::string label);       // wires_deformer.cpp
std::unique_ptr<Deformer> makeBeierNeelyDeformer(std::string label);  // engine_deformers.cpp
std::unique_ptr<Deformer> makeMeshWarpDeformer(std::string label);    // engine_deformers.cpp
std::unique_ptr<Deformer> makeSlideDeformer(std::string label);       // slide_deformer.cpp

}  // namespace deformkit::host::detail
