// Python bindings of the Beier-Neely image warp (core/include/deformkit/warp/beier_neely.h) and whole-image
// resampling (image_warp.h): the one-off functions beier_neely_map / beier_neely and the BeierNeely class
// that keeps the destination segments' weighting terms and takes new source segments cheaply. numpy
// float32 in and out; positions in pixels, origin at the top-left image corner, pixel centres at +0.5.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cstring>
#include <memory>
#include <new>
#include <optional>
#include <string>
#include <vector>

#include "deformkit/error.h"
#include "deformkit/io/image.h"
#include "deformkit/warp/beier_neely.h"
#include "deformkit/warp/engine.h"
#include "deformkit/warp/image_warp.h"
#include "numpy_support.h"
#include "object_lock.h"

namespace py = pybind11;

namespace deformkit::python {
namespace {

using io::SampleFilter;
using warp::BeierNeelyVariant;
using warp::SegmentPair;

constexpr const char* kBeierNeely = "beier_neely";

// (n, 2, 2) lines: line i from (x, y) = a[i, 0] to a[i, 1], pixels.
std::vector<glm::vec2> linesOf(const FloatArray& a, const char* name) {
    requireFloats(a, kBeierNeely, name);
    if (a.ndim() != 3 || a.shape(1) != 2 || a.shape(2) != 2) {
        throw InvalidInput(formatError(kBeierNeely, name, "has shape " + shapeOf(a),
                                       "(n, 2, 2): n lines of 2 (x, y) points"));
    }
    std::vector<glm::vec2> out(static_cast<size_t>(a.shape(0)) * 2);
    std::memcpy(out.data(), a.data(), out.size() * sizeof(glm::vec2));
    return out;
}

BeierNeelyVariant beierNeelyVariantOf(const std::string& v) {
    if (v == "original") return BeierNeelyVariant::Original;
    if (v == "global") return BeierNeelyVariant::Global;
    throw InvalidInput(formatError(kBeierNeely, "variant", "is '" + v + "'", "'original' or 'global'"));
}

io::SampleFilter interpOf(const std::string& v) {
    if (v == "bilinear") return io::SampleFilter::Bilinear;
    if (v == "bicubic") return io::SampleFilter::Bicubic;
    throw InvalidInput(formatError(kBeierNeely, "interp", "is '" + v + "'", "'bilinear' or 'bicubic'"));
}

std::vector<SegmentPair> pairsOf(const FloatArray& src, const FloatArray& dst, float a, float b, float p) {
    const std::vector<glm::vec2> s = linesOf(src, "src_lines"), d = linesOf(dst, "dst_lines");
    if (s.size() != d.size()) {
        throw InvalidInput(formatError(kBeierNeely, "src_lines",
                                       "has " + std::to_string(s.size() / 2) + " lines",
                                       "as many as dst_lines (" + std::to_string(d.size() / 2) + ")"));
    }
    std::vector<SegmentPair> pairs(s.size() / 2);
    for (size_t i = 0; i < pairs.size(); ++i) {
        pairs[i].dstP = d[2 * i];
        pairs[i].dstQ = d[2 * i + 1];
        pairs[i].srcP = s[2 * i];
        pairs[i].srcQ = s[2 * i + 1];
        pairs[i].a = a;
        pairs[i].b = b;
        pairs[i].p = p;
    }
    warp::validateSegmentPairs(pairs, kBeierNeely);
    return pairs;
}

py::array mapToNumpy(std::vector<glm::vec2>&& map, int32_t width, int32_t height) {
    auto* data = new std::vector<glm::vec2>(std::move(map));
    py::capsule owner(data, [](void* p) { delete static_cast<std::vector<glm::vec2>*>(p); });
    return py::array_t<float>(
        {static_cast<py::ssize_t>(height), static_cast<py::ssize_t>(width), py::ssize_t{2}},
        reinterpret_cast<const float*>(data->data()), owner);
}

// Holds the warp; the deformer (generic engine path for 3-D points) is created on bind(). Calls are
// serialised (object_lock.h).
class PyBeierNeely {
  public:
    PyBeierNeely(const FloatArray& src, const FloatArray& dst, float a, float b, float p,
                 const std::string& variant)
        : warp_(std::make_unique<warp::BeierNeelyWarp>(
              pairsOf(src, dst, a, b, p), warp::BeierNeelyOptions{beierNeelyVariantOf(variant)})) {}

    void setSrcLines(const FloatArray& src) {
        const auto lines = linesOf(src, "src_lines");
        const Lock lock(mutex_);
        warp_->setSourceSegments(lines);
    }

    py::array map(int32_t width, int32_t height) {
        checkSize(width, height);
        std::vector<glm::vec2> out;
        try {
            out.resize(static_cast<size_t>(width) * height);
        } catch (const std::bad_alloc&) {
            throw OutOfMemory(formatError(
                kBeierNeely, "map",
                "cannot be held in memory: " + std::to_string(width) + " x " + std::to_string(height) +
                    " pixels (" + std::to_string(static_cast<uint64_t>(width) * height * 8) + " bytes)",
                "a map that fits in this machine's memory"));
        }
        {
            py::gil_scoped_release release;
            const Lock lock(mutex_);
            warp_->mapPixelCentres(width, height, out);
        }
        return mapToNumpy(std::move(out), width, height);
    }

    py::array warpImage(const FloatArray& image, const std::string& interp) {
        io::Image src = imageOf(image, kBeierNeely, "image");
        const io::SampleFilter interpolation = interpOf(interp);
        io::Image out;
        {
            py::gil_scoped_release release;
            std::vector<glm::vec2> map(static_cast<size_t>(src.width) * src.height);
            {
                const Lock lock(mutex_);
                warp_->mapPixelCentres(src.width, src.height, map);
            }
            out = warp::resampleImage(src, map, src.width, src.height, interpolation);
        }
        return imageArray(std::move(out), image.ndim() == 2);
    }

    void bind(const FloatArray& rest) {
        std::vector<glm::vec3> points = points3(rest, "rest_points");
        py::gil_scoped_release release;
        const Lock lock(mutex_);
        auto deformer = std::make_unique<warp::WarpDeformer>(*warp_, kBeierNeely);
        deformer->bind(points);
        deformer_ = std::move(deformer);
    }

    py::array evaluate(const FloatArray& points, const std::optional<FloatArray>& weights, float envelope) {
        std::vector<glm::vec3> p = points3(points, "points");
        const std::vector<float> w = weightsOf(weights, p.size(), kBeierNeely);
        {
            py::gil_scoped_release release;
            const Lock lock(mutex_);
            if (!deformer_ || !deformer_->isBound()) {
                throw InvalidInput(
                    formatError(kBeierNeely, "evaluate", "called before bind", "bind(rest_points) first"));
            }
            deformer_->evaluate(p, w, envelope);
        }
        return toArray(p);
    }

  private:
    // Sides from 1 to 65536 (the largest image side DeformKit writes a map for, as to-udim's tiles).
    static void checkSize(int32_t width, int32_t height) {
        if (width <= 0 || height <= 0 || width > 65536 || height > 65536) {
            throw InvalidInput(formatError(kBeierNeely, "width, height",
                                           "are " + std::to_string(width) + ", " + std::to_string(height),
                                           "1 to 65536 pixels per side"));
        }
    }
    static std::vector<glm::vec3> points3(const FloatArray& a, const char* name) {
        requireFloats(a, kBeierNeely, name);
        if (a.ndim() != 2 || a.shape(1) != 3) {
            throw InvalidInput(formatError(kBeierNeely, name, "has shape " + shapeOf(a), "(n, 3) float32"));
        }
        std::vector<glm::vec3> out(static_cast<size_t>(a.shape(0)));
        std::memcpy(out.data(), a.data(), out.size() * sizeof(glm::vec3));
        return out;
    }

    std::unique_ptr<warp::BeierNeelyWarp> warp_;
    std::unique_ptr<warp::WarpDeformer> deformer_;
    std::mutex mutex_;
};

}  // namespace

void bindBeierNeely(py::module_& m) {
    m.def(
        "beier_neely_map",
        [](int32_t width, int32_t height, const FloatArray& src, const FloatArray& dst, float a, float b,
           float p, const std::string& variant) {
            return PyBeierNeely(src, dst, a, b, p, variant).map(width, height);
        },
        py::arg("width"), py::arg("height"), py::arg("src_lines"), py::arg("dst_lines"), py::arg("a") = 1.0f,
        py::arg("b") = 2.0f, py::arg("p") = 0.5f, py::arg("variant") = "original",
        "Beier-Neely inverse map: (H, W, 2) float32 source-image position (x, y) of every destination pixel "
        "centre (x + 0.5, y + 0.5). src_lines, dst_lines: (n, 2, 2) segments (P, Q) in pixels; a > 0, b >= "
        "0, "
        "p >= 0; variant 'original' (paper 4.2) or 'global' (5.2).");
    m.def(
        "beier_neely",
        [](const FloatArray& image, const FloatArray& src, const FloatArray& dst, float a, float b, float p,
           const std::string& variant, const std::string& interp) {
            return PyBeierNeely(src, dst, a, b, p, variant).warpImage(image, interp);
        },
        py::arg("image"), py::arg("src_lines"), py::arg("dst_lines"), py::arg("a") = 1.0f,
        py::arg("b") = 2.0f, py::arg("p") = 0.5f, py::arg("variant") = "original",
        py::arg("interp") = "bilinear",
        "Warp a (H, W) or (H, W, C) float32 image with Beier-Neely segments; the result has the same shape. "
        "interp: 'bilinear' or 'bicubic' (Keys a = -0.5); outside the source, edge pixels repeat.");
    py::class_<PyBeierNeely>(
        m, "BeierNeely",
        "Beier-Neely warp kept between calls: set_src_lines() moves the source segments "
        "without redoing the destination-side work; bind()/evaluate() run it on 3-D points "
        "through the generic engine (z untouched).")
        .def(py::init<const FloatArray&, const FloatArray&, float, float, float, const std::string&>(),
             py::arg("src_lines"), py::arg("dst_lines"), py::arg("a") = 1.0f, py::arg("b") = 2.0f,
             py::arg("p") = 0.5f, py::arg("variant") = "original")
        .def("set_src_lines", &PyBeierNeely::setSrcLines, py::arg("src_lines"))
        .def("map", &PyBeierNeely::map, py::arg("width"), py::arg("height"))
        .def("warp", &PyBeierNeely::warpImage, py::arg("image"), py::arg("interp") = "bilinear")
        .def("bind", &PyBeierNeely::bind, py::arg("rest_points"))
        .def("evaluate", &PyBeierNeely::evaluate, py::arg("points"), py::arg("weights") = py::none(),
             py::arg("envelope") = 1.0f);
}

}  // namespace deformkit::python
