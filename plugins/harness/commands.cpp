#include "commands.h"

#include <algorithm>
#include <iomanip>
#include <map>

#include "deformkit/error.h"
#include "deformkit/geom/half_edge.h"
#include "deformkit/io/atomic_file.h"
#include "deformkit/io/image.h"
#include "deformkit/io/obj.h"
#include "deformkit/io/udim.h"
#include "deformkit/ptex/ptex_mesh.h"
#include "demo_assets.h"
#include "demo_ptex.h"
#include "demo_slide.h"
#include "demo_uvwarp.h"
#include "demo_warps.h"
#include "slide_command.h"

namespace deformkit::harness {
namespace fs = std::filesystem;

namespace {

bool isMeshPath(const fs::path& p) {
    std::string ext = p.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
    return ext == ".obj";
}

void describeMesh(const fs::path& file, std::ostream& out) {
    const io::ObjContent obj = io::readObj(file);
    const geom::Mesh& m = obj.mesh;
    std::map<int32_t, int32_t> sizes;
    for (int32_t c : m.faceCounts())
        ++sizes[std::min(c, 5)];
    const geom::Box3 box = m.bounds();
    const geom::ManifoldReport& r = m.halfEdges().report();

    out << "mesh        " << file.string() << "\n";
    out << "vertices    " << m.numVertices() << "\n";
    out << "faces       " << m.numFaces() << " (triangles " << sizes[3] << ", quads " << sizes[4]
        << ", n-gons " << sizes[5] << ")\n";
    out << "edges       " << m.halfEdges().numEdges() << "\n";
    out << std::setprecision(6) << "bounds      (" << box.min.x << ", " << box.min.y << ", " << box.min.z
        << ") - (" << box.max.x << ", " << box.max.y << ", " << box.max.z << ")\n";
    if (m.hasUVs()) {
        out << "uvs         " << m.numUVs() << ", UDIM tiles";
        for (int t : m.udimTiles())
            out << " " << t;
        out << "\n";
    } else {
        out << "uvs         none\n";
    }
    if (!obj.groups.empty()) {
        out << "groups      " << obj.groups.size() << ":";
        for (const auto& g : obj.groups)
            out << " " << g.name << " (" << g.faces.size() << ")";
        out << "\n";
    }
    out << "components  " << r.components << "\n";
    out << "boundary    " << r.boundaryEdges << " edges" << (r.isClosed() ? " (closed)" : "") << "\n";
    out << "manifold    " << (r.isManifold() ? "yes" : "no");
    if (!r.isManifold()) {
        out << " (" << r.nonManifoldEdges.size() << " non-manifold edges, " << r.inconsistentEdges.size()
            << " flipped edges, " << r.nonManifoldVertices.size() << " non-manifold vertices)";
    }
    out << "\n";
    if (!r.isolatedVertices.empty()) out << "isolated    " << r.isolatedVertices.size() << " vertices\n";
}

void describeImage(const fs::path& file, std::ostream& out) {
    const io::ImageInfo info = io::readImageInfo(file);
    out << "image       " << file.string() << "\n";
    out << "size        " << info.width << " x " << info.height << "\n";
    out << "channels    " << info.channels;
    if (!info.channelNames.empty()) {
        out << " (";
        for (size_t i = 0; i < info.channelNames.size(); ++i)
            out << (i ? ", " : "") << info.channelNames[i];
        out << ")";
    }
    out << "\n";
    out << "type        " << info.pixelType << "\n";
    out << "format      " << info.format << "\n";
    for (const auto& [key, value] : info.attributes)
        out << "attribute   " << key << " = " << value << "\n";
}

void describeUdim(const fs::path& pattern, std::ostream& out) {
    const std::vector<io::UdimFile> files = io::findUdimFiles(pattern);
    out << "udim        " << pattern.string() << "\n";
    out << "tiles       " << files.size() << ":";
    for (const auto& f : files)
        out << " " << f.tile;
    out << "\n";
    for (const auto& f : files) {
        const io::ImageInfo info = io::readImageInfo(f.path);
        out << "  " << f.tile << "  " << f.path.filename().string() << "  " << info.width << " x "
            << info.height << ", " << info.channels << " channels, " << info.pixelType << "\n";
    }
}

}  // namespace

void describe(const fs::path& file, std::ostream& out) {
    if (io::hasUdimToken(file.string())) {
        describeUdim(file, out);
        return;
    }
    std::error_code ec;
    if (!fs::exists(file, ec)) {
        throw IoError(
            formatError(file.string(), "", "no such file", "an existing mesh, image or UDIM pattern"));
    }
    if (isMeshPath(file)) {
        describeMesh(file, out);
    } else {
        describeImage(file, out);
    }
}

void preview(const PreviewCommand& command) {
    const io::ObjContent obj = io::readObj(command.mesh);
    std::optional<io::PreviewTexture> texture;
    if (command.texture) texture = io::loadPreviewTexture(*command.texture);
    if (command.weights && command.weightsPtex) {
        throw InvalidInput(
            formatError("--weights-ptex", "", "is given with --weights", "one weights source"));
    }
    io::PreviewOptions options = command.options;
    if (command.weights || command.weightsPtex) {
        const std::vector<float> weights =
            command.weights ? readWeights(*command.weights, static_cast<size_t>(obj.mesh.numVertices()))
                            : ptex::weightsFromPtex(obj.mesh, *command.weightsPtex, command.weightsChannel,
                                                    "--weights-ptex");
        options.vertexColors.clear();
        for (float w : weights)
            options.vertexColors.push_back(io::weightColor(w));
    }
    const io::Image image = io::renderPreview(obj.mesh, options, texture ? &*texture : nullptr);
    io::writeImage(command.out, image);
}

std::vector<fs::path> demo(const DemoCommand& command) {
    io::createFolder(command.outDir);
    const DemoAssets assets = makeDemoAssets({command.resolution});
    std::vector<fs::path> written;
    const fs::path meshPath = command.outDir / "tube.obj";
    io::writeObj(meshPath, assets.mesh);
    written.push_back(meshPath);

    io::ImageWriteOptions maps;
    maps.type = io::PixelType::Half;
    maps.attributes = {{"deformkit:asset", "demo"}};
    for (const auto& [tile, image] : assets.rigidity) {
        written.push_back(command.outDir / io::expandUdim("rigidity.<UDIM>.exr", tile));
        io::writeImage(written.back(), image, maps);
    }
    for (const auto& [tile, image] : assets.mask) {
        written.push_back(command.outDir / io::expandUdim("mask.<UDIM>.exr", tile));
        io::writeImage(written.back(), image, maps);
    }
    io::PreviewTexture texture;
    for (const auto& [tile, image] : assets.albedo) {
        written.push_back(command.outDir / io::expandUdim("albedo.<UDIM>.png", tile));
        io::writeImage(written.back(), image);
        texture.tiles.emplace(tile, image);
    }
    io::PreviewOptions view;
    view.drawEdges = false;
    written.push_back(command.outDir / "preview.png");
    io::writeImage(written.back(), io::renderPreview(assets.mesh, view, &texture));
    for (fs::path& f : writeDemoWarps(assets.mesh, texture, assets.albedo.at(1001), command.outDir)) {
        written.push_back(std::move(f));
    }
    for (fs::path& f : writeDemoSlide(assets.mesh, command.outDir)) {
        written.push_back(std::move(f));
    }
    for (fs::path& f : writeDemoPtex(assets.mesh, command.outDir)) {
        written.push_back(std::move(f));
    }
    for (fs::path& f : writeDemoUvWarp(assets.mesh, assets.rigidity.at(1001), assets.mask.at(1001),
                                       assets.albedo, command.outDir)) {
        written.push_back(std::move(f));
    }
    return written;
}

scene::Scene readScene(const fs::path& path) {
    scene::SceneReadOptions options;
    options.ptexWeights = ptex::weightsFromPtex;
    return scene::readScene(path, options);
}

}  // namespace deformkit::harness
