#include "ptex_command.h"

#include <charconv>
#include <map>

#include "deformkit/error.h"
#include "deformkit/io/atomic_file.h"
#include "deformkit/io/image.h"
#include "deformkit/io/obj.h"
#include "deformkit/io/udim.h"
#include "deformkit/ptex/ptex_mesh.h"
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

// The shortest text that reads back as the same float.
std::string floatText(float value) {
    char buffer[32];
    const auto end = std::to_chars(buffer, buffer + sizeof buffer, value).ptr;
    return std::string(buffer, end);
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
    const geom::Mesh mesh = io::readObj(command.mesh).mesh;
    const std::vector<float> weights =
        ptex::weightsFromPtex(mesh, command.ptex, command.channel, command.ptex.string());
    std::string text = "[";
    for (size_t v = 0; v < weights.size(); ++v) {
        if (v > 0) text += ", ";
        text += floatText(weights[v]);
    }
    text += "]\n";
    io::writeFileAtomically(command.out, text);
    return weights.size();
}

std::vector<fs::path> ptexToUdimCommand(const PtexToUdimCommand& command) {
    if (!io::hasUdimToken(command.out)) {
        throw InvalidInput(formatError("--out", "", "'" + command.out + "' has no UDIM token",
                                       "a pattern such as 'map.<UDIM>.exr'"));
    }
    const geom::Mesh mesh = io::readObj(command.mesh).mesh;
    const ptex::PtexFile file = ptex::readPtex(command.ptex);
    const ptex::PtexMesh ptexMesh(mesh, command.mesh.string());
    ptex::ToUdimOptions options;
    options.resolution = command.resolution;
    options.tiles = command.tiles;
    std::vector<fs::path> written;
    for (const ptex::UdimTile& tile :
         ptex::ptexToUdim(ptexMesh, mesh, file, command.ptex.string(), options)) {
        written.emplace_back(io::expandUdim(command.out, tile.tile));
        io::writeImage(written.back(), tile.image);
    }
    return written;
}

void ptexFromUdimCommand(const PtexFromUdimCommand& command) {
    const geom::Mesh mesh = io::readObj(command.mesh).mesh;
    std::vector<ptex::UdimTile> tiles;
    for (const io::UdimFile& f : io::findUdimFiles(command.pattern))
        tiles.push_back({f.tile, io::readImage(f.path)});
    const ptex::PtexMesh ptexMesh(mesh, command.mesh.string());
    ptex::FromUdimOptions options;
    options.ulog2 = options.vlog2 = command.faceLog2;
    options.dataType = command.type;
    const ptex::PtexFile file = ptex::udimToPtex(ptexMesh, mesh, tiles, options);
    ptex::WriteOptions write;
    write.mesh = ptex::meshData(mesh);
    ptex::writePtex(command.out, file, write);
}

void ptexFromVertexCommand(const PtexFromVertexCommand& command) {
    if (command.faceLog2 < 0) {
        throw InvalidInput(formatError("--face-res", "", "is auto", "a power of two (texels per face side)"));
    }
    const geom::Mesh mesh = io::readObj(command.mesh).mesh;
    const std::vector<float> weights = readWeights(command.weights, static_cast<size_t>(mesh.numVertices()));
    const ptex::PtexMesh ptexMesh(mesh, command.mesh.string());
    const ptex::PtexFile file =
        ptex::bakeVertexValues(ptexMesh, weights, 1, {command.faceLog2, command.faceLog2, command.type});
    ptex::WriteOptions write;
    write.mesh = ptex::meshData(mesh);
    ptex::writePtex(command.out, file, write);
}

ptex::DataType parsePtexType(const std::string& text) {
    if (text == "u8") return ptex::DataType::UInt8;
    if (text == "u16") return ptex::DataType::UInt16;
    if (text == "half") return ptex::DataType::Half;
    if (text == "float") return ptex::DataType::Float;
    throw InvalidInput(formatError("--type", "", "is '" + text + "'", "u8, u16, half or float"));
}

int8_t parseFaceResolution(const std::string& text) {
    if (text == "auto") return -1;
    int value = 0;
    const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
    if (error == std::errc() && end == text.data() + text.size() && value >= 1 && value <= 32768 &&
        (value & (value - 1)) == 0) {
        int8_t log2 = 0;
        while ((1 << log2) < value)
            ++log2;
        return log2;
    }
    throw InvalidInput(formatError("--face-res", "", "is '" + text + "'",
                                   "auto or a power of two from 1 to 32768 (texels per face side)"));
}

}  // namespace deformkit::harness
