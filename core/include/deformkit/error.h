#pragma once

#include <new>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>

namespace deformkit {

// Every error DeformKit raises on user data derives from Error. The message names the input (a file
// path, or a label such as "mesh 'body'"), the element (a line, a face, a vertex, a pixel) and what
// was expected. Library code never aborts on user data; hosts convert Error at their boundary
// (CLI: one line on stderr and exit code 2; 1 for a StorageError).
class Error : public std::runtime_error {
  public:
    explicit Error(const std::string& message) : std::runtime_error(message) {}
};

// A file or folder that is missing, unreadable or unwritable.
class IoError : public Error {
  public:
    using Error::Error;
};

// Storage that failed while a file was written: a full disk, an I/O error. Not the input's fault: the CLI
// exits 1 for it (anything else it names is exit 2), and a farm retries it, as any IoError.
class StorageError : public IoError {
  public:
    using IoError::IoError;
};

// A file whose bytes do not follow its format: OBJ syntax, a truncated or corrupt image.
class ParseError : public Error {
  public:
    using Error::Error;
};

// Well-formed data with values an algorithm cannot take: an index out of range, NaN coordinates, an
// image with the wrong channel count, a bad argument.
class InvalidInput : public Error {
  public:
    using Error::Error;
};

// Connectivity an algorithm cannot take: a non-manifold edge or vertex where a manifold is required.
class TopologyError : public InvalidInput {
  public:
    using InvalidInput::InvalidInput;
};

// Memory that ran out for a named input (a file too large to read into this machine's memory): a
// std::bad_alloc, as any allocation failure (the CLI exits 1, Python raises MemoryError), whose what() names
// the input and its size.
class OutOfMemory : public std::bad_alloc {
  public:
    explicit OutOfMemory(std::string message) : message_(std::move(message)) {}
    [[nodiscard]] const char* what() const noexcept override { return message_.c_str(); }

  private:
    std::string message_;
};

// Builds the message used across the library: "<source>: <element>: <problem> (expected <expected>)".
// Empty parts are left out.
[[nodiscard]] std::string formatError(std::string_view source, std::string_view element,
                                      std::string_view problem, std::string_view expected = {});

// The shortest text that reads back as `x` ("10", "0.1", "nan", "inf"), for numbers in messages.
[[nodiscard]] std::string numberText(double x);
// The same for a float: the shortest text that reads back as the float ("0.1" for 0.1f, not
// "0.10000000149011612").
[[nodiscard]] std::string numberText(float x);

}  // namespace deformkit
