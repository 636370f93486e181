// `deformkit info FILE`: a mesh, an image or the tiles of a UDIM pattern.
#include <algorithm>
#include <iomanip>
#include <iostream>
#include <map>

#include "cli.h"
#include "commands.h"
#include "deformkit/error.h"
#include "deformkit/geom/half_edge.h"
#include "deformkit/geom/weld.h"
#include "deformkit/io/image.h"
#include "deformkit/io/mesh_file.h"
#include "deformkit/io/obj.h"
#include "deformkit/io/point_cache.h"
#include "deformkit/io/udim.h"

namespace deformkit::harness {
namespace fs = std::filesystem;

namespace {

void describeMesh(const fs::path& file, std::ostream& out) {
    const io::ObjContent obj = io::readMesh(file);
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
    const geom::Welding weld = geom::weldVertices(m, 0.0, file.string());
    if (weld.merged() > 0) {
        out << "split       " << weld.merged() << " vertices are copies of a coincident vertex ("
            << weld.firstOf.size()
            << " distinct): connectivity-based tools (slide, previews' normals, mesh warp) weld them\n";
    }
    if (obj.repairedFaces > 0) {
        out << "repaired    " << obj.repairedFaces << (obj.repairedFaces == 1 ? " polygon" : " polygons")
            << " that visited a vertex twice (first "
            << (obj.firstRepairedLine > 0 ? "on line " + std::to_string(obj.firstRepairedLine)
                                          : "at " + obj.firstRepairedFace)
            << "): repeats dropped, split into loops\n";
    }
    out << std::setprecision(6) << "bounds      (" << box.min.x << ", " << box.min.y << ", " << box.min.z
        << ") - (" << box.max.x << ", " << box.max.y << ", " << box.max.z << ")\n";
    if (m.hasUVs()) {
        out << "uvs         " << m.numUVs() << ", UDIM tiles";
        for (int t : m.udimTiles())
            out << " " << t;
        out << "\n";
        if (obj.facesWithoutUVs > 0) {
            out << "warning     " << obj.facesWithoutUVs
                << (obj.facesWithoutUVs == 1 ? " face has" : " faces have") << " no UVs (first on line "
                << obj.firstLineWithoutUVs << "): in no UDIM tile, left alone by texture-space work\n";
        }
        const geom::UdimOverhang overhang = geom::udimOverhang(m);
        if (overhang.faces > 0) {
            out << "warning     " << overhang.faces
                << (overhang.faces == 1 ? " face overhangs its" : " faces overhang their")
                << " UDIM tile, by up to " << overhang.worst << " of a tile (face " << overhang.worstFace
                << (overhang.worst > 0.1f ? "); the UV warp refuses faces past 0.1 of a tile\n"
                                          : "); the UV warp takes them (up to 0.1 of a tile)\n");
        }
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
    // The header alone does not say the file is whole: the pixels are read too, so a truncated or corrupt
    // file is an error (exit 2) before anything is printed.
    (void)io::readImage(file);
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

void describeCache(const fs::path& file, std::ostream& out) {
    const io::PointCache cache(file);
    const std::vector<int> frames = cache.frames();
    out << "point cache " << file.string() << "\n";
    out << "format      " << io::formatName(cache.format()) << "\n";
    out << "vertices    " << cache.vertexCount() << "\n";
    out << "samples     " << cache.sampleCount() << " (every " << cache.sampling() << " frame)\n";
    out << "frames      ";
    if (frames.empty()) {
        out << "none\n";
    } else {
        out << frames.front() << "-" << frames.back() << " (" << frames.size() << " whole frames)\n";
    }
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
        (void)io::readImage(f.path);  // each tile whole (see describeImage)
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
    if (fs::is_regular_file(file, ec) && fs::file_size(file, ec) == 0 && !ec) {
        // Nothing to tell its format by (an image reader probes a file's first bytes).
        throw ParseError(
            formatError(file.string(), "", "is empty (0 bytes)", "a mesh, a point cache or an image"));
    }
    if (io::meshFormat(file)) {
        describeMesh(file, out);
    } else if (io::pointCacheFormat(file)) {
        describeCache(file, out);
    } else if (io::isImageFileName(file)) {
        describeImage(file, out);
    } else {
        throw InvalidInput(
            formatError(file.string(), "", "is neither a mesh, a point cache nor an image",
                        std::string("a mesh (") + io::kMeshExtensions +
                            "), a point cache (.pc2, .mdd) or an image OpenImageIO reads (.exr, "
                            ".png, .tif, .jpg, ...)"));
    }
}

void addInfoCommand(CommandLine& cli) {
    auto file = std::make_shared<std::string>();
    Command info =
        cli.add("info", "Describe a mesh, a point cache, an image, or the tiles of a UDIM pattern", [file] {
            describe(*file, std::cout);
            return 0;
        });
    info.option(
            "FILE", *file,
            "mesh (.obj, .gltf, .glb, .fbx, .ply, .dae), point cache (.pc2, .mdd), image, or pattern with "
            "<UDIM>, <UVTILE>, %(UDIM)d or _MAPID_")
        .required();
}

}  // namespace deformkit::harness
