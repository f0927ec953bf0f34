// The optimized serial-vector operations against SUNDIALS' own (serial_vector_ops.h): every
// operation CVODES calls must give the same bits, for every special case of its coefficients
// and every aliasing of its arguments, so that simulations and fits keep their bits.

#include "serial_vector_ops.h"

#include <gtest/gtest.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>

#include <cmath>
#include <cstring>
#include <functional>
#include <random>
#include <vector>

namespace mbid::simulation::internal {
namespace {

// Coefficients reaching every branch of SUNDIALS' N_VLinearSum_Serial and N_VScale_Serial:
// +-1, 0, equal and opposite pairs, and others.
const std::vector<double> kCoefficients = {1.0, -1.0, 0.0, 0.7, -0.7, 2.9, -1.3};

bool SameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

class SerialVectorOpsTest : public ::testing::Test {
 protected:
  void SetUp() override { ASSERT_EQ(SUNContext_Create(nullptr, &context_), 0); }
  void TearDown() override {
    for (N_Vector v : vectors_) N_VDestroy(v);
    SUNContext_Free(&context_);
  }

  // A pair of vectors holding the same values, one with SUNDIALS' operations (reference), one
  // with ours (optimized). Values span 1e-8..1e8 with both signs, so roundings differ between
  // formulas: a test that could not tell c (x + y) from c x + c y would prove nothing.
  struct Pair {
    N_Vector reference;
    N_Vector optimized;
  };
  Pair MakePair(sunindextype n) {
    Pair pair{N_VNew_Serial(n, context_), N_VNew_Serial(n, context_)};
    vectors_.push_back(pair.reference);
    vectors_.push_back(pair.optimized);
    UseOptimizedSerialOps(pair.optimized);
    std::uniform_real_distribution<double> mantissa(-1.0, 1.0);
    std::uniform_int_distribution<int> exponent(-8, 8);
    for (sunindextype i = 0; i < n; ++i) {
      const double value = mantissa(random_) * std::pow(10.0, exponent(random_));
      NV_Ith_S(pair.reference, i) = value;
      NV_Ith_S(pair.optimized, i) = value;
    }
    return pair;
  }
  // Every element of the pair holds the same bits.
  static ::testing::AssertionResult Same(const Pair& pair) {
    for (sunindextype i = 0; i < NV_LENGTH_S(pair.reference); ++i) {
      if (!SameBits(NV_Ith_S(pair.reference, i), NV_Ith_S(pair.optimized, i))) {
        return ::testing::AssertionFailure()
               << "element " << i << ": SUNDIALS " << NV_Ith_S(pair.reference, i) << ", ours "
               << NV_Ith_S(pair.optimized, i);
      }
    }
    return ::testing::AssertionSuccess();
  }

  SUNContext context_ = nullptr;
  std::mt19937 random_{20261125};  // fixed seed: the same vectors in every run
  std::vector<N_Vector> vectors_;
};

constexpr sunindextype kLengths[] = {1, 8, 13};

TEST_F(SerialVectorOpsTest, LinearSumInEveryCaseAndAliasing) {
  int checked = 0;
  for (sunindextype n : kLengths) {
    for (double a : kCoefficients) {
      for (double b : kCoefficients) {
        for (int alias = 0; alias < 3; ++alias) {  // z separate, z = x, z = y
          Pair x = MakePair(n), y = MakePair(n), z = MakePair(n);
          Pair& target = alias == 0 ? z : alias == 1 ? x : y;
          N_VLinearSum(a, x.reference, b, y.reference, target.reference);
          N_VLinearSum(a, x.optimized, b, y.optimized, target.optimized);
          EXPECT_TRUE(Same(target)) << "n " << n << " a " << a << " b " << b << " alias " << alias;
          ++checked;
        }
      }
    }
  }
  EXPECT_EQ(checked, 3 * 7 * 7 * 3);
}

TEST_F(SerialVectorOpsTest, TheDataTellTheSpecialCasesFromTheGeneralFormula) {
  // If a (x + y) and a x + a y never differed on these values, the test above could not catch
  // an implementation that dropped SUNDIALS' special cases.
  Pair x = MakePair(64), y = MakePair(64);
  int differing = 0;
  for (sunindextype i = 0; i < 64; ++i) {
    const double xi = NV_Ith_S(x.reference, i), yi = NV_Ith_S(y.reference, i);
    if (!SameBits(0.7 * (xi + yi), 0.7 * xi + 0.7 * yi)) ++differing;
  }
  EXPECT_GT(differing, 0);
}

TEST_F(SerialVectorOpsTest, ElementwiseOperations) {
  for (sunindextype n : kLengths) {
    for (double c : kCoefficients) {
      for (bool in_place : {false, true}) {
        Pair x = MakePair(n), z = MakePair(n);
        Pair& target = in_place ? x : z;
        N_VScale(c, x.reference, target.reference);
        N_VScale(c, x.optimized, target.optimized);
        EXPECT_TRUE(Same(target)) << "scale by " << c << (in_place ? " in place" : "");
      }
      Pair x = MakePair(n), z = MakePair(n);
      N_VAddConst(x.reference, c, z.reference);
      N_VAddConst(x.optimized, c, z.optimized);
      EXPECT_TRUE(Same(z)) << "add " << c;
      N_VConst(c, z.reference);
      N_VConst(c, z.optimized);
      EXPECT_TRUE(Same(z)) << "const " << c;
    }
    using Binary = std::function<void(N_Vector, N_Vector, N_Vector)>;
    for (const Binary& op : {Binary(N_VProd), Binary(N_VDiv)}) {
      Pair x = MakePair(n), y = MakePair(n), z = MakePair(n);
      op(x.reference, y.reference, z.reference);
      op(x.optimized, y.optimized, z.optimized);
      EXPECT_TRUE(Same(z));
    }
    using Unary = std::function<void(N_Vector, N_Vector)>;
    for (const Unary& op : {Unary(N_VAbs), Unary(N_VInv)}) {
      Pair x = MakePair(n), z = MakePair(n);
      op(x.reference, z.reference);
      op(x.optimized, z.optimized);
      EXPECT_TRUE(Same(z));
    }
  }
}

TEST_F(SerialVectorOpsTest, Reductions) {
  for (sunindextype n : kLengths) {
    Pair x = MakePair(n), w = MakePair(n);
    EXPECT_TRUE(
        SameBits(N_VDotProd(x.reference, w.reference), N_VDotProd(x.optimized, w.optimized)));
    EXPECT_TRUE(SameBits(N_VMaxNorm(x.reference), N_VMaxNorm(x.optimized)));
    EXPECT_TRUE(SameBits(N_VMin(x.reference), N_VMin(x.optimized)));
    EXPECT_TRUE(
        SameBits(N_VWrmsNorm(x.reference, w.reference), N_VWrmsNorm(x.optimized, w.optimized)));
    EXPECT_TRUE(SameBits(N_VWSqrSumLocal(x.reference, w.reference),
                         N_VWSqrSumLocal(x.optimized, w.optimized)));
  }
  // SUNRsqrt: a zero vector has norm +0.
  Pair zero = MakePair(8), w = MakePair(8);
  N_VConst(0.0, zero.reference);
  N_VConst(0.0, zero.optimized);
  EXPECT_TRUE(
      SameBits(N_VWrmsNorm(zero.reference, w.reference), N_VWrmsNorm(zero.optimized, w.optimized)));
}

// The fused operations against SUNDIALS' generic fallbacks (its serial vector has none by
// default), the way CVODES calls them: sums into the first vector, arrays of sensitivities.
TEST_F(SerialVectorOpsTest, FusedOperationsAsTheGenericFallbacksCompose) {
  const sunindextype n = 8;
  const int count = 4;
  std::vector<double> c = {1.0, -0.7, 0.7, 2.9};
  for (bool into_first : {false, true}) {
    std::vector<Pair> x;
    for (int i = 0; i < count; ++i) x.push_back(MakePair(n));
    Pair z = MakePair(n);
    Pair& target = into_first ? x[0] : z;
    std::vector<N_Vector> xr, xo;
    for (const Pair& p : x) {
      xr.push_back(p.reference);
      xo.push_back(p.optimized);
    }
    N_VLinearCombination(count, c.data(), xr.data(), target.reference);
    N_VLinearCombination(count, c.data(), xo.data(), target.optimized);
    EXPECT_TRUE(Same(target)) << "linear combination" << (into_first ? " into X[0]" : "");
  }
  {
    Pair x = MakePair(n);
    std::vector<Pair> y, z;
    std::vector<N_Vector> yr, yo, zr, zo;
    for (int i = 0; i < count; ++i) {
      y.push_back(MakePair(n));
      z.push_back(MakePair(n));
    }
    for (int i = 0; i < count; ++i) {
      yr.push_back(y[i].reference);
      yo.push_back(y[i].optimized);
      zr.push_back(i % 2 ? y[i].reference : z[i].reference);  // some in place
      zo.push_back(i % 2 ? y[i].optimized : z[i].optimized);
    }
    N_VScaleAddMulti(count, c.data(), x.reference, yr.data(), zr.data());
    N_VScaleAddMulti(count, c.data(), x.optimized, yo.data(), zo.data());
    for (int i = 0; i < count; ++i) EXPECT_TRUE(Same(i % 2 ? y[i] : z[i])) << "scale-add " << i;
  }
  // Vector arrays, as for the sensitivities.
  std::vector<Pair> x, y, z;
  std::vector<N_Vector> xr, xo, yr, yo, zr, zo;
  for (int i = 0; i < count; ++i) {
    x.push_back(MakePair(n));
    y.push_back(MakePair(n));
    z.push_back(MakePair(n));
  }
  for (int i = 0; i < count; ++i) {
    xr.push_back(x[i].reference);
    xo.push_back(x[i].optimized);
    yr.push_back(y[i].reference);
    yo.push_back(y[i].optimized);
    zr.push_back(z[i].reference);
    zo.push_back(z[i].optimized);
  }
  auto all_same = [&](const std::vector<Pair>& pairs) {
    for (const Pair& p : pairs) {
      if (!Same(p)) return false;
    }
    return true;
  };
  for (double a : kCoefficients) {
    for (double b : kCoefficients) {
      N_VLinearSumVectorArray(count, a, xr.data(), b, yr.data(), zr.data());
      N_VLinearSumVectorArray(count, a, xo.data(), b, yo.data(), zo.data());
      EXPECT_TRUE(all_same(z)) << "linear sum array " << a << " " << b;
      N_VLinearSumVectorArray(count, a, xr.data(), b, yr.data(), yr.data());
      N_VLinearSumVectorArray(count, a, xo.data(), b, yo.data(), yo.data());
      EXPECT_TRUE(all_same(y)) << "linear sum array in place " << a << " " << b;
    }
  }
  N_VScaleVectorArray(count, c.data(), xr.data(), zr.data());
  N_VScaleVectorArray(count, c.data(), xo.data(), zo.data());
  EXPECT_TRUE(all_same(z));
  N_VConstVectorArray(count, 0.7, zr.data());
  N_VConstVectorArray(count, 0.7, zo.data());
  EXPECT_TRUE(all_same(z));
  std::vector<double> norms_r(count), norms_o(count);
  N_VWrmsNormVectorArray(count, xr.data(), yr.data(), norms_r.data());
  N_VWrmsNormVectorArray(count, xo.data(), yo.data(), norms_o.data());
  for (int i = 0; i < count; ++i) EXPECT_TRUE(SameBits(norms_r[i], norms_o[i]));

  // Two-level arrays (CVODES' Nordsieck updates of the sensitivities): sums j of vectors i.
  const int sums = 3;
  std::vector<std::vector<Pair>> yy(sums), zz(sums);
  std::vector<std::vector<N_Vector>> yyr(sums), yyo(sums), zzr(sums), zzo(sums);
  std::vector<N_Vector*> yyr_p, yyo_p, zzr_p, zzo_p;
  for (int j = 0; j < sums; ++j) {
    for (int i = 0; i < count; ++i) {
      yy[j].push_back(MakePair(n));
      zz[j].push_back(MakePair(n));
    }
    for (int i = 0; i < count; ++i) {
      yyr[j].push_back(yy[j][i].reference);
      yyo[j].push_back(yy[j][i].optimized);
      zzr[j].push_back(zz[j][i].reference);
      zzo[j].push_back(zz[j][i].optimized);
    }
    yyr_p.push_back(yyr[j].data());
    yyo_p.push_back(yyo[j].data());
    zzr_p.push_back(zzr[j].data());
    zzo_p.push_back(zzo[j].data());
  }
  N_VScaleAddMultiVectorArray(count, sums, c.data(), xr.data(), yyr_p.data(), zzr_p.data());
  N_VScaleAddMultiVectorArray(count, sums, c.data(), xo.data(), yyo_p.data(), zzo_p.data());
  for (int j = 0; j < sums; ++j) EXPECT_TRUE(all_same(zz[j])) << "scale-add array, sum " << j;
  N_VLinearCombinationVectorArray(count, sums, c.data(), yyr_p.data(), zr.data());
  N_VLinearCombinationVectorArray(count, sums, c.data(), yyo_p.data(), zo.data());
  EXPECT_TRUE(all_same(z)) << "linear combination array";
}

TEST_F(SerialVectorOpsTest, ClonesCarryTheOptimizedOperations) {
  Pair x = MakePair(8);
  N_Vector clone = N_VClone(x.optimized);
  ASSERT_NE(clone, nullptr);
  vectors_.push_back(clone);
  EXPECT_EQ(clone->ops->nvlinearsum, x.optimized->ops->nvlinearsum);
  EXPECT_EQ(clone->ops->nvlinearcombination, x.optimized->ops->nvlinearcombination);
  // And they are not SUNDIALS' own.
  EXPECT_NE(x.optimized->ops->nvlinearsum, x.reference->ops->nvlinearsum);
  EXPECT_EQ(x.reference->ops->nvlinearcombination, nullptr);
}

}  // namespace
}  // namespace mbid::simulation::internal
