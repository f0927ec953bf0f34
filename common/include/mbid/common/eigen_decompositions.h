#pragma once
// Eigen's dense decompositions on MatrixXd, compiled once in mbid_common instead of in every
// file that uses them: each costs 4-21 s of -O2 per translation unit (BDCSVD the most); compiled
// once, a cold build takes 4% less CPU (docs/performance.md). Include this header instead of
// <Eigen/Eigenvalues> or <Eigen/SVD>; a decomposition of another matrix type (or from an
// expression, not a MatrixXd) is still compiled where it is used, correctly but without the
// saving.

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <Eigen/SVD>

namespace Eigen {

extern template class EigenSolver<MatrixXd>;
extern template EigenSolver<MatrixXd>& EigenSolver<MatrixXd>::compute(const EigenBase<MatrixXd>&,
                                                                      bool);
extern template class SelfAdjointEigenSolver<MatrixXd>;
extern template SelfAdjointEigenSolver<MatrixXd>& SelfAdjointEigenSolver<MatrixXd>::compute(
    const EigenBase<MatrixXd>&, int);
extern template class JacobiSVD<MatrixXd>;
extern template class JacobiSVD<MatrixXcd>;
extern template class BDCSVD<MatrixXd>;

}  // namespace Eigen
