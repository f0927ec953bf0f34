#include "dense_solve.h"

#include <nvector/nvector_serial.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>

// The order of SUNDIALS 6.4.1's SUNLinSolSolve_Dense and SUNDlsMat_denseGETRS: row swaps in
// pivot order, forward substitution by columns of L, back substitution by columns of U. This
// file is compiled with -ffp-contract=off (CMakeLists.txt): no fused multiply-add either.

namespace mbid::simulation::internal {
namespace {

int Solve(SUNLinearSolver solver, SUNMatrix a, N_Vector x, N_Vector b, realtype /*tolerance*/) {
  if (a == nullptr || solver == nullptr || x == nullptr || b == nullptr) return SUNLS_MEM_NULL;
  auto* content = static_cast<SUNLinearSolverContent_Dense>(solver->content);
  N_VScale(1.0, b, x);
  realtype** columns = SUNDenseMatrix_Cols(a);
  realtype* v = N_VGetArrayPointer(x);
  const sunindextype* pivots = content->pivots;
  if (columns == nullptr || v == nullptr || pivots == nullptr) {
    content->last_flag = SUNLS_MEM_FAIL;
    return SUNLS_MEM_FAIL;
  }
  const sunindextype n = SUNDenseMatrix_Rows(a);
  for (sunindextype k = 0; k < n; ++k) {
    const sunindextype p = pivots[k];
    if (p != k) {
      const realtype swap = v[k];
      v[k] = v[p];
      v[p] = swap;
    }
  }
  for (sunindextype k = 0; k + 1 < n; ++k) {
    const realtype* column = columns[k];
    const realtype v_k = v[k];
    for (sunindextype i = k + 1; i < n; ++i) v[i] -= column[i] * v_k;
  }
  for (sunindextype k = n - 1; k > 0; --k) {
    const realtype* column = columns[k];
    v[k] /= column[k];
    const realtype v_k = v[k];
    for (sunindextype i = 0; i < k; ++i) v[i] -= column[i] * v_k;
  }
  v[0] /= columns[0][0];
  content->last_flag = SUNLS_SUCCESS;
  return SUNLS_SUCCESS;
}

}  // namespace

void UseOptimizedDenseSolve(SUNLinearSolver solver) { solver->ops->solve = Solve; }

}  // namespace mbid::simulation::internal
