// Rng: reproducible streams with the right first two moments.
#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "msim/core/rng.hpp"

using namespace msim;

TEST(Rng, SameSeedSameSequence) {
  Rng a(42), b(42), c(43);
  int differences = 0;
  for (int i = 0; i < 1000; ++i) {
    const std::uint64_t x = a.next();
    EXPECT_EQ(x, b.next());
    differences += x != c.next();
  }
  EXPECT_EQ(differences, 1000);
}

TEST(Rng, SplitDependsOnlyOnSeedAndStream) {
  Rng fresh(5), used(5);
  for (int i = 0; i < 100; ++i) used.next();
  Rng s1 = fresh.split(3), s2 = used.split(3);
  for (int i = 0; i < 100; ++i) EXPECT_EQ(s1.next(), s2.next());
  // Distinct streams (and the parent) start differently.
  std::set<std::uint64_t> firsts{Rng(5).next()};
  for (std::uint64_t id = 0; id < 1000; ++id) firsts.insert(fresh.split(id).next());
  EXPECT_EQ(firsts.size(), 1001u);
  EXPECT_NE(fresh.split(1).split(2).next(), fresh.split(2).split(1).next());
}

TEST(Rng, SplitStreamsAreUncorrelated) {
  Rng root(17);
  Rng a = root.split(0), b = root.split(1);
  const int n = 100000;
  double sab = 0.0;
  for (int i = 0; i < n; ++i) sab += (a.uniform() - 0.5) * (b.uniform() - 0.5);
  // Correlation coefficient: sab / (n var) with var = 1/12; its std is about 1/sqrt(n).
  EXPECT_LT(std::abs(sab / (n / 12.0)), 5.0 / std::sqrt(double(n)));
}

TEST(Rng, UniformAndNormalMoments) {
  Rng rng(1);
  const int n = 200000;
  double su = 0.0, sn = 0.0, sn2 = 0.0;
  for (int i = 0; i < n; ++i) {
    const double u = rng.uniform(-2.0, 6.0);
    ASSERT_GE(u, -2.0);
    ASSERT_LT(u, 6.0);
    su += u;
    const double z = rng.normal();
    sn += z;
    sn2 += z * z;
  }
  // Means within 5 standard errors: uniform(-2,6) has sd 8/sqrt(12); normal has sd 1.
  EXPECT_NEAR(su / n, 2.0, 5.0 * (8.0 / std::sqrt(12.0)) / std::sqrt(double(n)));
  EXPECT_NEAR(sn / n, 0.0, 5.0 / std::sqrt(double(n)));
  EXPECT_NEAR(sn2 / n, 1.0, 5.0 * std::sqrt(2.0 / n));
  EXPECT_NEAR(Rng(2).normal(10.0, 0.0), 10.0, 0.0);
}

TEST(Rng, UniformIntCoversItsInclusiveRange) {
  Rng rng(8);
  int counts[7] = {};
  for (int i = 0; i < 70000; ++i) {
    const std::int64_t k = rng.uniformInt(-3, 3);
    ASSERT_GE(k, -3);
    ASSERT_LE(k, 3);
    ++counts[k + 3];
  }
  for (int c : counts) EXPECT_NEAR(c, 10000, 500);  // sd ~ 93
}
