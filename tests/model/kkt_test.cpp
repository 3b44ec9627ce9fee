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

// r copies of OneCell side by side (node i under cell i): the sums of (5.4) weigh one cell by
// about 1/r, the cell by cell residuals by its own size.
struct ManyCells {
  int r = 1000;
  double k = 2.0, P = 3.0, pull = 5.0, c = 1.5;
  Eigen::SparseMatrix<double> K{3 * r, 3 * r}, B{3 * r, 3 * r};
  Eigen::VectorXd f = Eigen::VectorXd::Zero(3 * r), radius = Eigen::VectorXd::Constant(r, c);
  Eigen::VectorXd lambda = Eigen::VectorXd::Zero(3 * r), w, h;
  ManyCells() {
    for (int i = 0; i < r; ++i) {
      for (int a = 0; a < 3; ++a) K.insert(3 * i + a, 3 * i + a) = k;
      B.insert(i, 3 * i + 2) = -1;
      B.insert(r + i, 3 * i) = 1;
      B.insert(2 * r + i, 3 * i + 1) = 1;
      f[3 * i] = pull;
      f[3 * i + 2] = -P;
      lambda[i] = P;
      lambda[r + i] = c;
    }
    settle();
    h = B * (f / k);
  }
  void settle() { w = (f - B.transpose() * lambda) / k; }
  KktResiduals residuals() const { return kkt_residuals(K * w, f, B, r, true, radius, w, lambda, h); }
};

TEST(KktResiduals, OneBadCellAmongManyIsSeenCellByCell) {
  ManyCells p;
  EXPECT_LT(p.residuals().max(), 1e-14);
  EXPECT_GE(p.residuals().worst_cell, 0);
  const int bad = 417;
  {  // cell 417's λ_t on its circle but across the slip: the sum barely moves
    ManyCells q;
    q.lambda[q.r + bad] = 0;
    q.lambda[2 * q.r + bad] = q.c;
    q.settle();
    const KktResiduals res = q.residuals();
    EXPECT_LT(res.slip_alignment, 5e-3);
    EXPECT_GT(res.friction_cellwise, 0.5);
    EXPECT_EQ(res.worst_cell, bad);
  }
  {  // cell 417 pressed where it has lifted off
    ManyCells q;
    q.f[3 * bad + 2] = +q.P;
    q.settle();
    const KktResiduals res = q.residuals();
    EXPECT_LT(res.normal_complementarity, 5e-3);
    EXPECT_GT(res.normal_cellwise, 0.5);
    EXPECT_EQ(res.worst_cell, bad);
  }
  {  // cell 417 penetrating under too little pressure
    ManyCells q;
    q.lambda[bad] = 0.5 * q.P;
    q.settle();
    const KktResiduals res = q.residuals();
    EXPECT_GT(res.normal_cellwise, 0.1);
    EXPECT_EQ(res.worst_cell, bad);
  }
}

}  // namespace
}  // namespace contact3d
