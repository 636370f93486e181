#include "deformkit/error.h"

#include <charconv>

namespace deformkit {

std::string formatError(std::string_view source, std::string_view element, std::string_view problem,
                        std::string_view expected) {
    std::string message;
    if (!source.empty()) {
        message.append(source);
        message.append(": ");
    }
    if (!element.empty()) {
        message.append(element);
        message.append(": ");
    }
    message.append(problem);
    if (!expected.empty()) {
        message.append(" (expected ");
        message.append(expected);
        message.append(")");
    }
    return message;
}

std::string numberText(double x) {
    char buffer[64];
    const auto result = std::to_chars(buffer, buffer + sizeof(buffer), x);
    return std::string(buffer, result.ptr);
}

std::string numberText(float x) {
    char buffer[64];
    const auto result = std::to_chars(buffer, buffer + sizeof(buffer), x);
    return std::string(buffer, result.ptr);
}

}  // namespace deformkit
