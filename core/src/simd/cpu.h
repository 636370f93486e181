#pragma once

// Private to core: the library's one SIMD dispatch scheme (docs/decisions.md, "SIMD kernels"). A kernel
// has a baseline build and, on x86, an AVX2 build in its own file compiled with -mavx2 (core/CMakeLists.txt);
// the caller picks one with activeIsa(). No kernel uses fused multiply-add, so both give the same bytes.

#if defined(__x86_64__) || defined(__i386__)
#define DEFORMKIT_SIMD_X86 1
#endif

namespace deformkit::simd {

enum class Isa {
    Baseline,  // what the build targets: SSE2 on x86-64, the target's own vectors elsewhere
    Avx2,      // x86 only: 8 floats per register
};

// The kernels this process runs: Avx2 when the CPU (and the OS) support it, Baseline otherwise or when the
// environment variable DEFORMKIT_SIMD is "baseline" (for tests and benchmarks that compare kernels). Decided
// on the first call.
[[nodiscard]] Isa activeIsa();

}  // namespace deformkit::simd
