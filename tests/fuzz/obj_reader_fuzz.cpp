// libFuzzer target for the OBJ reader. Any input may be rejected with deformkit::Error; anything else
// (another exception, a crash, a sanitizer report) is a bug. Inputs that parse must also survive a
// write and a second read unchanged, to the bit.
#include <bit>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <string_view>

#include "deformkit/error.h"
#include "deformkit/io/obj.h"

namespace {

template <typename T>
bool sameValues(std::span<const T> a, std::span<const T> b) {
    return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin());
}

bool sameBits(std::span<const float> a, std::span<const float> b) {
    if (a.size() != b.size()) return false;
    for (size_t i = 0; i < a.size(); ++i) {
        if (std::bit_cast<uint32_t>(a[i]) != std::bit_cast<uint32_t>(b[i])) return false;
    }
    return true;
}

std::span<const float> floatsOf(std::span<const glm::vec3> v) {
    return {reinterpret_cast<const float*>(v.data()), v.size() * 3};
}
std::span<const float> floatsOf(std::span<const glm::vec2> v) {
    return {reinterpret_cast<const float*>(v.data()), v.size() * 2};
}

bool identical(const deformkit::io::ObjContent& a, const deformkit::io::ObjContent& b) {
    if (!sameBits(floatsOf(a.mesh.points()), floatsOf(b.mesh.points()))) return false;
    if (!sameBits(floatsOf(a.mesh.uvs()), floatsOf(b.mesh.uvs()))) return false;
    if (!sameValues(a.mesh.faceCounts(), b.mesh.faceCounts())) return false;
    if (!sameValues(a.mesh.faceIndices(), b.mesh.faceIndices())) return false;
    if (!sameValues(a.mesh.uvIndices(), b.mesh.uvIndices())) return false;
    if (a.groups.size() != b.groups.size()) return false;
    for (size_t g = 0; g < a.groups.size(); ++g) {
        if (a.groups[g].name != b.groups[g].name || a.groups[g].faces != b.groups[g].faces) return false;
    }
    return true;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string_view text(reinterpret_cast<const char*>(data), size);
    deformkit::io::ObjContent first;
    try {
        first = deformkit::io::parseObj(text, "fuzz.obj");
    } catch (const deformkit::Error&) {
        return 0;
    }
    // Anything read must be writable and read back the same; an exception here escapes on purpose.
    const std::string written = deformkit::io::formatObj(first.mesh, first.groups);
    const deformkit::io::ObjContent second = deformkit::io::parseObj(written, "fuzz-rewritten.obj");
    if (!identical(first, second)) std::abort();
    return 0;
}
