// The singular value decompositions of mbid/common/eigen_decompositions.h, instantiated once.
#include "mbid/common/eigen_decompositions.h"

namespace Eigen {

template class JacobiSVD<MatrixXd>;
template class JacobiSVD<MatrixXcd>;

}  // namespace Eigen
