// libFuzzer target for scene files. Any input may be rejected with deformkit::Error; anything else is a
// bug. A scene reads its meshes and weights files relative to its own folder: the target writes a small
// mesh (m.obj: a 3 x 3 grid of quads with UVs), weights (w.json) and feature lines (l.json) into a
// temporary folder once, and parses every input as <that folder>/scene.json, so the seeds reach the
// objects, stacks, parameters, keys and weights. Inputs naming anything under /dev or /proc are skipped
// (reading /dev/zero never ends: the operating system's doing, not the parser's).
#include <unistd.h>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>

#include "deformkit/error.h"
#include "deformkit/scene/scene.h"

namespace {

namespace fs = std::filesystem;

// The folder, removed when the process ends.
struct Folder {
    fs::path path;
    ~Folder() {
        std::error_code ec;
        fs::remove_all(path, ec);
    }
};

const fs::path& folder() {
    static const Folder dir{[] {
        const fs::path d = fs::temp_directory_path() / ("deformkit-fuzz-scene-" + std::to_string(::getpid()));
        fs::create_directories(d);
        std::ofstream obj(d / "m.obj");
        for (int j = 0; j <= 3; ++j)
            for (int i = 0; i <= 3; ++i)
                obj << "v " << i << " " << j << " 0\nvt " << i / 3.0 << " " << j / 3.0 << "\n";
        for (int j = 0; j < 3; ++j)
            for (int i = 0; i < 3; ++i) {
                const int a = j * 4 + i + 1;
                obj << "f " << a << "/" << a << " " << a + 1 << "/" << a + 1 << " " << a + 5 << "/" << a + 5
                    << " " << a + 4 << "/" << a + 4 << "\n";
            }
        std::ofstream weights(d / "w.json");
        weights << "[0,0.1,0.2,0.3,0.4,0.5,0.6,0.7,0.8,0.9,1,1,1,1,1,1]\n";
        std::ofstream lines(d / "l.json");
        lines << R"({"lines": [{"src": [[0, 0], [1, 0]], "dst": [[0, 0], [1, 0.5]]}]})"
              << "\n";
        return d;
    }()};
    return dir.path;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string_view text(reinterpret_cast<const char*>(data), size);
    if (text.find("/dev") != std::string_view::npos || text.find("/proc") != std::string_view::npos) return 0;
    try {
        const deformkit::scene::Scene scene = deformkit::scene::parseScene(text, folder() / "scene.json");
        if (scene.lastFrame < scene.firstFrame) std::abort();
    } catch (const deformkit::Error&) {
        return 0;
    }
    return 0;
}
