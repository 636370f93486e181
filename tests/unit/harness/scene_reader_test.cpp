// Painted weights from Ptex files in scenes: `"weights": {"ptex": file, "channel": c}`.

#include <catch2/catch.hpp>

#include <cstring>
#include <map>
#include <string>
#include <vector>

#include "commands.h"
#include "deformkit/error.h"
#include "deformkit/host/deformers.h"
#include "deformkit/host/stack.h"
#include "deformkit/io/obj.h"
#include "deformkit/ptex/ptex_mesh.h"
#include "deformkit/scene/evaluator.h"
#include "deformkit/scene/scene.h"
#include "mesh_support.h"
#include "ptex/ptex_mesh_support.h"
#include "test_support.h"

using namespace deformkit;
using Catch::Contains;

namespace {

// A two-channel Ptex file of the tube with constant faces: face p holds (p / 100, (p % 7) / 8).
ptex::PtexFile constantFaces(const geom::Mesh& mesh) {
    return test::constantFaces(ptex::PtexMesh(mesh), 2, 1, [](int32_t p, int32_t c) {
        return c == 0 ? p / 100.0f : static_cast<float>(p % 7) / 8.0f;
    });
}

std::string sceneWith(const std::string& weights) {
    return R"({"deformkit_scene": 1, "frames": [1, 2], "objects": [{"name": "tube", "mesh": "tube.obj",
        "stack": [{"type": "twist", "weights": )" +
           weights + R"(, "params": {"handleY": [0, 1, 0], "endAngle": 0.8}}]}]})";
}

std::string readError(const std::filesystem::path& scene) {
    try {
        (void)harness::readScene(scene);
    } catch (const Error& e) {
        return e.what();
    }
    return "no error";
}

}  // namespace

TEST_CASE("scene ptex weights: a Ptex channel gives each vertex the mean of its faces' corners",
          "[harness][scene][ptex]") {
    test::TempDir dir;
    const geom::Mesh tube = test::tube();
    io::writeObj(dir / "tube.obj", tube);
    ptex::writePtex(dir / "w.ptx", constantFaces(tube));
    test::writeText(dir / "shot.json", sceneWith(R"({"ptex": "w.ptx", "channel": 1})"));

    const scene::Scene scene = harness::readScene(dir / "shot.json");
    const std::vector<float>& weights = scene.objects[0].stack[0].weights;
    REQUIRE(weights.size() == static_cast<size_t>(tube.numVertices()));
    CHECK(scene.objects[0].stack[0].weightsFile == dir / "w.ptx");
    // Independent reference: the tube is all quads (one Ptex face each, in face order), so a vertex's
    // weight is the mean of (f % 7) / 8 over the faces using it.
    std::map<int32_t, std::vector<double>> faceValues;
    for (int32_t f = 0; f < tube.numFaces(); ++f) {
        REQUIRE(tube.faceCounts()[f] == 4);
        for (int32_t v : tube.face(f))
            faceValues[v].push_back((f % 7) / 8.0);
    }
    for (const auto& [v, values] : faceValues) {
        double mean = 0.0;
        for (double x : values)
            mean += x / static_cast<double>(values.size());
        CHECK(weights[v] == Approx(mean).margin(1e-7));  // a float mean of exact eighths
    }

    // Evaluated like any other weights: bit-identical to the stack set directly with them.
    scene::SceneEvaluator evaluator(scene);
    const geom::Mesh& out = evaluator.evaluate(0, 1);
    host::DeformerStack direct;
    direct.setRest(tube);
    direct.add(host::makeDeformer("twist", "twist1"));
    direct.set(0, "handleY", std::vector<double>{0, 1, 0});
    direct.set(0, "endAngle", 0.8);
    direct.setWeights(0, weights);
    std::vector<glm::vec3> expected(tube.points().begin(), tube.points().end());
    direct.evaluate(expected);
    CHECK(test::sameBits(out.points(), expected));
}

TEST_CASE("scene ptex weights: bad files and keys name the JSON path and the file",
          "[harness][scene][ptex]") {
    test::TempDir dir;
    const geom::Mesh tube = test::tube();
    io::writeObj(dir / "tube.obj", tube);
    ptex::writePtex(dir / "w.ptx", constantFaces(tube));
    const auto scene = [&](const std::string& weights) {
        test::writeText(dir / "shot.json", sceneWith(weights));
        return dir / "shot.json";
    };
    CHECK_THAT(readError(scene(R"({"ptex": "w.ptx", "channel": 2})")),
               Contains("objects[0].stack[0].weights.ptex") && Contains("w.ptx") && Contains("channel 2") &&
                   Contains("2 channels"));
    CHECK_THAT(readError(scene(R"({"ptex": "w.ptx", "image": "w.<UDIM>.exr"})")),
               Contains("objects[0].stack[0].weights") && Contains("both"));
    CHECK_THAT(readError(scene(R"({"channel": 0})")), Contains("neither"));
    CHECK_THAT(readError(scene(R"({"ptex": "missing.ptx"})")),
               Contains("objects[0].stack[0].weights.ptex") && Contains("missing.ptx"));
    test::writeText(dir / "junk.ptx", std::string(100, 'x'));  // past the header size, wrong magic
    CHECK_THAT(readError(scene(R"({"ptex": "junk.ptx"})")), Contains("junk.ptx") && Contains("magic"));

    // A file painted on another mesh: its face count is named with the mesh's.
    test::TubeOptions other;
    other.rings = 3;
    ptex::writePtex(dir / "other.ptx", constantFaces(test::tube(other)));
    CHECK_THAT(readError(scene(R"({"ptex": "other.ptx"})")),
               Contains("other.ptx") && Contains("faces") &&
                   Contains(std::to_string(tube.numFaces()) + " Ptex faces"));

    // The core reader alone has no Ptex support and says so.
    CHECK_THAT(test::errorOf<InvalidInput>([&] { (void)scene::readScene(scene(R"({"ptex": "w.ptx"})")); }),
               Contains("weights.ptex") && Contains("cannot read"));
}
