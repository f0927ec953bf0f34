// BDCSVD of mbid/common/eigen_decompositions.h, instantiated once: alone in its file, as it
// takes as long to compile as the other decompositions together.
#include "mbid/common/eigen_decompositions.h"

namespace Eigen {

template class BDCSVD<MatrixXd>;

}  // namespace Eigen
