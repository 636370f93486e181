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

}  // namespace deformkit::test
