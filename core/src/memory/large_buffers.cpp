#include "memory/large_buffers.h"

#include <cstdint>

#ifdef __linux__
#include <sys/mman.h>
#endif
#ifdef __GLIBC__
#include <malloc.h>
#endif

namespace deformkit::detail {

void adviseHugePages(void* data, size_t bytes) {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    constexpr uintptr_t kHugePage = uintptr_t{2} << 20;
    const auto begin = reinterpret_cast<uintptr_t>(data);
    const uintptr_t first = (begin + kHugePage - 1) & ~(kHugePage - 1);
    const uintptr_t last = (begin + bytes) & ~(kHugePage - 1);
    if (data == nullptr || last <= first) return;
    // Advice only: a kernel without transparent huge pages answers EINVAL, and nothing depends on it.
    (void)madvise(reinterpret_cast<void*>(first), last - first, MADV_HUGEPAGE);
#else
    (void)data;
    (void)bytes;
#endif
}

void prefault(void* data, size_t bytes) {
    constexpr int64_t kPage = 4096;
    auto* begin = static_cast<unsigned char*>(data);
    const auto pages = static_cast<int64_t>((bytes + kPage - 1) / kPage);
    if (data == nullptr || pages == 0) return;
        // Pages in blocks of 2 MiB, so that a thread's pages share huge pages.
#pragma omp parallel for schedule(static, 512)
    for (int64_t page = 0; page < pages; ++page)
        begin[page * kPage] = 0;
}

void releaseFreedMemory() {
#ifdef __GLIBC__
    (void)malloc_trim(0);
#endif
}

}  // namespace deformkit::detail
