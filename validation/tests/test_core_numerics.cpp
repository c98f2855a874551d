// core.h's fused_multiply_add (the same bits as std::fma, on inputs that stress its two exact steps), sine and
// cosine (as accurate as std::sin and std::cos), stable_norm (accurate at every scale, the same at every address),
// has_finite_reciprocal (the division's overflow without it), atan2_in_double (within 4 ulps; float results correctly
// rounded) and kernel_atan2 (the library's in double and long double).
#include <gtest/gtest.h>

#include <boost/multiprecision/cpp_bin_float.hpp>

#include <array>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "warpcheck/core.h"

namespace warpcheck {
namespace {

using LD = long double;

struct FmaInputs {
  std::mt19937_64 rng{20261204};

  // A full 64-bit significand with an exponent in [emin, emax] and a random sign.
  LD full(int emin, int emax) {
    const LD x = std::ldexp(LD(rng() | (1ull << 63)), -63 + emin + int(rng() % unsigned(emax - emin + 1)));
    return (rng() & 1) ? -x : x;
  }
  // A 33-bit integer: products of two are exact in 66 bits, so a b + c often lands on a tie of the 64-bit grid.
  LD short_integer() { return LD((rng() >> 31) | (1ull << 32)); }
};

int mismatches_against_std_fma(LD a, LD b, LD c) {
  const LD expected = std::fma(a, b, c), got = fused_multiply_add(a, b, c);
  const bool same =
      (expected == got && std::signbit(expected) == std::signbit(got)) || (std::isnan(expected) && std::isnan(got));
  return same ? 0 : 1;
}

TEST(FusedMultiplyAdd, LongDoubleGivesTheBitsOfStdFmaOnRandomCancellingAndTieInputs) {
  FmaInputs in;
  int bad = 0;
  for (int i = 0; i < 100000; ++i) {
    const LD a = in.full(-20, 20), b = in.full(-20, 20), p = a * b;
    bad += mismatches_against_std_fma(a, b, in.full(-60, 60));
    bad += mismatches_against_std_fma(a, b, -p);  // the product's rounding error, as Kahan's determinant uses
    bad += mismatches_against_std_fma(a, b, -p * (1 + LD(int(in.rng() % 64) - 32) * 0x1p-63L));
    bad += mismatches_against_std_fma(a, b, std::ldexp(p, -int(in.rng() % 140)));
    const LD a2 = in.short_integer(), b2 = in.short_integer();
    const LD c2 = std::ldexp(LD(in.rng() >> (in.rng() % 64)), int(in.rng() % 80) - 10);
    bad += mismatches_against_std_fma(a2, b2, (in.rng() & 1) ? c2 : -c2);
    bad += mismatches_against_std_fma(a2, b2, -std::ldexp(LD(1), int(in.rng() % 70)));
    // a b on a tie of the grid and c far below it: one rounding of the low parts to nearest would lose c's side
    const LD below = std::ldexp(LD(1), -63 - int(in.rng() % 60));
    bad += mismatches_against_std_fma(a2, b2, (in.rng() & 1) ? below : -below);
  }
  EXPECT_EQ(bad, 0) << "of 700000 inputs";
}

TEST(FusedMultiplyAdd, NegatedProductErrorGivesTheBitsOfStdFmaOfTheRoundedProduct) {
  FmaInputs in;
  int bad = 0;
  for (int i = 0; i < 100000; ++i) {
    const LD a = in.full(-20, 20), b = in.full(-20, 20), a2 = in.short_integer(), b2 = in.short_integer();
    for (const auto& [x, y] : {std::pair{a, b}, std::pair{a2, b2}, std::pair{a2, LD(1)}}) {
      const LD p = x * y, expected = std::fma(-x, y, p), got = negated_product_error(x, y, p);
      bad += !(expected == got && std::signbit(expected) == std::signbit(got));
    }
  }
  EXPECT_EQ(bad, 0) << "of 300000 inputs";
}

TEST(FusedMultiplyAdd, LongDoubleGivesTheBitsOfStdFmaOutsideItsExactRangeAndForSpecialValues) {
  const LD inf = std::numeric_limits<LD>::infinity(), nan = std::numeric_limits<LD>::quiet_NaN();
  const LD tiny = std::numeric_limits<LD>::denorm_min(), huge = std::numeric_limits<LD>::max();
  const LD values[] = {0.0L, -0.0L, 1.0L, -3.5L, 0x1p-9000L, 0x1p9000L, tiny, huge, inf, -inf, nan, 0x1.8p-16382L};
  int bad = 0;
  for (const LD a : values)
    for (const LD b : values) {
      for (const LD c : values) bad += mismatches_against_std_fma(a, b, c);
      const LD p = a * b, expected = std::fma(-a, b, p), got = negated_product_error(a, b, p);
      bad += !((expected == got && std::signbit(expected) == std::signbit(got)) ||
               (std::isnan(expected) && std::isnan(got)));
    }
  EXPECT_EQ(bad, 0);
}

TEST(FusedMultiplyAdd, FloatAndDoubleAreStdFma) {
  EXPECT_EQ(fused_multiply_add(0.1f, 10.0f, -1.0f), std::fma(0.1f, 10.0f, -1.0f));
  EXPECT_EQ(fused_multiply_add(0.1, 10.0, -1.0), std::fma(0.1, 10.0, -1.0));
}

using Reference = boost::multiprecision::cpp_bin_float_50;

// |got - exact| in units of the last place of the exact value rounded to long double.
double ulps_from(LD got, const Reference& exact) {
  const LD rounded = static_cast<LD>(exact);
  const LD ulp = std::ldexp(LD(1), std::ilogb(rounded) - (std::numeric_limits<LD>::digits - 1));
  return static_cast<double>(abs(Reference(got) - exact) / Reference(ulp));
}

TEST(SineCosine, LongDoubleIsWithinOneAndAHalfUlpsOfA50DigitReferenceAsSinlAndCoslAre) {
  std::mt19937_64 rng(20261204);
  const Reference half_pi = boost::math::constants::half_pi<Reference>();
  double worst = 0, worst_std = 0;
  auto check = [&](LD x) {
    const Reference s = sin(Reference(x)), c = cos(Reference(x));
    LD both_s, both_c;
    sine_cosine(x, both_s, both_c);
    worst =
        std::max({worst, ulps_from(sine(x), s), ulps_from(cosine(x), c), ulps_from(both_s, s), ulps_from(both_c, c)});
    worst_std = std::max({worst_std, ulps_from(std::sin(x), s), ulps_from(std::cos(x), c)});
  };
  for (int i = 0; i < 20000; ++i) {
    // |x| below pi/4, where no reduction is made.
    check(std::ldexp(LD(rng() | (1ull << 63)), -64 - int(rng() % 30)) * 0.78L);
    // |x| in [1/2, 2^13): both sides of the reduced range's bound 2^12.
    const LD x = std::ldexp(LD(rng() | (1ull << 63)), -64 + int(rng() % 14));
    check((rng() & 1) ? x : -x);
    // The long doubles nearest a multiple of pi/2, where the reduced argument cancels.
    LD near = static_cast<LD>(half_pi * int(1 + rng() % 2600));
    check(near), check(std::nextafter(near, LD(0))), check(std::nextafter(near, LD(1e9)));
  }
  EXPECT_LE(worst, 1.5) << "glibc's sinl and cosl: " << worst_std << " ulps";
}

TEST(SineCosine, FloatAndDoubleAreStdSinAndCos) {
  for (const double x : {0.3, 1.0, 2.5, -7.0, 1e5}) {
    EXPECT_EQ(sine(x), std::sin(x));
    EXPECT_EQ(cosine(float(x)), std::cos(float(x)));
    double s, c;
    sine_cosine(x, s, c);
    EXPECT_EQ(s, std::sin(x));
    EXPECT_EQ(c, std::cos(x));
  }
}

}  // namespace
}  // namespace warpcheck
namespace warpcheck {
namespace {

// |v| of float and double vectors of every scale against the long double norm of the same vector, including where
// a plain sum of squares would overflow or underflow, and its special cases. Bound: the roundings of 1 / m, of each
// x_i / m, its square, the two sums, the root and the final product give a relative error below
// (1 + 1 + 1/2 + 1/2 + 1/2 + 1 + 1) u = 5.5 u (u = eps / 2; a square's and a sum's errors are halved by the root),
// which is at most 5.5 ulps of the result.
template <class T> void check_stable_norm() {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> unit(-1, 1);
  std::uniform_int_distribution<int> exponent(std::numeric_limits<T>::min_exponent - 10,
                                              std::numeric_limits<T>::max_exponent - 1);
  double worst = 0;
  for (int i = 0; i < 100000; ++i) {
    const int e = exponent(rng);
    const Vec3<T> v(std::ldexp(T(unit(rng)), e), std::ldexp(T(unit(rng)), e), std::ldexp(T(unit(rng)), e - i % 30));
    const Vec3<long double> w = v.template cast<long double>();
    const long double exact = std::sqrt(w.x() * w.x() + w.y() * w.y() + w.z() * w.z());
    const T n = stable_norm(v);
    const long double ulp = std::nextafter(T(exact), std::numeric_limits<T>::infinity()) - T(exact);
    if (exact > 0 && ulp > 0) worst = std::max(worst, double(std::abs(n - exact) / ulp));
  }
  EXPECT_LE(worst, 5.5) << sizeof(T) << "-byte scalar";
  EXPECT_EQ(stable_norm(Vec3<T>(Vec3<T>::Zero())), T(0));
  const T inf = std::numeric_limits<T>::infinity(), dmin = std::numeric_limits<T>::denorm_min();
  EXPECT_EQ(stable_norm(Vec3<T>(inf, 1, 0)), inf);
  EXPECT_TRUE(std::isnan(stable_norm(Vec3<T>(std::numeric_limits<T>::quiet_NaN(), 1, 0))));
  EXPECT_EQ(stable_norm(Vec3<T>(dmin, 0, 0)), dmin);
  const T big = std::numeric_limits<T>::max() / 2;
  const long double huge = stable_norm(Vec3<T>(big, big, 0)), expected = std::sqrt(2.0L) * big;
  EXPECT_LE(std::abs(huge - expected), 5.5L * std::numeric_limits<T>::epsilon() / 2 * expected);
}

TEST(StableNorm, IsWithinItsRoundingBoundAtEveryScaleAndKeepsZeroInfinityNanAndSubnormals) {
  check_stable_norm<float>();
  check_stable_norm<double>();
}

// The same vector at every place of an array of Vec3 (offsets of 12 bytes: every alignment) gives the same bits.
// Eigen's stableNorm, run alongside, does not: it blocks a 3-vector by its address, which shows the array does
// place the vectors at different alignments.
TEST(StableNorm, DoesNotDependOnWhereTheVectorLies) {
  std::mt19937_64 rng(8);
  std::uniform_real_distribution<float> unit(-1, 1);
  std::array<Vec3<float>, 16> at;
  int ours = 0, eigens = 0;
  for (int i = 0; i < 4000; ++i) {
    const Vec3<float> v(unit(rng), unit(rng), unit(rng));
    at.fill(v);
    for (const Vec3<float>& a : at) {
      ours += stable_norm(a) != stable_norm(at[0]);
      eigens += a.stableNorm() != at[0].stableNorm();
    }
  }
  EXPECT_EQ(ours, 0);
  EXPECT_GT(eigens, 0);
}

// has_finite_reciprocal(x) is std::isfinite(1 / x) for x >= 0 or NaN: at the 64 numbers on either side of the
// threshold, at the special values, and at 10^5 numbers spread over every exponent.
template <class T> void check_has_finite_reciprocal() {
  using limits = std::numeric_limits<T>;
  std::vector<T> xs = {T(0),          limits::denorm_min(), limits::min(),      T(1),
                       limits::max(), limits::infinity(),   limits::quiet_NaN()};
  T up = limits::min() / T(4), down = up;
  for (int i = 0; i < 64; ++i, up = std::nextafter(up, T(1)), down = std::nextafter(down, T(0)))
    xs.push_back(up), xs.push_back(down);
  std::mt19937_64 rng(44);
  std::uniform_real_distribution<double> mantissa(1, 2);
  std::uniform_int_distribution<int> exponent(limits::min_exponent - limits::digits, limits::max_exponent - 1);
  for (int i = 0; i < 100000; ++i) xs.push_back(std::ldexp(T(mantissa(rng)), exponent(rng)));
  int finite = 0;
  for (const T x : xs) {
    const bool expected = x != T(0) && std::isfinite(T(1) / x);  // 1 / 0 is Inf, without dividing by zero under UBSan
    ASSERT_EQ(has_finite_reciprocal(x), expected) << double(x);
    finite += expected;
  }
  EXPECT_GT(finite, 64);  // both answers occur next to the threshold
  EXPECT_LT(finite, int(xs.size()) - 64);
}

TEST(HasFiniteReciprocal, IsWhetherTheDivisionOverflowsInFloatDoubleAndLongDouble) {
  check_has_finite_reciprocal<float>();
  check_has_finite_reciprocal<double>();
  check_has_finite_reciprocal<long double>();
}

// Error of got in ulps of double at the long-double reference (whose own error is 2^-11 of those).
double double_ulps(double got, LD ref) {
  const double r = std::abs(double(ref));
  return double(std::abs(LD(got) - ref) / LD(std::nextafter(r, HUGE_VAL) - r));
}

// Pairs (y, x) over exponents in [-480, 480], near the diagonal and near tan(pi/8), where the reduction switches.
std::vector<std::array<double, 2>> atan2_arguments(int n) {
  std::mt19937_64 rng(20261206);
  std::uniform_real_distribution<double> u(-1, 1);
  std::uniform_int_distribution<int> e(-480, 480);
  std::vector<std::array<double, 2>> out;
  for (int i = 0; i < n; ++i) {
    double x = std::ldexp(u(rng), e(rng)), y = std::ldexp(u(rng), e(rng));
    if (i % 4 == 1) y = x * (1 + 1e-3 * u(rng));
    if (i % 4 == 2) y = x * (0.41421356237309504880 + 1e-3 * u(rng));
    if (i % 4 == 3) y = std::ldexp(u(rng), std::ilogb(x) + int(rng() % 61) - 30);
    if (rng() & 1) std::swap(x, y);
    out.push_back({y, x});
  }
  return out;
}

TEST(Atan2InDouble, IsWithinFourUlpsOfDoubleAndRoundsFloatArgumentsCorrectly) {
  double worst = 0;
  int misrounded = 0;
  for (const auto& [y, x] : atan2_arguments(2000000)) {
    worst = std::max(worst, double_ulps(atan2_in_double(y, x), std::atan2(LD(y), LD(x))));
    const float fy = float(y), fx = float(x);
    if (std::abs(fy) < 1e-30f || std::abs(fx) < 1e-30f || std::isinf(fy) || std::isinf(fx)) continue;
    misrounded += kernel_atan2(fy, fx) != float(std::atan2(LD(fy), LD(fx)));
  }
  EXPECT_LE(worst, 4.0);
  EXPECT_GT(worst, 0.5);  // the arguments reach the reduction's rounding: a bound that can fail
  EXPECT_EQ(misrounded, 0);
}

TEST(Atan2InDouble, GivesTheLibrarysSignsOfZeroQuadrantsAndSpecialValues) {
  const double inf = HUGE_VAL, nan = std::numeric_limits<double>::quiet_NaN(), big = std::numeric_limits<double>::max();
  const double values[] = {0.0,       -0.0,     1.0,         -1.0, 3.5,  -0.25, 0x1p-1000, -0x1p-1070,
                           0x1p-1074, 0x1p1000, -0x1.8p1023, big,  -big, inf,   -inf,      nan};
  for (double y : values)
    for (double x : values) {
      const double got = atan2_in_double(y, x), want = std::atan2(y, x);
      if (std::isnan(want)) {
        EXPECT_TRUE(std::isnan(got)) << y << " " << x;
        continue;
      }
      EXPECT_EQ(std::signbit(got), std::signbit(want)) << y << " " << x;
      EXPECT_LE(double_ulps(got, std::atan2(LD(y), LD(x))), 4.0) << y << " " << x;
    }
}

TEST(KernelAtan2, IsTheLibrarysInDoubleAndLongDouble) {
  for (const auto& [y, x] : atan2_arguments(1000)) {
    EXPECT_EQ(kernel_atan2(y, x), std::atan2(y, x));
    EXPECT_EQ(kernel_atan2(LD(y), LD(x)), std::atan2(LD(y), LD(x)));
  }
}

}  // namespace
}  // namespace warpcheck
