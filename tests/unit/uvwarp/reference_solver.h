#pragma once

// A reference for the UV-warp solver: the PBD model's energy minimised to convergence by Levenberg-Marquardt
// (Eigen, sparse normal equations), kept fold-free by its line search. It tells how far a PBD solve is from
// the optimum of the model it approximates, on grids up to 256^2.
//
// The model's two terms as one energy over the movable grid points W_k (the same inputs as uvwarp::Solver:
// f_O and f_D at the grid points, rigidity, movability):
//   E(W) = sum over 8-connected segments (i, j) of (max(R_i, R_j) (l_def - l_org))^2               (Eq. 1-3)
//        + lambda sum over movable points k of b_k g^2 |W_k - mean of its 8 neighbours|^2           (Eq. 4-5)
// with l_org = |f_O(p_j) - f_O(p_i)|, l_def = |f_D(W_j) - f_D(W_i)| (f_D looked up bilinearly), the
// regularisation weight b_k = (1 - R_k) + R_k s of Eq. 4 (s: the smoothing option) and g the mean rest
// segment length per grid cell, which puts both terms in scene units. lambda weighs the smoothing that the
// PBD loop applies once per iteration; it only decides the elastic areas, which the first term leaves free.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>

#include "deformkit/uvwarp/grid.h"

namespace deformkit::test {

struct ReferenceProblem {
    const uvwarp::PointField* rest = nullptr;      // f_O, 3 channels
    const uvwarp::PointField* deformed = nullptr;  // f_D, 3 channels
    const uvwarp::PointField* rigidity = nullptr;  // 1 channel
    const uvwarp::PointField* movable = nullptr;   // 1 channel: 1 may move
    double smoothing = 0.1;                        // s of Eq. 4
    double lambda = 1.0;
};

struct ReferenceResult {
    uvwarp::WarpGrid warp;
    double startEnergy = 0.0;
    double energy = 0.0;
    int iterations = 0;
};

namespace reference_detail {

struct Segment {
    int32_t a, b;
    double weight, rest;
};

// f_D at (u, v) bilinearly (clamped to the tile, as the solver's look-up) and its derivatives along u and v.
inline void lookup(const uvwarp::PointField& f, double u, double v, double out[3], double du[3],
                   double dv[3]) {
    const int32_t n = f.cells;
    const double x = std::clamp(u, 0.0, 1.0) * n, y = std::clamp(v, 0.0, 1.0) * n;
    const int32_t i = std::min(static_cast<int32_t>(x), n - 1), j = std::min(static_cast<int32_t>(y), n - 1);
    const double fx = x - i, fy = y - j;
    const float* p00 = &f.values[f.index(i, j)];
    const float* p10 = &f.values[f.index(i + 1, j)];
    const float* p01 = &f.values[f.index(i, j + 1)];
    const float* p11 = &f.values[f.index(i + 1, j + 1)];
    for (int c = 0; c < 3; ++c) {
        out[c] =
            (1 - fx) * (1 - fy) * p00[c] + fx * (1 - fy) * p10[c] + (1 - fx) * fy * p01[c] + fx * fy * p11[c];
        du[c] = n * ((1 - fy) * (p10[c] - p00[c]) + fy * (p11[c] - p01[c]));
        dv[c] = n * ((1 - fx) * (p01[c] - p00[c]) + fx * (p11[c] - p10[c]));
    }
}

inline bool foldFree(const uvwarp::WarpGrid& w) {
    const int32_t s = w.side();
    for (int32_t j = 0; j + 1 < s; ++j) {
        for (int32_t i = 0; i + 1 < s; ++i) {
            const auto at = [&](int32_t a, int32_t b) {
                const size_t k = static_cast<size_t>(b) * s + a;
                return std::array<double, 2>{w.u[k], w.v[k]};
            };
            const auto p00 = at(i, j), p10 = at(i + 1, j), p01 = at(i, j + 1), p11 = at(i + 1, j + 1);
            const auto area = [](const auto& a, const auto& b, const auto& c) {
                return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
            };
            if (area(p00, p10, p11) <= 0 || area(p00, p11, p01) <= 0 || area(p00, p10, p01) <= 0 ||
                area(p10, p11, p01) <= 0)
                return false;
        }
    }
    return true;
}

}  // namespace reference_detail

// Minimises E from `start` (fold-free) for at most `maxIterations` Levenberg-Marquardt steps or until a step
// lowers E by less than 1e-10 of it. Every accepted step keeps the grid fold-free (both splittings).
inline ReferenceResult minimiseReference(const ReferenceProblem& p, const uvwarp::WarpGrid& start,
                                         int maxIterations) {
    using namespace reference_detail;
    const int32_t n = p.rest->cells, s = n + 1;
    const size_t points = static_cast<size_t>(s) * s;
    std::vector<int32_t> var(points, -1);
    int32_t vars = 0;
    for (size_t k = 0; k < points; ++k) {
        const int32_t i = static_cast<int32_t>(k % s), j = static_cast<int32_t>(k / s);
        const bool border = i == 0 || j == 0 || i == n || j == n;
        if (!border && p.movable->values[k] >= 0.5f) var[k] = vars++;
    }
    std::vector<Segment> segments;
    double restSum = 0.0;
    int64_t restCount = 0;
    const auto restLength = [&](size_t a, size_t b) {
        const float* x = &p.rest->values[3 * a];
        const float* y = &p.rest->values[3 * b];
        return std::sqrt(double(x[0] - y[0]) * (x[0] - y[0]) + double(x[1] - y[1]) * (x[1] - y[1]) +
                         double(x[2] - y[2]) * (x[2] - y[2]));
    };
    const int32_t offsets[4][2] = {{1, 0}, {0, 1}, {1, 1}, {-1, 1}};
    for (int32_t j = 0; j < s; ++j) {
        for (int32_t i = 0; i < s; ++i) {
            for (const auto& o : offsets) {
                const int32_t i2 = i + o[0], j2 = j + o[1];
                if (i2 < 0 || i2 > n || j2 > n) continue;
                const size_t a = static_cast<size_t>(j) * s + i, b = static_cast<size_t>(j2) * s + i2;
                const double rest = restLength(a, b);
                const double weight = std::max(p.rigidity->values[a], p.rigidity->values[b]);
                if (o[0] == 1 && o[1] == 0 && rest > 0) {
                    restSum += rest;
                    ++restCount;
                }
                if (weight > 0 && rest > 0 && (var[a] >= 0 || var[b] >= 0))
                    segments.push_back({static_cast<int32_t>(a), static_cast<int32_t>(b), weight, rest});
            }
        }
    }
    const double g = restCount > 0 ? restSum / restCount * n : 1.0;  // scene units per unit of uv
    std::vector<double> regWeight(points, 0.0);
    for (size_t k = 0; k < points; ++k) {
        const double r = p.rigidity->values[k];
        regWeight[k] = std::sqrt(p.lambda * ((1 - r) + r * p.smoothing)) * g;
    }
    const auto neighbours = [&](size_t k, auto&& visit) {
        const int32_t i = static_cast<int32_t>(k % s), j = static_cast<int32_t>(k / s);
        for (int32_t dj = -1; dj <= 1; ++dj)
            for (int32_t di = -1; di <= 1; ++di)
                if ((di || dj) && i + di >= 0 && i + di <= n && j + dj >= 0 && j + dj <= n)
                    visit(static_cast<size_t>(j + dj) * s + (i + di));
    };
    const auto energy = [&](const uvwarp::WarpGrid& w) {
        double e = 0.0;
        double fa[3], fb[3], d[3];
        for (const Segment& sg : segments) {
            lookup(*p.deformed, w.u[sg.a], w.v[sg.a], fa, d, d);
            lookup(*p.deformed, w.u[sg.b], w.v[sg.b], fb, d, d);
            const double l = std::sqrt((fb[0] - fa[0]) * (fb[0] - fa[0]) + (fb[1] - fa[1]) * (fb[1] - fa[1]) +
                                       (fb[2] - fa[2]) * (fb[2] - fa[2]));
            e += sg.weight * sg.weight * (l - sg.rest) * (l - sg.rest);
        }
        for (size_t k = 0; k < points; ++k) {
            if (var[k] < 0) continue;
            double mu = 0.0, mv = 0.0;
            int c = 0;
            neighbours(k, [&](size_t m) {
                mu += w.u[m];
                mv += w.v[m];
                ++c;
            });
            const double ru = w.u[k] - mu / c, rv = w.v[k] - mv / c;
            e += regWeight[k] * regWeight[k] * (ru * ru + rv * rv);
        }
        return e;
    };

    ReferenceResult result;
    result.warp = start;
    result.startEnergy = result.energy = energy(start);
    double mu = 1e-3;
    for (int it = 0; it < maxIterations && vars > 0; ++it) {
        // Residuals and their Jacobian (rows: segments, then 2 per regularised point).
        std::vector<Eigen::Triplet<double>> jt;
        std::vector<double> res;
        const uvwarp::WarpGrid& w = result.warp;
        double fa[3], fb[3], dua[3], dva[3], dub[3], dvb[3];
        for (const Segment& sg : segments) {
            lookup(*p.deformed, w.u[sg.a], w.v[sg.a], fa, dua, dva);
            lookup(*p.deformed, w.u[sg.b], w.v[sg.b], fb, dub, dvb);
            double d[3] = {fb[0] - fa[0], fb[1] - fa[1], fb[2] - fa[2]};
            const double l = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
            if (l <= 0) continue;
            const int row = static_cast<int>(res.size());
            res.push_back(sg.weight * (l - sg.rest));
            const double gaU = -(d[0] * dua[0] + d[1] * dua[1] + d[2] * dua[2]) / l;
            const double gaV = -(d[0] * dva[0] + d[1] * dva[1] + d[2] * dva[2]) / l;
            const double gbU = (d[0] * dub[0] + d[1] * dub[1] + d[2] * dub[2]) / l;
            const double gbV = (d[0] * dvb[0] + d[1] * dvb[1] + d[2] * dvb[2]) / l;
            if (var[sg.a] >= 0) {
                jt.emplace_back(row, 2 * var[sg.a], sg.weight * gaU);
                jt.emplace_back(row, 2 * var[sg.a] + 1, sg.weight * gaV);
            }
            if (var[sg.b] >= 0) {
                jt.emplace_back(row, 2 * var[sg.b], sg.weight * gbU);
                jt.emplace_back(row, 2 * var[sg.b] + 1, sg.weight * gbV);
            }
        }
        for (size_t k = 0; k < points; ++k) {
            if (var[k] < 0) continue;
            double su = 0.0, sv = 0.0;
            int c = 0;
            neighbours(k, [&](size_t m) {
                su += w.u[m];
                sv += w.v[m];
                ++c;
            });
            const double rw = regWeight[k];
            for (int axis = 0; axis < 2; ++axis) {
                const int row = static_cast<int>(res.size());
                res.push_back(rw * ((axis == 0 ? w.u[k] : w.v[k]) - (axis == 0 ? su : sv) / c));
                jt.emplace_back(row, 2 * var[k] + axis, rw);
                neighbours(k, [&](size_t m) {
                    if (var[m] >= 0) jt.emplace_back(row, 2 * var[m] + axis, -rw / c);
                });
            }
        }
        Eigen::SparseMatrix<double> J(static_cast<int>(res.size()), 2 * vars);
        J.setFromTriplets(jt.begin(), jt.end());
        const Eigen::Map<const Eigen::VectorXd> r(res.data(), static_cast<int>(res.size()));
        Eigen::SparseMatrix<double> A = J.transpose() * J;
        const Eigen::VectorXd gradient = J.transpose() * r;
        bool accepted = false;
        for (int attempt = 0; attempt < 12 && !accepted; ++attempt) {
            Eigen::SparseMatrix<double> damped = A;
            for (int k = 0; k < damped.rows(); ++k)
                damped.coeffRef(k, k) += mu * (1.0 + A.coeff(k, k));
            Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(damped);
            if (solver.info() != Eigen::Success) {
                mu *= 10;
                continue;
            }
            const Eigen::VectorXd step = solver.solve(-gradient);
            // The step, or where it would fold the grid a fraction of it (halved up to kBacktracks times):
            // next to a nearly collapsed cell a whole step folds it for any damping that still moves.
            uvwarp::WarpGrid trial = w;
            double e = std::numeric_limits<double>::infinity();
            for (int half = 0, kBacktracks = 10; half <= kBacktracks; ++half) {
                const double fraction = std::ldexp(1.0, -half);
                for (size_t k = 0; k < points; ++k) {
                    if (var[k] < 0) continue;
                    trial.u[k] = static_cast<float>(w.u[k] + fraction * step[2 * var[k]]);
                    trial.v[k] = static_cast<float>(w.v[k] + fraction * step[2 * var[k] + 1]);
                }
                if (!foldFree(trial)) continue;
                e = energy(trial);
                break;
            }
            if (e < result.energy) {
                const double gain = result.energy - e;
                result.warp = std::move(trial);
                result.energy = e;
                result.iterations = it + 1;
                mu = std::max(mu / 3, 1e-9);
                accepted = true;
                if (gain < 1e-10 * e) return result;
            } else {
                mu *= 4;
            }
        }
        if (!accepted) break;
    }
    return result;
}

// E of a given warp, with the same problem (for the PBD solve's energy).
inline double referenceEnergy(const ReferenceProblem& p, const uvwarp::WarpGrid& w) {
    return minimiseReference(p, w, 0).energy;
}

}  // namespace deformkit::test
