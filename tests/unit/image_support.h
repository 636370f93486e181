#pragma once

// Images for the unit tests, made from a closed form.

#include "deformkit/io/image.h"

namespace deformkit::test {

// A w x h image of c channels whose channel k at pixel (i, j) is f(k, i, j).
template <class F>
io::Image makeImage(int w, int h, int c, F f) {
    io::Image image(w, h, c);
    for (int j = 0; j < h; ++j) {
        for (int i = 0; i < w; ++i) {
            for (int k = 0; k < c; ++k)
                image.at(i, j, k) = static_cast<float>(f(k, double(i), double(j)));
        }
    }
    return image;
}

// A square RGB texture whose values are multiples of 1/256 (exact in half floats, so a half EXR bake keeps
// them): channel c at (x, y) is ((7 x + 13 y + 29 c) mod 256) / 256.
inline io::Image exactHalfTexture(int texels) {
    return makeImage(texels, texels, 3, [](int c, double x, double y) {
        return static_cast<double>((static_cast<int>(x) * 7 + static_cast<int>(y) * 13 + c * 29) % 256) /
               256.0;
    });
}

}  // namespace deformkit::test
