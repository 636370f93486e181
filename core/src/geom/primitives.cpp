#include "deformkit/geom/primitives.h"

#include <cmath>
#include <limits>
#include <numbers>

#include "deformkit/error.h"

namespace deformkit::geom {
namespace {

constexpr float kTwoPi = 2.0f * std::numbers::pi_v<float>;

void requireAtLeast(const char* what, int32_t value, int32_t minimum) {
    if (value < minimum) {
        throw InvalidInput(formatError("primitive", what, "is " + std::to_string(value),
                                       "at least " + std::to_string(minimum)));
    }
}

void addFace(Mesh::Data& d, std::initializer_list<int32_t> verts, std::initializer_list<int32_t> uvs) {
    d.faceCounts.push_back(static_cast<int32_t>(verts.size()));
    d.faceIndices.insert(d.faceIndices.end(), verts);
    d.uvIndices.insert(d.uvIndices.end(), uvs);
}

}  // namespace

Mesh makeGrid(const GridOptions& o) {
    requireAtLeast("cellsX", o.cellsX, 1);
    requireAtLeast("cellsY", o.cellsY, 1);
    // Every face corner is an int32 index: refused at once, not after minutes of filling memory.
    const int64_t corners = int64_t{4} * o.cellsX * o.cellsY;
    if (corners > std::numeric_limits<int32_t>::max()) {
        throw InvalidInput(formatError("primitive", "cellsX x cellsY",
                                       "is " + std::to_string(o.cellsX) + " x " + std::to_string(o.cellsY) +
                                           ", " + std::to_string(corners) + " face corners",
                                       "at most 2147483647 face corners (4 a cell)"));
    }
    Mesh::Data d;
    const int32_t nx = o.cellsX + 1;
    for (int32_t j = 0; j <= o.cellsY; ++j) {
        for (int32_t i = 0; i <= o.cellsX; ++i) {
            const float u = static_cast<float>(i) / o.cellsX, v = static_cast<float>(j) / o.cellsY;
            d.points.emplace_back(u * o.sizeX, v * o.sizeY, 0.0f);
            d.uvs.emplace_back(u, v);
        }
    }
    for (int32_t j = 0; j < o.cellsY; ++j) {
        for (int32_t i = 0; i < o.cellsX; ++i) {
            const int32_t a = j * nx + i, b = a + 1, c = a + 1 + nx, e = a + nx;
            addFace(d, {a, b, c, e}, {a, b, c, e});
        }
    }
    return Mesh(std::move(d), "grid");
}

Mesh makeSphere(const SphereOptions& o) {
    requireAtLeast("segments", o.segments, 3);
    requireAtLeast("rings", o.rings, 2);
    Mesh::Data d;
    const int32_t s = o.segments;
    // Vertices: north pole, rings - 1 latitude rows of s vertices, south pole.
    d.points.emplace_back(0.0f, 0.0f, o.radius);
    for (int32_t j = 1; j < o.rings; ++j) {
        const float polar = std::numbers::pi_v<float> * j / o.rings;
        for (int32_t i = 0; i < s; ++i) {
            const float az = kTwoPi * i / s;
            d.points.emplace_back(o.radius * std::sin(polar) * std::cos(az),
                                  o.radius * std::sin(polar) * std::sin(az), o.radius * std::cos(polar));
        }
    }
    const int32_t south = static_cast<int32_t>(d.points.size());
    d.points.emplace_back(0.0f, 0.0f, -o.radius);
    auto vert = [&](int32_t j, int32_t i) { return 1 + (j - 1) * s + (i % s); };

    // UVs: s + 1 columns per latitude row (seam), plus one pole UV per segment at each pole.
    for (int32_t j = 1; j < o.rings; ++j) {
        for (int32_t i = 0; i <= s; ++i)
            d.uvs.emplace_back(static_cast<float>(i) / s, 1.0f - static_cast<float>(j) / o.rings);
    }
    const int32_t northUV = static_cast<int32_t>(d.uvs.size());
    for (int32_t i = 0; i < s; ++i)
        d.uvs.emplace_back((i + 0.5f) / s, 1.0f);
    const int32_t southUV = static_cast<int32_t>(d.uvs.size());
    for (int32_t i = 0; i < s; ++i)
        d.uvs.emplace_back((i + 0.5f) / s, 0.0f);
    auto uv = [&](int32_t j, int32_t i) { return (j - 1) * (s + 1) + i; };

    for (int32_t i = 0; i < s; ++i)
        addFace(d, {0, vert(1, i), vert(1, i + 1)}, {northUV + i, uv(1, i), uv(1, i + 1)});
    for (int32_t j = 1; j + 1 < o.rings; ++j) {
        for (int32_t i = 0; i < s; ++i) {
            addFace(d, {vert(j, i), vert(j + 1, i), vert(j + 1, i + 1), vert(j, i + 1)},
                    {uv(j, i), uv(j + 1, i), uv(j + 1, i + 1), uv(j, i + 1)});
        }
    }
    const int32_t last = o.rings - 1;
    for (int32_t i = 0; i < s; ++i) {
        addFace(d, {south, vert(last, i + 1), vert(last, i)}, {southUV + i, uv(last, i + 1), uv(last, i)});
    }
    return Mesh(std::move(d), "sphere");
}

Mesh makeCappedTube(const CappedTubeOptions& o) {
    requireAtLeast("segments", o.segments, 3);
    requireAtLeast("rows", o.rows, 1);
    requireAtLeast("capRings", o.capRings, 1);
    Mesh::Data d;
    const int32_t s = o.segments;

    // Side: (rows + 1) rings of s vertices; UVs have s + 1 columns (the seam at angle 0).
    for (int32_t j = 0; j <= o.rows; ++j) {
        const float y = o.length * j / o.rows;
        for (int32_t i = 0; i < s; ++i) {
            const float a = kTwoPi * i / s;
            d.points.emplace_back(o.radius * std::cos(a), y, o.radius * std::sin(a));
        }
        // u runs against the angle so the layout is unmirrored seen from outside.
        for (int32_t i = 0; i <= s; ++i)
            d.uvs.emplace_back(static_cast<float>(s - i) / s, static_cast<float>(j) / o.rows);
    }
    auto sideVert = [&](int32_t j, int32_t i) { return j * s + (i % s); };
    auto sideUV = [&](int32_t j, int32_t i) { return j * (s + 1) + i; };
    for (int32_t j = 0; j < o.rows; ++j) {
        for (int32_t i = 0; i < s; ++i) {
            // Winding chosen so the normal points away from the axis.
            addFace(d, {sideVert(j, i), sideVert(j + 1, i), sideVert(j + 1, i + 1), sideVert(j, i + 1)},
                    {sideUV(j, i), sideUV(j + 1, i), sideUV(j + 1, i + 1), sideUV(j, i + 1)});
        }
    }

    // Caps: ring 0 is the tube's end ring (shared vertices), rings 1..capRings-1 are new, then the centre.
    // UV disks of radius 0.24 centred at (1.25, 0.5) (bottom) and (1.75, 0.5) (top), tile 1002.
    for (int32_t cap = 0; cap < 2; ++cap) {
        const bool top = cap == 1;
        const float y = top ? o.length : 0.0f;
        const glm::vec2 centreUV(top ? 1.75f : 1.25f, 0.5f);
        std::vector<int32_t> ringStart(o.capRings);
        ringStart[0] = top ? sideVert(o.rows, 0) : 0;
        for (int32_t k = 1; k < o.capRings; ++k) {
            ringStart[k] = static_cast<int32_t>(d.points.size());
            const float r = o.radius * static_cast<float>(o.capRings - k) / o.capRings;
            for (int32_t i = 0; i < s; ++i) {
                const float a = kTwoPi * i / s;
                d.points.emplace_back(r * std::cos(a), y, r * std::sin(a));
            }
        }
        const int32_t centre = static_cast<int32_t>(d.points.size());
        d.points.emplace_back(0.0f, y, 0.0f);

        const int32_t uvBase = static_cast<int32_t>(d.uvs.size());
        for (int32_t k = 0; k < o.capRings; ++k) {
            const float r = 0.24f * static_cast<float>(o.capRings - k) / o.capRings;
            for (int32_t i = 0; i < s; ++i) {
                const float a = kTwoPi * i / s;
                // Mirror the bottom cap's UVs so both disks are seen unmirrored from outside.
                d.uvs.push_back(centreUV + r * glm::vec2(std::cos(a), top ? -std::sin(a) : std::sin(a)));
            }
        }
        const int32_t centreUVIndex = static_cast<int32_t>(d.uvs.size());
        d.uvs.push_back(centreUV);

        auto vert = [&](int32_t k, int32_t i) { return ringStart[k] + (i % s); };
        auto uv = [&](int32_t k, int32_t i) { return uvBase + k * s + (i % s); };
        for (int32_t k = 0; k + 1 < o.capRings; ++k) {
            for (int32_t i = 0; i < s; ++i) {
                if (top) {
                    addFace(d, {vert(k, i), vert(k + 1, i), vert(k + 1, i + 1), vert(k, i + 1)},
                            {uv(k, i), uv(k + 1, i), uv(k + 1, i + 1), uv(k, i + 1)});
                } else {
                    addFace(d, {vert(k, i), vert(k, i + 1), vert(k + 1, i + 1), vert(k + 1, i)},
                            {uv(k, i), uv(k, i + 1), uv(k + 1, i + 1), uv(k + 1, i)});
                }
            }
        }
        const int32_t k = o.capRings - 1;
        for (int32_t i = 0; i < s; ++i) {
            if (top) {
                addFace(d, {vert(k, i), centre, vert(k, i + 1)}, {uv(k, i), centreUVIndex, uv(k, i + 1)});
            } else {
                addFace(d, {vert(k, i), vert(k, i + 1), centre}, {uv(k, i), uv(k, i + 1), centreUVIndex});
            }
        }
    }
    return Mesh(std::move(d), "capped tube");
}

}  // namespace deformkit::geom
