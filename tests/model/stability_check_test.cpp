// The stability check (5.1) on the dual operator (model/stability_check.hpp): cond(Q) of a Q whose
// spectrum is known, the factor handed to the Newton steps, the warning above 1e10, and a Q with
// dependent rows refused naming the cell.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "base/errors.hpp"
#include "model/stability_check.hpp"

using namespace contact3d;

namespace {

// A dual problem that is just a given Q (the displacement is not asked for here).
class GivenQ : public DualProblem {
 public:
  explicit GivenQ(Eigen::MatrixXd Q) {
    h_ = Eigen::VectorXd::Ones(Q.rows());
    Q_ = std::move(Q);
  }
  Eigen::VectorXd face_displacement(const Eigen::VectorXd&) const override { return {}; }
  Eigen::VectorXd displacement(const Eigen::VectorXd&) const override { return {}; }
  void release_factor() override {}
};

// Q = V diag(spectrum) Vᵀ with V orthogonal (a QR of a fixed matrix).
Eigen::MatrixXd with_spectrum(const Eigen::VectorXd& spectrum) {
  const Eigen::Index m = spectrum.size();
  Eigen::MatrixXd A(m, m);
  for (Eigen::Index i = 0; i < m; ++i)
    for (Eigen::Index j = 0; j < m; ++j) A(i, j) = std::sin(1.0 + 3.0 * i + 7.0 * j * j);
  const Eigen::MatrixXd V = Eigen::HouseholderQR<Eigen::MatrixXd>(A).householderQ();
  return V * spectrum.asDiagonal() * V.transpose();
}

// A frictionless operator of m cells (one row each), each cell a unit square in a row.
struct Cells {
  ContactOperator op;
  SolveResult res;
  explicit Cells(int m) {
    op.r = m;
    op.with_friction = false;
    for (int i = 0; i < m; ++i) {
      ContactCell c;
      c.lo = Eigen::Vector2d(i, 0);
      c.hi = Eigen::Vector2d(i + 1, 1);
      c.centroid = (c.lo + c.hi) / 2;
      c.area = 1;
      res.partition.cells.push_back(c);
    }
  }
};

}  // namespace

TEST(StabilityCheck, ConditionOfAKnownSpectrumAndTheFactorForNewtonSteps) {
  const int m = 12;
  for (const double cond : {1e2, 1e6, 1e12}) {
    Eigen::VectorXd spectrum(m);
    for (int i = 0; i < m; ++i) spectrum[i] = std::pow(cond, static_cast<double>(i) / (m - 1));
    const GivenQ dual(with_spectrum(spectrum));
    Cells cells(m);
    std::vector<std::string> lines;
    Progress report([&lines](const std::string& line) { lines.push_back(line); }, {}, 1.0);
    double q_norm = 0;
    const auto factor = check_dual_stability(dual, q_norm, cells.op, QpSettings{}, 0.0, report, cells.res);
    EXPECT_NEAR(q_norm, cond, 1e-6 * cond) << cond;
    EXPECT_NEAR(cells.res.stability_condition, cond, 1e-3 * cond) << cond;
    EXPECT_TRUE(factor) << cond;  // auto QP, Newton systems auto, no memory asked for
    ASSERT_EQ(lines.size(), 1u);
    EXPECT_NE(lines[0].find("stability (5.1): cond(Q)"), std::string::npos) << lines[0];
    const bool warned =
        !cells.res.warnings.empty() && cells.res.warnings[0].find("ill-conditioned") != std::string::npos;
    EXPECT_EQ(warned, cond > 1e10) << cond;
  }
}

TEST(StabilityCheck, DependentRowsAreRefusedNamingTheirCell) {
  const int m = 6;
  Eigen::MatrixXd B = Eigen::MatrixXd::Identity(m, m);
  B.row(4) = B.row(2);  // cells 2 and 4 press the same nodes alike
  const GivenQ dual(B * B.transpose());
  Cells cells(m);
  Progress report;
  double q_norm = 0;
  try {
    check_dual_stability(dual, q_norm, cells.op, QpSettings{}, 0.0, report, cells.res);
    FAIL() << "a Q with dependent rows passed";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("violates the stability condition (5.1): 1 rows"), std::string::npos) << what;
    EXPECT_NE(what.find("cell 4 [4, 5] x [0, 1]"), std::string::npos) << what;
  }
}
