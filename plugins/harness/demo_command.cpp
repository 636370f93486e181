// `deformkit demo`: the demo assets, every deformer on them, and previews.
#include <iostream>

#include "cli.h"
#include "commands.h"
#include "deformkit/io/atomic_file.h"
#include "deformkit/io/image.h"
#include "deformkit/io/obj.h"
#include "deformkit/io/udim.h"
#include "demo_assets.h"
#include "demo_ptex.h"
#include "demo_slide.h"
#include "demo_uvwarp.h"
#include "demo_warps.h"

namespace deformkit::harness {
namespace fs = std::filesystem;

std::vector<fs::path> demo(const DemoCommand& command) {
    io::createFolder(command.outDir);
    const DemoAssets assets = makeDemoAssets({command.resolution});
    std::vector<fs::path> written;
    const fs::path meshPath = command.outDir / "tube.obj";
    io::writeObj(meshPath, assets.mesh);
    written.push_back(meshPath);

    io::ImageWriteOptions maps;
    maps.type = io::PixelType::Half;
    maps.attributes = {{"deformkit:asset", "demo"}};
    for (const auto& [tile, image] : assets.rigidity) {
        written.push_back(command.outDir / io::expandUdim("rigidity.<UDIM>.exr", tile));
        io::writeImage(written.back(), image, maps);
    }
    for (const auto& [tile, image] : assets.mask) {
        written.push_back(command.outDir / io::expandUdim("mask.<UDIM>.exr", tile));
        io::writeImage(written.back(), image, maps);
    }
    io::PreviewTexture texture;
    for (const auto& [tile, image] : assets.albedo) {
        written.push_back(command.outDir / io::expandUdim("albedo.<UDIM>.png", tile));
        io::writeImage(written.back(), image);
        texture.tiles.emplace(tile, image);
    }
    io::PreviewOptions view;
    view.drawEdges = false;
    written.push_back(command.outDir / "preview.png");
    io::writeImage(written.back(), io::renderPreview(assets.mesh, view, &texture));
    for (fs::path& f : writeDemoWarps(assets.mesh, texture, assets.albedo.at(1001), command.outDir)) {
        written.push_back(std::move(f));
    }
    for (fs::path& f : writeDemoSlide(assets.mesh, command.outDir)) {
        written.push_back(std::move(f));
    }
    for (fs::path& f : writeDemoPtex(assets.mesh, command.outDir)) {
        written.push_back(std::move(f));
    }
    for (fs::path& f : writeDemoUvWarp(assets.mesh, assets.rigidity.at(1001), assets.mask.at(1001),
                                       assets.albedo, command.outDir)) {
        written.push_back(std::move(f));
    }
    for (fs::path& f :
         writeDemoUvWarpShot(assets.mesh, std::min<int32_t>(command.resolution, 256), command.outDir))
        written.push_back(std::move(f));
    return written;
}

void addDemoCommand(CommandLine& cli) {
    auto command = std::make_shared<DemoCommand>();
    auto out = std::make_shared<std::string>(command->outDir.string());
    Command demo = cli.add("demo", "Generate the demo assets and previews into a folder", [command, out] {
        command->outDir = *out;
        const std::vector<fs::path> files = harness::demo(*command);
        std::cout << "demo: wrote " << files.size() << " files to " << command->outDir.string() << "/\n";
        for (const fs::path& f : files)
            std::cout << "  " << f.string() << "\n";
        return 0;
    });
    demo.option("--out", *out, "output folder").showDefault();
    demo.option("--resolution", command->resolution, "texels per UDIM tile side").showDefault();
}

}  // namespace deformkit::harness
