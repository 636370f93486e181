// Ptex writer: version 1, a 40-byte extended header, level 0 plus reductions, constant faces flagged with
// their value in ConstData, large faces tiled, small and large metadata, no edit data.
#include <zlib.h>

#include <algorithm>
#include <bit>
#include <cstring>
#include <numeric>
#include <string>

#include "deformkit/error.h"
#include "deformkit/io/atomic_file.h"
#include "deformkit/ptex/ptex_file.h"
#include "format.h"

namespace deformkit::ptex {
namespace {

using namespace detail;

const char* const kFaceVertCounts = "PtexFaceVertCounts";
const char* const kFaceVertIndices = "PtexFaceVertIndices";
const char* const kVertPositions = "PtexVertPositions";

class Writer {
  public:
    Writer(const PtexFile& file, const WriteOptions& options, std::string source)
        : file_(file), options_(options), source_(std::move(source)) {}

    std::vector<uint8_t> write() {
        validate();
        classifyFaces();
        std::vector<uint8_t> levelInfo;
        std::vector<uint8_t> levelData;
        const int levels = levelCount();
        std::vector<uint32_t> levelFaces;
        ByteWriter info(levelInfo);
        for (int level = 0; level < levels; ++level) {
            const size_t before = levelData.size();
            const auto [headerZipSize, faceCount] = writeLevel(level, levelData);
            info.put(static_cast<uint64_t>(levelData.size() - before));
            info.put(static_cast<uint32_t>(headerZipSize));
            info.put(static_cast<uint32_t>(faceCount));
        }

        std::vector<uint8_t> faceInfo;
        ByteWriter fi(faceInfo);
        for (size_t f = 0; f < faces_.size(); ++f)
            storeFaceInfo(fi, faces_[f]);
        const std::vector<uint8_t> faceInfoZip = zip(faceInfo, "face info");
        const std::vector<uint8_t> constZip = zip(constData_, "constant data");

        const std::vector<MetaValue> entries = allMetadata();
        std::vector<uint8_t> smallMeta;
        std::vector<uint8_t> largeHeader;
        std::vector<uint8_t> largeData;
        for (const MetaValue& entry : entries) {
            const std::vector<uint8_t> value = entry.bytes();
            if (value.size() > kLargeMetaThreshold) {
                const std::vector<uint8_t> valueZip = zip(value, "metadata '" + entry.key + "'");
                ByteWriter h(largeHeader);
                putMetaKey(h, entry, value.size());
                h.put(static_cast<uint32_t>(valueZip.size()));
                largeData.insert(largeData.end(), valueZip.begin(), valueZip.end());
            } else {
                ByteWriter m(smallMeta);
                putMetaKey(m, entry, value.size());
                m.bytes(value);
            }
        }
        const std::vector<uint8_t> smallMetaZip =
            smallMeta.empty() ? std::vector<uint8_t>{} : zip(smallMeta, "metadata");
        const std::vector<uint8_t> largeHeaderZip =
            largeHeader.empty() ? std::vector<uint8_t>{} : zip(largeHeader, "large metadata");
        const bool barrier = !entries.empty();
        checkU32(faceInfoZip.size(), "face info");
        checkU32(constZip.size(), "constant data");
        checkU32(smallMeta.size(), "metadata");
        checkU32(largeHeader.size(), "large metadata");

        const uint64_t total = kHeaderSize + kExtHeaderSize + faceInfoZip.size() + constZip.size() +
                               levelInfo.size() + levelData.size() + smallMetaZip.size() +
                               (barrier ? kBarrierSize : 0) + largeHeaderZip.size() + largeData.size();
        std::vector<uint8_t> out;
        out.reserve(total);
        ByteWriter w(out);
        w.put(kMagic);
        w.put(kVersion);
        w.put(static_cast<uint32_t>(file_.meshType));
        w.put(static_cast<uint32_t>(file_.dataType));
        w.put(static_cast<int32_t>(file_.alphaChannel));
        w.put(static_cast<uint16_t>(file_.channels));
        w.put(static_cast<uint16_t>(levels));
        w.put(static_cast<uint32_t>(faces_.size()));
        w.put(static_cast<uint32_t>(kExtHeaderSize));
        w.put(static_cast<uint32_t>(faceInfoZip.size()));
        w.put(static_cast<uint32_t>(constZip.size()));
        w.put(static_cast<uint32_t>(levelInfo.size()));
        w.put(kMinorVersion);
        w.put(static_cast<uint64_t>(levelData.size()));
        w.put(static_cast<uint32_t>(smallMetaZip.size()));
        w.put(static_cast<uint32_t>(smallMeta.size()));
        // Extended header.
        w.put(static_cast<uint16_t>(file_.uBorderMode));
        w.put(uint16_t{0});
        w.put(static_cast<uint16_t>(file_.vBorderMode));
        w.put(static_cast<uint16_t>(file_.edgeFilterMode));
        w.put(static_cast<uint32_t>(largeHeaderZip.size()));
        w.put(static_cast<uint32_t>(largeHeader.size()));
        w.put(static_cast<uint64_t>(largeData.size()));
        w.put(uint64_t{0});  // edit data size
        w.put(total);        // edit data position: the end of the file
        w.bytes(faceInfoZip);
        w.bytes(constZip);
        w.bytes(levelInfo);
        w.bytes(levelData);
        w.bytes(smallMetaZip);
        if (barrier) out.insert(out.end(), kBarrierSize, uint8_t{0});
        w.bytes(largeHeaderZip);
        w.bytes(largeData);
        return out;
    }

  private:
    [[noreturn]] void fail(const std::string& element, const std::string& problem,
                           const std::string& expected) const {
        throw InvalidInput(formatError(source_, element, problem, expected));
    }

    void checkU32(size_t size, const std::string& section) const {
        if (size > 0xffffffffu) fail(section, "is " + std::to_string(size) + " bytes", "less than 4 GiB");
    }

    void validate() const {
        const auto dataType = static_cast<uint32_t>(file_.dataType);
        const auto meshType = static_cast<uint32_t>(file_.meshType);
        if (dataType > 3) fail("data type", "is " + std::to_string(dataType), "0..3 (u8, u16, half, float)");
        if (meshType > 1) fail("mesh type", "is " + std::to_string(meshType), "0 (triangle) or 1 (quad)");
        if (file_.channels < 1 || file_.channels > kMaxChannels) {
            fail("channels", "is " + std::to_string(file_.channels), "1..64");
        }
        if (file_.alphaChannel < -1 || file_.alphaChannel >= file_.channels) {
            fail("alpha channel", "is " + std::to_string(file_.alphaChannel),
                 "-1 (none) or 0.." + std::to_string(file_.channels - 1));
        }
        if (static_cast<uint16_t>(file_.uBorderMode) > 2 || static_cast<uint16_t>(file_.vBorderMode) > 2) {
            fail("border mode", "is out of range", "0 (clamp), 1 (black) or 2 (periodic)");
        }
        if (static_cast<uint16_t>(file_.edgeFilterMode) > 1) {
            fail("edge filter mode", "is out of range", "0 (none) or 1 (tangent vectors)");
        }
        if (options_.compressionLevel < 0 || options_.compressionLevel > 9) {
            fail("compression level", "is " + std::to_string(options_.compressionLevel), "0..9");
        }
        if (options_.tileBytes == 0) fail("tile size", "is 0 bytes", "at least 1");
        const size_t n = file_.faces.size();
        // The reference library writes no file without faces, and reads none ("unzip failed").
        if (n == 0) fail("faces", "are none", "at least one face");
        if (n > 0x7fffffffu) fail("faces", "are " + std::to_string(n), "fewer than 2^31");
        if (file_.texels.size() != n) {
            fail("texels", "has " + std::to_string(file_.texels.size()) + " faces",
                 std::to_string(n) + " (one buffer per face)");
        }
        const size_t pixel = file_.pixelSize();
        if (!file_.constData.empty() && file_.constData.size() != n * pixel) {
            fail("constant data", "is " + std::to_string(file_.constData.size()) + " bytes",
                 std::to_string(n * pixel) + " (one pixel per face) or empty");
        }
        for (size_t f = 0; f < n; ++f) {
            const FaceInfo& info = file_.faces[f];
            const std::string face = "face " + std::to_string(f);
            if (info.ulog2 < 0 || info.ulog2 > kMaxLog2 || info.vlog2 < 0 || info.vlog2 > kMaxLog2) {
                fail(face,
                     "has resolution log2 " + std::to_string(info.ulog2) + " x " + std::to_string(info.vlog2),
                     "each log2 in 0..15");
            }
            if (file_.meshType == MeshType::Triangle && info.ulog2 != info.vlog2) {
                fail(face,
                     "has resolution log2 " + std::to_string(info.ulog2) + " x " +
                         std::to_string(info.vlog2) + " in a triangle file",
                     "equal log2 resolutions (a triangle face is stored as a square)");
            }
            for (int e = 0; e < 4; ++e) {
                if (info.adjFaces[e] < -1 || info.adjFaces[e] >= static_cast<int64_t>(n)) {
                    fail(face,
                         "edge " + std::to_string(e) + " names neighbour " + std::to_string(info.adjFaces[e]),
                         "-1 (none) or a face id below " + std::to_string(n));
                }
                if (info.adjEdges[e] > 3) {
                    fail(face,
                         "edge " + std::to_string(e) + " names neighbour edge " +
                             std::to_string(info.adjEdges[e]),
                         "0..3");
                }
            }
            const size_t expected = info.texelCount() * pixel;
            if (file_.texels[f].empty()) {
                if (file_.constData.empty()) {
                    fail(face, "has no texels and there is no constant data", "texels or a constant value");
                }
            } else if (file_.texels[f].size() != expected) {
                fail(face, "has " + std::to_string(file_.texels[f].size()) + " texel bytes",
                     std::to_string(expected) + " (" + std::to_string(info.ures()) + " x " +
                         std::to_string(info.vres()) + " texels of " + std::to_string(pixel) + " bytes)");
            }
        }
        for (size_t i = 0; i < file_.metadata.size(); ++i)
            validateMeta(file_.metadata[i], i);
        if (options_.mesh) validateMesh(*options_.mesh);
    }

    void validateMeta(const MetaValue& m, size_t index) const {
        const std::string element = "metadata entry " + std::to_string(index);
        if (m.key.empty() || m.key.size() > 254 || m.key.find('\0') != std::string::npos) {
            fail(element, "has key '" + m.key + "'", "1..254 bytes without NUL");
        }
        if (static_cast<uint8_t>(m.type) > 5) fail(element, "has an unknown type", "0..5");
        const size_t size = m.bytes().size();
        if (size > 0xffffffffu) fail(element, "is larger than 4 GiB", "a smaller value");
        if (size == 0) fail(element, "key '" + m.key + "' has no values", "at least one value");
        // Stored NUL-terminated: readers (the reference library, renderers) stop at the first NUL.
        if (m.type == MetaType::String && m.string.find('\0') != std::string::npos) {
            fail(element,
                 "key '" + m.key + "' has a NUL byte at " + std::to_string(m.string.find('\0')) +
                     " of its text",
                 "text without NUL");
        }
        if (options_.mesh &&
            (m.key == kFaceVertCounts || m.key == kFaceVertIndices || m.key == kVertPositions)) {
            fail(element, "key '" + m.key + "' is also given as WriteOptions::mesh", "one or the other");
        }
    }

    void validateMesh(const MeshData& mesh) const {
        int64_t corners = 0;
        for (size_t i = 0; i < mesh.faceVertCounts.size(); ++i) {
            if (mesh.faceVertCounts[i] < 3) {
                fail("mesh polygon " + std::to_string(i),
                     "has " + std::to_string(mesh.faceVertCounts[i]) + " vertices", "at least 3");
            }
            corners += mesh.faceVertCounts[i];
        }
        if (corners != static_cast<int64_t>(mesh.faceVertIndices.size())) {
            fail("mesh", "has " + std::to_string(mesh.faceVertIndices.size()) + " vertex indices",
                 std::to_string(corners) + " (the sum of the polygon vertex counts)");
        }
        if (mesh.vertPositions.size() % 3 != 0) {
            fail("mesh", "has " + std::to_string(mesh.vertPositions.size()) + " position floats",
                 "3 per vertex");
        }
        const int64_t vertices = static_cast<int64_t>(mesh.vertPositions.size() / 3);
        for (size_t i = 0; i < mesh.faceVertIndices.size(); ++i) {
            if (mesh.faceVertIndices[i] < 0 || mesh.faceVertIndices[i] >= vertices) {
                fail("mesh vertex index " + std::to_string(i),
                     "is " + std::to_string(mesh.faceVertIndices[i]), "0.." + std::to_string(vertices - 1));
            }
        }
        // The faces are the mesh's Ptex faces: a triangle file has one per triangle (and only triangles), a
        // quad file one per quad and N per other N-gon.
        int64_t ptexFaces = 0;
        for (size_t i = 0; i < mesh.faceVertCounts.size(); ++i) {
            const int32_t count = mesh.faceVertCounts[i];
            if (file_.meshType == MeshType::Triangle && count != 3) {
                fail("mesh polygon " + std::to_string(i),
                     "has " + std::to_string(count) + " vertices in a triangle-mesh file",
                     "triangles only (or a quad-mesh file)");
            }
            ptexFaces += file_.meshType == MeshType::Triangle || count == 4 ? 1 : count;
        }
        if (ptexFaces != static_cast<int64_t>(file_.faces.size())) {
            fail("mesh", "has " + std::to_string(ptexFaces) + " Ptex faces",
                 std::to_string(file_.faces.size()) + ", the file's faces (" +
                     (file_.meshType == MeshType::Triangle ? "one per triangle"
                                                           : "one per quad, N per N-gon") +
                     ")");
        }
    }

    std::vector<MetaValue> allMetadata() const {
        std::vector<MetaValue> entries = file_.metadata;
        if (options_.mesh) {
            entries.push_back(MetaValue::ofInt32(kFaceVertCounts, options_.mesh->faceVertCounts));
            entries.push_back(MetaValue::ofInt32(kFaceVertIndices, options_.mesh->faceVertIndices));
            entries.push_back(MetaValue::ofFloat(kVertPositions, options_.mesh->vertPositions));
        }
        return entries;
    }

    static void putMetaKey(ByteWriter& out, const MetaValue& m, size_t valueSize) {
        out.put(static_cast<uint8_t>(m.key.size() + 1));
        out.bytes({reinterpret_cast<const uint8_t*>(m.key.data()), m.key.size()});
        out.put(uint8_t{0});
        out.put(static_cast<uint8_t>(m.type));
        out.put(static_cast<uint32_t>(valueSize));
    }

    // Decides which faces are constant (their ConstData pixel is the texel value), the neighbourhood-constant
    // flag, and each face's place in the reduction levels. A triangle file's faces keep no flags but
    // `constant` and no fourth edge, as the format defines them.
    void classifyFaces() {
        const size_t n = file_.faces.size();
        const size_t pixel = file_.pixelSize();
        faces_ = file_.faces;
        constData_.assign(n * pixel, 0);
        for (size_t f = 0; f < n; ++f) {
            FaceInfo& info = faces_[f];
            info.hasEdits = false;
            info.neighbourhoodConstant = false;
            if (file_.meshType == MeshType::Triangle) {
                info.subface = false;
                info.adjFaces[3] = -1;
                info.adjEdges[3] = 0;
            }
            const std::vector<uint8_t>& texels = file_.texels[f];
            if (texels.empty()) {
                info.constant = true;
                std::memcpy(constData_.data() + f * pixel, file_.constData.data() + f * pixel, pixel);
                continue;
            }
            bool allEqual = true;
            for (size_t t = pixel; t < texels.size() && allEqual; t += pixel) {
                allEqual = std::memcmp(texels.data(), texels.data() + t, pixel) == 0;
            }
            info.constant = allEqual;
            if (allEqual) std::memcpy(constData_.data() + f * pixel, texels.data(), pixel);
        }
        for (size_t f = 0; f < n; ++f)
            faces_[f].neighbourhoodConstant = faces_[f].constant && constantAroundCorners(f);
        order_ = reductionOrder(faces_);
        lastLevel_.assign(n, 0);
        for (size_t f = 0; f < n; ++f) {
            if (!faces_[f].constant && options_.reductions)
                lastLevel_[f] = std::max(0, reductionRank(faces_[f]) - kMinReductionLog2);
        }
    }

    // True when every face met walking around each corner of constant face f is constant with f's value,
    // walking as the reference writer does: clockwise from each edge's neighbour, at most 9 faces, stopping
    // at a T-vertex between a sub-face and a main face; at a boundary (which only clamp border modes allow)
    // also counter-clockwise, starting from the edge before the one the clockwise walk ended on.
    bool constantAroundCorners(size_t f) const {
        const size_t pixel = file_.pixelSize();
        const uint8_t* value = constData_.data() + f * pixel;
        const int edges = file_.meshType == MeshType::Triangle ? 3 : 4;
        const auto sameConstant = [&](int32_t g) {
            return faces_[g].constant && std::memcmp(value, constData_.data() + g * pixel, pixel) == 0;
        };
        constexpr int kMaxValence = 10;
        const auto self = static_cast<int32_t>(f);
        for (int e = 0; e < edges; ++e) {
            bool previousWasSubface = faces_[f].subface;
            int32_t previous = self;
            int32_t g = faces_[f].adjFaces[e];
            int edge = faces_[f].adjEdges[e];
            for (int count = 1; g != self && g >= 0 && count < kMaxValence; ++count) {
                if (!sameConstant(g)) return false;
                const FaceInfo& other = faces_[g];
                const bool tVertex =
                    edges == 4 && previousWasSubface && !other.subface && other.adjFaces[edge] == previous;
                if (tVertex) break;
                previousWasSubface = other.subface;
                previous = g;
                const int next = (edge + 1) % edges;
                g = other.adjFaces[next];
                edge = other.adjEdges[next];
            }
            if (g >= 0) continue;
            if (file_.uBorderMode != BorderMode::Clamp || file_.vBorderMode != BorderMode::Clamp)
                return false;
            int start = (edge - 1 + edges) % edges;
            g = faces_[f].adjFaces[start];
            edge = faces_[f].adjEdges[start];
            for (int count = 1; g != self && g >= 0 && count < kMaxValence; ++count) {
                if (!sameConstant(g)) return false;
                const FaceInfo& other = faces_[g];
                const int next = (edge - 1 + edges) % edges;
                g = other.adjFaces[next];
                edge = other.adjEdges[next];
                if (other.subface && !previousWasSubface) {
                    // Entering a sub-face from a main face: continue from the second sub-face of the edge.
                    const int turned = (edge + 3) % 4;
                    edge = (other.adjEdges[turned] + 3) % 4;
                    g = other.adjFaces[turned];
                }
                previousWasSubface = other.subface;
            }
        }
        return true;
    }

    // Level 0 plus one level per reduction down to kMinReductionLog2 on the smaller side.
    int levelCount() const {
        int levels = 1;
        for (size_t f = 0; f < faces_.size(); ++f)
            levels = std::max(levels, lastLevel_[f] + 1);
        return levels;
    }

    // Appends one level (zipped face-data headers, then the blocks) and returns the zipped header size and
    // the number of faces. Level 0 lists every face in face order; level i the faces whose reductions reach
    // it, in reduction order. Each face's premultiplied texels at the level are kept for the next one, and
    // at its last level give its ConstData value.
    std::pair<size_t, size_t> writeLevel(int level, std::vector<uint8_t>& out) {
        std::vector<uint32_t> order;
        if (level == 0) {
            order.resize(faces_.size());
            std::iota(order.begin(), order.end(), 0u);
            reduced_.assign(faces_.size(), {});
        } else {
            for (const uint32_t f : order_) {
                if (lastLevel_[f] < level) break;  // reduction order is by descending last level
                order.push_back(f);
            }
        }
        std::vector<uint8_t> headers;
        std::vector<uint8_t> blocks;
        ByteWriter h(headers);
        const bool alpha = file_.alphaChannel >= 0;
        for (const uint32_t f : order) {
            const FaceInfo& info = faces_[f];
            if (info.constant) {
                h.put(uint32_t{0});
                continue;
            }
            const int w = info.ures() >> level;
            const int hgt = info.vres() >> level;
            const std::string element = "face " + std::to_string(f) + " at level " + std::to_string(level);
            if (level == 0) {
                h.put(encodeFace(file_.texels[f], w, hgt, blocks, element));
                if (alpha) {
                    reduced_[f] = file_.texels[f];
                    premultiplyAlpha(reduced_[f], file_.dataType, file_.channels, file_.alphaChannel);
                }
            } else {
                const std::vector<uint8_t>& source = reduced_[f].empty() ? file_.texels[f] : reduced_[f];
                reduced_[f] = file_.meshType == MeshType::Triangle
                                  ? reduceTriangleFace(source, w * 2, file_.dataType, file_.channels)
                                  : reduceQuadFace(source, w * 2, hgt * 2, file_.dataType, file_.channels);
                h.put(encodeFace(reduced_[f], w, hgt, blocks, element));
            }
            if (level == lastLevel_[f]) {
                const std::vector<uint8_t>& last = reduced_[f].empty() ? file_.texels[f] : reduced_[f];
                uint8_t* value = constData_.data() + f * file_.pixelSize();
                averageTexels(last, static_cast<size_t>(w) * hgt, file_.dataType, file_.channels, value);
                unpremultiplyAlpha({value, file_.pixelSize()}, file_.dataType, file_.channels,
                                   file_.alphaChannel);
                reduced_[f] = {};
            }
        }
        const std::vector<uint8_t> headerZip = zip(headers, "level " + std::to_string(level) + " headers");
        out.insert(out.end(), headerZip.begin(), headerZip.end());
        out.insert(out.end(), blocks.begin(), blocks.end());
        return {headerZip.size(), order.size()};
    }

    // Appends a non-constant face block and returns its face-data header.
    uint32_t encodeFace(const std::vector<uint8_t>& texels, int w, int h, std::vector<uint8_t>& out,
                        const std::string& element) {
        const size_t pixel = file_.pixelSize();
        const size_t bytes = static_cast<size_t>(w) * h * pixel;
        if (bytes < options_.tileThresholdBytes || w * h == 1) {
            const size_t before = out.size();
            const uint32_t encoding = zipRect(texels.data(), w, 0, 0, w, h, out, element);
            return blockHeader(encoding, checkedBlockSize(out.size() - before, element));
        }
        // Tiles of about tileBytes: 2^k tiles, k = floor(log2(bytes / tileBytes)), as square as the face
        // allows (the reference writer's rule, so both write the same blocks).
        const int faceLog2 =
            std::countr_zero(static_cast<unsigned>(w)) + std::countr_zero(static_cast<unsigned>(h));
        const int tilesLog2 = std::max(1, static_cast<int>(std::bit_width(bytes / options_.tileBytes)) - 1);
        const int tileLog2 = std::max(0, faceLog2 - tilesLog2);
        const int tileULog2 = std::min((tileLog2 + 1) / 2, std::countr_zero(static_cast<unsigned>(w)));
        const int tileVLog2 = std::min(tileLog2 - tileULog2, std::countr_zero(static_cast<unsigned>(h)));
        const int tw = 1 << tileULog2;
        const int th = 1 << tileVLog2;
        std::vector<uint8_t> tileHeaders;
        std::vector<uint8_t> tiles;
        ByteWriter th_(tileHeaders);
        for (int ty = 0; ty < h / th; ++ty) {
            for (int tx = 0; tx < w / tw; ++tx) {
                const uint8_t* first = texels.data() + (static_cast<size_t>(ty) * th * w + tx * tw) * pixel;
                bool allEqual = true;
                for (int y = 0; y < th && allEqual; ++y) {
                    const uint8_t* row =
                        texels.data() + (static_cast<size_t>(ty * th + y) * w + tx * tw) * pixel;
                    for (int x = 0; x < tw && allEqual; ++x)
                        allEqual = std::memcmp(first, row + x * pixel, pixel) == 0;
                }
                if (allEqual) {
                    tiles.insert(tiles.end(), first, first + pixel);
                    th_.put(blockHeader(kConstant, static_cast<uint32_t>(pixel)));
                    continue;
                }
                const size_t before = tiles.size();
                const uint32_t encoding = zipRect(texels.data(), w, tx * tw, ty * th, tw, th, tiles, element);
                th_.put(blockHeader(encoding, checkedBlockSize(tiles.size() - before, element)));
            }
        }
        const std::vector<uint8_t> headerZip = zip(tileHeaders, element + " tile headers");
        const size_t before = out.size();
        ByteWriter o(out);
        o.put(static_cast<int8_t>(tileULog2));
        o.put(static_cast<int8_t>(tileVLog2));
        o.put(static_cast<uint32_t>(headerZip.size()));
        o.bytes(headerZip);
        o.bytes(tiles);
        return blockHeader(kTiled, checkedBlockSize(out.size() - before, element));
    }

    uint32_t checkedBlockSize(size_t size, const std::string& element) const {
        if (size > kBlockSizeMask) {
            fail(element, "encodes to " + std::to_string(size) + " bytes",
                 "fewer than 2^30 (the block size field)");
        }
        return static_cast<uint32_t>(size);
    }

    // Zips the (x0, y0, w, h) rectangle in channel planes, difference-coded for u8/u16; returns the encoding.
    uint32_t zipRect(const uint8_t* face, int faceWidth, int x0, int y0, int w, int h,
                     std::vector<uint8_t>& out, const std::string& element) {
        const int bpc = static_cast<int>(bytesPerChannel(file_.dataType));
        planar_.resize(static_cast<size_t>(w) * h * file_.pixelSize());
        interleavedToPlanar(face, faceWidth, x0, y0, w, h, file_.channels, bpc, planar_.data());
        const bool diff = file_.dataType == DataType::UInt8 || file_.dataType == DataType::UInt16;
        if (diff) diffEncode(planar_, bpc);
        const std::vector<uint8_t> zipped = zip(planar_, element);
        out.insert(out.end(), zipped.begin(), zipped.end());
        return diff ? kDiffZipped : kZipped;
    }

    std::vector<uint8_t> zip(std::span<const uint8_t> data, const std::string& element) const {
        uLongf size = compressBound(static_cast<uLong>(data.size()));
        std::vector<uint8_t> out(size);
        const int rc = compress2(out.data(), &size, data.data(), static_cast<uLong>(data.size()),
                                 options_.compressionLevel);
        if (rc != Z_OK) fail(element, "zlib compression failed (code " + std::to_string(rc) + ")", "");
        out.resize(size);
        return out;
    }

    const PtexFile& file_;
    const WriteOptions& options_;
    std::string source_;
    std::vector<FaceInfo> faces_;
    std::vector<uint8_t> constData_;
    std::vector<uint32_t> order_;                // reduction order
    std::vector<int> lastLevel_;                 // per face: its smallest stored reduction (0: none)
    std::vector<std::vector<uint8_t>> reduced_;  // per face: premultiplied texels at the level being written
    std::vector<uint8_t> planar_;
};

}  // namespace

std::vector<uint8_t> writePtexBytes(const PtexFile& file, const WriteOptions& options) {
    return Writer(file, options, "Ptex data").write();
}

void writePtex(const std::filesystem::path& path, const PtexFile& file, const WriteOptions& options) {
    io::requireExtension(path, {".ptx"}, "a Ptex file");
    const std::vector<uint8_t> bytes = Writer(file, options, path.string()).write();
    io::writeFileAtomically(path, {reinterpret_cast<const char*>(bytes.data()), bytes.size()});
}

}  // namespace deformkit::ptex
