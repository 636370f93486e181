// A studio plugin's view of DeformKit: headers and deformkit::core from an installed package.
#include <cstdio>

#include "deformkit/error.h"
#include "deformkit/geom/half_edge.h"
#include "deformkit/geom/primitives.h"
#include "deformkit/version.h"

// OpenMP is a private dependency of the library: a consumer is not compiled with -fopenmp because of it.
#ifdef _OPENMP
#error "deformkit::core passed -fopenmp to a consumer"
#endif

int main() {
    const deformkit::geom::Mesh grid = deformkit::geom::makeGrid({4, 4});
    if (!grid.halfEdges().report().isManifold()) return 1;
    std::printf("deformkit %s grid %d vertices %d faces\n", deformkit::kVersionString, grid.numVertices(),
                grid.numFaces());
    return 0;
}
