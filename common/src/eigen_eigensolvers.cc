// The eigensolvers of mbid/common/eigen_decompositions.h, instantiated once.
#include "mbid/common/eigen_decompositions.h"

namespace Eigen {

template class EigenSolver<MatrixXd>;
template EigenSolver<MatrixXd>& EigenSolver<MatrixXd>::compute(const EigenBase<MatrixXd>&, bool);
template class SelfAdjointEigenSolver<MatrixXd>;
template SelfAdjointEigenSolver<MatrixXd>& SelfAdjointEigenSolver<MatrixXd>::compute(
    const EigenBase<MatrixXd>&, int);

}  // namespace Eigen
