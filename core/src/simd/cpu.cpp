#include "cpu.h"

#include <cstdlib>
#include <cstring>

namespace deformkit::simd {

namespace {

Isa detect() {
    const char* forced = std::getenv("DEFORMKIT_SIMD");
    if (forced != nullptr && std::strcmp(forced, "baseline") == 0) return Isa::Baseline;
#ifdef DEFORMKIT_SIMD_X86
    // Also checks that the OS saves the 256-bit registers. The init makes the check valid even when the
    // first call comes from another file's static initialiser.
    __builtin_cpu_init();
    if (__builtin_cpu_supports("avx2")) return Isa::Avx2;
#endif
    return Isa::Baseline;
}

}  // namespace

Isa activeIsa() {
    static const Isa isa = detect();
    return isa;
}

}  // namespace deformkit::simd
