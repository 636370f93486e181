#include "deformkit/host/parameter_reference.h"

#include <memory>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "deformkit/error.h"
#include "deformkit/host/deformers.h"

namespace deformkit::host {
namespace {

// How many values a parameter takes: "3", or "3n" for a resizable one (any positive multiple of 3).
std::string countText(const ParamInfo& info) {
    if (info.stride == 0) return std::to_string(info.components);
    return info.stride == 1 ? "n" : std::to_string(info.stride) + "n";
}

// The default values, or their count when there are many.
std::string defaultText(const std::vector<double>& values) {
    constexpr size_t kMaxShown = 9;
    if (values.size() > kMaxShown) return std::to_string(values.size()) + " values";
    std::string out;
    for (double v : values) {
        if (!out.empty()) out += ' ';
        out += numberText(v);
    }
    return out;
}

// `text` wrapped at 100 columns, each line indented by `indent` spaces.
std::string wrapped(std::string_view text, size_t indent) {
    constexpr size_t kColumns = 100;
    std::string out, line;
    size_t start = 0;
    while (start < text.size()) {
        const size_t space = text.find(' ', start);
        const std::string_view word =
            text.substr(start, space == std::string_view::npos ? space : space - start);
        if (!line.empty() && indent + line.size() + 1 + word.size() > kColumns) {
            out += std::string(indent, ' ') + line + "\n";
            line.clear();
        }
        if (!line.empty()) line += ' ';
        line += word;
        if (space == std::string_view::npos) break;
        start = space + 1;
    }
    if (!line.empty()) out += std::string(indent, ' ') + line + "\n";
    return out;
}

}  // namespace

std::string parameterReference(ReferenceFormat format) {
    const bool markdown = format == ReferenceFormat::Markdown;
    std::ostringstream out;
    const std::string envelope =
        "Every stack entry also has `envelope` (1 value, default 1): it scales the entry's displacement, "
        "0 = off; animatable.";
    if (markdown) {
        out << "Parameters marked [bind] rebind the deformer when they change; the others are animatable "
               "controls. Values: how many numbers a parameter takes (`3n`: any positive multiple of 3).\n"
            << envelope << "\n";
    } else {
        out << "Parameters marked [bind] rebind the deformer when they change; the others are animatable.\n"
            << "Values: how many numbers a parameter takes (3n: any positive multiple of 3).\n"
            << envelope << "\n";
    }
    for (const DeformerType& type : deformerTypes()) {
        const std::unique_ptr<Deformer> d = type.make("reference");
        if (markdown) {
            out << "\n### `" << type.name << "`\n\n"
                << type.summary << "\n\n"
                << "| parameter | values | default | meaning |\n"
                << "| --- | --- | --- | --- |\n";
        } else {
            out << "\n" << type.name << "\n" << wrapped(type.summary, 2);
        }
        for (const ParamInfo& info : d->parameters()) {
            const std::string name = info.name + (info.rebinds ? " [bind]" : "");
            const std::string values = countText(info), value = defaultText(d->get(info.name));
            if (markdown) {
                out << "| `" << info.name << "`" << (info.rebinds ? " [bind]" : "") << " | " << values
                    << " | " << value << " | " << info.doc << " |\n";
            } else {
                out << "  " << name << ": " << values << (values == "1" ? " value" : " values")
                    << ", default " << value << "\n"
                    << wrapped(info.doc, 6);
            }
        }
    }
    return out.str();
}

}  // namespace deformkit::host
