// Storage faults no test machine has on demand (an NFS quota reported at fsync, an EIO on rename), injected
// into a process by LD_PRELOAD: DEFORMKIT_FAULT names the call that fails and DEFORMKIT_FAULT_ERRNO the
// error it reports (a number; EIO by default). Every other call, and every call without the variables, goes
// to the C library.
#include <dlfcn.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>

namespace {

bool faulty(const char* call) {
    const char* fault = std::getenv("DEFORMKIT_FAULT");
    if (fault == nullptr || std::strcmp(fault, call) != 0) return false;
    const char* code = std::getenv("DEFORMKIT_FAULT_ERRNO");
    errno = code != nullptr ? std::atoi(code) : EIO;
    return true;
}

template <typename Function>
Function next(const char* name) {
    return reinterpret_cast<Function>(dlsym(RTLD_NEXT, name));
}

}  // namespace

extern "C" int fsync(int fd) {
    if (faulty("fsync")) return -1;
    static const auto real = next<int (*)(int)>("fsync");
    return real(fd);
}

extern "C" int rename(const char* from, const char* to) noexcept {
    if (faulty("rename")) return -1;
    static const auto real = next<int (*)(const char*, const char*)>("rename");
    return real(from, to);
}
