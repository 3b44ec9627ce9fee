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
