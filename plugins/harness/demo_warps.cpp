#include "demo_warps.h"

#include <cmath>
#include <numbers>

#include "deformkit/error.h"
#include "deformkit/geom/primitives.h"
#include "deformkit/io/atomic_file.h"
#include "deformkit/io/image.h"
#include "deformkit/io/obj.h"
#include "deformkit/warp/barr.h"
#include "deformkit/warp/beier_neely.h"
#include "deformkit/warp/ffd.h"
#include "deformkit/warp/ffd_frames.h"
#include "deformkit/warp/image_warp.h"
#include "deformkit/warp/mesh_warp.h"
#include "deformkit/warp/wires.h"

namespace deformkit::harness {
namespace fs = std::filesystem;

namespace {

constexpr float kPi = std::numbers::pi_v<float>;

geom::Mesh withPoints(const geom::Mesh& tube, const std::vector<glm::vec3>& points) {
    geom::Mesh out = tube;
    out.setPoints(points);
    return out;
}

// A 3 x 3 x 3-cell lattice around the tube; the middle ring of controls pushed outwards.
std::vector<glm::vec3> ffdBulge(const geom::Mesh& tube) {
    warp::Lattice lattice;
    lattice.origin = {-1.1f, -0.1f, -1.1f};
    lattice.axes = glm::mat3(glm::vec3(2.2f, 0, 0), glm::vec3(0, 4.2f, 0), glm::vec3(0, 0, 2.2f));
    lattice.divisions = {3, 3, 3};
    warp::Ffd ffd(lattice);
    std::vector<glm::vec3> target = lattice.controlPoints();
    for (int i = 0; i <= 3; ++i) {
        for (int k = 0; k <= 3; ++k) {
            for (int j : {1, 2}) {
                glm::vec3& p = target[lattice.index(i, j, k)];
                p.x *= j == 2 ? 1.6f : 0.7f;  // bulge the upper middle, pinch the lower
                p.z *= j == 2 ? 1.6f : 0.7f;
            }
        }
    }
    ffd.setTargets(target);
    std::vector<glm::vec3> points(tube.points().begin(), tube.points().end());
    ffd.bind(points);
    ffd.evaluate(points);
    return points;
}

// A 2 x 2 x 2-cell lattice of frames whose top layer turns half a turn about the tube's axis: each top
// frame's origin and basis rotate, so the cap turns rigidly and the twist fades towards the bottom.
std::vector<glm::vec3> ffdFramesTwist(const geom::Mesh& tube) {
    warp::Lattice lattice;
    lattice.origin = {-1.1f, -0.1f, -1.1f};
    lattice.axes = glm::mat3(glm::vec3(2.2f, 0, 0), glm::vec3(0, 4.2f, 0), glm::vec3(0, 0, 2.2f));
    lattice.divisions = {2, 2, 2};
    warp::FfdFrames ffd(lattice);
    std::vector<warp::Frame> targets(ffd.targetFrames().begin(), ffd.targetFrames().end());
    const float a = 1.2f;
    const glm::mat3 rot(glm::vec3(std::cos(a), 0, -std::sin(a)), glm::vec3(0, 1, 0),
                        glm::vec3(std::sin(a), 0, std::cos(a)));
    for (int i = 0; i <= 2; ++i) {
        for (int k = 0; k <= 2; ++k) {
            warp::Frame& f = targets[lattice.index(i, 2, k)];
            f.origin = rot * f.origin;
            f.basis = rot * f.basis;
        }
    }
    ffd.setTargetFrames(targets);
    std::vector<glm::vec3> points(tube.points().begin(), tube.points().end());
    ffd.bind(points);
    ffd.evaluate(points);
    return points;
}

template <class W>
std::vector<glm::vec3> axial(const geom::Mesh& tube, W& warp) {
    std::vector<glm::vec3> points(tube.points().begin(), tube.points().end());
    warp::SparseFields unused;
    warp.bind(points, unused);
    warp.deform(points);
    return points;
}

std::vector<glm::vec3> wires(const geom::Mesh& tube, warp::WiresVariant variant) {
    // A wire along the tube's side (x = 1), lifted outwards in the middle.
    warp::Wire w;
    for (int i = 0; i <= 16; ++i) {
        const float y = 4.0f * i / 16.0f;
        w.reference.emplace_back(1.0f, y, 0.0f);
        const float lift = 0.6f * std::sin(kPi * i / 16.0f);
        w.wire.emplace_back(1.0f + lift, y, 0.0f);
    }
    w.radius = 0.9f;
    warp::WiresOptions options;
    options.variant = variant;
    warp::Wires warp({w}, options);
    std::vector<glm::vec3> points(tube.points().begin(), tube.points().end());
    warp.bind(points);
    warp.evaluate(points);
    return points;
}

std::vector<glm::vec3> meshCage(const geom::Mesh& tube) {
    // A coarse tube enclosing the surface; its top ring is scaled and shifted sideways.
    const geom::Mesh cage = geom::makeCappedTube({1.25f, 4.4f, 8, 4, 1});
    std::vector<glm::vec3> rest(cage.points().begin(), cage.points().end());
    for (auto& p : rest)
        p.y -= 0.2f;
    const geom::Mesh restCage = withPoints(cage, rest);
    std::vector<glm::vec3> target = rest;
    for (auto& p : target) {
        if (p.y > 3.0f) {
            p.x = 1.4f * p.x + 0.6f;
            p.z *= 1.4f;
        }
    }
    std::vector<glm::vec3> points(tube.points().begin(), tube.points().end());
    warp::MeshWarpOptions options;
    options.beta = 1.6f;
    warp::meshWarp(points, restCage, target, options);
    return points;
}

}  // namespace

std::vector<DemoWarp> makeDemoWarps(const geom::Mesh& tube) {
    std::vector<DemoWarp> out;
    out.push_back({"ffd", withPoints(tube, ffdBulge(tube))});
    out.push_back({"ffd_frames", withPoints(tube, ffdFramesTwist(tube))});
    const warp::AxisFrame axis{{0, 0, 0}, {0, 1, 0}, {1, 0, 0}};
    warp::TaperWarp taper(axis, warp::ProfileCurve({0.0f, 2.0f, 4.0f}, {1.0f, 0.55f, 1.3f}));
    out.push_back({"taper", withPoints(tube, axial(tube, taper))});
    warp::TwistWarp twist(axis, warp::ProfileCurve({0.0f, 4.0f}, {0.0f, kPi / 2}));
    out.push_back({"twist", withPoints(tube, axial(tube, twist))});
    warp::BendWarp bend(axis, {kPi / 2 / 3.0f, 0.5f, 0.5f, 3.5f});
    out.push_back({"bend", withPoints(tube, axial(tube, bend))});
    out.push_back({"wires", withPoints(tube, wires(tube, warp::WiresVariant::Original))});
    out.push_back({"wires_smooth", withPoints(tube, wires(tube, warp::WiresVariant::Smooth))});
    out.push_back({"mesh_warp", withPoints(tube, meshCage(tube))});
    return out;
}

std::vector<fs::path> writeDemoWarps(const geom::Mesh& tube, const io::PreviewTexture& texture,
                                     const io::Image& image, const fs::path& outDir) {
    const fs::path dir = outDir / "warps";
    io::createFolder(dir);
    std::vector<fs::path> written;
    io::PreviewOptions view;
    view.width = 480;
    view.height = 360;
    for (const DemoWarp& w : makeDemoWarps(tube)) {
        written.push_back(dir / (w.name + ".obj"));
        io::writeObj(written.back(), w.mesh);
        written.push_back(dir / (w.name + ".png"));
        io::writeImage(written.back(), io::renderPreview(w.mesh, view, &texture));
    }
    // Beier-Neely (global variant) on the side texture: the band is pulled into a wave.
    const float n = static_cast<float>(image.width);
    std::vector<warp::SegmentPair> pairs(2);
    pairs[0].srcP = {0.1f * n, 0.5f * n};
    pairs[0].srcQ = {0.5f * n, 0.5f * n};
    pairs[0].dstP = {0.1f * n, 0.4f * n};
    pairs[0].dstQ = {0.5f * n, 0.6f * n};
    pairs[1].srcP = {0.55f * n, 0.2f * n};
    pairs[1].srcQ = {0.9f * n, 0.2f * n};
    pairs[1].dstP = {0.55f * n, 0.2f * n};
    pairs[1].dstQ = {0.9f * n, 0.25f * n};
    warp::BeierNeelyOptions options;
    options.variant = warp::BeierNeelyVariant::Global;
    const auto map = warp::beierNeelyMap(image.width, image.height, pairs, options);
    written.push_back(dir / "beier_neely.png");
    io::writeImage(written.back(), warp::resampleImage(image, map, image.width, image.height));
    return written;
}

}  // namespace deformkit::harness
