// `deformkit preview MESH --out FILE`: a shaded, optionally textured or weight-coloured view of a mesh.
#include <cmath>
#include <cstdio>
#include <iostream>
#include <optional>
#include <vector>

#include "cli.h"
#include "commands.h"
#include "deformkit/error.h"
#include "deformkit/io/file_uses.h"
#include "deformkit/io/image.h"
#include "deformkit/io/mesh_file.h"
#include "deformkit/io/obj.h"
#include "deformkit/ptex/ptex_mesh.h"
#include "deformkit/scene/weights_file.h"

namespace deformkit::harness {
namespace fs = std::filesystem;

namespace {

// "x,y,z" -> vec3, for --view.
glm::vec3 parseVec3(const std::string& text) {
    glm::vec3 v;
    char tail = 0;
    if (std::sscanf(text.c_str(), "%f,%f,%f%c", &v.x, &v.y, &v.z, &tail) != 3 || !std::isfinite(v.x) ||
        !std::isfinite(v.y) || !std::isfinite(v.z) || (v.x == 0.0f && v.y == 0.0f && v.z == 0.0f)) {
        throw InvalidInput(formatError("--view", "", "'" + text + "' is not a direction",
                                       "three finite numbers x,y,z, not all 0"));
    }
    return v;
}

// "x0,y0,z0,x1,y1,z1" -> the box --frame aims the camera at.
geom::Box3 parseBox(const std::string& text) {
    float v[6];
    char tail = 0;
    if (std::sscanf(text.c_str(), "%f,%f,%f,%f,%f,%f%c", &v[0], &v[1], &v[2], &v[3], &v[4], &v[5], &tail) !=
            6 ||
        !(v[0] <= v[3] && v[1] <= v[4] && v[2] <= v[5])) {
        throw InvalidInput(formatError("--frame", "", "'" + text + "' is not a box",
                                       "six numbers: the low corner x,y,z then the high corner x,y,z"));
    }
    geom::Box3 box;
    box.min = glm::vec3(v[0], v[1], v[2]);
    box.max = glm::vec3(v[3], v[4], v[5]);
    return box;
}

}  // namespace

void preview(const PreviewCommand& command) {
    std::vector<io::FileUse> files = {{command.out, "the picture (--out)", true}, {command.mesh, "the mesh"}};
    if (command.texture) files.push_back({*command.texture, "the texture (--texture)"});
    if (command.weights) files.push_back({*command.weights, "the weights (--weights)"});
    if (command.weightsPtex) files.push_back({*command.weightsPtex, "the weights (--weights-ptex)"});
    io::requireFilesApart(files);
    const io::ObjContent obj = io::readMesh(command.mesh);
    std::optional<io::PreviewTexture> texture;
    if (command.texture) texture = io::loadPreviewTexture(*command.texture);
    if (command.weights && command.weightsPtex) {
        throw InvalidInput(
            formatError("--weights-ptex", "", "is given with --weights", "one weights source"));
    }
    io::PreviewOptions options = command.options;
    if (command.weights || command.weightsPtex) {
        const std::vector<float> weights =
            command.weights
                ? scene::readWeightsFile(*command.weights, static_cast<size_t>(obj.mesh.numVertices()))
                : ptex::weightsFromPtex(obj.mesh, command.mesh.string(), *command.weightsPtex,
                                        command.weightsChannel, "--weights-ptex");
        options.vertexColors.clear();
        for (float w : weights)
            options.vertexColors.push_back(io::weightColor(w));
    }
    const io::Image image = io::renderPreview(obj.mesh, options, texture ? &*texture : nullptr);
    io::writeImage(command.out, image);
}

void addPreviewCommand(CommandLine& cli) {
    struct Options {
        PreviewCommand command;
        std::string mesh, texture, out, view, frame, weights, weightsPtex;
    };
    auto o = std::make_shared<Options>();
    Command preview =
        cli.add("preview", "Render a shaded, optionally textured view of a mesh to an image", [o] {
            PreviewCommand& c = o->command;
            c.mesh = o->mesh;
            c.out = o->out;
            if (!o->texture.empty()) c.texture = o->texture;
            if (!o->view.empty()) c.options.viewDirection = parseVec3(o->view);
            if (!o->frame.empty()) c.options.frame = parseBox(o->frame);
            if (!o->weights.empty()) c.weights = o->weights;
            if (!o->weightsPtex.empty()) c.weightsPtex = o->weightsPtex;
            harness::preview(c);
            std::cout << "wrote " << o->out << "\n";
            return 0;
        });
    preview.option("MESH", o->mesh, "mesh (.obj, .gltf, .glb, .fbx, .ply, .dae)").required();
    preview.option("--texture", o->texture, "image, or UDIM pattern such as albedo.<UDIM>.png");
    preview.option("--out", o->out, "output image (.png, .jpg, .exr: any format OpenImageIO writes)")
        .required();
    preview.option("--width", o->command.options.width, "pixels").showDefault();
    preview.option("--height", o->command.options.height, "pixels").showDefault();
    preview.option("--view", o->view, "camera direction x,y,z (y up); default -0.55,-0.45,-1");
    preview.option("--frame", o->frame,
                   "box the camera frames instead of the whole mesh, x0,y0,z0,x1,y1,z1 (a close-up; the same "
                   "box for every frame of a shot)");
    preview.flag("--edges", o->command.options.drawEdges, "draw polygon edges");
    preview.option("--weights", o->weights, "show painted weights (JSON array, one per vertex) as colours");
    const Option ptex =
        preview.option("--weights-ptex", o->weightsPtex, "show a Ptex map's per-vertex values as colours");
    preview
        .option("--weights-channel", o->command.weightsChannel,
                "the Ptex map's channel (needs --weights-ptex)")
        .showDefault()
        .needs(ptex);
}

}  // namespace deformkit::harness
