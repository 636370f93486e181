#pragma once

#include <pybind11/pybind11.h>

// Each area of the module registers its functions from its own file (bind_<area>.cpp).
namespace deformkit::python {

void bindFfd(pybind11::module_& m);
void bindBarr(pybind11::module_& m);
void bindBeierNeely(pybind11::module_& m);
void bindWires(pybind11::module_& m);
void bindMeshWarp(pybind11::module_& m);
void bindWarpEngine(pybind11::module_& m);
void bindSlide(pybind11::module_& m);
void bindUvWarp(pybind11::module_& m);
void bindHost(pybind11::module_& m);
void bindPtex(pybind11::module_& m);

}  // namespace deformkit::python
