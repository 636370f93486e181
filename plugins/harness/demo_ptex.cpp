#include "demo_ptex.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numbers>

#include "deformkit/error.h"
#include "deformkit/io/atomic_file.h"
#include "deformkit/io/obj.h"
#include "deformkit/io/preview.h"
#include "deformkit/ptex/ptex_mesh.h"
#include "deformkit/slide/slider.h"
#include "demo_slide.h"

namespace deformkit::harness {
namespace fs = std::filesystem;

double demoStar(const glm::dvec3& point, double centreAngle, double centreY) {
    // Arc length round the unit tube and height, relative to the centre; the star's radius swings between
    // 0.45 (between the points) and 0.95 (at the points) with the polar angle, one point straight up.
    double dAngle = std::atan2(point.z, point.x) - centreAngle;
    dAngle -= 2.0 * std::numbers::pi * std::round(dAngle / (2.0 * std::numbers::pi));
    const double s = dAngle, t = point.y - centreY;
    const double r = std::hypot(s, t), phi = std::atan2(t, s) - 0.5 * std::numbers::pi;
    const double radius = 0.45 + 0.5 * std::pow(0.5 + 0.5 * std::cos(5.0 * phi), 2.0);
    const double x = std::clamp((r - (radius - 0.3)) / 0.6, 0.0, 1.0);
    return 1.0 - x * x * (3.0 - 2.0 * x);  // 1 - smoothstep
}

DemoPtex makeDemoPtex(const geom::Mesh& tube) {
    geom::Mesh::Data data;
    data.points.assign(tube.points().begin(), tube.points().end());
    data.faceCounts.assign(tube.faceCounts().begin(), tube.faceCounts().end());
    data.faceIndices.assign(tube.faceIndices().begin(), tube.faceIndices().end());
    DemoPtex demo{geom::Mesh(std::move(data), "demo tube"), {}, {}, {}};

    // The slide of the demo (same handle and drive), painted around its handle.
    DemoSlide slide = makeDemoSlide(demo.mesh);
    const glm::dvec3 centre(demo.mesh.points()[slide.handle.vertex]);
    const double centreAngle = std::atan2(centre.z, centre.x), centreY = centre.y;

    // Paint: every texel centre's point on the face (the Ptex face's corner weights), the star there.
    const ptex::PtexMesh ptexMesh(demo.mesh, "demo tube");
    ptex::PtexFile& file = demo.falloff;
    file.dataType = ptex::DataType::Float;
    file.channels = 1;
    file.faces = ptexMesh.faceInfos(3, 3);
    file.texels.resize(file.faces.size());
    file.constData.assign(file.faces.size() * 4, 0);
    std::vector<double> weights;
    for (int32_t p = 0; p < ptexMesh.numPtexFaces(); ++p) {
        const auto corners = ptexMesh.faceVertices(ptexMesh.meshFace(p));
        weights.resize(corners.size());
        file.texels[p].resize(64 * 4);
        for (int32_t j = 0; j < 8; ++j) {
            for (int32_t i = 0; i < 8; ++i) {
                ptexMesh.cornerWeights(p, (i + 0.5) / 8.0, (j + 0.5) / 8.0, weights);
                glm::dvec3 at(0.0);
                for (size_t k = 0; k < corners.size(); ++k)
                    at += weights[k] * glm::dvec3(demo.mesh.points()[corners[k]]);
                const auto value = static_cast<float>(demoStar(at, centreAngle, centreY));
                std::memcpy(file.texels[p].data() + 4 * (j * 8 + i), &value, 4);
            }
        }
    }
    demo.weights = ptex::vertexValues(ptexMesh, file, "falloff.ptx");

    const std::vector<slide::SlideHandle> handles = {slide.handle};
    // 0.6 of the demo slide's drive: across the painted edge (0.6 wide) the weighted displacement changes
    // by less than the distance between two points, so the slid star does not fold over itself.
    const std::vector<slide::SlideDrive> drives = {{0.6 * slide.displacement}};
    demo.slid = demo.mesh;
    demo.slid.setPoints(slide::slide(demo.mesh, handles, drives, demo.weights));
    return demo;
}

std::vector<fs::path> writeDemoPtex(const geom::Mesh& tube, const fs::path& outDir) {
    const fs::path dir = outDir / "ptex";
    io::createFolder(dir);
    const DemoPtex demo = makeDemoPtex(tube);
    std::vector<fs::path> written;
    written.push_back(dir / "tube.obj");
    io::writeObj(written.back(), demo.mesh);
    written.push_back(dir / "tube_slid.obj");
    io::writeObj(written.back(), demo.slid);
    written.push_back(dir / "falloff.ptx");
    ptex::WriteOptions options;
    options.mesh = ptex::meshData(demo.mesh);
    ptex::writePtex(written.back(), demo.falloff, options);

    // The weights as read back from the file, as `deformkit preview --weights-ptex` shows them.
    io::PreviewOptions view = demoSlideView();
    const std::vector<float> weights = ptex::weightsFromPtex(demo.mesh, "demo tube", written.back(), 0, "");
    for (float w : weights)
        view.vertexColors.push_back(io::weightColor(w));
    const io::Image before = io::renderPreview(demo.mesh, view);
    const io::Image after = io::renderPreview(demo.slid, view);
    written.push_back(dir / "before.png");
    io::writeImage(written.back(), before);
    written.push_back(dir / "after.png");
    io::writeImage(written.back(), after);
    written.push_back(dir / "ptex.png");
    io::writeImage(written.back(), sideBySide(before, after, 8));
    return written;
}

}  // namespace deformkit::harness
