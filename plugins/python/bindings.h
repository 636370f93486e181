#pragma once

#include <pybind11/pybind11.h>

#include <string>

#include "deformkit/uvwarp/tile_warp.h"

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
void bindPointCache(pybind11::module_& m);
void bindShotReport(pybind11::module_& m);

// Text read from a file or a header (bytes) as a str: bytes that are not UTF-8 (a Latin-1 header attribute,
// a Ptex key) become surrogate escapes (PEP 383), which encode back to the same bytes.
[[nodiscard]] pybind11::str textOf(const std::string& bytes);

// Every UV-warp option of `options` (uvwarp/options.h) as {name: value}, the names in snake_case (Python's
// keywords) or camelCase (scenes'): bool, int, float or a list of ints.
[[nodiscard]] pybind11::dict uvwarpOptionsDict(const uvwarp::TileWarpOptions& options, bool snakeCase);

}  // namespace deformkit::python
