// Point caches from Python: deformkit.PointCache reads PC2 and MDD frame by frame, write_point_cache writes
// them (io/point_cache.h).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <cstring>
#include <memory>
#include <string>

#include "bindings.h"
#include "deformkit/error.h"
#include "deformkit/io/point_cache.h"
#include "numpy_support.h"

namespace py = pybind11;

namespace deformkit::python {

void bindPointCache(py::module_& m) {
    py::class_<io::PointCache, std::shared_ptr<io::PointCache>>(
        m, "PointCache",
        "A point cache (.pc2, .mdd) opened for reading frame by frame: PointCache(path, first_frame=None).\n"
        "first_frame: the frame of its first sample (default: a PC2's start frame, an MDD's 1).")
        .def(py::init([](const std::filesystem::path& path, std::optional<double> firstFrame) {
                 return std::make_shared<io::PointCache>(path, firstFrame);
             }),
             py::arg("path"), py::arg("first_frame") = py::none())
        .def_property_readonly("format", [](const io::PointCache& c) { return io::formatName(c.format()); })
        .def_property_readonly("vertex_count", &io::PointCache::vertexCount)
        .def_property_readonly("sample_count", &io::PointCache::sampleCount)
        .def_property_readonly("sampling", &io::PointCache::sampling, "frames per sample")
        .def_property_readonly("frames", &io::PointCache::frames, "the whole frames that are samples")
        .def_property_readonly("times", &io::PointCache::times, "an MDD's frame times in seconds (PC2: [])")
        .def(
            "sample_frame",
            [](const io::PointCache& cache, int64_t sample) {
                if (sample < 0 || sample >= cache.sampleCount()) {
                    throw InvalidInput(formatError(
                        cache.path().string(), "sample " + std::to_string(sample), "does not exist",
                        "a sample from 0 to " + std::to_string(cache.sampleCount() - 1)));
                }
                return cache.sampleFrame(static_cast<int32_t>(sample));
            },
            py::arg("sample"), "The frame of sample `sample` (0 to sample_count - 1).")
        .def(
            "read",
            [](io::PointCache& cache, int frame) {
                std::vector<glm::vec3> points;
                {
                    py::gil_scoped_release release;
                    cache.read(frame, points);
                }
                py::array_t<float> out({static_cast<py::ssize_t>(points.size()), py::ssize_t{3}});
                std::memcpy(out.mutable_data(), points.data(), points.size() * sizeof(glm::vec3));
                return out;
            },
            py::arg("frame"), "The positions of a whole frame: (N, 3) float32.");

    m.def(
        "write_point_cache",
        [](const std::filesystem::path& path, const FloatArray& positions, int firstFrame, double fps) {
            requireFloats(positions, "write_point_cache", "positions");
            if (positions.ndim() != 3 || positions.shape(2) != 3) {
                throw InvalidInput(formatError("write_point_cache", "positions",
                                               "has shape " + shapeOf(positions),
                                               "(frames, vertices, 3) float32"));
            }
            const auto frames = static_cast<int32_t>(positions.shape(0));
            const auto vertices = static_cast<int32_t>(positions.shape(1));
            const auto* data = reinterpret_cast<const glm::vec3*>(positions.data());
            py::gil_scoped_release release;
            io::PointCacheWriter writer(path, vertices, frames, firstFrame, fps);
            for (int32_t f = 0; f < frames; ++f)
                writer.append({data + static_cast<size_t>(f) * vertices, static_cast<size_t>(vertices)});
            writer.finish();
        },
        py::arg("path"), py::arg("positions"), py::arg("first_frame") = 1, py::arg("fps") = 24.0,
        "Write (frames, vertices, 3) positions as a point cache, atomically; the format is the extension's\n"
        "(.pc2: start frame first_frame, sampling 1; .mdd: times (frame - first_frame) / fps).");
}

}  // namespace deformkit::python
