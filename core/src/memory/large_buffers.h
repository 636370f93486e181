#pragma once

// Private to the library: per-point buffers of a UV-warp tile (geometry images, maps, the warp grid, its
// velocities, the redirect map) run to tens or hundreds of megabytes at 2048^2 and more. Each 4 KiB page of a
// fresh allocation costs a page fault when it is first written, and in a virtual machine a fault can cost
// several microseconds: on the 2-core test machine a cold 2048^2 frame faulted about 65,000 times, 0.5-0.8 s
// of its 1.6-1.8 s. Buffers sized here are, from kLargeBuffer bytes, fresh memory that the kernel is asked to
// back with transparent huge pages (2 MiB) before it is first written, so they fault once per 2 MiB instead
// of once per 4 KiB (docs/decisions.md, UV-22). Nothing else changes: the same values, an ordinary
// std::vector; on kernels without transparent huge pages (or set to "never") the advice is ignored.

#include <cstddef>
#include <type_traits>
#include <vector>

namespace deformkit::detail {

// Buffers from this size on are advised (a few huge pages each: smaller ones would gain little).
constexpr size_t kLargeBuffer = size_t{4} << 20;

// Asks the kernel to back the whole 2 MiB pages inside [data, data + bytes) with transparent huge pages.
// Harmless where they are unavailable.
void adviseHugePages(void* data, size_t bytes);

// Writes a zero into every 4 KiB page of [data, data + bytes) from all OpenMP threads, so that the kernel's
// page faults (zeroing each page, or each 2 MiB huge page) run on every core rather than on the one thread
// that first fills the buffer: on a virtual machine, first touches cost about a third of a tile's bind.
// For fresh storage of trivial values, before anything is written to it.
void prefault(void* data, size_t bytes);

// Gives the pages of freed heap memory back to the system. A UV-warp tile's bind frees several buffers of
// its size (rasters, maps at grid points); glibc serves buffers this large from its heap once a freed mapping
// has raised its mmap threshold, and keeps their pages when they are freed, so the process would go on
// holding about 13 bytes a texel it no longer uses. glibc: malloc_trim(0); elsewhere nothing.
void releaseFreedMemory();

// A capacity of at least n elements whose allocation, with the allocator's own header, fills whole huge
// pages: Linux places an anonymous mapping of a whole number of huge pages on a huge-page boundary, so all of
// the buffer can be backed by huge pages, not only the aligned pages inside it. Only where that adds at most
// an eighth to the buffer (from 16 MiB on); smaller buffers keep n and get huge pages inside them only.
template <class T>
size_t hugeCapacity(size_t n) {
    constexpr size_t kHugePage = size_t{2} << 20, kHeader = 64;
    const size_t bytes = n * sizeof(T);
    const size_t whole = (bytes + kHeader + kHugePage - 1) / kHugePage * kHugePage - kHeader;
    return whole - bytes <= bytes / 8 ? whole / sizeof(T) : n;
}

// values.reserve(n) for a buffer that is then filled by push_back: when it is large and has to grow, its
// storage is allocated afresh (what it held is kept) and advised before anything is written to the new part.
template <class T>
void reserveLarge(std::vector<T>& values, size_t n) {
    if (n * sizeof(T) < kLargeBuffer || values.capacity() >= n) {
        values.reserve(n);
        return;
    }
    std::vector<T> fresh;
    fresh.reserve(hugeCapacity<T>(n));
    adviseHugePages(fresh.data(), fresh.capacity() * sizeof(T));
    if constexpr (std::is_trivially_copyable_v<T> && std::is_trivially_default_constructible_v<T>)
        prefault(fresh.data(), n * sizeof(T));  // not the rounding past n, which may stay untouched
    fresh.insert(fresh.end(), values.begin(), values.end());
    values.swap(fresh);
}

// values = n copies of fill. When the buffer is large and has to grow, it is allocated afresh and advised
// before the fill writes it (an allocation that already holds n is reused as it is).
template <class T>
void assignLarge(std::vector<T>& values, size_t n, const T& fill) {
    if (n * sizeof(T) >= kLargeBuffer && values.capacity() < n) {
        values.clear();
        reserveLarge(values, n);
    }
    values.assign(n, fill);
}

// to = from, with to's storage allocated as assignLarge's.
template <class T>
void copyLarge(std::vector<T>& to, const std::vector<T>& from) {
    if (from.size() * sizeof(T) >= kLargeBuffer && to.capacity() < from.size()) {
        to.clear();
        reserveLarge(to, from.size());
    }
    to.assign(from.begin(), from.end());
}

}  // namespace deformkit::detail
