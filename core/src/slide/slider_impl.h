#pragma once

// Private to the slider: its bound state, Slider::Impl, whose work is spread by job over binding and
// evaluation (slider.cpp), the walk over the rest surface (slider_walk.cpp), the incoming frame
// (slider_incoming_frame.cpp), landing on the limit surface (slider_limit_surface.cpp) and the fold limit
// (slider_fold_limit.cpp).

#include <cstdint>
#include <memory>
#include <mutex>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "deformkit/geom/limit_surface.h"
#include "deformkit/geom/mesh.h"
#include "deformkit/geom/weld.h"
#include "deformkit/slide/region.h"
#include "deformkit/slide/slider.h"
#include "deformkit/slide/surface.h"

namespace deformkit::slide {

// Types Slider::Impl holds, in a named namespace: a class's fields must not have types of an anonymous
// namespace when the source is compiled as part of a unity batch (-Wsubobject-linkage).
namespace detail {

// Loops over fewer items than this run on the calling thread: waking a second thread costs more than the
// work (a 500-vertex slide takes ~0.2 ms), and far more when the other core is busy (a host's own threads).
constexpr int32_t kParallelFrom = 4096;

// How a walk ended: WalkLimit after SlideOptions::maxWalkTriangles triangles, or when its line left the
// triangles it crossed.
enum class Stop : uint8_t { None, Reached, Boundary, WalkLimit };

struct Landing {
    int32_t triangle = -1;
    glm::dvec3 barycentric{0.0};  // on the triangle's corners 3t, 3t+1, 3t+2
    Stop stop = Stop::None;
};

// A landing on the edge of `corner` (from vertex(corner) to vertex(next(corner))) at parameter mu.
inline Landing onEdge(int32_t corner, double mu, Stop stop) {
    Landing landing;
    landing.triangle = SlideSurface::triangleOf(corner);
    landing.barycentric[corner % 3] = 1.0 - mu;
    landing.barycentric[SlideSurface::next(corner) % 3] = mu;
    landing.stop = stop;
    return landing;
}

// The Catmull-Clark limit surface over the part of the mesh the slide can reach: the faces landings may
// fall on ("covered") and every face sharing a vertex with them, so that the patches of covered faces see
// their whole one-ring and equal those of the whole mesh. Grows when a landing leaves the covered faces.
struct LocalLimit {
    std::vector<int32_t> vertexFaceOffsets, vertexFaces;  // the mesh's faces at each vertex (CSR)
    std::vector<uint8_t> covered;                         // per mesh face
    std::vector<int32_t> localFace;                       // per mesh face: its face in the part, or -1
    std::vector<int32_t> vertices;                        // the part's vertices (mesh indices), ascending
    std::vector<int32_t> localVertex;                     // per mesh vertex: its vertex in the part, or -1
    std::unique_ptr<geom::LimitSurface> rest;             // over the rest positions
    std::unique_ptr<geom::LimitSurface> incoming;         // over the last incoming positions
    std::vector<glm::vec3> incomingCage;                  // those positions, per part vertex
    const geom::LimitSurface* current = nullptr;          // rest or incoming, for this evaluation
};

}  // namespace detail

struct Slider::Impl {
    using Landing = detail::Landing;
    using Stop = detail::Stop;

    std::string source;
    // Distinct vertices within a radius that no region moves, and without a tangent plane (SlideResult).
    int32_t unreachable = 0, withoutTangentPlane = 0;
    geom::Mesh mesh;
    SlideOptions options;
    std::vector<SlideHandle> handles;
    SlideSurface surface;
    std::vector<SupportRegion> regions;
    std::vector<std::vector<int32_t>> regionSlots;  // per region, per active vertex: its slot in `active`
    std::vector<int32_t> active;                    // union of active vertices, ascending
    std::vector<glm::dvec2> displacement;           // per slot: d_P in the vertex's basis (Eq. 7), scratch
    std::vector<Landing> landings;                  // per slot, scratch
    std::vector<int32_t> slotOf;                    // per vertex: its slot in `active`, -1 when inactive
    std::vector<glm::dvec3> slid;                   // per slot: the slid position, scratch
    std::vector<glm::dvec3> restDisplacement;       // per handle: its displacement in its rest frame, scratch
    std::vector<double> scales;                     // per handle: its fold-limit scale, scratch
    // Triangles with an active corner (not degenerate at rest), ascending: where folds are counted. Per
    // handle: the triangles with a corner in its region.
    std::vector<int32_t> regionTriangles;
    std::vector<std::vector<int32_t>> handleTriangles;
    std::unique_ptr<detail::LocalLimit> limit;
    int32_t degenerateTriangles = 0;
    std::mutex mutex;

    // A rest mesh with split vertices (geom/weld.h) is bound welded: everything above is on the welded mesh,
    // and the public interface speaks of the file's vertices through these. Null when nothing was welded.
    std::unique_ptr<geom::Welding> weld;
    std::vector<SlideHandle> fileHandles;    // the handles as given (file vertices)
    std::vector<SupportRegion> fileRegions;  // the regions with every copy of each welded vertex
    std::vector<int32_t> fileActive;         // every copy of the active vertices, ascending
    std::vector<glm::vec3> weldedPoints;     // scratch: the incoming points of the welded vertices
    std::vector<glm::vec3> weldedIn;         // scratch: the same before the slide
    std::vector<float> weldedWeights;        // scratch: each welded vertex's weight, the mean of its copies'
    std::vector<int32_t> fileFaceOffsets;    // the file's faces: corners [offsets[f], offsets[f + 1])
    std::vector<int32_t> fileFaceIndices;    // of fileFaceIndices

    // The file vertex at the corner of file face `face` whose welded vertex is `welded`.
    [[nodiscard]] int32_t fileCornerVertex(int32_t face, int32_t welded) const {
        for (int32_t c = fileFaceOffsets[face]; c < fileFaceOffsets[face + 1]; ++c) {
            if (weld->weldedOf[static_cast<size_t>(fileFaceIndices[c])] == welded) return fileFaceIndices[c];
        }
        return -1;
    }

    // InvalidInput unless there is one point per vertex and no weight or one per vertex.
    void requireCounts(int32_t vertices, size_t points, size_t weights) const;
    // The evaluation on the surface's own vertices (the welded ones when `weld` is set).
    void evaluateSurface(std::span<const SlideDrive> drives, std::span<glm::vec3> points,
                         std::span<const float> weights, double envelope, SlideResult* result);

    Impl(const geom::Mesh& rest, std::vector<SlideHandle> h, const SlideOptions& o, std::string s)
        : source(std::move(s)), mesh(rest), options(o), handles(std::move(h)), surface(rest, source) {}

    // The one-ring part of a vertex's local map (Eq. 1-2 for the vertices sharing a triangle with it),
    // computed at bind: per corner c at the vertex, the images of vertex(next(c)) and vertex(prev(c)).
    std::vector<int32_t> ringOffsets;  // per slot, into ringNext / ringPrev; corners in vertexCorners order
    std::vector<glm::dvec2> ringNext, ringPrev;
    std::vector<uint8_t> interior;  // per slot: no boundary edge at the vertex

    // The walk (slider_walk.cpp).

    // The image of one-ring neighbour q in p's tangent space (Eq. 1-2, computed at bind).
    [[nodiscard]] glm::dvec2 ringImage(int32_t slot, int32_t p, int32_t q) const;
    [[nodiscard]] bool isInteriorVertex(int32_t p) const;
    // At a boundary vertex, a slide along the boundary (within kParallel radians of a boundary edge) is
    // turned kInward radians into the surface, so that rounding in the propagated direction cannot start
    // its path just outside the surface, which would stop it at once.
    [[nodiscard]] glm::dvec2 alongBoundary(int32_t slot, int32_t p, const glm::dvec2& target) const;
    // §3.3: the triangle F' where p lands when it slides by `requested` (d_P in p's basis): the sector of
    // p's one-ring map that holds the direction, then a straight walk of |d_P| across the triangles,
    // each unfolded into the plane of the one before across the edge the walk crosses.
    [[nodiscard]] Landing walk(int32_t slot, int32_t p, const glm::dvec2& requested) const;

    // Landing on the limit surface (slider_limit_surface.cpp).
    [[nodiscard]] glm::dvec3 limitPoint(const Landing& landing) const;
    // The limit point under vertex v, taken through the same face evaluation as its landings so that a
    // vanishing slide moves it by a vanishing amount.
    [[nodiscard]] glm::dvec3 limitOrigin(int32_t v) const;
    // (Re)builds the limit surface of the covered faces and their one-ring of faces.
    void buildLocalLimit();
    void bindLimit();
    // Makes every landing's face covered, growing the limit part when one is not; true when it grew.
    bool coverLandings();
    // The limit surface over the incoming positions: the rest one when they equal the rest positions on
    // the part, the last one when they have not changed since.
    void prepareLimit(std::span<const glm::vec3> in);

    // The incoming frame (slider_incoming_frame.cpp).

    // A drag given in the incoming space, carried back into handle h's rest frame: through the inverse of
    // the linear map that best takes the handle's rest one-ring edges and normal (scaled to the ring) onto
    // the incoming ones (least squares), so the handle follows the locator on a stretched or compressed
    // input; for a ring moved rigidly by (R, t) that map is R, up to rounding. Where the incoming ring has
    // collapsed (the map is not invertible) the best rotation (Kabsch) of the same data is used instead.
    // The identity when the ring did not move.
    [[nodiscard]] glm::dvec3 toRestFrame(size_t h, std::span<const glm::vec3> in, const glm::dvec3& d) const;

    // Evaluation (slider.cpp).

    struct Counts {
        int32_t moved = 0, boundaryStopped = 0, walkLimitStopped = 0;
    };

    // One slide: the tangent displacements of every handle's rest-frame displacement times its scale
    // (Eq. 5-7), the walks, and the slid position of every moved vertex over the incoming points `in`.
    Counts slideOnce(std::span<const glm::dvec3> restDisplacement, std::span<const double> scales,
                     std::span<const SlideDrive> drives, std::span<const glm::vec3> in,
                     std::span<const float> weights, double envelope);

    // The fold limit (slider_fold_limit.cpp).

    [[nodiscard]] glm::dvec3 slidPoint(int32_t v, std::span<const glm::vec3> in) const;
    // Triangles of `triangles` whose orientation after the slide opposes the incoming one.
    [[nodiscard]] int32_t countFlips(std::span<const int32_t> triangles, std::span<const glm::vec3> in) const;
    // The largest scale in [0, 1] (to 2^-kSteps) at which slideOnce with scales `base` times it flips no
    // triangle of `triangles`; 0 moves nothing, so it never flips.
    double foldLimitScale(std::span<const glm::dvec3> restDisplacement, std::vector<double> base,
                          std::span<const int32_t> triangles, std::span<const SlideDrive> drives,
                          std::span<const glm::vec3> in, std::span<const float> weights, double envelope);
    // SlideOptions::foldLimit, after a slide at `scales` that flipped `flipped` (> 0) triangles: lowers
    // `scales` until no triangle flips, each handle alone first (its own region), then all together while
    // overlapping regions still fold. The last slide stays in `landings` and `slid`; returns its counts
    // and sets `flipped` to its flips.
    Counts limitFolds(std::span<const glm::dvec3> restDisplacement, std::vector<double>& scales,
                      std::span<const SlideDrive> drives, std::span<const glm::vec3> in,
                      std::span<const float> weights, double envelope, int32_t& flipped);
};

}  // namespace deformkit::slide
