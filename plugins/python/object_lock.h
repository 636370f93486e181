#pragma once

// The module's rule for objects shared between Python threads. A bound C++ object (a deformer, a stack, a
// point cache) is not thread-safe: its calls run without the GIL, or reuse its scratch buffers. So each
// Python object carries a mutex that every method touching its state takes: two threads sharing one object
// are serialised instead of racing. Nothing runs Python code while the mutex is held (arguments are
// converted before, results after), so a thread holding it never waits for the GIL and the two cannot
// deadlock.

#include <mutex>
#include <utility>

namespace deformkit::python {

using Lock = std::lock_guard<std::mutex>;

// A `T` with the mutex of its Python object.
template <class T>
struct Locked {
    template <class... Args>
    explicit Locked(Args&&... args) : object(std::forward<Args>(args)...) {}
    T object;
    std::mutex mutex;
};

}  // namespace deformkit::python
