#include "deformkit/io/mesh_file.h"

#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <array>
#include <assimp/DefaultLogger.hpp>
#include <assimp/Importer.hpp>
#include <assimp/LogStream.hpp>
#include <cctype>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <map>
#include <mutex>
#include <numeric>
#include <optional>
#include <set>
#include <span>
#include <sstream>
#include <string>
#include <system_error>
#include <tuple>
#include <utility>
#include <vector>

#include <zlib.h>
#include <nlohmann/json.hpp>

#include "deformkit/error.h"
#include "deformkit/io/read_file.h"
#include "polygon_loops.h"

namespace deformkit::io {
namespace fs = std::filesystem;

namespace {

// Exact position key for welding assimp's per-corner vertices.
using PositionKey = std::tuple<float, float, float>;

// A mesh's rest positions where pre-transforming its vertices by its node is wrong: a mesh skinned to
// joints, or with morph targets at non-zero default weights.
// - glTF places a skinned mesh by its joints alone (the mesh node's own transform is ignored):
//     p = sum_j w_j (G(joint_j) * offset_j) (v + sum_k m_k (target_k - v)),
//   G the joint nodes' global transforms as the file poses them, offset_j their inverse bind matrices, m_k
//   the default morph weights: what Blender's importer shows at rest.
// - Collada (Placement::NodeThenJoints): p = N * sum_j w_j (F(joint_j) * offset_j) v, N the global
//   transform of the node instancing the skin, F a joint's transform in the file's space (below assimp's
//   root, which holds the up-axis and unit conversion N already has). assimp folds the bind shape matrix B
//   into each offset (offset_j = inverse bind_j * B), so at the bind pose p = N * B * v: Blender writes the
//   mesh node under its armature's node and the mesh's placement relative to the armature as B, and
//   assimp's pre-transform (N * v) would leave B out. Exact where the file's joints are at their bind pose
//   (Blender writes the rest pose) or its skin node is at the origin (the Collada specification's skin);
//   a posed joint under a moved skin node is turned about the node's frame as well (assimp gives B only
//   folded into the offsets). A vertex no joint weighs goes with the first joint.
class RestPose {
  public:
    enum class Placement { JointsOnly, NodeThenJoints };

    // Whether `scene` has such a mesh; only then is the file read without assimp's pre-transform.
    static bool needed(const aiScene& scene) {
        for (unsigned m = 0; m < scene.mNumMeshes; ++m) {
            const aiMesh& mesh = *scene.mMeshes[m];
            if (mesh.HasBones()) return true;
            for (unsigned k = 0; k < mesh.mNumAnimMeshes; ++k)
                if (mesh.mAnimMeshes[k]->mWeight != 0.0f) return true;
        }
        return false;
    }

    RestPose(const aiScene& scene, Placement placement) : scene_(scene), placement_(placement) {
        visit(*scene.mRootNode, aiMatrix4x4());
    }

    // False when a mesh is placed by no node or by several (instances): the caller keeps assimp's
    // pre-transform then.
    [[nodiscard]] bool placesEveryMeshOnce() const {
        for (unsigned m = 0; m < scene_.mNumMeshes; ++m)
            if (placements_.count(m) != 1) return false;
        return true;
    }

    // The rest positions of mesh m, in world space.
    [[nodiscard]] std::vector<aiVector3D> positions(unsigned m) const {
        const aiMesh& mesh = *scene_.mMeshes[m];
        std::vector<aiVector3D> v(mesh.mVertices, mesh.mVertices + mesh.mNumVertices);
        for (unsigned k = 0; k < mesh.mNumAnimMeshes; ++k) {
            const aiAnimMesh& target = *mesh.mAnimMeshes[k];
            if (target.mWeight == 0.0f || !target.HasPositions() || target.mNumVertices != mesh.mNumVertices)
                continue;
            for (unsigned i = 0; i < mesh.mNumVertices; ++i)
                v[i] += target.mWeight * (target.mVertices[i] - mesh.mVertices[i]);
        }
        const aiMatrix4x4 node = placements_.find(m)->second;
        if (!mesh.HasBones()) {
            for (aiVector3D& p : v)
                p = node * p;
            return v;
        }
        std::vector<aiVector3D> skinned(v.size(), aiVector3D(0, 0, 0));
        std::vector<double> weight(v.size(), 0.0);
        // Where a vertex no joint moves goes: with the mesh's node; in Collada with the first joint, whose
        // offset holds the bind shape matrix the node alone would leave out (at the bind pose, N * B * v).
        aiMatrix4x4 unweighted = node;
        for (unsigned b = 0; b < mesh.mNumBones; ++b) {
            const aiBone& bone = *mesh.mBones[b];
            const aiNode* joint = scene_.mRootNode->FindNode(bone.mName);
            aiMatrix4x4 toWorld = node * bone.mOffsetMatrix;
            if (joint != nullptr) {
                toWorld = placement_ == Placement::JointsOnly ? global(*joint) * bone.mOffsetMatrix
                                                              : node * belowRoot(*joint) * bone.mOffsetMatrix;
            }
            if (b == 0 && placement_ == Placement::NodeThenJoints) unweighted = toWorld;
            for (unsigned i = 0; i < bone.mNumWeights; ++i) {
                const aiVertexWeight& w = bone.mWeights[i];
                if (w.mVertexId >= v.size()) continue;
                skinned[w.mVertexId] += w.mWeight * (toWorld * v[w.mVertexId]);
                weight[w.mVertexId] += w.mWeight;
            }
        }
        // Weights that do not sum to 1 are normalised; a vertex no joint moves stays with the mesh's node.
        for (size_t i = 0; i < v.size(); ++i)
            v[i] = weight[i] > 0.0 ? skinned[i] / static_cast<float>(weight[i]) : unweighted * v[i];
        return v;
    }

  private:
    void visit(const aiNode& n, const aiMatrix4x4& parent) {
        const aiMatrix4x4 g = parent * n.mTransformation;
        for (unsigned i = 0; i < n.mNumMeshes; ++i)
            placements_.emplace(n.mMeshes[i], g);
        for (unsigned c = 0; c < n.mNumChildren; ++c)
            visit(*n.mChildren[c], g);
    }

    static aiMatrix4x4 global(const aiNode& n) {
        aiMatrix4x4 g = n.mTransformation;
        for (const aiNode* p = n.mParent; p; p = p->mParent)
            g = p->mTransformation * g;
        return g;
    }

    // The node's transform in the file's own space: without the root's, where assimp puts its conversions
    // (a Collada file's up axis and unit), which the node instancing the skin applies once.
    static aiMatrix4x4 belowRoot(const aiNode& n) {
        aiMatrix4x4 g = n.mTransformation;
        for (const aiNode* p = n.mParent; p && p->mParent; p = p->mParent)
            g = p->mTransformation * g;
        return n.mParent ? g : aiMatrix4x4();
    }

    const aiScene& scene_;
    Placement placement_;
    std::multimap<unsigned, aiMatrix4x4> placements_;
};

// A PLY's header declares its elements; assimp does not check that the file holds them. An ASCII PLY with
// fewer lines than declared gets the missing elements made up from copies of the last lines (1000 vertices
// declared, 4 given: 996 made up), and a binary PLY cut short fails with "aiMesh::mFaces[0]::mIndices[1] is
// out of range", which does not say the file is short. Both are checked here first: an ASCII file's data
// lines are counted, a binary file's elements walked (list properties by their counts) to where they end.
struct PlyProperty {
    int32_t size = 0;      // bytes of a scalar, or of a list's count
    int32_t itemSize = 0;  // bytes of a list's items; 0 for a scalar
    bool unsignedCount = false;
    bool integerItems = false;  // a list of an integer type (face indices)
    std::string name;
};
struct PlyElement {
    std::string name;
    int64_t count = 0;
    std::vector<PlyProperty> properties;
};

// Bytes of a PLY scalar type, 0 for an unknown one.
int32_t plyTypeSize(const std::string& type) {
    static const std::map<std::string, int32_t> sizes = {
        {"char", 1},  {"uchar", 1},   {"int8", 1},   {"uint8", 1},  {"short", 2}, {"ushort", 2},
        {"int16", 2}, {"uint16", 2},  {"int", 4},    {"uint", 4},   {"int32", 4}, {"uint32", 4},
        {"float", 4}, {"float32", 4}, {"double", 8}, {"float64", 8}};
    const auto it = sizes.find(type);
    return it == sizes.end() ? 0 : it->second;
}

void requireCompletePly(const fs::path& path) {
    const std::string text = readFile(path, "PLY file");
    std::istringstream in(text);
    std::string line, format;
    std::vector<PlyElement> elements;
    bool ended = false;
    int64_t lineNumber = 0;
    while (std::getline(in, line)) {
        ++lineNumber;
        std::istringstream words(line);
        std::string keyword;
        words >> keyword;
        if (keyword == "format") {
            words >> format;
        } else if (keyword == "element") {
            PlyElement element;
            element.count = -1;
            std::string count;
            words >> element.name >> count;
            // Read as whole digits: a count beyond int64 saturated and overflowed the total below, and
            // assimp takes it modulo 2^32 (2^64 + 1000 read 1000 faces made up from the last line).
            if (!count.empty() && std::all_of(count.begin(), count.end(),
                                              [](unsigned char c) { return std::isdigit(c) != 0; })) {
                const std::string digits = count.substr(std::min(count.find_first_not_of('0'), count.size()));
                if (digits.size() > 10 || (digits.size() == 10 && digits > "2147483647")) {
                    throw InvalidInput(
                        formatError(path.string(), "line " + std::to_string(lineNumber),
                                    "element " + element.name + " declares " + count + " elements",
                                    "at most 2147483647 elements"));
                }
                element.count = digits.empty() ? 0 : std::stoll(digits);
            }
            elements.push_back(std::move(element));
        } else if (keyword == "property" && !elements.empty()) {
            std::string type;
            words >> type;
            PlyProperty property;
            if (type == "list") {
                std::string countType, itemType;
                words >> countType >> itemType >> property.name;
                property.size = plyTypeSize(countType);
                property.itemSize = plyTypeSize(itemType);
                property.unsignedCount = countType.starts_with('u');
                property.integerItems = itemType.find("float") == std::string::npos && itemType != "double";
                // A count of floating-point type is left to assimp, as an unknown type is.
                const bool integer = countType.find("float") == std::string::npos && countType != "double";
                if (property.itemSize == 0 || !integer) property.size = 0;
            } else {
                property.size = plyTypeSize(type);
                words >> property.name;
            }
            elements.back().properties.push_back(property);
        } else if (keyword == "end_header") {
            ended = true;
            break;
        }
    }
    // A header cut short (no end_header) keeps assimp's reader looping: refused here.
    if (!ended && text.starts_with("ply")) {
        throw InvalidInput(formatError(
            path.string(), "", "has no end_header line after " + std::to_string(lineNumber) + " header lines",
            "a PLY header ending in end_header (a file cut short in its header)"));
    }
    // Positions: assimp reads a vertex element without x, y or z as zeros.
    for (const PlyElement& element : elements) {
        if (element.name != "vertex") continue;
        for (const char* axis : {"x", "y", "z"}) {
            const bool has = std::any_of(element.properties.begin(), element.properties.end(),
                                         [&](const PlyProperty& p) { return p.name == axis; });
            if (!has) {
                throw InvalidInput(formatError(path.string(), "element vertex",
                                               std::string("has no property ") + axis,
                                               "vertex positions as properties x, y and z"));
            }
        }
    }
    // What assimp refuses on its own (an unknown type, a negative count) is left to it.
    if (!ended) return;
    for (const PlyElement& element : elements) {
        if (element.count < 0) return;
        for (const PlyProperty& property : element.properties)
            if (property.size == 0) return;
    }
    std::string declared;
    for (const PlyElement& element : elements)
        declared += (declared.empty() ? "" : " and ") + std::to_string(element.count) + " " + element.name;
    if (format == "ascii") {
        const std::streampos data = in.tellg();
        int64_t lines = 0;
        while (std::getline(in, line))
            if (line.find_first_not_of(" \t\r") != std::string::npos) ++lines;
        int64_t total = 0;
        for (const PlyElement& element : elements)
            total += element.count;
        if (lines < total) {
            throw InvalidInput(formatError(
                path.string(), "",
                "declares " + declared + " elements but holds " + std::to_string(lines) + " data lines",
                "one line per element the header declares (an ASCII PLY cut short or with a wrong count)"));
        }
        // Each element on its own line with one value per scalar property and a list's count, then its items:
        // assimp reads the values as a stream, so a line short of a value takes the next line's first one.
        in.clear();
        in.seekg(data);
        size_t e = 0;
        int64_t index = 0;
        while (std::getline(in, line)) {
            ++lineNumber;
            if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
            while (e < elements.size() && index == elements[e].count) {
                ++e;
                index = 0;
            }
            // Lines after the declared elements: assimp ignores them, the header's counts too small.
            if (e == elements.size()) {
                throw InvalidInput(
                    formatError(path.string(), "line " + std::to_string(lineNumber),
                                "holds data after the " + declared + " elements its header declares",
                                "a header whose element counts cover the file's data (a count too small "
                                "drops the rest)"));
            }
            const PlyElement& element = elements[e];
            std::istringstream values(line);
            const std::vector<std::string> tokens{std::istream_iterator<std::string>(values), {}};
            size_t needed = 0;
            for (const PlyProperty& property : element.properties) {
                if (property.itemSize == 0) {
                    ++needed;
                    continue;
                }
                if (needed >= tokens.size()) break;
                const std::string& count = tokens[needed];
                const bool whole = !count.empty() && count.size() < 10 &&
                                   count.find_first_not_of("0123456789") == std::string::npos;
                const size_t items = whole ? static_cast<size_t>(std::stoul(count)) : 0;
                // Integer items (face indices) whole numbers: assimp reads 2.5 as 2.
                for (size_t k = needed + 1; property.integerItems && k <= needed + items && k < tokens.size();
                     ++k) {
                    const std::string& item = tokens[k];
                    const size_t digits = !item.empty() && (item[0] == '+' || item[0] == '-') ? 1 : 0;
                    if (item.size() == digits ||
                        item.find_first_not_of("0123456789", digits) != std::string::npos) {
                        throw InvalidInput(
                            formatError(path.string(),
                                        "line " + std::to_string(lineNumber) + " (" + element.name + " " +
                                            std::to_string(index) + ")",
                                        "holds '" + item + "' in its list " + property.name,
                                        "whole numbers, as the header's integer list type declares"));
                    }
                }
                needed += 1 + items;
            }
            if (tokens.size() != needed) {
                throw InvalidInput(formatError(
                    path.string(),
                    "line " + std::to_string(lineNumber) + " (" + element.name + " " + std::to_string(index) +
                        ")",
                    "holds " + std::to_string(tokens.size()) + " values",
                    std::to_string(needed) + ", as the header's properties of " + element.name + " declare"));
            }
            ++index;
        }
        return;
    }
    const bool big = format == "binary_big_endian";
    if (!big && format != "binary_little_endian") return;
    const auto fileSize = static_cast<uint64_t>(text.size());
    auto at = static_cast<uint64_t>(in.tellg() < 0 ? text.size() : static_cast<size_t>(in.tellg()));
    const auto shortAt = [&](const PlyElement& element, int64_t index) {
        throw InvalidInput(formatError(path.string(), "",
                                       "is cut short: the file has " + std::to_string(fileSize) +
                                           " bytes and ends in " + element.name + " " +
                                           std::to_string(index) + " of " + std::to_string(element.count),
                                       "the " + declared + " elements its header declares"));
    };
    for (const PlyElement& element : elements) {
        const bool lists = std::any_of(element.properties.begin(), element.properties.end(),
                                       [](const PlyProperty& p) { return p.itemSize > 0; });
        if (!lists) {
            uint64_t stride = 0;
            for (const PlyProperty& property : element.properties)
                stride += static_cast<uint64_t>(property.size);
            const uint64_t left = fileSize - std::min(at, fileSize);
            if (stride > 0 && left / stride < static_cast<uint64_t>(element.count))
                shortAt(element, static_cast<int64_t>(left / stride));
            at += stride * static_cast<uint64_t>(element.count);
            continue;
        }
        for (int64_t i = 0; i < element.count; ++i) {
            for (const PlyProperty& property : element.properties) {
                const auto size = static_cast<uint64_t>(property.size);
                if (at + size > fileSize) shortAt(element, i);
                if (property.itemSize == 0) {
                    at += size;
                    continue;
                }
                uint64_t items = 0;  // the list's count, in the file's byte order
                for (uint64_t k = 0; k < size; ++k) {
                    const auto byte = static_cast<unsigned char>(text[at + (big ? k : size - 1 - k)]);
                    items = (items << 8) | byte;
                }
                // A signed count with its top bit set is negative: assimp refuses that itself.
                if (!property.unsignedCount && (items >> (8 * size - 1)) != 0) return;
                at += size;
                const uint64_t bytes = items * static_cast<uint64_t>(property.itemSize);  // < 2^35
                if (at + bytes > fileSize) shortAt(element, i);
                at += bytes;
            }
        }
    }
    // Bytes after the declared elements (beyond a line end or padding of spaces or zeros): the header's
    // counts are too small, and assimp drops what follows without a word.
    const bool extra = std::any_of(text.begin() + static_cast<ptrdiff_t>(std::min(at, fileSize)), text.end(),
                                   [](char c) { return c != '\n' && c != '\r' && c != ' ' && c != '\0'; });
    if (extra) {
        throw InvalidInput(
            formatError(path.string(), "",
                        "holds " + std::to_string(fileSize - at) + " bytes after the " + declared +
                            " elements its header declares",
                        "a header whose element counts cover the file's data (a count too small "
                        "drops the rest)"));
    }
}

// A mesh's name in messages and groups: its own, or "mesh<m>" without one.
std::string meshNameOf(const aiMesh& mesh, unsigned m) {
    return mesh.mName.length > 0 ? std::string(mesh.mName.C_Str()) : "mesh" + std::to_string(m);
}

// The group name of each mesh: its name, unless meshes share it (assimp splits an FBX or Collada mesh per
// material, each part named as the mesh); then "<mesh>_<material>", as Blender's OBJ names an object's
// material groups, and ".2", ".3", ... after any name still taken. Groups written back keep their parts.
std::vector<std::string> meshGroupNames(const aiScene& scene) {
    std::map<std::string, int> uses;
    for (unsigned m = 0; m < scene.mNumMeshes; ++m)
        ++uses[meshNameOf(*scene.mMeshes[m], m)];
    std::vector<std::string> names;
    std::set<std::string> taken;
    for (unsigned m = 0; m < scene.mNumMeshes; ++m) {
        const aiMesh& mesh = *scene.mMeshes[m];
        std::string base = meshNameOf(mesh, m);
        if (uses[base] > 1 && mesh.mMaterialIndex < scene.mNumMaterials) {
            const aiString material = scene.mMaterials[mesh.mMaterialIndex]->GetName();
            if (material.length > 0) base += "_" + std::string(material.C_Str());
        }
        std::string name = base;
        for (int n = 2; taken.count(name) > 0; ++n)
            name = base + "." + std::to_string(n);
        taken.insert(name);
        names.push_back(std::move(name));
    }
    return names;
}

// assimp drops what it cannot read of what the mesh keeps (faces with an index past the vertices, a UV
// stream shorter than the vertices, a trailing vertex that makes no triangle, a morph target's positions of
// another count) and says so only in a warning: those warnings are collected while a file is read, and the
// file is refused. Other warnings (an unreferenced vertex, normals or colours of another count, lines left
// out) lose nothing the mesh keeps. Reads go one at a time: assimp's logger writes every message through
// one shared buffer, and the warnings must be the file's own.
class DroppedDataLog : public Assimp::LogStream {
  public:
    // While a Collect lives: reads are serialised and their warnings kept.
    class Collect {
      public:
        Collect() : lock_(mutex()) {
            install();
            warnings().clear();
        }
        Collect(const Collect&) = delete;
        Collect& operator=(const Collect&) = delete;
        [[nodiscard]] std::optional<std::string> dropped() const {
            for (const std::string& w : warnings()) {
                // An FBX object that fails to read (a damaged array) is logged as an error with its
                // exception's text ("FBX-DOM ...", "FBX-Parser ...", "CompressionFailure ...") and left out
                // of a read that succeeds. The reader's other errors ("FBX: no material assigned to mesh")
                // are notes.
                if (w.starts_with("Error")) {
                    const std::string text = w.substr(std::min(w.find(": ") + 2, w.size()));
                    if (text.starts_with("FBX-") || text.starts_with("Compression")) return text;
                    continue;
                }
                for (const char* sign : {"Texcoord stream size", "not compatible with the TRIANGLE",
                                         "out-of-range indices", "Positions of target"})
                    if (w.find(sign) != std::string::npos) return w;
            }
            return std::nullopt;
        }

      private:
        std::lock_guard<std::mutex> lock_;
    };

    void write(const char* message) override {
        std::string text(message);
        while (!text.empty() && (text.back() == '\n' || text.back() == '\r'))
            text.pop_back();
        // "Warn,  T0: ..." kept as its text, "Error, T0: ..." whole (dropped() reads its level).
        const size_t body = text.find(": ");
        warnings().push_back(body == std::string::npos || text.starts_with("Error") ? text
                                                                                    : text.substr(body + 2));
    }

  private:
    static std::mutex& mutex() {
        static std::mutex m;
        return m;
    }
    static std::vector<std::string>& warnings() {
        static std::vector<std::string> list;
        return list;
    }
    // A logger when the process has none (assimp's default logs nothing), and this stream on its warnings;
    // again on a logger made since (another part of the process may replace it). Under the lock.
    static void install() {
        static Assimp::Logger* attachedTo = nullptr;
        if (Assimp::DefaultLogger::isNullLogger())
            Assimp::DefaultLogger::create("", Assimp::Logger::NORMAL, 0);  // no file, no debugger
        Assimp::Logger* logger = Assimp::DefaultLogger::get();
        if (logger != attachedTo) {
            logger->attachStream(new DroppedDataLog, Assimp::Logger::Warn | Assimp::Logger::Err);
            attachedTo = logger;
        }
    }
};

// The JSON of a .gltf file, or of a .glb's first chunk (read alone: its binary chunk, the bulk of the file,
// is assimp's to read); nullopt where it is not there to read (assimp then refuses the file with its own
// message).
std::optional<nlohmann::json> gltfJson(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    unsigned char header[20] = {};
    in.read(reinterpret_cast<char*>(header), sizeof(header));
    const auto le32 = [&](size_t at) {
        return uint32_t(header[at]) | (uint32_t(header[at + 1]) << 8) | (uint32_t(header[at + 2]) << 16) |
               (uint32_t(header[at + 3]) << 24);
    };
    std::string text;
    if (in.gcount() == sizeof(header) && std::memcmp(header, "glTF", 4) == 0) {
        const uint32_t length = le32(12);
        std::error_code error;
        const uintmax_t size = fs::file_size(path, error);
        if (error || le32(16) != 0x4E4F534Au || length > size - sizeof(header))
            return std::nullopt;  // "JSON"
        text.resize(length);
        if (!in.read(text.data(), length)) return std::nullopt;
    } else {
        text = readFile(path, "glTF file");
    }
    nlohmann::json json = nlohmann::json::parse(text, nullptr, false);
    if (json.is_discarded() || !json.is_object()) return std::nullopt;
    return json;
}

// requireReadableGltf's checks on the file's JSON.
void requireReadableGltfJson(const fs::path& path, const std::optional<nlohmann::json>& json) {
    const std::string name = path.string();
    if (const auto required = json->find("extensionsRequired");
        required != json->end() && required->is_array()) {
        for (const nlohmann::json& extension : *required) {
            if (!extension.is_string()) continue;
            const std::string e = extension.get<std::string>();
            const bool looks = e.starts_with("KHR_materials_") || e.starts_with("KHR_texture_") ||
                               e.starts_with("EXT_texture_") || e == "KHR_lights_punctual" ||
                               e == "KHR_draco_mesh_compression";
            if (!looks) {
                throw InvalidInput(formatError(name, "extensionsRequired",
                                               "names " + e + ", which is not read",
                                               "a glTF without required geometry extensions (KHR_draco_mesh_"
                                               "compression is read; export without quantization or "
                                               "meshopt compression)"));
            }
        }
    }
    const auto accessors = json->find("accessors");
    const auto views = json->find("bufferViews");
    const auto meshes = json->find("meshes");
    if (accessors == json->end() || !accessors->is_array() || meshes == json->end() || !meshes->is_array())
        return;
    for (size_t m = 0; m < meshes->size(); ++m) {
        const auto primitives = (*meshes)[m].find("primitives");
        if (primitives == (*meshes)[m].end() || !primitives->is_array()) continue;
        for (size_t p = 0; p < primitives->size(); ++p) {
            const auto attributes = (*primitives)[p].find("attributes");
            if (attributes == (*primitives)[p].end() || !attributes->is_object()) continue;
            const auto position = attributes->find("POSITION");
            if (position == attributes->end() || !position->is_number_unsigned()) continue;
            const auto a = position->get<size_t>();
            if (a >= accessors->size() || !(*accessors)[a].is_object()) continue;
            const nlohmann::json& accessor = (*accessors)[a];
            const std::string element = "accessors[" + std::to_string(a) + "] (POSITION of meshes[" +
                                        std::to_string(m) + "].primitives[" + std::to_string(p) + "])";
            const bool vec3 = accessor.value("type", std::string()) == "VEC3";
            const bool floats = accessor.value("componentType", 0) == 5126;
            if (!vec3 || !floats) {
                throw InvalidInput(formatError(name, element,
                                               "is " + accessor.value("type", std::string("?")) +
                                                   " of component type " +
                                                   std::to_string(accessor.value("componentType", 0)),
                                               "VEC3 of floats (5126): quantized positions are not read"));
            }
            // UVs as normalized integers (core glTF 2.0): assimp copies their bytes as float bits.
            const auto uv = attributes->find("TEXCOORD_0");
            if (uv != attributes->end() && uv->is_number_unsigned() &&
                uv->get<size_t>() < accessors->size() && (*accessors)[uv->get<size_t>()].is_object()) {
                const nlohmann::json& uvs = (*accessors)[uv->get<size_t>()];
                const int type = uvs.value("componentType", 5126);
                if (type != 5126) {
                    throw InvalidInput(formatError(
                        name,
                        "accessors[" + std::to_string(uv->get<size_t>()) + "] (TEXCOORD_0 of meshes[" +
                            std::to_string(m) + "].primitives[" + std::to_string(p) + "])",
                        "is of component type " + std::to_string(type) + " (normalized integers)",
                        "UVs as floats (5126): export without texture-coordinate quantization"));
                }
            }
            const auto view = accessor.find("bufferView");
            if (view == accessor.end() || !view->is_number_unsigned() || views == json->end() ||
                !views->is_array() || view->get<size_t>() >= views->size())
                continue;
            const nlohmann::json& bufferView = (*views)[view->get<size_t>()];
            if (bufferView.is_object() && bufferView.contains("byteStride") &&
                bufferView.value("byteStride", 0) < 12) {
                throw InvalidInput(formatError(
                    name, "bufferViews[" + std::to_string(view->get<size_t>()) + "] of " + element,
                    "has byteStride " + std::to_string(bufferView.value("byteStride", 0)),
                    "a stride of at least 12 bytes, one position"));
            }
        }
    }
}

// What assimp would read wrong without a word: positions that are not 3 floats (KHR_mesh_quantization's
// integers, read as float bits), UVs that are not floats, a buffer view stride shorter than a position
// (overlapping reads), and any required extension that changes geometry (only materials, textures and
// lights are not). A field of the wrong JSON type ("byteStride": "12") is named, not an internal error.
void requireReadableGltf(const fs::path& path) {
    const std::optional<nlohmann::json> json = gltfJson(path);
    if (!json) return;
    try {
        requireReadableGltfJson(path, json);
    } catch (const nlohmann::json::exception& e) {
        throw InvalidInput(
            formatError(path.string(), "", std::string("holds a field of the wrong type: ") + e.what(),
                        "a glTF 2.0 file whose fields have the types the specification gives"));
    }
}

// A binary FBX's arrays checked before assimp reads them: each array's declared length against its bytes (a
// compressed one inflated in pieces, its zlib stream whole and of exactly that length). assimp allocates a
// declared length before inflating (52 KB claiming 4.2 GB), and leaves out an object whose array does not
// inflate, reporting success (it also leaks the stream). Node records as the FBX binary layout gives them:
// end offset, property count and list length (64-bit from version 7500), name, properties, nested records.
class FbxArrays {
  public:
    FbxArrays(const fs::path& path, std::string bytes) : path_(path), bytes_(std::move(bytes)) {}

    void check() {
        if (!bytes_.starts_with(std::string("Kaydara FBX Binary  \0", 21)) || bytes_.size() < 27) return;
        wide_ = u32(23) >= 7500;
        records(27, bytes_.size(), 0);
    }

  private:
    [[noreturn]] void fail(uint64_t at, const std::string& what, const std::string& problem,
                           const std::string& expected) const {
        throw InvalidInput(
            formatError(path_.string(), what + " at byte " + std::to_string(at), problem, expected));
    }
    void need(uint64_t at, uint64_t size, const std::string& what) const {
        if (at > bytes_.size() || size > bytes_.size() - at)
            fail(at, what, "needs " + std::to_string(size) + " bytes past the end of the file",
                 "a complete FBX file");
    }
    [[nodiscard]] uint32_t u32(uint64_t at) const {
        uint32_t v = 0;
        std::memcpy(&v, bytes_.data() + at, 4);
        return v;
    }
    [[nodiscard]] uint64_t word(uint64_t at) const {
        if (!wide_) return u32(at);
        uint64_t v = 0;
        std::memcpy(&v, bytes_.data() + at, 8);
        return v;
    }

    // The records in [at, end), nested `depth` deep; a record of zeros ends a nested list.
    void records(uint64_t at, uint64_t end, int depth) {
        const uint64_t header = wide_ ? 25 : 13;
        while (at + header <= end) {
            need(at, header, "node record");
            const uint64_t next = word(at), count = word(at + (wide_ ? 8 : 4));
            const uint8_t nameLength = static_cast<uint8_t>(bytes_[at + header - 1]);
            if (next == 0) return;  // the null record closing a list
            if (depth > 64) fail(at, "node record", "nests more than 64 deep", "an FBX file's node tree");
            if (next <= at || next > end) {
                fail(at, "node record", "ends at byte " + std::to_string(next),
                     "an end after its start and within its parent");
            }
            need(at + header, nameLength, "node name");
            const std::string name = bytes_.substr(at + header, nameLength);
            uint64_t p = at + header + nameLength;
            for (uint64_t k = 0; k < count; ++k)
                p = property(p, next, name);
            if (p < next) records(p, next, depth + 1);
            at = next;
        }
    }

    // The property at `at` of node `node`, checked; returns where the next one starts.
    uint64_t property(uint64_t at, uint64_t end, const std::string& node) {
        need(at, 1, "property of node " + node);
        const char type = bytes_[at];
        const auto fixed = [&](uint64_t size) {
            need(at + 1, size, "property of node " + node);
            return at + 1 + size;
        };
        switch (type) {
            case 'Y':
                return fixed(2);
            case 'C':
                return fixed(1);
            case 'I':
            case 'F':
                return fixed(4);
            case 'D':
            case 'L':
                return fixed(8);
            case 'S':
            case 'R':
                need(at + 1, 4, "property of node " + node);
                return fixed(4 + uint64_t{u32(at + 1)});
            case 'f':
            case 'i':
                return array(at, end, node, 4);
            case 'd':
            case 'l':
                return array(at, end, node, 8);
            case 'b':
            case 'c':
                return array(at, end, node, 1);
            default:
                fail(at, "property of node " + node, std::string("has the type code '") + type + "'",
                     "one of Y C I F D L S R f d l i b c");
        }
    }

    uint64_t array(uint64_t at, uint64_t end, const std::string& node, uint64_t itemSize) {
        const std::string what = "array of node " + node;
        need(at + 1, 12, what);
        const uint64_t length = u32(at + 1), encoding = u32(at + 5), stored = u32(at + 9);
        const uint64_t data = at + 13, bytes = length * itemSize;
        need(data, stored, what);
        if (data + stored > end) fail(at, what, "runs past its node's end", "an array inside its node");
        if (encoding == 0 && stored != bytes) {
            fail(at, what,
                 "holds " + std::to_string(stored) + " bytes for " + std::to_string(length) + " items",
                 std::to_string(bytes) + " bytes");
        }
        if (encoding == 1)
            inflated(at, what, data, stored, bytes);
        else if (encoding != 0)
            fail(at, what, "has encoding " + std::to_string(encoding), "0 (raw) or 1 (zlib)");
        return data + stored;
    }

    // Inflates the zlib stream in pieces: it must end, whole, after exactly `bytes` bytes.
    void inflated(uint64_t at, const std::string& what, uint64_t data, uint64_t stored,
                  uint64_t bytes) const {
        if (bytes > stored * 1032 + 64) {  // zlib's largest ratio
            fail(at, what, std::to_string(stored) + " zipped bytes declared to hold " + std::to_string(bytes),
                 "at most 1032 times the zipped size (zlib's limit)");
        }
        z_stream stream{};
        if (inflateInit(&stream) != Z_OK) fail(at, what, "cannot start inflating", "memory for zlib");
        std::array<unsigned char, 16384> piece{};
        stream.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(bytes_.data() + data));
        stream.avail_in = static_cast<uInt>(stored);
        uint64_t produced = 0;
        int status = Z_OK;
        while (status == Z_OK) {
            stream.next_out = piece.data();
            stream.avail_out = static_cast<uInt>(piece.size());
            status = inflate(&stream, Z_NO_FLUSH);
            produced += piece.size() - stream.avail_out;
            if (status == Z_BUF_ERROR && stream.avail_in == 0) break;  // cut short
        }
        inflateEnd(&stream);
        if (status != Z_STREAM_END || produced != bytes) {
            fail(at, what,
                 status == Z_STREAM_END ? "inflates to " + std::to_string(produced) + " bytes"
                                        : "does not inflate (a damaged or cut zlib stream)",
                 "a zlib stream of the " + std::to_string(bytes) + " bytes its length declares");
        }
    }

    fs::path path_;
    std::string bytes_;
    bool wide_ = false;
};

void requireReadableFbx(const fs::path& path) {
    FbxArrays(path, readFile(path, "FBX file")).check();
}

// Collada's index lists (<p> of polygons and triangles, <vcount>, a skin's <v> and <vcount>) hold whole
// numbers >= 0. Assimp reads "-2" as a wrapped index and drops the face without a word, and "2.5" or "x" as
// a count that fails allocating ("std::bad_alloc"): refused here, naming the list and its line.
void requireColladaIndices(const fs::path& path) {
    const std::string text = readFile(path, "Collada file");
    for (const char* tag : {"p", "vcount", "v"}) {
        const std::string open = std::string("<") + tag + ">", close = std::string("</") + tag + ">";
        int64_t ordinal = 0;
        for (size_t at = text.find(open); at != std::string::npos; at = text.find(open, at)) {
            const size_t begin = at + open.size(), end = text.find(close, begin);
            if (end == std::string::npos) return;  // left to assimp's XML reader
            const std::string_view list(text.data() + begin, end - begin);
            size_t k = 0;
            int64_t item = 0;
            while (k < list.size()) {
                while (k < list.size() && std::isspace(static_cast<unsigned char>(list[k])))
                    ++k;
                const size_t start = k;
                while (k < list.size() && !std::isspace(static_cast<unsigned char>(list[k])))
                    ++k;
                if (k == start) break;
                const std::string_view token = list.substr(start, k - start);
                if (token.find_first_not_of("0123456789") != std::string_view::npos || token.size() > 9) {
                    const auto line =
                        1 +
                        std::count(text.begin(), text.begin() + static_cast<ptrdiff_t>(begin + start), '\n');
                    throw InvalidInput(formatError(path.string(),
                                                   "line " + std::to_string(line) + " (<" + tag + "> list " +
                                                       std::to_string(ordinal) + ", item " +
                                                       std::to_string(item) + ")",
                                                   "holds '" + std::string(token) + "'",
                                                   "whole numbers from 0 to 999999999 (indices and counts)"));
                }
                ++item;
            }
            ++ordinal;
            at = end;
        }
    }
}

ObjContent readWithAssimp(const fs::path& path, MeshFormat format) {
    const std::string name = path.string();
    std::error_code ec;
    const fs::file_status status = fs::status(path, ec);
    if (!fs::exists(status)) throw IoError(formatError(name, "", "does not exist", "an existing mesh file"));
    if (!fs::is_regular_file(status))
        throw IoError(formatError(name, "", "is not a regular file", "a mesh file"));

    if (format == MeshFormat::Ply) requireCompletePly(path);
    if (format == MeshFormat::Gltf) requireReadableGltf(path);
    if (format == MeshFormat::Fbx) requireReadableFbx(path);
    if (format == MeshFormat::Collada) requireColladaIndices(path);
    Assimp::Importer importer;
    const auto check = [&](const aiScene* scene) {
        if (!scene) {
            throw InvalidInput(
                formatError(name, "", std::string("cannot be read as a mesh: ") + importer.GetErrorString(),
                            "a valid glTF, FBX, PLY or Collada file"));
        }
        return scene;
    };
    // Meshes stay apart (one group each) while their vertices move to world space: by assimp's
    // pre-transform, or for skinned and morphed glTF and Collada meshes by their rest pose (RestPose).
    importer.SetPropertyBool(AI_CONFIG_PP_PTV_KEEP_HIERARCHY, true);
    const DroppedDataLog::Collect log;
    const aiScene* scene = check(importer.ReadFile(path.string(), aiProcess_ValidateDataStructure));
    if (const std::optional<std::string> dropped = log.dropped()) {
        throw InvalidInput(formatError(name, "", "assimp left data out while reading it: " + *dropped,
                                       "faces and UVs that all refer to the file's vertices"));
    }
    std::optional<RestPose> rest;
    if ((format == MeshFormat::Gltf || format == MeshFormat::Collada) && RestPose::needed(*scene)) {
        rest.emplace(*scene, format == MeshFormat::Gltf ? RestPose::Placement::JointsOnly
                                                        : RestPose::Placement::NodeThenJoints);
        if (!rest->placesEveryMeshOnce()) rest.reset();
    }
    if (!rest) scene = check(importer.ApplyPostProcessing(aiProcess_PreTransformVertices));
    const bool weld = format == MeshFormat::Fbx || format == MeshFormat::Collada;
    geom::Mesh::Data data;
    std::vector<FaceGroup> groups;
    bool anyUVs = false;
    for (unsigned m = 0; m < scene->mNumMeshes; ++m)
        anyUVs = anyUVs || scene->mMeshes[m]->HasTextureCoords(0);
    std::map<PositionKey, int32_t> welded;
    int64_t repaired = 0;
    std::string firstRepaired;
    const std::vector<std::string> groupNames = meshGroupNames(*scene);
    for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
        const aiMesh& mesh = *scene->mMeshes[m];
        const std::string meshName = meshNameOf(mesh, m);
        const bool uvs = mesh.HasTextureCoords(0);
        const std::vector<aiVector3D> posed = rest ? rest->positions(m) : std::vector<aiVector3D>{};
        const aiVector3D* vertices = rest ? posed.data() : mesh.mVertices;
        // Vertex k of this mesh is point pointOf[k]; its UV is uv base + k.
        std::vector<int32_t> pointOf(mesh.mNumVertices);
        for (unsigned k = 0; k < mesh.mNumVertices; ++k) {
            const aiVector3D& p = vertices[k];
            const glm::vec3 point(p.x, p.y, p.z);
            // Checked here, before welding: a NaN compares equal to every position and would be welded
            // onto another point, and the faces around it dropped as slivers.
            if (!std::isfinite(point.x) || !std::isfinite(point.y) || !std::isfinite(point.z)) {
                throw InvalidInput(formatError(name, "mesh '" + meshName + "': vertex " + std::to_string(k),
                                               "is (" + numberText(point.x) + ", " + numberText(point.y) +
                                                   ", " + numberText(point.z) + ")",
                                               "finite coordinates"));
            }
            if (weld) {
                const auto [it, added] =
                    welded.try_emplace({point.x, point.y, point.z}, static_cast<int32_t>(data.points.size()));
                if (added) data.points.push_back(point);
                pointOf[k] = it->second;
            } else {
                pointOf[k] = static_cast<int32_t>(data.points.size());
                data.points.push_back(point);
            }
        }
        const auto uvBase = static_cast<int32_t>(data.uvs.size());
        if (uvs) {
            for (unsigned k = 0; k < mesh.mNumVertices; ++k)
                data.uvs.emplace_back(mesh.mTextureCoords[0][k].x, mesh.mTextureCoords[0][k].y);
        }
        FaceGroup group;
        group.name = groupNames[m];
        std::vector<int32_t> points, sorted;
        std::vector<size_t> corners;  // 0 .. n - 1: a polygon of distinct points (nearly all) as it is
        for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
            const aiFace& face = mesh.mFaces[f];
            const auto emit = [&](std::span<const size_t> loop) {
                group.faces.push_back(static_cast<int32_t>(data.faceCounts.size()));
                data.faceCounts.push_back(static_cast<int32_t>(loop.size()));
                for (const size_t c : loop) {
                    const unsigned k = face.mIndices[c];
                    data.faceIndices.push_back(pointOf[k]);
                    if (anyUVs) data.uvIndices.push_back(uvs ? uvBase + static_cast<int32_t>(k) : -1);
                }
            };
            points.clear();
            for (unsigned c = 0; c < face.mNumIndices; ++c)
                points.push_back(pointOf[face.mIndices[c]]);
            sorted = points;
            std::sort(sorted.begin(), sorted.end());
            if (std::adjacent_find(sorted.begin(), sorted.end()) == sorted.end()) {
                if (points.size() < 3) continue;  // points and lines are left out
                corners.resize(points.size());
                std::iota(corners.begin(), corners.end(), size_t{0});
                emit(corners);
                continue;
            }
            // The polygon's loops, as an OBJ's (polygon_loops.h): a corner welded onto the one before it is
            // dropped (a sliver of coincident points), a polygon that comes back to a point (a hole bridged
            // to its outline) is split there, and what is left with fewer than 3 corners is left out.
            // Repaired, as an OBJ counts it, when a loop is kept.
            const std::vector<std::vector<size_t>> loops = polygonLoops(points);
            if (face.mNumIndices >= 3 && !loops.empty() && repaired++ == 0)
                firstRepaired = "mesh '" + meshName + "' face " + std::to_string(f);
            for (const std::vector<size_t>& loop : loops)
                emit(loop);
        }
        if (!group.faces.empty()) groups.push_back(std::move(group));
    }
    if (data.faceCounts.empty()) {
        throw InvalidInput(formatError(name, "",
                                       "has no polygon (" + std::to_string(scene->mNumMeshes) + " meshes)",
                                       "a file with at least one mesh of polygons"));
    }
    // Every member named (no line numbers in these files; every face here has its UVs or none has).
    return ObjContent{geom::Mesh(std::move(data), name), std::move(groups), repaired, 0, firstRepaired, 0, 0};
}

}  // namespace

std::optional<MeshFormat> meshFormat(const fs::path& path) {
    std::string extension = path.extension().string();
    for (char& c : extension)
        c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    if (extension == ".obj") return MeshFormat::Obj;
    if (extension == ".gltf" || extension == ".glb") return MeshFormat::Gltf;
    if (extension == ".fbx") return MeshFormat::Fbx;
    if (extension == ".ply") return MeshFormat::Ply;
    if (extension == ".dae") return MeshFormat::Collada;
    return std::nullopt;
}

ObjContent readMesh(const fs::path& path) {
    const std::optional<MeshFormat> format = meshFormat(path);
    if (!format) {
        throw InvalidInput(formatError(path.string(), "",
                                       path.extension().empty()
                                           ? "has no extension"
                                           : "has the extension '" + path.extension().string() + "'",
                                       std::string("a mesh file: ") + kMeshExtensions));
    }
    if (*format == MeshFormat::Obj) return readObj(path);
    return readWithAssimp(path, *format);
}

}  // namespace deformkit::io
