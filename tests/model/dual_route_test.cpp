// Which dual route a scene gets when its dense Q does or does not fit in memory (model/dual_route.hpp).
#include <gtest/gtest.h>

#include "model/dual_route.hpp"

using namespace contact3d;

TEST(DualRoute, DenseRoutesStayWhereQFits) {
  for (const DualMethod m : {DualMethod::Augmented, DualMethod::ContactLast, DualMethod::BlockSolve, DualMethod::Mumps,
                             DualMethod::MumpsPetsc, DualMethod::MatrixFree})
    EXPECT_EQ(dual_method_for_memory(m, m, true), m);
  EXPECT_EQ(dual_method_for_memory(DualMethod::Auto, DualMethod::Augmented, true), DualMethod::Augmented);
}

TEST(DualRoute, AutoGoesMatrixFreeWhereQDoesNotFitAndANamedDenseRouteIsRefused) {
  EXPECT_EQ(dual_method_for_memory(DualMethod::Auto, DualMethod::Augmented, false), DualMethod::MatrixFree);
  EXPECT_EQ(dual_method_for_memory(DualMethod::MatrixFree, DualMethod::MatrixFree, false), DualMethod::MatrixFree);
  EXPECT_FALSE(dual_method_for_memory(DualMethod::Augmented, DualMethod::Augmented, false));
  EXPECT_FALSE(dual_method_for_memory(DualMethod::ContactLast, DualMethod::ContactLast, false));
  // MUMPS's Schur complement is dense, and its K lives on the ranks: no fallback in the distributed build.
  EXPECT_FALSE(dual_method_for_memory(DualMethod::Auto, DualMethod::Mumps, false));
  EXPECT_FALSE(dual_method_for_memory(DualMethod::MumpsPetsc, DualMethod::MumpsPetsc, false));
}

// A helper's slab face: 27 648 multipliers, the dense Q with its working copies 14.2 GiB, the whole run
// 22.1 GiB with the augmented factor, 22.3 GiB available; matrix-free it needed 2.29 GiB. There: matrix-free.
// The same with room to spare, or where K's factor alone would not leave room either (the augmented route's
// refusal then says what it needs), or with the memory unknown: the augmented route stays.
TEST(DualRoute, AutoLeavesTheAugmentedFactorWhereItAndQCrowdTheMemory) {
  const double GiB = double(1 << 30);
  const int m = 27648;
  const double dense = 14.2 * GiB;
  const double augmented_lnz = (22.1 * GiB - dense) / (kFactorOverhead * 8.0);
  EXPECT_TRUE(augmented_crowds_memory(augmented_lnz, m, dense, 22.3 * GiB));
  EXPECT_FALSE(augmented_crowds_memory(augmented_lnz, m, dense, 64 * GiB));
  EXPECT_FALSE(augmented_crowds_memory(augmented_lnz, m, dense, 4 * GiB));
  EXPECT_FALSE(augmented_crowds_memory(augmented_lnz, m, dense, 0));
}

TEST(DualRoute, TheTwoLevelPreconditionerOnlyWhereItsArraysFit) {
  // 30 000 multipliers, 192 groups: 4 · 8 · 30 000 · 192 bytes = 176 MiB.
  EXPECT_NEAR(coarse_space_bytes(30000, 192), 184.32e6, 1.0);
  EXPECT_TRUE(coarse_space_fits(30000, 192, 8e9));
  EXPECT_TRUE(coarse_space_fits(30000, 192, 0));  // unknown memory: taken
  EXPECT_TRUE(coarse_space_fits(30000, 192, 4 * 184.32e6));
  EXPECT_FALSE(coarse_space_fits(30000, 192, 4 * 184.32e6 - 1e3));
  EXPECT_FALSE(coarse_space_fits(30000, 192, 500e6));
}

// A second solve with other cells forms its Q from the first solve's factor where the forward solves'
// W (the first factor's coupling, scaled by the rows) stays under half of K's factor and fits in memory.
TEST(DualRoute, ForwardSolvesOnTheFirstFactorWhereTheyStoreLittle) {
  const AugmentedFactorParts compact{1e8, 2e7};  // a block: its cells reach a fifth of the factor
  EXPECT_TRUE(forward_solves_pay(compact, 1000, 1780, 0.0));
  EXPECT_TRUE(forward_solves_pay(compact, 1000, 1780, 16e9));
  EXPECT_FALSE(forward_solves_pay(compact, 1000, 1780, 0.5e9));  // 8 B × 3.6e7 > half of 0.5 GB
  const AugmentedFactorParts slab{1e8, 8e7};                     // a thin slab: W is most of the factor
  EXPECT_FALSE(forward_solves_pay(slab, 1000, 1780, 0.0));
  EXPECT_FALSE(forward_solves_pay(AugmentedFactorParts{1e8, 0.0}, 1000, 1780, 0.0));  // a factor of K alone
  EXPECT_FALSE(forward_solves_pay(compact, 0, 1780, 0.0));
}
