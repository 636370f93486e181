// "ffd" and "ffdframes": free-form deformation over a lattice (warp/ffd.h, warp/ffd_frames.h).

#include <algorithm>
#include <array>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "deformkit/error.h"
#include "deformkit/warp/ffd.h"
#include "deformkit/warp/ffd_frames.h"
#include "host/deformers/families.h"
#include "host/deformers/param_values.h"

namespace deformkit::host::detail {
namespace {

// The bind-time lattice parameters of both FFD types (basis, outside, divisions, origin, axes) and their
// checks; the derived types add their controls.
class LatticeDeformer : public Deformer {
  protected:
    LatticeDeformer(std::string type, std::string label) : Deformer(std::move(type), std::move(label)) {
        basis_ = addParameter({.name = "basis",
                               .rebinds = true,
                               .stride = 1,
                               .doc = "one value for every axis, or three (X, Y, Z): 0 Bernstein (divisions "
                                      "<= 64), 1 uniform cubic B-spline, 2 linear, 3 cardinal (tension "
                                      "0.71), 4 Catmull-Rom: Blender's four lattice interpolations are 1-4"},
                              {0.0});
        outside_ =
            addParameter({.name = "outside",
                          .rebinds = true,
                          .doc = "0 points outside the lattice stay put (Maya's default), 1 the "
                                 "deformation continues beyond it from each face with its value and "
                                 "slope there (with ends 1: the end controls move them, as in Blender)"},
                         {0.0});
        ends_ =
            addParameter({.name = "ends",
                          .rebinds = true,
                          .doc = "how the spline bases make up controls beyond the end faces: 0 linear "
                                 "extrapolation of the end controls, 1 the end controls repeated "
                                 "(Blender's Lattice modifier; with outside 1 it deforms as Blender does)"},
                         {0.0});
        // Rebinds: back at 0, the lattice coordinates are the rest points' again, not the last input's.
        evaluateAt_ = addParameter({.name = "evaluateAt",
                                    .rebinds = true,
                                    .doc = "where each point's lattice coordinates are taken: 0 at its rest "
                                           "position, once at bind; 1 at its incoming position, every "
                                           "evaluation (as Maya's and Blender's lattices do after other "
                                           "deformers)"},
                                   {0.0});
        divisions_ = addParameter({.name = "divisions",
                                   .rebinds = true,
                                   .doc = "l, m, n: cells along X, Y, Z, whole numbers in [1, 1024]"},
                                  {1.0, 1.0, 1.0});
        origin_ =
            addParameter({.name = "origin", .rebinds = true, .doc = "the rest lattice's corner, scene units"},
                         {0.0, 0.0, 0.0});
        axes_ =
            addParameter({.name = "axes",
                          .rebinds = true,
                          .doc = "the rest lattice's edge vectors X, Y, Z (x, y, z of each), scene units, "
                                 "linearly independent"},
                         {1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0});
    }

    void validate(size_t index, std::span<const double> given) const override {
        if (index == basis_) {
            if (given.size() != 1 && given.size() != 3) {
                fail(index, "has " + std::to_string(given.size()) + " values", "1 value, or 3 (X, Y, Z)");
            }
            requireIntegers(index, given, 0, 4);
        }
        if (index == outside_ || index == ends_ || index == evaluateAt_) requireIntegers(index, given, 0, 1);
        if (index == divisions_) requireIntegers(index, given, 1, warp::kMaxFfdDivisions);
        if (index == basis_ || index == divisions_ || index == origin_ || index == axes_) {
            // The whole lattice with the candidate value in place, through the core's own checks (axes
            // coplanar, too many controls, a Bernstein degree above 64).
            std::array<std::vector<double>, 4> candidate = {value(basis_), value(divisions_), value(origin_),
                                                            value(axes_)};
            const size_t slot = index == basis_ ? 0 : index == divisions_ ? 1 : index == origin_ ? 2 : 3;
            candidate[slot].assign(given.begin(), given.end());
            try {
                (void)warp::FfdLattice(latticeFrom(candidate[1], candidate[2], candidate[3]),
                                       {basesFrom(candidate[0])});
            } catch (const InvalidInput& e) {
                fail(index, e.what(), "a valid lattice");
            }
        }
    }

    // True for the parameters that define the rest lattice's shape (its control points move with them).
    [[nodiscard]] bool shapesLattice(size_t index) const {
        return index == divisions_ || index == origin_ || index == axes_;
    }
    [[nodiscard]] warp::FfdOptions ffdOptions() const {
        warp::FfdOptions options;
        options.basis = basesFrom(value(basis_));
        options.outside = value(outside_)[0] == 0.0 ? warp::FfdOutside::None : warp::FfdOutside::Extrapolate;
        options.ends = value(ends_)[0] == 0.0 ? warp::FfdEnds::Extrapolate : warp::FfdEnds::Repeat;
        return options;
    }
    // True when the lattice coordinates are taken at the incoming points on every evaluation.
    [[nodiscard]] bool atInput() const { return value(evaluateAt_)[0] != 0.0; }
    [[nodiscard]] warp::Lattice restLattice() const {
        return latticeFrom(value(divisions_), value(origin_), value(axes_));
    }

  private:
    // The "basis" parameter's codes (validated: 1 or 3 integers in [0, 4]) as the core's per-axis bases.
    static warp::FfdBases basesFrom(std::span<const double> codes) {
        constexpr warp::FfdBasis kBases[5] = {warp::FfdBasis::Bernstein, warp::FfdBasis::BSpline,
                                              warp::FfdBasis::Linear, warp::FfdBasis::Cardinal,
                                              warp::FfdBasis::CatmullRom};
        const auto at = [&](size_t a) {
            return kBases[static_cast<size_t>(codes[codes.size() == 3 ? a : 0])];
        };
        return {at(0), at(1), at(2)};
    }

    static warp::Lattice latticeFrom(std::span<const double> divisions, std::span<const double> origin,
                                     std::span<const double> axes) {
        warp::Lattice lattice;
        lattice.divisions = glm::ivec3(static_cast<int32_t>(divisions[0]), static_cast<int32_t>(divisions[1]),
                                       static_cast<int32_t>(divisions[2]));
        lattice.origin = vec3At(origin);
        for (int c = 0; c < 3; ++c)
            lattice.axes[c] = vec3At(axes, 3 * static_cast<size_t>(c));
        return lattice;
    }

    size_t basis_, outside_, ends_, evaluateAt_, divisions_, origin_, axes_;
};

class FfdDeformer final : public LatticeDeformer {
  public:
    explicit FfdDeformer(std::string label) : LatticeDeformer("ffd", std::move(label)) {
        points_ =
            addParameter({.name = "points",
                          .doc = "the deformed control points P*_ijk, x, y, z each, C order over (i, j, k) "
                                 "(index (i (m+1) + j) (n+1) + k), 3 (l+1)(m+1)(n+1) values, scene units; "
                                 "reset to the rest lattice when divisions, origin or axes change"},
                         flatten(restLattice().controlPoints()));
    }

  protected:
    void changed(size_t index) override {
        if (shapesLattice(index)) assign(points_, flatten(restLattice().controlPoints()));
    }
    void bindRest(const geom::Mesh& rest, std::span<const float>) override {
        ffd_.reset();
        auto ffd = std::make_unique<warp::Ffd>(restLattice(), ffdOptions());
        ffd->bind(rest.points());
        ffd_ = std::move(ffd);
    }
    void pushControls() override {
        unflatten(value(points_), targets_);
        ffd_->setTargets(targets_);
    }
    void deform(std::span<const glm::vec3> in, std::span<glm::vec3> out) override {
        if (atInput()) ffd_->bind(in);
        ffd_->evaluate(in, out, {}, 1.0f);
    }

  private:
    size_t points_;
    std::unique_ptr<warp::Ffd> ffd_;
    std::vector<glm::vec3> targets_;
};

// FFD with coordinate-frame controls: each control carries a target frame (origin = the deformed control
// point, basis = the rotation x scale of the control's neighbourhood); the source frames are the core's
// defaults, (P_ijk, identity), so T_ijk<p> = B*_ijk (p - P_ijk) + P*_ijk.
class FfdFramesDeformer final : public LatticeDeformer {
  public:
    explicit FfdFramesDeformer(std::string label) : LatticeDeformer("ffdframes", std::move(label)) {
        points_ =
            addParameter({.name = "points",
                          .doc = "the target frame origins P*_ijk, as ffd's points: x, y, z each, index "
                                 "(i (m+1) + j) (n+1) + k, 3 (l+1)(m+1)(n+1) values, scene units; reset to "
                                 "the rest lattice when divisions, origin or axes change"},
                         flatten(restLattice().controlPoints()));
        frames_ = addParameter({.name = "frames",
                                .doc = "the target frame bases B*_ijk, 9 values per control in the order of "
                                       "points: the images of the unit X, Y, Z axes (x, y, z of each), "
                                       "rotation x scale, any finite matrix; reset to the identity when "
                                       "divisions, origin or axes change"},
                               identityFrames());
    }

  protected:
    void changed(size_t index) override {
        if (shapesLattice(index)) {
            assign(points_, flatten(restLattice().controlPoints()));
            assign(frames_, identityFrames());
        }
    }
    void bindRest(const geom::Mesh& rest, std::span<const float>) override {
        ffd_.reset();
        auto ffd = std::make_unique<warp::FfdFrames>(restLattice(), ffdOptions());
        ffd->bind(rest.points());
        ffd_ = std::move(ffd);
    }
    void pushControls() override {
        const std::vector<double>& points = value(points_);
        const std::vector<double>& bases = value(frames_);
        targets_.resize(points.size() / 3);
        for (size_t c = 0; c < targets_.size(); ++c) {
            targets_[c].origin = vec3At(points, 3 * c);
            for (int a = 0; a < 3; ++a)
                targets_[c].basis[a] = vec3At(bases, 9 * c + 3 * static_cast<size_t>(a));
        }
        ffd_->setTargetFrames(targets_);
    }
    void deform(std::span<const glm::vec3> in, std::span<glm::vec3> out) override {
        if (atInput()) ffd_->bind(in);
        ffd_->evaluate(in, out, {}, 1.0f);
    }

  private:
    [[nodiscard]] std::vector<double> identityFrames() const {
        std::vector<double> out;
        const auto controls = static_cast<size_t>(restLattice().numControls());
        out.reserve(9 * controls);
        for (size_t c = 0; c < controls; ++c)
            out.insert(out.end(), {1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0});
        return out;
    }

    size_t points_, frames_;
    std::unique_ptr<warp::FfdFrames> ffd_;
    std::vector<warp::Frame> targets_;
};

}  // namespace

std::unique_ptr<Deformer> makeFfdDeformer(std::string label) {
    return std::make_unique<FfdDeformer>(std::move(label));
}

std::unique_ptr<Deformer> makeFfdFramesDeformer(std::string label) {
    return std::make_unique<FfdFramesDeformer>(std::move(label));
}

}  // namespace deformkit::host::detail
