#include "io/image_codec.h"

#include <dlfcn.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>

#include "deformkit/error.h"

// Set by core/CMakeLists.txt: the module's file name, its folder relative to the folder of an installed
// executable, and the absolute folders of the build tree and of the installation.
#ifndef DEFORMKIT_IMAGE_MODULE_NAME
#define DEFORMKIT_IMAGE_MODULE_NAME "deformkit_image_oiio.so"
#endif
#ifndef DEFORMKIT_IMAGE_MODULE_RELATIVE_DIR
#define DEFORMKIT_IMAGE_MODULE_RELATIVE_DIR "../lib/deformkit"
#endif
#ifndef DEFORMKIT_IMAGE_MODULE_BUILD_DIR
#define DEFORMKIT_IMAGE_MODULE_BUILD_DIR ""
#endif
#ifndef DEFORMKIT_IMAGE_MODULE_INSTALL_DIR
#define DEFORMKIT_IMAGE_MODULE_INSTALL_DIR ""
#endif

namespace deformkit::io::codec {
namespace fs = std::filesystem;

namespace {

// The file this code was loaded from (the executable, the Python module or a host plugin): the mapping of
// /proc/self/maps that holds this function. dladdr would give the executable as it was started
// ("deformkit" found on PATH), not where it is.
std::optional<fs::path> fileHoldingThisCode() {
    const auto here = reinterpret_cast<uintptr_t>(&fileHoldingThisCode);
    std::ifstream maps("/proc/self/maps");
    std::string line;
    while (std::getline(maps, line)) {
        std::istringstream fields(line);
        std::string range, perms, offset, device, inode, path;
        fields >> range >> perms >> offset >> device >> inode;
        std::getline(fields >> std::ws, path);
        const size_t dash = range.find('-');
        if (dash == std::string::npos || path.empty() || path.front() != '/') continue;
        const uintptr_t begin = std::stoull(range.substr(0, dash), nullptr, 16);
        const uintptr_t end = std::stoull(range.substr(dash + 1), nullptr, 16);
        if (here >= begin && here < end) return fs::path(path);
    }
    Dl_info info{};
    if (dladdr(reinterpret_cast<void*>(&fileHoldingThisCode), &info) != 0 && info.dli_fname != nullptr &&
        info.dli_fname[0] == '/') {
        return fs::path(info.dli_fname);
    }
    return std::nullopt;
}

// Where the module is looked for, in order. DEFORMKIT_IMAGE_MODULE, when set, is the only place.
std::vector<fs::path> moduleCandidates() {
    if (const char* chosen = std::getenv("DEFORMKIT_IMAGE_MODULE"); chosen != nullptr && chosen[0] != '\0')
        return {fs::path(chosen)};
    std::vector<fs::path> out;
    auto add = [&](const fs::path& folder) {
        if (folder.empty()) return;
        const fs::path file = (folder / DEFORMKIT_IMAGE_MODULE_NAME).lexically_normal();
        for (const fs::path& known : out) {
            if (known == file) return;
        }
        out.push_back(file);
    };
    if (const auto self = fileHoldingThisCode()) {
        add(self->parent_path());
        add(self->parent_path() / DEFORMKIT_IMAGE_MODULE_RELATIVE_DIR);
    }
    add(DEFORMKIT_IMAGE_MODULE_BUILD_DIR);
    add(DEFORMKIT_IMAGE_MODULE_INSTALL_DIR);
    return out;
}

struct LoadedModule {
    const Codec* codec = nullptr;
    std::string failures;  // every place tried and why it failed
};

LoadedModule loadModule() {
    LoadedModule loaded;
    for (const fs::path& file : moduleCandidates()) {
        std::string why;
        std::error_code ec;
        if (!fs::exists(file, ec)) {
            why = "no such file";
        } else if (void* handle = dlopen(file.c_str(), RTLD_NOW | RTLD_LOCAL); handle == nullptr) {
            const char* error = dlerror();
            why = error != nullptr ? error : "cannot be loaded";
            if (why.starts_with(file.string() + ": ")) why.erase(0, file.string().size() + 2);
        } else if (auto entry = reinterpret_cast<EntryPoint>(dlsym(handle, kEntryPoint)); entry == nullptr) {
            why = std::string("has no ") + kEntryPoint;
        } else if (const Codec* codec = entry(); codec == nullptr || codec->abiVersion != kAbiVersion) {
            why = "was built for another version of DeformKit (interface " +
                  std::to_string(codec == nullptr ? 0 : codec->abiVersion) + ", expected " +
                  std::to_string(kAbiVersion) + ")";
        } else {
            loaded.codec = codec;  // kept loaded for the life of the process
            return loaded;
        }
        loaded.failures += (loaded.failures.empty() ? "" : "; ") + file.string() + ": " + why;
    }
    if (loaded.failures.empty()) loaded.failures = "nowhere to look";
    return loaded;
}

}  // namespace

const Codec& load(const std::string& imagePath) {
    static const LoadedModule loaded = loadModule();
    if (loaded.codec == nullptr) {
        throw IoError(formatError(imagePath, "",
                                  "cannot load DeformKit's image module (" + loaded.failures + ")",
                                  std::string(DEFORMKIT_IMAGE_MODULE_NAME) +
                                      " installed beside the library (lib/deformkit) or named by "
                                      "DEFORMKIT_IMAGE_MODULE"));
    }
    return *loaded.codec;
}

}  // namespace deformkit::io::codec
