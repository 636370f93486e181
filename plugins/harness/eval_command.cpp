#include "eval_command.h"

#include <cstdio>
#include <cstdlib>

#include "deformkit/error.h"
#include "deformkit/host/evaluator.h"
#include "deformkit/host/scene.h"
#include "deformkit/io/obj.h"

namespace deformkit::harness {

namespace fs = std::filesystem;

std::string evalFileName(const std::string& object, int frame) {
    char digits[32];
    std::snprintf(digits, sizeof(digits), "%s%04lld", frame < 0 ? "-" : "",
                  std::llabs(static_cast<long long>(frame)));
    return object + "." + digits + ".obj";
}

EvalReport evalCommand(const EvalCommand& command, std::ostream* progress) {
    host::SceneEvaluator evaluator(host::readScene(command.scene));
    const host::Scene& scene = evaluator.scene();
    EvalReport report;
    if (command.frames.empty()) {
        for (int f = scene.firstFrame; f <= scene.lastFrame; ++f)
            report.frames.push_back(f);
    } else {
        report.frames = command.frames;
    }
    std::error_code ec;
    fs::create_directories(command.outDir, ec);
    if (!fs::is_directory(command.outDir)) {
        throw IoError(
            formatError(command.outDir.string(), "", "cannot be created", "a writable output folder"));
    }
    for (size_t i = 0; i < report.frames.size(); ++i) {
        const int frame = report.frames[i];
        for (size_t o = 0; o < evaluator.numObjects(); ++o) {
            const geom::Mesh& mesh = evaluator.evaluate(o, frame);
            const fs::path file = command.outDir / evalFileName(scene.objects[o].name, frame);
            io::writeObj(file, mesh, scene.objects[o].groups);
            report.files.push_back(file);
        }
        if (progress) {
            *progress << "eval: frame " << frame << " (" << (i + 1) << "/" << report.frames.size()
                      << "): " << evaluator.numObjects()
                      << (evaluator.numObjects() == 1 ? " object" : " objects") << " written\n";
        }
    }
    for (size_t o = 0; o < evaluator.numObjects(); ++o)
        report.binds.push_back(evaluator.stack(o).bindCount());
    return report;
}

}  // namespace deformkit::harness
