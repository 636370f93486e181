#include "deformkit/ptex/ptex_file.h"

#include <cstring>

#include "format.h"

namespace deformkit::ptex {

namespace {

template <typename T>
std::vector<uint8_t> littleEndian(const std::vector<T>& values) {
    std::vector<uint8_t> out;
    out.reserve(values.size() * sizeof(T));
    detail::ByteWriter w(out);
    for (const T v : values)
        w.put(v);
    return out;
}

MetaValue keyed(std::string key, MetaType type) {
    MetaValue m;
    m.key = std::move(key);
    m.type = type;
    return m;
}

}  // namespace

MetaValue MetaValue::ofString(std::string key, std::string value) {
    MetaValue m = keyed(std::move(key), MetaType::String);
    m.string = std::move(value);
    return m;
}
MetaValue MetaValue::ofInt8(std::string key, std::vector<int8_t> values) {
    MetaValue m = keyed(std::move(key), MetaType::Int8);
    m.int8s = std::move(values);
    return m;
}
MetaValue MetaValue::ofInt16(std::string key, std::vector<int16_t> values) {
    MetaValue m = keyed(std::move(key), MetaType::Int16);
    m.int16s = std::move(values);
    return m;
}
MetaValue MetaValue::ofInt32(std::string key, std::vector<int32_t> values) {
    MetaValue m = keyed(std::move(key), MetaType::Int32);
    m.int32s = std::move(values);
    return m;
}
MetaValue MetaValue::ofFloat(std::string key, std::vector<float> values) {
    MetaValue m = keyed(std::move(key), MetaType::Float);
    m.floats = std::move(values);
    return m;
}
MetaValue MetaValue::ofDouble(std::string key, std::vector<double> values) {
    MetaValue m = keyed(std::move(key), MetaType::Double);
    m.doubles = std::move(values);
    return m;
}

std::vector<uint8_t> MetaValue::bytes() const {
    switch (type) {
        case MetaType::String: {
            std::vector<uint8_t> out(string.begin(), string.end());
            out.push_back(0);
            return out;
        }
        case MetaType::Int8:
            return littleEndian(int8s);
        case MetaType::Int16:
            return littleEndian(int16s);
        case MetaType::Int32:
            return littleEndian(int32s);
        case MetaType::Float:
            return littleEndian(floats);
        case MetaType::Double:
            return littleEndian(doubles);
    }
    return {};
}

std::vector<uint8_t> expandedTexels(const PtexFile& file, size_t face) {
    const size_t pixel = file.pixelSize();
    if (face >= file.faces.size()) return {};
    if (face < file.texels.size() && !file.texels[face].empty()) return file.texels[face];
    const size_t count = file.faces[face].texelCount();
    std::vector<uint8_t> out(count * pixel);
    if (file.constData.size() < (face + 1) * pixel) return out;
    const uint8_t* value = file.constData.data() + face * pixel;
    for (size_t t = 0; t < count; ++t)
        std::memcpy(out.data() + t * pixel, value, pixel);
    return out;
}

}  // namespace deformkit::ptex
