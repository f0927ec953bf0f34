// The optimized dense solve against SUNDIALS' own (dense_solve.h): the same bits on the same LU
// factors, with row swaps, and a solution of A x = b.

#include "dense_solve.h"

#include <gtest/gtest.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>

namespace mbid::simulation::internal {
namespace {

bool SameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

TEST(DenseSolveTest, SameBitsAsSundialsOnTheSameFactors) {
  SUNContext context = nullptr;
  ASSERT_EQ(SUNContext_Create(nullptr, &context), 0);
  std::mt19937 random(20261125);  // fixed seed: the same matrices in every run
  std::uniform_real_distribution<double> entry(-1.0, 1.0);
  int swapped_rows = 0;
  for (sunindextype n : {1, 2, 8, 13}) {
    for (int trial = 0; trial < 20; ++trial) {
      // A Newton matrix's shape, I - gamma J, with J of mixed scales: pivoting is needed.
      SUNMatrix a_reference = SUNDenseMatrix(n, n, context);
      SUNMatrix a_optimized = SUNDenseMatrix(n, n, context);
      for (sunindextype j = 0; j < n; ++j) {
        for (sunindextype i = 0; i < n; ++i) {
          const double value = (i == j ? 1.0 : 0.0) - 3.0 * entry(random) * std::pow(10.0, j % 3);
          SM_ELEMENT_D(a_reference, i, j) = value;
          SM_ELEMENT_D(a_optimized, i, j) = value;
        }
      }
      N_Vector b = N_VNew_Serial(n, context);
      for (sunindextype i = 0; i < n; ++i) NV_Ith_S(b, i) = entry(random) * 1e3;
      N_Vector x_reference = N_VClone(b), x_optimized = N_VClone(b);
      SUNLinearSolver reference = SUNLinSol_Dense(b, a_reference, context);
      SUNLinearSolver optimized = SUNLinSol_Dense(b, a_optimized, context);
      UseOptimizedDenseSolve(optimized);
      ASSERT_NE(optimized->ops->solve, reference->ops->solve);

      // The original matrix, for the residual, before the factorization overwrites it.
      SUNMatrix original = SUNDenseMatrix(n, n, context);
      SUNMatCopy(a_reference, original);
      ASSERT_EQ(SUNLinSolSetup(reference, a_reference), SUNLS_SUCCESS);
      ASSERT_EQ(SUNLinSolSetup(optimized, a_optimized), SUNLS_SUCCESS);
      const sunindextype* pivots =
          static_cast<SUNLinearSolverContent_Dense>(optimized->content)->pivots;
      for (sunindextype k = 0; k < n; ++k) swapped_rows += pivots[k] != k ? 1 : 0;

      ASSERT_EQ(SUNLinSolSolve(reference, a_reference, x_reference, b, 0.0), SUNLS_SUCCESS);
      ASSERT_EQ(SUNLinSolSolve(optimized, a_optimized, x_optimized, b, 0.0), SUNLS_SUCCESS);
      EXPECT_EQ(SUNLinSolLastFlag(optimized), SUNLS_SUCCESS);
      double largest_residual = 0.0, scale = 0.0;
      for (sunindextype i = 0; i < n; ++i) {
        EXPECT_TRUE(SameBits(NV_Ith_S(x_reference, i), NV_Ith_S(x_optimized, i)))
            << "n " << n << " trial " << trial << " element " << i;
        double row = -NV_Ith_S(b, i);
        for (sunindextype j = 0; j < n; ++j) {
          row += SM_ELEMENT_D(original, i, j) * NV_Ith_S(x_optimized, j);
          scale =
              std::max(scale, std::abs(SM_ELEMENT_D(original, i, j) * NV_Ith_S(x_optimized, j)));
        }
        largest_residual = std::max(largest_residual, std::abs(row));
      }
      // Backward stable LU with partial pivoting: a residual of a few n eps times |A| |x|.
      EXPECT_LT(largest_residual, 1e-12 * std::max(scale, 1.0)) << "n " << n;

      SUNLinSolFree(reference);
      SUNLinSolFree(optimized);
      SUNMatDestroy(a_reference);
      SUNMatDestroy(a_optimized);
      SUNMatDestroy(original);
      N_VDestroy(b);
      N_VDestroy(x_reference);
      N_VDestroy(x_optimized);
    }
  }
  EXPECT_GT(swapped_rows, 0) << "no row swaps: the pivoting branch went untested";
  SUNContext_Free(&context);
}

}  // namespace
}  // namespace mbid::simulation::internal
