// KKT residuals of (5.4) on a one-cell problem whose solution is known in closed form: a single
// node on a spring K = k·I pressed down by P and pulled along x by more than the disc allows.
#include <gtest/gtest.h>

#include <Eigen/SparseCore>

#include "model/kkt.hpp"

namespace contact3d {
namespace {

struct OneCell {
  double k = 2.0, P = 3.0, pull = 5.0, c = 1.5;
  Eigen::SparseMatrix<double> K{3, 3}, B{3, 3};
  Eigen::VectorXd f{3}, radius{1}, lambda{3}, w{3}, h{3};
  OneCell() {
    K.insert(0, 0) = k;
    K.insert(1, 1) = k;
    K.insert(2, 2) = k;
    B.insert(0, 2) = -1;  // ∫ w_n = −w_3
    B.insert(1, 0) = 1;   // ∫ w_t1
    B.insert(2, 1) = 1;   // ∫ w_t2
    f << pull, 0, -P;
    radius << c;
    lambda << P, c, 0;                     // closed contact, slipping along +x
    w = (f - B.transpose() * lambda) / k;  // equilibrium
    h = B * (f / k);
  }
  KktResiduals residuals() const { return kkt_residuals(K * w, f, B, 1, true, radius, w, lambda, h); }
};

TEST(KktResiduals, VanishAtTheClosedFormSolution) {
  const OneCell p;
  const KktResiduals r = p.residuals();
  EXPECT_LT(r.max(), 1e-14);
}

TEST(KktResiduals, EachConditionIsSeenWhenBroken) {
  {  // too little normal pressure: the node penetrates
    OneCell p;
    p.lambda[0] = 0.5 * p.P;
    p.w = (p.f - p.B.transpose() * p.lambda) / p.k;
    EXPECT_GT(p.residuals().normal_feasibility, 0.1);
  }
  {  // pressure where the node has lifted off
    OneCell p;
    p.f[2] = +p.P;  // pulled up: open contact
    p.w = (p.f - p.B.transpose() * p.lambda) / p.k;
    EXPECT_GT(p.residuals().normal_complementarity, 0.1);
  }
  {  // λ_t outside the disc
    OneCell p;
    p.lambda[1] = 2 * p.c;
    p.w = (p.f - p.B.transpose() * p.lambda) / p.k;
    EXPECT_NEAR(p.residuals().disc_feasibility, 1.0, 1e-12);
  }
  {  // λ_t on the circle but not opposing the slip
    OneCell p;
    p.lambda[1] = 0;
    p.lambda[2] = p.c;
    p.w = (p.f - p.B.transpose() * p.lambda) / p.k;
    EXPECT_GT(p.residuals().slip_alignment, 0.1);
  }
  {  // a w that is not K⁻¹(f − 𝔹ᵀλ)
    OneCell p;
    p.w[0] *= 1.5;
    EXPECT_GT(p.residuals().equilibrium, 0.01);
  }
}

}  // namespace
}  // namespace contact3d
