#include "deformkit/ptex/ptex_vertex_values.h"

#include <cmath>
#include <string>

#include "deformkit/error.h"
#include "deformkit/ptex/ptex_mesh.h"
#include "texel_access.h"

namespace deformkit::ptex {

namespace {

// Sums of the corner texels at each vertex and their counts, for one data type (read without a per-value
// switch).
template <DataType Type>
void sumCorners(const PtexMesh& mesh, const PtexFile& file, const std::string& fileSource,
                std::vector<double>& sum, std::vector<int32_t>& count) {
    const int32_t channels = file.channels;
    const size_t bytes = bytesPerChannel(Type), pixel = file.pixelSize();
    const auto add = [&](int32_t vertex, int32_t p, int32_t i, int32_t j) {
        const uint8_t* texel =
            file.texels[p].empty()
                ? file.constData.data() + static_cast<size_t>(p) * pixel
                : file.texels[p].data() + ((static_cast<size_t>(j) << file.faces[p].ulog2) + i) * pixel;
        vertex =
            mesh.weldedVertex(vertex);  // every copy of a split vertex sums into one (its faces around it)
        double* out = sum.data() + static_cast<size_t>(vertex) * channels;
        for (int32_t c = 0; c < channels; ++c) {
            const double value = detail::loadValue(texel + c * bytes, Type);
            if constexpr (Type == DataType::Half || Type == DataType::Float) {
                if (!std::isfinite(value)) {
                    throw InvalidInput(formatError(
                        fileSource,
                        "face " + std::to_string(p) + " texel (" + std::to_string(i) + ", " +
                            std::to_string(j) + ") channel " + std::to_string(c),
                        "is " + numberText(value), "finite values at the faces' corners (a vertex's value)"));
                }
            }
            out[c] += value;
        }
        ++count[static_cast<size_t>(vertex)];
    };
    for (int32_t f = 0; f < mesh.numMeshFaces(); ++f) {
        const auto corners = mesh.faceVertices(f);
        const int32_t p = mesh.firstPtexFace(f);
        if (corners.size() == 4) {
            const int32_t iu = file.faces[p].ures() - 1, jv = file.faces[p].vres() - 1;
            add(corners[0], p, 0, 0);
            add(corners[1], p, iu, 0);
            add(corners[2], p, iu, jv);
            add(corners[3], p, 0, jv);
        } else {
            for (size_t k = 0; k < corners.size(); ++k)
                add(corners[k], p + static_cast<int32_t>(k), 0, 0);
        }
    }
}

}  // namespace

std::vector<float> vertexValues(const PtexMesh& mesh, const PtexFile& file, const std::string& fileSource) {
    mesh.requireMatches(file, fileSource);
    detail::requireBuffers(file, fileSource);
    // Only the corner texels are read, straight from the file's bytes.
    const int32_t channels = file.channels;
    std::vector<double> sum(static_cast<size_t>(mesh.numWeldedVertices()) * channels, 0.0);
    std::vector<int32_t> count(static_cast<size_t>(mesh.numWeldedVertices()), 0);
    switch (file.dataType) {
        case DataType::UInt8:
            sumCorners<DataType::UInt8>(mesh, file, fileSource, sum, count);
            break;
        case DataType::UInt16:
            sumCorners<DataType::UInt16>(mesh, file, fileSource, sum, count);
            break;
        case DataType::Half:
            sumCorners<DataType::Half>(mesh, file, fileSource, sum, count);
            break;
        case DataType::Float:
            sumCorners<DataType::Float>(mesh, file, fileSource, sum, count);
            break;
    }
    // Each file vertex takes its welded vertex's mean: split copies read alike, as the shared vertex does.
    std::vector<float> values(static_cast<size_t>(mesh.numVertices()) * channels, 0.0f);
    for (int32_t v = 0; v < mesh.numVertices(); ++v) {
        const auto w = static_cast<size_t>(mesh.weldedVertex(v));
        if (count[w] == 0) continue;
        for (int32_t c = 0; c < channels; ++c)
            values[static_cast<size_t>(v) * channels + c] =
                static_cast<float>(sum[w * channels + c] / count[w]);
    }
    return values;
}

std::vector<float> weightsFromPtex(const geom::Mesh& mesh, const std::string& meshName,
                                   const std::filesystem::path& file, int32_t channel,
                                   const std::string& source) {
    // The file is named once: a source that is the file itself adds nothing.
    const bool prefix = !source.empty() && source != file.string();
    const std::string fileSource = prefix ? source + ": " + file.string() : file.string();
    const PtexFile ptexFile = [&] {
        try {
            return readPtex(file);  // its errors name the file
        } catch (const IoError& e) {
            throw IoError(prefix ? source + ": " + e.what() : e.what());
        } catch (const ParseError& e) {
            throw ParseError(prefix ? source + ": " + e.what() : e.what());
        }
    }();
    if (channel < 0 || channel >= ptexFile.channels) {
        throw InvalidInput(
            formatError(fileSource, "channel " + std::to_string(channel),
                        "is not one of the file's " + std::to_string(ptexFile.channels) + " channels",
                        "a channel in [0, " + std::to_string(ptexFile.channels) + ")"));
    }
    const PtexMesh ptexMesh(mesh, meshName);
    const std::vector<float> values = vertexValues(ptexMesh, ptexFile, fileSource);
    std::vector<float> weights(static_cast<size_t>(mesh.numVertices()));
    for (size_t v = 0; v < weights.size(); ++v)
        weights[v] = values[v * ptexFile.channels + channel];
    return weights;
}

PtexFile bakeVertexValues(const PtexMesh& mesh, std::span<const float> values, int32_t channels,
                          const BakeOptions& options) {
    if (channels < 1 || channels > 64) {
        throw InvalidInput(
            formatError(mesh.source(), "channels", "is " + std::to_string(channels), "1 to 64 channels"));
    }
    if (values.size() != static_cast<size_t>(mesh.numVertices()) * channels) {
        throw InvalidInput(formatError(
            mesh.source(), "vertex values", "has " + std::to_string(values.size()),
            std::to_string(mesh.numVertices()) + " vertices x " + std::to_string(channels) + " channels"));
    }
    if (options.ulog2 < 0 || options.ulog2 > 15 || options.vlog2 < 0 || options.vlog2 > 15) {
        throw InvalidInput(
            formatError(mesh.source(), "bake resolution",
                        "is 2^" + std::to_string(options.ulog2) + " x 2^" + std::to_string(options.vlog2),
                        "log2 sizes in [0, 15]"));
    }
    for (size_t i = 0; i < values.size(); ++i) {
        if (!std::isfinite(values[i])) {
            throw InvalidInput(formatError(mesh.source(), "vertex " + std::to_string(i / channels),
                                           "has value " + numberText(values[i]), "finite values"));
        }
        // Texels are blends of their face's vertex values (weights >= 0, summing to 1): in the type's range
        // when the vertices are. A value beyond it would be clamped (u8, u16) or become inf (half).
        if (const std::string range = detail::outsideTypeRange(values[i], options.dataType); !range.empty()) {
            throw InvalidInput(formatError(mesh.source(), "vertex " + std::to_string(i / channels),
                                           "has value " + numberText(values[i]), range));
        }
    }
    PtexFile file;
    file.meshType = MeshType::Quad;
    file.dataType = options.dataType;
    file.channels = channels;
    file.faces = mesh.faceInfos(options.ulog2, options.vlog2);
    file.texels.resize(file.faces.size());
    file.constData.assign(file.faces.size() * file.pixelSize(), 0);
    const size_t bytes = bytesPerChannel(options.dataType);
    std::vector<double> weights;
    for (int32_t p = 0; p < mesh.numPtexFaces(); ++p) {
        const FaceInfo& info = file.faces[p];
        const auto corners = mesh.faceVertices(mesh.meshFace(p));
        weights.resize(corners.size());
        std::vector<uint8_t>& texels = file.texels[p];
        texels.resize(info.texelCount() * file.pixelSize());
        for (int32_t j = 0; j < info.vres(); ++j) {
            for (int32_t i = 0; i < info.ures(); ++i) {
                mesh.cornerWeights(p, (i + 0.5) / info.ures(), (j + 0.5) / info.vres(), weights);
                for (int32_t c = 0; c < channels; ++c) {
                    double value = 0.0;
                    for (size_t k = 0; k < corners.size(); ++k)
                        value += weights[k] * values[static_cast<size_t>(corners[k]) * channels + c];
                    const size_t at = ((static_cast<size_t>(j) * info.ures() + i) * channels + c) * bytes;
                    detail::storeValue(static_cast<float>(value), options.dataType, texels.data() + at);
                }
            }
        }
    }
    return file;
}

}  // namespace deformkit::ptex
