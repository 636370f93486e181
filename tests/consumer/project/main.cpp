// A studio plugin's view of DeformKit: headers and deformkit::core from an installed package.
#include <cstdio>

#include "deformkit/error.h"
#include "deformkit/geom/half_edge.h"
#include "deformkit/geom/primitives.h"
#include "deformkit/io/image.h"
#include "deformkit/version.h"

// OpenMP is a private dependency of the library: a consumer is not compiled with -fopenmp because of it.
#ifdef _OPENMP
#error "deformkit::core passed -fopenmp to a consumer"
#endif

int main() {
    const deformkit::geom::Mesh grid = deformkit::geom::makeGrid({4, 4});
    if (!grid.halfEdges().report().isManifold()) return 1;
    // An image through the OpenImageIO module copied beside this binary.
    deformkit::io::Image image(3, 2, 1, 0.25f);
    deformkit::io::writeImage("consumer.exr", image);
    const deformkit::io::Image back = deformkit::io::readImage("consumer.exr");
    std::printf("deformkit %s grid %d vertices %d faces image %dx%d %g\n", deformkit::kVersionString,
                grid.numVertices(), grid.numFaces(), back.width, back.height, double(back.pixels.at(5)));
    return 0;
}
