#include "ptex_command.h"
#include <iostream>
#include "cli.h"
#include "uvwarp_command.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <map>

#include "deformkit/error.h"
#include "deformkit/io/atomic_file.h"
#include "deformkit/io/image.h"
#include "deformkit/io/mesh_file.h"
#include "deformkit/io/obj.h"
#include "deformkit/io/udim.h"
#include "deformkit/ptex/ptex_mesh.h"
#include "deformkit/scene/weights_file.h"
#include "slide_command.h"

namespace deformkit::harness {
namespace fs = std::filesystem;

namespace {

const char* typeName(ptex::DataType type) {
    switch (type) {
        case ptex::DataType::UInt8:
            return "u8";
        case ptex::DataType::UInt16:
            return "u16";
        case ptex::DataType::Half:
            return "half";
        case ptex::DataType::Float:
            return "float";
    }
    return "?";
}

const char* borderName(ptex::BorderMode mode) {
    return mode == ptex::BorderMode::Clamp ? "clamp" : mode == ptex::BorderMode::Black ? "black" : "periodic";
}

std::string metaText(const ptex::MetaValue& m) {
    const auto list = [](const auto& values, const char* type) {
        std::string s = type;
        s += " x ";
        s += std::to_string(values.size());
        if (values.size() <= 4) {
            s += ":";
            for (const auto& v : values) {
                s += ' ';
                s += numberText(static_cast<double>(v));
            }
        }
        return s;
    };
    switch (m.type) {
        case ptex::MetaType::String:
            return "string \"" + m.string + "\"";
        case ptex::MetaType::Int8:
            return list(m.int8s, "int8");
        case ptex::MetaType::Int16:
            return list(m.int16s, "int16");
        case ptex::MetaType::Int32:
            return list(m.int32s, "int32");
        case ptex::MetaType::Float:
            return list(m.floats, "float");
        case ptex::MetaType::Double:
            return list(m.doubles, "double");
    }
    return "";
}

}  // namespace

void ptexInfo(const fs::path& file, std::ostream& out) {
    const ptex::PtexFile f = ptex::readPtex(file);
    std::map<std::pair<int, int>, size_t> resolutions;
    size_t constant = 0, subfaces = 0, edited = 0;
    for (const ptex::FaceInfo& face : f.faces) {
        ++resolutions[{face.ures(), face.vres()}];
        constant += face.constant ? 1 : 0;
        subfaces += face.subface ? 1 : 0;
        edited += face.hasEdits ? 1 : 0;
    }
    out << "ptex        " << file.string() << "\n";
    out << "mesh type   " << (f.meshType == ptex::MeshType::Quad ? "quad" : "triangle") << "\n";
    out << "data        " << typeName(f.dataType) << " x " << f.channels << " channels";
    if (f.alphaChannel >= 0) out << ", alpha " << f.alphaChannel;
    out << "\n";
    out << "borders     u " << borderName(f.uBorderMode) << ", v " << borderName(f.vBorderMode) << "\n";
    out << "faces       " << f.faces.size() << " (constant " << constant << ", sub-faces " << subfaces
        << ", edited " << edited << ")\n";
    for (const auto& [res, count] : resolutions)
        out << "resolution  " << res.first << "x" << res.second << ": " << count << " faces\n";
    bool mesh = false;
    for (const ptex::MetaValue& m : f.metadata) {
        out << "metadata    " << m.key << " = " << metaText(m) << "\n";
        mesh = mesh || m.key == "PtexFaceVertCounts";
    }
    out << "mesh data   " << (mesh ? "yes" : "no") << "\n";
}

size_t ptexToVertexCommand(const PtexToVertexCommand& command) {
    // Checked first: a Ptex or mesh file named as --out would be overwritten with JSON.
    std::string extension = command.out.extension().string();
    std::ranges::transform(extension, extension.begin(), [](unsigned char c) { return std::tolower(c); });
    if (extension != ".json") {
        throw InvalidInput(formatError("--out", "", "is '" + command.out.string() + "'",
                                       "a weights file name ending in .json"));
    }
    const geom::Mesh mesh = io::readMesh(command.mesh).mesh;
    const std::vector<float> weights =
        ptex::weightsFromPtex(mesh, command.mesh.string(), command.ptex, command.channel, "");
    io::writeFileAtomically(command.out, scene::formatWeightsFile(weights, command.out.string()));
    return weights.size();
}

std::vector<fs::path> ptexToUdimCommand(const PtexToUdimCommand& command) {
    if (!io::hasUdimToken(command.out)) {
        throw InvalidInput(formatError("--out", "", "'" + command.out + "' has no UDIM token",
                                       "a pattern such as 'map.<UDIM>.exr'"));
    }
    const geom::Mesh mesh = io::readMesh(command.mesh).mesh;
    const ptex::PtexFile file = ptex::readPtex(command.ptex);
    const ptex::PtexMesh ptexMesh(mesh, command.mesh.string());
    ptex::ToUdimOptions options;
    options.resolution = command.resolution;
    options.tiles = command.tiles;
    options.padding = command.padding;
    options.coverageChannel = command.coverage;
    // An EXR keeps the map's precision: float for float and 16-bit data, half for half and 8-bit data
    // (every 8-bit value within half a step of 1/255). Other formats take their own default (8 bits).
    io::ImageWriteOptions write;
    std::string extension = fs::path(command.out).extension().string();
    std::ranges::transform(extension, extension.begin(), [](unsigned char c) { return std::tolower(c); });
    if (extension == ".exr") {
        write.type = file.dataType == ptex::DataType::Float || file.dataType == ptex::DataType::UInt16
                         ? io::PixelType::Float
                         : io::PixelType::Half;
    }
    // Every tile's file checked before the first is written: a tile that could not be written after
    // others were left a partial set of maps.
    for (const int tile : command.tiles.empty() ? mesh.udimTiles() : command.tiles) {
        const fs::path path = io::expandUdim(command.out, tile);
        io::requireImageWriter(path);
        io::requireWritable(path);
    }
    std::vector<fs::path> written;
    for (const ptex::UdimTile& tile :
         ptex::ptexToUdim(ptexMesh, mesh, file, command.ptex.string(), options)) {
        written.emplace_back(io::expandUdim(command.out, tile.tile));
        io::writeImage(written.back(), tile.image, write);
    }
    return written;
}

int32_t ptexFromUdimCommand(const PtexFromUdimCommand& command) {
    const geom::Mesh mesh = io::readMesh(command.mesh).mesh;
    std::vector<ptex::UdimTile> tiles;
    for (const io::UdimFile& f : io::findUdimFiles(command.pattern))
        tiles.push_back({f.tile, io::readImage(f.path), f.path.string()});
    const ptex::PtexMesh ptexMesh(mesh, command.mesh.string());
    ptex::FromUdimOptions options;
    options.ulog2 = options.vlog2 = command.faceLog2;
    options.dataType = command.type;
    const ptex::PtexFile file = ptex::udimToPtex(ptexMesh, mesh, tiles, options);
    ptex::WriteOptions write;
    write.mesh = ptex::meshData(mesh, command.mesh.string());
    ptex::writePtex(command.out, file, write);
    return mesh.numFacesWithoutUVs();
}

void ptexFromVertexCommand(const PtexFromVertexCommand& command) {
    if (command.faceLog2 < 0) {
        throw InvalidInput(formatError("--face-res", "", "is auto", "a power of two (texels per face side)"));
    }
    const geom::Mesh mesh = io::readMesh(command.mesh).mesh;
    const std::vector<float> weights =
        scene::readWeightsFile(command.weights, static_cast<size_t>(mesh.numVertices()));
    const ptex::PtexMesh ptexMesh(mesh, command.mesh.string());
    const ptex::PtexFile file =
        ptex::bakeVertexValues(ptexMesh, weights, 1, {command.faceLog2, command.faceLog2, command.type});
    ptex::WriteOptions write;
    write.mesh = ptex::meshData(mesh, command.mesh.string());
    ptex::writePtex(command.out, file, write);
}

ptex::DataType parsePtexType(const std::string& text) {
    if (text == "u8") return ptex::DataType::UInt8;
    if (text == "u16") return ptex::DataType::UInt16;
    if (text == "half") return ptex::DataType::Half;
    if (text == "float") return ptex::DataType::Float;
    throw InvalidInput(formatError("--type", "", "is '" + text + "'", "u8, u16, half or float"));
}

int8_t parseFaceResolution(const std::string& text, bool allowAuto) {
    if (text == "auto" && allowAuto) return -1;
    int value = 0;
    const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
    if (error == std::errc() && end == text.data() + text.size() && value >= 1 && value <= 32768 &&
        (value & (value - 1)) == 0) {
        int8_t log2 = 0;
        while ((1 << log2) < value)
            ++log2;
        return log2;
    }
    throw InvalidInput(formatError(
        "--face-res", "", "is '" + text + "'",
        std::string(allowAuto ? "auto or " : "") + "a power of two from 1 to 32768 (texels per face side)"));
}

namespace {

// The options of a command that writes a Ptex file: texels per face side (--face-res) and the data type
// (--type), read into the command's own fields.
void addPtexOutputOptions(Command& command, int8_t& faceLog2, ptex::DataType& type,
                          const std::string& faceRes, const std::string& faceResHelp, bool allowAuto) {
    command.option(
        "--face-res",
        [&faceLog2, allowAuto](const std::string& text) { faceLog2 = parseFaceResolution(text, allowAuto); },
        faceRes, faceResHelp);
    command.option(
        "--type", [&type](const std::string& text) { type = parsePtexType(text); }, "float",
        "u8, u16, half or float");
}

}  // namespace

void addPtexCommands(CommandLine& cli) {
    Command ptex = cli.group("ptex", "Ptex files: describe, per-vertex values, UDIM conversions");

    auto infoFile = std::make_shared<std::string>();
    cli.add(ptex, "info", "Header, faces and resolutions, metadata of a Ptex file",
            [infoFile] {
                ptexInfo(*infoFile, std::cout);
                return 0;
            })
        .option("FILE", *infoFile, "Ptex file (.ptx)")
        .required();

    auto tv = std::make_shared<PtexToVertexCommand>();
    Command toVertex =
        cli.add(ptex, "to-vertex", "Per-vertex values of a Ptex map as a JSON weights file", [tv] {
            const size_t count = ptexToVertexCommand(*tv);
            std::cout << "wrote " << tv->out.string() << ": " << count << " vertex values\n";
            return 0;
        });
    toVertex.option("FILE", tv->ptex, "Ptex file painted on MESH").required();
    toVertex.option("MESH", tv->mesh, "mesh (.obj, .gltf, .glb, .fbx, .ply, .dae)").required();
    toVertex.option("--out", tv->out, "weights file (.json)").required();
    toVertex.option("--channel", tv->channel, "channel").showDefault();

    struct ToUdim {
        PtexToUdimCommand command;
        std::string tiles;
    };
    auto tu = std::make_shared<ToUdim>();
    Command toUdim =
        cli.add(ptex, "to-udim", "Render a Ptex map into UDIM tile images through the mesh's UVs", [tu] {
            if (!tu->tiles.empty()) tu->command.tiles = parseTiles(tu->tiles);
            for (const auto& f : ptexToUdimCommand(tu->command))
                std::cout << "wrote " << f.string() << "\n";
            return 0;
        });
    toUdim.option("FILE", tu->command.ptex, "Ptex file painted on MESH").required();
    toUdim.option("MESH", tu->command.mesh, "mesh with UVs (.obj, .gltf, .glb, .fbx, .ply, .dae)").required();
    toUdim.option("--out", tu->command.out, "UDIM pattern, such as 'map.<UDIM>.exr'").required();
    toUdim.option("--resolution", tu->command.resolution, "pixels per tile side")
        .range(1, 65536)
        .showDefault();
    toUdim.option("--tiles", tu->tiles, "tiles to write, each once (default: every tile of the mesh)");
    toUdim.option("--padding", tu->command.padding, "texels of edge padding around the UV charts")
        .range(0, 65536)
        .showDefault();
    toUdim.flag("--coverage", tu->command.coverage,
                "add a last channel: 1 on the UV charts, 0 in the padding and outside them");

    auto fu = std::make_shared<PtexFromUdimCommand>();
    Command fromUdim =
        cli.add(ptex, "from-udim", "Sample UDIM tile images into a Ptex file through the mesh's UVs", [fu] {
            const int32_t withoutUVs = ptexFromUdimCommand(*fu);
            if (withoutUVs > 0) {
                std::cout << withoutUVs << (withoutUVs == 1 ? " face has" : " faces have")
                          << " no UVs: written as 0\n";
            }
            std::cout << "wrote " << fu->out.string() << "\n";
            return 0;
        });
    fromUdim.option("PATTERN", fu->pattern, "UDIM pattern, such as 'map.<UDIM>.exr'").required();
    fromUdim.option("MESH", fu->mesh, "mesh with UVs (.obj, .gltf, .glb, .fbx, .ply, .dae)").required();
    fromUdim.option("--out", fu->out, "Ptex file (.ptx)").required();
    addPtexOutputOptions(fromUdim, fu->faceLog2, fu->type, "auto",
                         "texels per face side: auto or a power of two", true);

    auto fv = std::make_shared<PtexFromVertexCommand>();
    Command fromVertex =
        cli.add(ptex, "from-vertex", "Bake per-vertex weights (a JSON weights file) into a Ptex file", [fv] {
            ptexFromVertexCommand(*fv);
            std::cout << "wrote " << fv->out.string() << "\n";
            return 0;
        });
    fromVertex.option("WEIGHTS", fv->weights, "weights file (.json), one per vertex").required();
    fromVertex.option("MESH", fv->mesh, "mesh (.obj, .gltf, .glb, .fbx, .ply, .dae)").required();
    fromVertex.option("--out", fv->out, "Ptex file (.ptx)").required();
    addPtexOutputOptions(fromVertex, fv->faceLog2, fv->type, "16", "texels per face side, a power of two",
                         false);
}

}  // namespace deformkit::harness
