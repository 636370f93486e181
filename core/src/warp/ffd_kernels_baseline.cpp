#include "ffd_kernels.h"

namespace deformkit::warp::detail {

const FfdKernels kBaselineFfdKernels = {bernstein444,        window444,         frames444,
                                        bernsteinWeights444, bsplineWeights444, bsplineRepeatWeights444,
                                        bspline444,          bsplineRepeat444};

}  // namespace deformkit::warp::detail
