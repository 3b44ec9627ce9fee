// DualProblem: the dualisation of (5.4) as one object. It owns the factorization of K (or of the
// augmented matrix [K 𝔹ᵀ; 𝔹 σI]) and gives the data of the dual QP (5.5)-(5.6) — the dense
// Q = 𝔹K⁻¹𝔹ᵀ and h = 𝔹K⁻¹f + b — and its recovery: the displacement w = K⁻¹(f − 𝔹ᵀλ), on the
// contact face for one fixed-point step, everywhere at the end. This is the seam where a linear-
// algebra backend plugs in (CHOLMOD here; PETSc/MUMPS behind the same interface).
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "base/stage_clock.hpp"
#include "linalg/dense_view.hpp"
#include "linalg/sparse_cholesky.hpp"
#include "linalg/symmetric_product.hpp"

namespace contact3d {

struct Mesh;
struct DofMap;
class TetMaterials;

// K as what assembles it (fem/assembly.hpp), for a backend that assembles K on its ranks instead of
// receiving it from one process (the distributed backend's direct MUMPS route).
struct StiffnessSource {
  const Mesh& mesh;
  const DofMap& dofs;
  const TetMaterials& materials;
  // (dof, value) added to K's diagonal: the springs of a body held by contact alone
  // (model/held_by_contact.hpp); empty otherwise.
  std::vector<std::pair<int, double>> springs = {};
};

// How Q is formed with CHOLMOD (the dual problem's "method"):
//   Augmented   — factor [K 𝔹ᵀ; 𝔹 σI] with the multipliers last: Q = L₂₁L₂₁ᵀ (about 1.1
//                 factorizations), and each step's face displacement by a restricted back
//                 substitution (DisplacementTrace). What Auto takes at every size measured.
//   ContactLast — factor K with the contact dofs last; Q from the dense trailing block (trsm/syrk).
//   BlockSolve  — one K⁻¹ solve per row of 𝔹 (the reference the tests compare against).
//   Mumps       — the distributed backend (distributed/backend.hpp): MUMPS's Schur complement
//                 of [K 𝔹ᵀ; 𝔹 0] on the multipliers, under MPI, MUMPS called directly with our
//                 nested dissection as its pivot order. Auto takes it in the MPI build.
//   MumpsPetsc  — the same through PETSc's MUMPS interface, which orders by MUMPS's own AMD.
//   MatrixFree  — Q never formed: the factor of K alone; forward solves give the rows W = L⁻¹P𝔹ᵀ,
//                 kept in supernodal blocks where they are small (forward_solve_by_supernodes), each
//                 product then Wᵀ(Wv), else only Q's diagonal (forward_solved_diagonal) and each
//                 product 𝔹K⁻¹(𝔹ᵀv) by one solve. For contact faces whose
//                 dense Q does not fit in memory (Auto takes it there in the serial build); the QP's
//                 Newton steps go by CG there (qp/reduced_cg.hpp).
enum class DualMethod { Auto, Augmented, ContactLast, BlockSolve, Mumps, MumpsPetsc, MatrixFree };

// What a backend needs: K and f over the free dofs, 𝔹 (multipliers × free dofs), the free dofs
// at which face_displacement() reports w (the contact face, in the caller's order), and the
// offset b of the constraint rows 𝔹w + b (empty: zero), which h takes on.
struct DualProblemInput {
  const Eigen::SparseMatrix<double>& K;
  const Eigen::SparseMatrix<double>& B;
  const Eigen::VectorXd& f;
  std::vector<int> face_dofs;
  Eigen::VectorXd offset = Eigen::VectorXd();
  AnalysisObserver on_analysis = {};  // the factor's predicted size, before the numeric factorization
  // Called by a backend that has made its own copy of K (the distributed one, before it factors):
  // the caller may then free K, which the backend will not read again. Empty: nobody to tell.
  std::function<void()> release_K = {};
  // Set, with K left empty, for the direct MUMPS route: it assembles K on its ranks from this, so
  // that no process ever holds the whole of K.
  const StiffnessSource* stiffness_source = nullptr;
  // K's near-null space (n × 6, fem's rigid_body_modes) for a backend whose matrix object carries
  // one (the PETSc route attaches it for multigrid); empty: not asked for.
  Eigen::MatrixXd near_null_space = Eigen::MatrixXd();
  // A line for the run's progress report (the distributed backend's factor size and memory after
  // MUMPS's analysis, where on_analysis's one-process memory check would not apply). Empty: none.
  std::function<void(const std::string&)> report = {};
};

// The entries of w at `dofs`, in that order (a face displacement from a whole one).
inline Eigen::VectorXd gather(const Eigen::VectorXd& w, const std::vector<int>& dofs) {
  Eigen::VectorXd out(static_cast<Eigen::Index>(dofs.size()));
  for (std::size_t k = 0; k < dofs.size(); ++k) out[static_cast<Eigen::Index>(k)] = w[dofs[k]];
  return out;
}

class DualProblem {
 public:
  virtual ~DualProblem() = default;

  // Q, dense and symmetric (both triangles filled), wherever it is held (in the augmented factor, or
  // a matrix of its own); empty when matrix-free.
  DenseView Q() const { return Q_in_factor_ ? *Q_in_factor_ : DenseView(Q_); }
  const Eigen::VectorXd& h() const { return h_; }
  int size() const { return static_cast<int>(h_.size()); }
  // Whether Q() holds Q (every method but MatrixFree); apply_Q and Q_diagonal work either way.
  bool forms_Q() const { return Q().rows() == h_.size(); }
  // Q v (a K⁻¹ solve when matrix-free).
  virtual Eigen::VectorXd apply_Q(const Eigen::VectorXd& v) const { return symmetric_product(Q(), v); }
  virtual Eigen::VectorXd Q_diagonal() const { return Q().diagonal(); }
  // Q V for several columns: column by column here; matrix-free, by blocked solves (BLAS-3 through the
  // factor: a sixth to an eighth of a single product's time per column on the thin slab) or through W.
  // `blocks_pay`: whether a column of a block costs far less than apply_Q (the blocked solves).
  virtual bool blocks_pay() const { return false; }
  virtual Eigen::MatrixXd apply_Q_block(const Eigen::MatrixXd& V) const {
    Eigen::MatrixXd out(V.rows(), V.cols());
    for (Eigen::Index j = 0; j < V.cols(); ++j) out.col(j) = apply_Q(V.col(j));
    return out;
  }

  // Q v in single precision where the backend has made such products (prepare_single_products),
  // else apply_Q. Matrix-free through a float copy of K's factor: half the bytes of a solve, a
  // relative error of order 1e-7 · cond(K) at worst (single_precision_factor.hpp).
  virtual Eigen::VectorXd apply_Q_single(const Eigen::VectorXd& v) const { return apply_Q(v); }
  // Q V in single precision likewise (blocked float solves), else apply_Q_block.
  virtual Eigen::MatrixXd apply_Q_block_single(const Eigen::MatrixXd& V) const { return apply_Q_block(V); }
  // Makes apply_Q_single's products where they pay (matrix-free products by solves through the
  // factor) and their copy takes at most `memory_bytes`; returns whether it did.
  virtual bool prepare_single_products(double /*memory_bytes*/) { return false; }

  // w = K⁻¹(f − 𝔹ᵀλ) at the face dofs, in the order of DualProblemInput::face_dofs.
  virtual Eigen::VectorXd face_displacement(const Eigen::VectorXd& lambda) const = 0;
  // w = K⁻¹(f − 𝔹ᵀλ) at every free dof.
  virtual Eigen::VectorXd displacement(const Eigen::VectorXd& lambda) const = 0;
  // The factor of K this problem holds, to be shared with a dual problem for another 𝔹
  // (make_dual_problem_on_factor): the augmented CHOLMOD factor; null for every other route.
  virtual std::shared_ptr<const SparseCholesky> factor_to_share() const { return nullptr; }
  // Frees the factorization (benchmarks time a reference factorization afterwards), and with it Q
  // where it lies in the factor (Q() is then empty): only after the dual solve's last use of Q. h stays.
  virtual void release_factor() = 0;

  std::string method;               // "augmented", "contactlast", "blocksolve", "mumps", ...
  std::string backend = "cholmod";  // the library behind it: "cholmod", "mumps" (called directly) or "petsc-mumps"
  double factor_nonzeros = 0;       // nnz(L) of the factorization held
  double step_solve_fraction = 1;   // share of the factor one face_displacement() reads (1: a full solve)
  int near_null_space = 0;          // vectors attached to the backend's matrix as its near-null space

 protected:
  Eigen::MatrixXd Q_;
  DenseViewPtr Q_in_factor_;  // Q in the factor that holds it (Q_ then empty), or null
  Eigen::VectorXd h_;
};

// The CHOLMOD backend (every method but Mumps, MumpsPetsc). Laps `clock` at "factorization" and at
// "dual" (forming Q and h; matrix-free: h and Q's diagonal).
std::unique_ptr<DualProblem> make_cholmod_dual_problem(DualMethod method, const DualProblemInput& input,
                                                       StageClock& clock);

// The dual problem for another 𝔹 on a factor of K already made (factor_to_share(): the same K, e.g.
// contact.cell_size = "auto" solving again with smaller cells), without factoring again:
// W = L₁₁⁻¹P𝔹ᵀ by sparse forward solves, Q = WᵀW by supernodes, each step's face displacement by
// DisplacementTrace through W. Laps `clock` at "factorization" (nothing done) and "dual".
std::unique_ptr<DualProblem> make_dual_problem_on_factor(std::shared_ptr<const SparseCholesky> factor,
                                                         const DualProblemInput& input, StageClock& clock);

// The entries of an augmented factor by part: K's (L₁₁, its supernodes' columns × rows) and the
// multipliers' rows beside them (L₂₁) — what forward solves of another 𝔹 of as many rows would store.
// `coupling` is 0 for a factor of K alone.
struct AugmentedFactorParts {
  double leading = 0, coupling = 0;
};
AugmentedFactorParts augmented_factor_parts(const SparseCholesky& factor);

}  // namespace contact3d
