// libFuzzer target for the Ptex reader. Any input may be rejected with deformkit::Error; anything else
// (another exception, a crash, a sanitizer report) is a bug. Inputs that read must also survive a write and
// a second read with the same faces, texels and metadata, to the bit.
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <span>
#include <vector>

#include "deformkit/error.h"
#include "deformkit/ptex/ptex_file.h"

namespace {

using namespace deformkit::ptex;

bool allEqual(const std::vector<uint8_t>& texels, size_t pixel) {
    for (size_t i = pixel; i < texels.size(); i += pixel) {
        if (std::memcmp(texels.data(), texels.data() + i, pixel) != 0) return false;
    }
    return true;
}

// Compares without expanding constant faces (a tiny file may declare a huge constant face).
bool identical(const PtexFile& a, const PtexFile& b) {
    if (a.dataType != b.dataType || a.channels != b.channels || a.alphaChannel != b.alphaChannel)
        return false;
    if (a.meshType != b.meshType || a.uBorderMode != b.uBorderMode || a.vBorderMode != b.vBorderMode)
        return false;
    if (a.edgeFilterMode != b.edgeFilterMode || a.faces.size() != b.faces.size()) return false;
    const size_t pixel = a.pixelSize();
    for (size_t f = 0; f < a.faces.size(); ++f) {
        const FaceInfo& fa = a.faces[f];
        const FaceInfo& fb = b.faces[f];
        if (fa.ulog2 != fb.ulog2 || fa.vlog2 != fb.vlog2 || fa.adjFaces != fb.adjFaces ||
            fa.adjEdges != fb.adjEdges || fa.subface != fb.subface) {
            return false;
        }
        const uint8_t* constB = b.constData.data() + f * pixel;
        if (a.texels[f].empty()) {
            if (!b.texels[f].empty() || std::memcmp(a.constData.data() + f * pixel, constB, pixel) != 0)
                return false;
        } else if (allEqual(a.texels[f], pixel)) {
            if (!b.texels[f].empty() || std::memcmp(a.texels[f].data(), constB, pixel) != 0) return false;
        } else if (a.texels[f] != b.texels[f]) {
            return false;
        }
    }
    // The second read lists small entries before large ones (over 1024 bytes).
    std::vector<const MetaValue*> expected;
    for (const MetaValue& m : a.metadata) {
        if (m.bytes().size() <= 1024) expected.push_back(&m);
    }
    for (const MetaValue& m : a.metadata) {
        if (m.bytes().size() > 1024) expected.push_back(&m);
    }
    if (expected.size() != b.metadata.size()) return false;
    for (size_t i = 0; i < expected.size(); ++i) {
        if (expected[i]->key != b.metadata[i].key || expected[i]->type != b.metadata[i].type ||
            expected[i]->bytes() != b.metadata[i].bytes()) {
            return false;
        }
    }
    return true;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    ReadOptions options;
    options.readReductions = true;
    options.maxDecodedBytes = uint64_t{64} << 20;  // keeps the fuzzer far from its memory limit
    PtexFile first;
    try {
        first = readPtex(std::span(data, size), "fuzz.ptx", options);
    } catch (const deformkit::Error&) {
        return 0;
    }
    // Anything read must be writable and read back the same; an exception here escapes on purpose. The one
    // exception: metadata entries without values, which readers accept and writers refuse (the format's
    // writer has no empty entry); they are dropped before the write.
    std::erase_if(first.metadata, [](const MetaValue& m) { return m.bytes().empty(); });
    const std::vector<uint8_t> written = writePtexBytes(first);
    const PtexFile second = readPtex(written, "fuzz-rewritten.ptx", options);
    if (!identical(first, second)) std::abort();
    return 0;
}
