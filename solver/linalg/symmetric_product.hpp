// Products with a dense symmetric matrix of which only the lower triangle is read (the dual
// operator Q and its copies): BLAS dsymv / ssymv, on the BLAS threads. Reading one triangle halves
// the memory traffic that bounds a product once Q outgrows the caches; single precision halves it
// again (ssymv 1.8-2.7x faster than dsymv at 4800-14000 rows on the 2-core machine).
#pragma once

#include <Eigen/Core>

#include "linalg/dense_view.hpp"

namespace contact3d {

// Q v.
Eigen::VectorXd symmetric_product(const DenseView& Q, const Eigen::VectorXd& v);

// scale · Q_single · v, computed in single precision with v scaled to unit max-norm (no under- or
// overflow for any v); rounding error about 1e-7 ‖Q‖‖v‖.
Eigen::VectorXd symmetric_product(const Eigen::MatrixXf& Q_single, double scale, const Eigen::VectorXd& v);

// The lower triangle of Q / scale in single precision (the upper one is left unset: never read); with
// `diagonal` (size of Q), of S Q S / scale, S = diag(diagonal).
Eigen::MatrixXf lower_triangle_in_single(const DenseView& Q, double scale,
                                         const Eigen::VectorXd& diagonal = Eigen::VectorXd());

}  // namespace contact3d
