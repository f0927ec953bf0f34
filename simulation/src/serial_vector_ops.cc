#include "serial_vector_ops.h"

#include <cmath>

// Each operation below keeps the order of SUNDIALS 6.4.1's serial arithmetic: the same products
// and sums, element by element, reductions summed from the first element on. This file is
// compiled with -ffp-contract=off (CMakeLists.txt), so no multiply-add is fused either.

namespace mbid::simulation::internal {
namespace {

sunindextype Length(N_Vector v) { return NV_LENGTH_S(v); }
realtype* Data(N_Vector v) { return NV_DATA_S(v); }

// z = a x + b y, with SUNDIALS' special cases: where it computes c (x + y) or c (x - y) the
// rounding differs from a x + b y, so the cases are kept, not only the general formula.
void LinearSum(realtype a, N_Vector x, realtype b, N_Vector y, N_Vector z) {
  const sunindextype n = Length(x);
  const realtype* xd = Data(x);
  const realtype* yd = Data(y);
  realtype* zd = Data(z);
  if ((b == 1.0 && z == y) || (a == 1.0 && z == x)) {
    // y += a x (or x += b y): the same sums as the general formula below with a unit factor.
    const realtype c = (b == 1.0 && z == y) ? a : b;
    const realtype* v = (b == 1.0 && z == y) ? xd : yd;
    for (sunindextype i = 0; i < n; ++i) zd[i] += c * v[i];
    return;
  }
  const bool a_unit = a == 1.0 || a == -1.0;
  const bool b_unit = b == 1.0 || b == -1.0;
  if (!a_unit && !b_unit && a == b) {
    for (sunindextype i = 0; i < n; ++i) zd[i] = a * (xd[i] + yd[i]);
    return;
  }
  if (!a_unit && !b_unit && a == -b) {
    for (sunindextype i = 0; i < n; ++i) zd[i] = a * (xd[i] - yd[i]);
    return;
  }
  // The remaining special cases (a or b = +-1) round as a x + b y does: 1 x and -1 x are exact.
  for (sunindextype i = 0; i < n; ++i) zd[i] = (a * xd[i]) + (b * yd[i]);
}

void Const(realtype c, N_Vector z) {
  const sunindextype n = Length(z);
  realtype* zd = Data(z);
  for (sunindextype i = 0; i < n; ++i) zd[i] = c;
}

void Prod(N_Vector x, N_Vector y, N_Vector z) {
  const sunindextype n = Length(x);
  const realtype* xd = Data(x);
  const realtype* yd = Data(y);
  realtype* zd = Data(z);
  for (sunindextype i = 0; i < n; ++i) zd[i] = xd[i] * yd[i];
}

void Div(N_Vector x, N_Vector y, N_Vector z) {
  const sunindextype n = Length(x);
  const realtype* xd = Data(x);
  const realtype* yd = Data(y);
  realtype* zd = Data(z);
  for (sunindextype i = 0; i < n; ++i) zd[i] = xd[i] / yd[i];
}

// c x: SUNDIALS' copy (c = 1) and negation (c = -1) give the same bits as the product.
void Scale(realtype c, N_Vector x, N_Vector z) {
  const sunindextype n = Length(x);
  const realtype* xd = Data(x);
  realtype* zd = Data(z);
  for (sunindextype i = 0; i < n; ++i) zd[i] = c * xd[i];
}

void Abs(N_Vector x, N_Vector z) {
  const sunindextype n = Length(x);
  const realtype* xd = Data(x);
  realtype* zd = Data(z);
  for (sunindextype i = 0; i < n; ++i) zd[i] = std::fabs(xd[i]);
}

void Inv(N_Vector x, N_Vector z) {
  const sunindextype n = Length(x);
  const realtype* xd = Data(x);
  realtype* zd = Data(z);
  for (sunindextype i = 0; i < n; ++i) zd[i] = 1.0 / xd[i];
}

void AddConst(N_Vector x, realtype b, N_Vector z) {
  const sunindextype n = Length(x);
  const realtype* xd = Data(x);
  realtype* zd = Data(z);
  for (sunindextype i = 0; i < n; ++i) zd[i] = xd[i] + b;
}

realtype DotProd(N_Vector x, N_Vector y) {
  const sunindextype n = Length(x);
  const realtype* xd = Data(x);
  const realtype* yd = Data(y);
  realtype sum = 0.0;
  for (sunindextype i = 0; i < n; ++i) sum += xd[i] * yd[i];
  return sum;
}

realtype MaxNorm(N_Vector x) {
  const sunindextype n = Length(x);
  const realtype* xd = Data(x);
  realtype max = 0.0;
  for (sunindextype i = 0; i < n; ++i) {
    if (std::fabs(xd[i]) > max) max = std::fabs(xd[i]);
  }
  return max;
}

realtype WSqrSumLocal(N_Vector x, N_Vector w) {
  const sunindextype n = Length(x);
  const realtype* xd = Data(x);
  const realtype* wd = Data(w);
  realtype sum = 0.0;
  for (sunindextype i = 0; i < n; ++i) {
    const realtype product = xd[i] * wd[i];
    sum += product * product;
  }
  return sum;
}

// SUNRsqrt: 0 for a non-positive mean square.
realtype WrmsNorm(N_Vector x, N_Vector w) {
  const realtype mean_square = WSqrSumLocal(x, w) / static_cast<realtype>(Length(x));
  return mean_square <= 0.0 ? 0.0 : std::sqrt(mean_square);
}

realtype Min(N_Vector x) {
  const sunindextype n = Length(x);
  const realtype* xd = Data(x);
  realtype min = xd[0];
  for (sunindextype i = 1; i < n; ++i) {
    if (xd[i] < min) min = xd[i];
  }
  return min;
}

// The fused operations, as SUNDIALS' generic fallbacks compose them from the ones above.

int LinearCombination(int count, realtype* c, N_Vector* x, N_Vector z) {
  Scale(c[0], x[0], z);
  for (int i = 1; i < count; ++i) LinearSum(c[i], x[i], 1.0, z, z);
  return 0;
}

int ScaleAddMulti(int count, realtype* a, N_Vector x, N_Vector* y, N_Vector* z) {
  for (int i = 0; i < count; ++i) LinearSum(a[i], x, 1.0, y[i], z[i]);
  return 0;
}

int LinearSumVectorArray(int count, realtype a, N_Vector* x, realtype b, N_Vector* y, N_Vector* z) {
  for (int i = 0; i < count; ++i) LinearSum(a, x[i], b, y[i], z[i]);
  return 0;
}

int ScaleVectorArray(int count, realtype* c, N_Vector* x, N_Vector* z) {
  for (int i = 0; i < count; ++i) Scale(c[i], x[i], z[i]);
  return 0;
}

int ConstVectorArray(int count, realtype c, N_Vector* z) {
  for (int i = 0; i < count; ++i) Const(c, z[i]);
  return 0;
}

int WrmsNormVectorArray(int count, N_Vector* x, N_Vector* w, realtype* norms) {
  for (int i = 0; i < count; ++i) norms[i] = WrmsNorm(x[i], w[i]);
  return 0;
}

// The fallback through ScaleAddMulti (non-null here) for each of the `count` vectors.
int ScaleAddMultiVectorArray(int count, int sums, realtype* a, N_Vector* x, N_Vector** y,
                             N_Vector** z) {
  for (int i = 0; i < count; ++i) {
    for (int j = 0; j < sums; ++j) LinearSum(a[j], x[i], 1.0, y[j][i], z[j][i]);
  }
  return 0;
}

// The fallback through LinearCombination (non-null here) for each of the `count` vectors.
int LinearCombinationVectorArray(int count, int sums, realtype* c, N_Vector** x, N_Vector* z) {
  for (int i = 0; i < count; ++i) {
    Scale(c[0], x[0][i], z[i]);
    for (int j = 1; j < sums; ++j) LinearSum(c[j], x[j][i], 1.0, z[i], z[i]);
  }
  return 0;
}

}  // namespace

void UseOptimizedSerialOps(N_Vector v) {
  N_Vector_Ops ops = v->ops;
  ops->nvlinearsum = LinearSum;
  ops->nvconst = Const;
  ops->nvprod = Prod;
  ops->nvdiv = Div;
  ops->nvscale = Scale;
  ops->nvabs = Abs;
  ops->nvinv = Inv;
  ops->nvaddconst = AddConst;
  ops->nvdotprod = DotProd;
  ops->nvdotprodlocal = DotProd;
  ops->nvmaxnorm = MaxNorm;
  ops->nvmaxnormlocal = MaxNorm;
  ops->nvwrmsnorm = WrmsNorm;
  ops->nvwsqrsumlocal = WSqrSumLocal;
  ops->nvmin = Min;
  ops->nvminlocal = Min;
  ops->nvlinearcombination = LinearCombination;
  ops->nvscaleaddmulti = ScaleAddMulti;
  ops->nvlinearsumvectorarray = LinearSumVectorArray;
  ops->nvscalevectorarray = ScaleVectorArray;
  ops->nvconstvectorarray = ConstVectorArray;
  ops->nvwrmsnormvectorarray = WrmsNormVectorArray;
  ops->nvscaleaddmultivectorarray = ScaleAddMultiVectorArray;
  ops->nvlinearcombinationvectorarray = LinearCombinationVectorArray;
}

}  // namespace mbid::simulation::internal
