// Python bindings of the coarse-mesh warp (core/include/deformkit/warp/mesh_warp.h, paper §6): the
// one-off function mesh_warp and the MeshWarp class that binds once to a rest surface and evaluates for
// many target cages. numpy float32 in and out.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cstring>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "deformkit/error.h"
#include "deformkit/geom/mesh.h"
#include "deformkit/warp/engine.h"
#include "deformkit/warp/mesh_warp.h"
#include "numpy_support.h"
#include "object_lock.h"

namespace py = pybind11;

namespace deformkit::python {
namespace {

constexpr const char* kMeshWarp = "mesh_warp";

geom::Mesh cageOf(const FloatArray& points, const IntArray& counts, const IntArray& indices) {
    return meshOf(points, counts, indices, std::nullopt, std::nullopt, kMeshWarp, "mesh_warp cage", "cage_");
}

warp::MeshWarpOptions optionsOf(float alpha, float beta, float gamma, float mu) {
    warp::MeshWarpOptions o;
    o.alpha = alpha;
    o.beta = beta;
    o.gamma = gamma;
    o.mu = mu;
    return o;
}

// Bind once to a rest surface, evaluate for many target cages. Calls are serialised (object_lock.h).
class PyMeshWarp {
  public:
    PyMeshWarp(const FloatArray& cagePoints, const IntArray& counts, const IntArray& indices, float alpha,
               float beta, float gamma, float mu)
        : warp_(std::make_unique<warp::MeshWarp>(cageOf(cagePoints, counts, indices),
                                                 optionsOf(alpha, beta, gamma, mu), kMeshWarp)),
          deformer_(std::make_unique<warp::WarpDeformer>(*warp_, kMeshWarp)) {}

    void bind(const FloatArray& restPoints) {
        std::vector<glm::vec3> rest = pointsOf(restPoints, kMeshWarp, "rest_points");
        py::gil_scoped_release release;
        const Lock lock(mutex_);
        deformer_->bind(rest);
        rest_ = std::move(rest);
    }

    py::array_t<float> evaluate(const FloatArray& targetCage, const std::optional<FloatArray>& points,
                                const std::optional<FloatArray>& weights, float envelope) {
        std::vector<glm::vec3> target = pointsOf(targetCage, kMeshWarp, "target_cage_points");
        std::vector<glm::vec3> pts;
        {
            const Lock lock(mutex_);
            requireBound();
            if (!points) pts = rest_;
        }
        if (points) pts = pointsOf(*points, kMeshWarp, "points");
        const std::vector<float> w = weightsOf(weights, pts.size(), kMeshWarp);
        {
            py::gil_scoped_release release;
            const Lock lock(mutex_);
            warp_->setTarget(std::move(target));
            deformer_->evaluate(pts, w, envelope);
        }
        return toArray(pts);
    }

    [[nodiscard]] int32_t numControlVertices() {
        const Lock lock(mutex_);
        return warp_->numControlVertices();
    }
    [[nodiscard]] bool isBound() {
        const Lock lock(mutex_);
        return deformer_->isBound();
    }
    [[nodiscard]] int64_t numFieldEntries() {
        const Lock lock(mutex_);
        return static_cast<int64_t>(deformer_->fields().weight.size());
    }

  private:
    void requireBound() const {
        if (!deformer_->isBound()) {
            throw InvalidInput(
                formatError(kMeshWarp, "evaluate", "called before bind", "bind(rest_points) first"));
        }
    }

    std::unique_ptr<warp::MeshWarp> warp_;
    std::unique_ptr<warp::WarpDeformer> deformer_;
    std::vector<glm::vec3> rest_;
    std::mutex mutex_;
};

}  // namespace

void bindMeshWarp(py::module_& m) {
    m.def(
        "mesh_warp",
        [](const FloatArray& points, const FloatArray& cagePoints, const IntArray& counts,
           const IntArray& indices, const FloatArray& targetCage, float alpha, float beta, float gamma,
           float mu, const std::optional<FloatArray>& weights, float envelope) {
            std::vector<glm::vec3> pts = pointsOf(points, kMeshWarp, "points");
            const geom::Mesh cage = cageOf(cagePoints, counts, indices);
            const std::vector<glm::vec3> target = pointsOf(targetCage, kMeshWarp, "target_cage_points");
            const std::vector<float> w = weightsOf(weights, pts.size(), kMeshWarp);
            {
                py::gil_scoped_release release;
                warp::meshWarp(pts, cage, target, optionsOf(alpha, beta, gamma, mu), w, envelope);
            }
            return toArray(pts);
        },
        py::arg("points"), py::arg("cage_points"), py::arg("cage_face_counts"), py::arg("cage_face_indices"),
        py::arg("target_cage_points"), py::arg("alpha") = 0.0f, py::arg("beta") = 1.0f,
        py::arg("gamma") = 0.0f, py::arg("mu") = 1.0f, py::arg("weights") = py::none(),
        py::arg("envelope") = 1.0f,
        "Coarse-mesh warp (Milliron et al. 2002, §6). points (n, 3) float32, the surface at rest; "
        "cage_points\n"
        "(m, 3), cage_face_counts (F,) int32, cage_face_indices (sum of counts,) int32: the control mesh at "
        "rest;\n"
        "target_cage_points (m, 3): the edited control mesh. alpha < beta: radial falloff in units of each\n"
        "control vertex's longest edge; gamma < mu: falloff along each edge in units of its length. weights\n"
        "(n,) painted per point, envelope scalar. Returns the deformed points (n, 3) float32.");

    py::class_<PyMeshWarp>(
        m, "MeshWarp",
        "Coarse-mesh warp that binds once to a rest surface (weights cached) and evaluates for "
        "many target cages.")
        .def(py::init<const FloatArray&, const IntArray&, const IntArray&, float, float, float, float>(),
             py::arg("cage_points"), py::arg("cage_face_counts"), py::arg("cage_face_indices"),
             py::arg("alpha") = 0.0f, py::arg("beta") = 1.0f, py::arg("gamma") = 0.0f, py::arg("mu") = 1.0f)
        .def("bind", &PyMeshWarp::bind, py::arg("rest_points"),
             "Compute the sparse weights on the rest surface (n, 3) float32.")
        .def(
            "evaluate", &PyMeshWarp::evaluate, py::arg("target_cage_points"), py::arg("points") = py::none(),
            py::arg("weights") = py::none(), py::arg("envelope") = 1.0f,
            "Deform `points` (default: the bound rest points) for target_cage_points (m, 3); returns (n, 3).")
        .def_property_readonly("num_control_vertices", &PyMeshWarp::numControlVertices)
        .def_property_readonly("is_bound", &PyMeshWarp::isBound)
        .def_property_readonly("num_field_entries", &PyMeshWarp::numFieldEntries,
                               "Total (point, control vertex) pairs with non-zero weight.");
}

}  // namespace deformkit::python
