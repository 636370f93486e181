#include <catch2/catch.hpp>

#include <algorithm>
#include <filesystem>
#include <map>
#include <string>
#include <tuple>
#include <vector>

#include "deformkit/error.h"
#include "deformkit/host/deformers.h"
#include "deformkit/host/stack.h"
#include "deformkit/io/obj.h"
#include "deformkit/scene/evaluator.h"
#include "deformkit/scene/scene.h"
#include "mesh_support.h"
#include "test_support.h"

using namespace deformkit;
using Catch::Contains;

namespace {

// A scene folder with tube.obj, and a scene text around one stack entry.
struct Fixture {
    test::TempDir dir;
    Fixture() { io::writeObj(dir / "tube.obj", test::tube()); }
    [[nodiscard]] std::filesystem::path scenePath() const { return dir / "shot.json"; }
    [[nodiscard]] scene::Scene parse(const std::string& text) const {
        return scene::parseScene(text, scenePath());
    }
    // The message of the error parsing `text` raises, or "no error".
    [[nodiscard]] std::string error(const std::string& text) const {
        try {
            (void)parse(text);
        } catch (const InvalidInput& e) {
            return e.what();
        }
        return "no error";
    }
};

std::string withEntry(const std::string& entry) {
    return R"({"deformkit_scene": 1, "frames": [1, 5], "objects": [{"name": "tube", "mesh": "tube.obj", "stack": [)" +
           entry + "]}]}";
}

std::vector<glm::vec3> pointsOf(const geom::Mesh& mesh) {
    return {mesh.points().begin(), mesh.points().end()};
}

}  // namespace

TEST_CASE("scene: a valid scene parses with its defaults", "[host][scene]") {
    Fixture f;
    const scene::Scene s = f.parse(withEntry(
        R"({"type": "twist", "params": {"handleY": [0, 2, 0], "endAngle": {"keys": [{"frame": 1, "value": 0},
            {"frame": 5, "value": 1.2, "interpolation": "linear"}]}}},
           {"type": "taper", "label": "flare", "envelope": 0.5, "params": {"endScale": 2}})"));
    CHECK(s.source == f.scenePath().string());
    CHECK(s.firstFrame == 1);
    CHECK(s.lastFrame == 5);
    REQUIRE(s.objects.size() == 1);
    const scene::SceneObject& o = s.objects[0];
    CHECK(o.name == "tube");
    CHECK(o.rest.numVertices() == 40);
    CHECK(o.rest.numFaces() == 32);
    REQUIRE(o.stack.size() == 2);
    CHECK(o.stack[0].label == "twist1");  // default: type and entry number from 1
    CHECK(o.stack[0].envelope.at(3) == std::vector<double>{1.0});
    CHECK(o.stack[1].label == "flare");
    CHECK(o.stack[1].envelope.at(3) == std::vector<double>{0.5});
    // Parameters in the deformer's order (bind-time handleY before endAngle), whatever the JSON order.
    REQUIRE(o.stack[0].params.size() == 2);
    CHECK(o.stack[0].params[0].name == "handleY");
    CHECK(o.stack[0].params[0].value.constant == std::vector<double>{0, 2, 0});
    CHECK(o.stack[0].params[1].name == "endAngle");
    CHECK(o.stack[0].params[1].path == "objects[0].stack[0].params.endAngle");
    CHECK(o.stack[0].params[1].value.animated());
}

TEST_CASE("scene: bad scenes name the file and the JSON path", "[host][scene][errors]") {
    Fixture f;
    const std::string file = f.scenePath().string();
    const std::string twist = R"({"type": "twist", "params": )";

    CHECK_THAT(f.error(R"({"deformkit_scene": 2, "frames": [1, 5], "objects": []})"),
               Contains(file + ": deformkit_scene: is 2") && Contains("expected 1"));
    CHECK_THAT(
        f.error(R"({"deformkit_scene": 1, "frame": [1, 5], "frames": [1, 5], "objects": []})"),
        Contains(file + ": frame: is not a known key") && Contains("deformkit_scene, frames, objects"));
    // A key given twice (an InvalidInput naming its full path): JSON readers keep one silently, so the other
    // value the user wrote was ignored. The same keys in sibling objects are fine.
    CHECK_THAT(f.error(R"({"deformkit_scene": 1, "frames": [1, 2], "objects": [], "frames": [5, 9]})"),
               Contains(file + ": frames: is given twice in one object (expected each key once)"));
    CHECK_THAT(f.error(withEntry(twist + R"({"endAngle": 1.5, "endAngle": 0}})")),
               Contains(file + ": objects[0].stack[0].params.endAngle: is given twice in one object"));
    CHECK_THAT(f.error(withEntry(twist + R"({"endAngle": 1}}, )" + twist + R"({"endAngle": 1}, "label": "b",
                   "label": "c"})")),
               Contains(file + ": objects[0].stack[1].label: is given twice"));
    CHECK_THAT(f.error(R"({"a": {"list": [{}, [1, [2]], {"b": 1, "b": 2}], "z": 1}})"),
               Contains(file + ": a.list[2].b: is given twice"));  // elements of every kind counted
    CHECK_THAT(f.error(R"({"a": {"list": [{}, {"b": 1}], "z": 1, "z": 2}})"),
               Contains(file + ": a.z: is given twice"));  // containers closed inside keep the path right
    // A NUL character in a string cut the message (and a path) off there; a NUL byte ended the text, so
    // what followed it was ignored.
    CHECK_THAT(f.error(withEntry(twist + R"({"endAngle": 1}, "label": "a\u0000b"})")),
               Contains(file + ": objects[0].stack[0].label: holds a NUL character (\\u0000)"));
    CHECK_THAT(f.error(R"({"deformkit_scene": 1, "frames": [1, 2], "objects": [], "x\u0000": 1})"),
               Contains(file + ": x\\u0000: holds a NUL character"));
    const std::string cut =
        std::string(R"({"deformkit_scene": 1, "frames": [1, 2], "objects": []})") + '\0' + "junk";
    CHECK_THAT(test::errorOf<ParseError>([&] { (void)f.parse(cut); }),
               Contains(file + ": holds a NUL byte at line 1, column 56"));
    CHECK(f.error(withEntry(twist + R"({"endAngle": 1.5}}, )" + twist +
                            R"({"endAngle": 1}, "label": "b"})")) == "no error");
    // A range of more frames than a job takes (a typo) is refused before anything is written.
    CHECK_THAT(f.error(R"({"deformkit_scene": 1, "frames": [1, 5000000], "objects": []})"),
               Contains(file + ": frames: is [1,5000000], 5000000 frames (expected at most 1000000 frames)"));
    CHECK(f.error(R"({"deformkit_scene": 1, "frames": [1, 1000000], "objects": []})") == "no error");
    CHECK_THAT(
        f.error(R"({"deformkit_scene": 1, "frames": [2147483646, 2147483647], "objects": []})"),
        Contains(file + ": frames[0]: is 2147483646 (expected a whole frame number from -1000000000 to "
                        "1000000000)"));
    CHECK_THAT(f.error(withEntry(R"({"type": "twist", "label": ""})")),
               Contains(file + ": objects[0].stack[0].label: is empty (expected a non-empty string)"));
    CHECK_THAT(f.error(R"({"deformkit_scene": 1, "frames": "1-5", "objects": []})"),
               Contains("frames: is a string") && Contains("[first, last]"));
    CHECK_THAT(
        f.error(R"({"deformkit_scene": 1, "frames": [1, 5], "objects": [{"name": "tube", "meshes": "a"}]})"),
        Contains("objects[0].meshes: is not a known key"));
    CHECK_THAT(f.error(withEntry(R"({"type": "twirl"})")),
               Contains("objects[0].stack[0].type: is \"twirl\"") && Contains("bend, ") &&
                   Contains("twist, wires, uvwarp (last entry)"));
    CHECK_THAT(f.error(withEntry(twist + R"({"endangle": 1}})")),
               Contains(file + ": objects[0].stack[0].params.endangle") && Contains("endAngle"));
    CHECK_THAT(
        f.error(withEntry(twist + R"({"handleY": [0, 1]}})")),
        Contains("objects[0].stack[0].params.handleY") && Contains("has 2 values") && Contains("3 values"));
    CHECK_THAT(
        f.error(withEntry(twist + R"({"endAngle": {"keys": [{"frame": 1, "value": 0},
                   {"frame": 3, "value": 1}, {"frame": 3, "value": 2}]}}})")),
        Contains("objects[0].stack[0].params.endAngle.keys[2].frame: is 3") && Contains("increasing frames"));
    CHECK_THAT(f.error(withEntry(twist + R"({"endAngle": {"keys": [{"frame": 1, "value": "x"}]}}})")),
               Contains("params.endAngle.keys[0].value: is a string"));
    CHECK_THAT(f.error(withEntry(twist + R"({"endAngle": {"keys": [{"frame": 1, "value": 0,
                   "interpolation": "cubic"}]}}})")),
               Contains("params.endAngle.keys[0].interpolation: is \"cubic\"") && Contains("\"bezier\""));
    CHECK_THAT(f.error(withEntry(twist + R"({"endAngle": {"keys": [{"frame": 1, "value": 0, "in": 1}]}}})")),
               Contains("params.endAngle.keys[0].in: is given") && Contains("explicit"));
    CHECK_THAT(f.error(withEntry(twist + R"({"handleY": {"keys": [{"frame": 1, "value": [0, 1, 0]},
                   {"frame": 2, "value": [0, 1]}]}}})")),
               Contains("params.handleY.keys[1].value: has 2 components"));
    // A key value the deformer rejects (falloff is 0, 1 or 2), named with the key's path.
    CHECK_THAT(
        f.error(withEntry(R"({"type": "slide", "params": {"falloff": {"keys": [{"frame": 1, "value": 0},
                   {"frame": 2, "value": 5}]}}})")),
        Contains("params.falloff.keys[1].value") && Contains("parameter 'falloff'"));
    // A curve that leaves what its parameter takes between its keys (a whole-number parameter between whole
    // keys) is refused at parse, naming the key, the frame and the value, not at the first frame between.
    CHECK_THAT(
        f.error(withEntry(R"({"type": "slide", "params": {"falloff": {"keys": [{"frame": 1, "value": 0,
                   "interpolation": "linear"}, {"frame": 3, "value": 2}]}}})")),
        Contains(file + ": objects[0].stack[0].params.falloff.keys[0]: interpolates to 0.6366197723675815 at "
                        "frame 1.6366197723675815 on its way to keys[1], which the parameter refuses") &&
            Contains("(expected \"interpolation\": \"constant\" on this key for a whole-number parameter"));
    CHECK_THAT(f.error(withEntry(R"({"type": "ffd", "params": {"divisions": {"keys": [{"frame": 1,
                   "value": [1, 1, 1]}, {"frame": 4, "value": [4, 1, 1]}]}}})")),
               Contains("params.divisions.keys[0]: interpolates to (2.5, 1, 1) at frame 2.5"));
    // Stepped, or with keys the curve joins by values the parameter takes, it parses.
    CHECK(f.error(withEntry(R"({"type": "ffd", "params": {"divisions": {"keys": [{"frame": 1,
              "value": [1, 1, 1], "interpolation": "constant"}, {"frame": 4, "value": [4, 1, 1]}]}}})")) ==
          "no error");
    CHECK(f.error(withEntry(R"({"type": "slide", "params": {"falloff": {"keys": [{"frame": 1, "value": 1},
              {"frame": 3, "value": 1}]}}})")) == "no error");
    CHECK_THAT(f.error(withEntry(R"({"type": "twist", "envelope": [1, 2]})")),
               Contains("objects[0].stack[0].envelope: has 2 components"));
    CHECK_THAT(f.error(withEntry(R"({"type": "twist"}, {"type": "taper", "label": "twist1"})")),
               Contains("objects[0].stack[1].label: is \"twist1\""));
    CHECK_THAT(f.error(withEntry(R"({"type": "twist", "label": "twist2"}, {"type": "twist"})")),
               Contains(file + ": objects[0].stack[1]: has no label, and its default one (type and entry "
                               "number), \"twist2\", is an earlier entry's") &&
                   Contains("give this entry a \"label\""));
    CHECK_THAT(f.error(R"({"deformkit_scene": 1, "frames": [1, 5], "objects": [{"name": "tube",
                   "mesh": "missing.obj", "stack": []}]})"),
               Contains("objects[0].mesh: names") && Contains("missing.obj, which does not exist"));
    std::filesystem::create_directories(f.dir / "meshes.obj");
    CHECK_THAT(f.error(R"({"deformkit_scene": 1, "frames": [1, 5], "objects": [{"name": "tube",
                   "mesh": "meshes.obj", "stack": []}]})"),
               Contains("objects[0].mesh: names") && Contains("meshes.obj, which is a folder, not a file"));
    CHECK_THAT(f.error(R"({"deformkit_scene": 1, "frames": [1, 5], "objects": [{"name": "a/b",
                   "mesh": "tube.obj", "stack": []}]})"),
               Contains("objects[0].name: is \"a/b\""));

    test::writeText(f.dir / "short.json", "[1, 0.5, 0]");
    CHECK_THAT(f.error(withEntry(R"({"type": "twist", "weights": "short.json"})")),
               Contains("objects[0].stack[0].weights") && Contains("has 3 weights") &&
                   Contains("40, one per vertex"));
    test::writeText(f.dir / "bad.json", R"({"weights": [1, "x"]})");
    CHECK_THAT(f.error(withEntry(R"({"type": "twist", "weights": "bad.json"})")),
               Contains("objects[0].stack[0].weights"));

    CHECK_THROWS_AS(f.parse("{\"deformkit_scene\": 1,"), ParseError);
    CHECK_THROWS_AS(scene::readScene(f.dir / "none.json"), IoError);
}

TEST_CASE("scene: a linearly keyed twist equals the twist set directly", "[host][scene]") {
    Fixture f;
    std::vector<float> weights(40);
    std::string weightsText = "{\"weights\": [";
    for (size_t i = 0; i < weights.size(); ++i) {
        weights[i] = static_cast<float>(i % 5) / 4.0f;  // 0, 0.25, ..., 1: exact in float and in JSON text
        weightsText += (i ? ", " : "") + std::to_string(weights[i]);
    }
    test::writeText(f.dir / "w.json", weightsText + "]}");
    scene::SceneEvaluator evaluator(f.parse(withEntry(
        R"({"type": "twist", "label": "t", "envelope": 0.75, "weights": "w.json",
            "params": {"handleY": [0, 1, 0], "endAngle": {"keys": [{"frame": 1, "value": 0, "interpolation": "linear"},
            {"frame": 5, "value": 1.2}]}}})")));
    const geom::Mesh& out = evaluator.evaluate(0, 3);
    // Frame 3 is half way: 0.5 * 1.2 is exactly the double nearest 0.6 (halving is exact).
    CHECK(evaluator.stack(0).get(0, "endAngle") == std::vector<double>{0.6});

    host::DeformerStack direct;
    const geom::Mesh tube = test::tube();
    direct.setRest(tube);
    direct.add(host::makeDeformer("twist", "t"));
    direct.set(0, "handleY", std::vector<double>{0, 1, 0});
    direct.set(0, "endAngle", 0.6);
    direct.setEnvelope(0, 0.75);
    direct.setWeights(0, weights);
    std::vector<glm::vec3> expected = pointsOf(tube);
    direct.evaluate(expected);
    // Same deformer, same values, same order of operations: bit-identical.
    CHECK(test::sameBits(out.points(), expected));
    // And the twist did move points (a top vertex with weight > 0).
    CHECK(out.points()[37] != tube.points()[37]);
}

TEST_CASE("scene: Bezier auto keys and vector keys evaluate as hand-computed curves", "[host][scene]") {
    Fixture f;
    scene::SceneEvaluator evaluator(f.parse(withEntry(
        R"({"type": "twist", "params": {"endAngle": {"keys": [{"frame": 1, "value": 0}, {"frame": 3, "value": 1},
            {"frame": 7, "value": 3}]}}},
           {"type": "taper", "params": {"endScale": {"keys": [{"frame": 0, "value": 1, "tangent": "explicit",
            "in": 0, "out": 2}, {"frame": 4, "value": 1, "tangent": "flat"}]}}},
           {"type": "slide", "params": {"displacement": {"keys": [{"frame": 0, "value": [0, 0, 0],
            "interpolation": "constant"}, {"frame": 10, "value": [1, 2, 3], "interpolation": "linear"}]}}})")));
    // Hermite by hand, h00 = 2s^3 - 3s^2 + 1, h10 = s^3 - 2s^2 + s, h01 = -2s^3 + 3s^2, h11 = s^3 - s^2.
    // Auto slopes: end keys 0; the middle key (1 between 0 and 3, not an extremum) (3 - 0) / (7 - 1) = 0.5,
    // within the clamps 3 * 1 / 2 and 3 * 2 / 4.
    auto hermite = [](double s, double v0, double v1, double dt, double m0, double m1) {
        const double h00 = 2 * s * s * s - 3 * s * s + 1, h10 = s * s * s - 2 * s * s + s;
        const double h01 = -2 * s * s * s + 3 * s * s, h11 = s * s * s - s * s;
        return h00 * v0 + h10 * dt * m0 + h01 * v1 + h11 * dt * m1;
    };
    const struct {
        double frame, expected;
    } cases[] = {
        {2.0, hermite(0.5, 0, 1, 2, 0, 0.5)},   // 0.375
        {5.0, hermite(0.5, 1, 3, 4, 0.5, 0)},   // 2.25
        {6.0, hermite(0.75, 1, 3, 4, 0.5, 0)},  // 2.78125
        {0.0, 0.0},                             // held before the first key
        {9.0, 3.0},                             // held after the last
    };
    host::DeformerStack& stack = evaluator.stack(0);
    for (const auto& c : cases) {
        (void)evaluator.evaluate(0, c.frame);
        // The curve and the hand formula differ only in the order of a few double operations.
        CHECK(stack.get(0, "endAngle")[0] == Approx(c.expected).margin(1e-12));
    }
    CHECK(hermite(0.5, 0, 1, 2, 0, 0.5) == 0.375);
    // Explicit out-slope 2 at frame 0, flat at frame 4 (value 1 at both): at frame 2 (s = 0.5),
    // 1 + h10(0.5) (4 - 0) 2 = 1 + 0.125 * 8 = 2.
    (void)evaluator.evaluate(0, 2.0);
    CHECK(stack.get(1, "endScale")[0] == Approx(hermite(0.5, 1, 1, 4, 2, 0)).margin(1e-12));
    CHECK(stack.get(1, "endScale")[0] == Approx(2.0).margin(1e-12));
    // Vector keys: one curve per component; constant holds [0, 0, 0] until frame 10.
    const scene::SceneParameter& d = evaluator.scene().objects[0].stack[2].params[0];
    CHECK(d.value.at(9.999) == std::vector<double>{0, 0, 0});
    CHECK(d.value.at(10) == std::vector<double>{1, 2, 3});
}

TEST_CASE("scene: a rest mesh in another format (PLY) reads as its OBJ does", "[host][scene][mesh_file]") {
    test::TempDir dir;
    // The same quad and triangle as a PLY and as an OBJ.
    test::writeText(
        dir / "two.ply",
        "ply\nformat ascii 1.0\nelement vertex 5\nproperty float x\nproperty float y\nproperty float "
        "z\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n2 0 0\n2 1 "
        "0\n0 1 0\n1 2 0\n4 0 1 2 3\n3 3 2 4\n");
    test::writeText(dir / "two.obj", "v 0 0 0\nv 2 0 0\nv 2 1 0\nv 0 1 0\nv 1 2 0\nf 1 2 3 4\nf 4 3 5\n");
    auto sceneWith = [](const std::string& mesh) {
        return R"({"deformkit_scene": 1, "frames": [1, 2], "objects": [{"name": "t", "mesh": ")" + mesh +
               R"(", "stack": [{"type": "twist", "params": {"endAngle": 0.5}}]}]})";
    };
    scene::SceneEvaluator ply(scene::parseScene(sceneWith("two.ply"), dir / "a.json"));
    scene::SceneEvaluator obj(scene::parseScene(sceneWith("two.obj"), dir / "b.json"));
    CHECK(test::sameBits(ply.evaluate(0, 2).points(), obj.evaluate(0, 2).points()));
    CHECK(std::ranges::equal(ply.scene().objects[0].rest.faceIndices(),
                             obj.scene().objects[0].rest.faceIndices()));
    test::writeText(dir / "two.stl", "solid two\nendsolid\n");
    CHECK_THAT(
        test::errorOf<InvalidInput>([&] { (void)scene::parseScene(sceneWith("two.stl"), dir / "c.json"); }),
        Contains("objects[0].mesh") && Contains(".obj, .gltf, .glb, .fbx, .ply, .dae"));
}

TEST_CASE("scene: a slide on a glTF with split vertices moves every copy of a position together",
          "[host][scene][weld]") {
    // The Khronos Fox as its glTF has it: every triangle with its own corners (1,728 vertices, 290
    // positions).
    test::TempDir dir;
    const std::string fox = std::string(DEFORMKIT_TEST_DATA) + "/fox/Fox.glb";
    const std::string text =
        R"({"deformkit_scene": 1, "frames": [1, 2], "objects": [{"name": "fox", "mesh": ")" + fox +
        R"(", "stack": [{"type": "slide", "params": {"vertex": 100, "radius": 20,
        "displacement": {"keys": [{"frame": 1, "value": [0, 0, 0]}, {"frame": 2, "value": [2, 1, 0]}]}}}]}]})";
    scene::SceneEvaluator evaluator(scene::parseScene(text, dir / "fox.json"));
    const geom::Mesh& rest = evaluator.scene().objects[0].rest;
    REQUIRE(rest.numVertices() == 1728);
    const geom::Mesh& moved = evaluator.evaluate(0, 2);
    // Copies that coincide at rest coincide after the slide (no crack), and more than the handle's own
    // triangle moved.
    std::map<std::tuple<float, float, float>, glm::vec3> where;
    int movedCopies = 0, cracks = 0;
    for (int32_t v = 0; v < rest.numVertices(); ++v) {
        const glm::vec3 r = rest.points()[v], p = moved.points()[v];
        movedCopies += p != r ? 1 : 0;
        const auto [it, added] = where.try_emplace({r.x, r.y, r.z}, p);
        if (!added && it->second != p) ++cracks;
    }
    CHECK(where.size() == 290);
    CHECK(cracks == 0);
    CHECK(movedCopies > 3 * 6);
}
