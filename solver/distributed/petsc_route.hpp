// The PETSc route of the distributed backend (solver.schur = "mumps_petsc"): [K 𝔹ᵀ; 𝔹 0] as an
// MPISBAIJ matrix carrying K's rigid-body modes as its near-null space, factored by MUMPS through
// PETSc's interface (MatFactorSetSchurIS). It is a module of its own, libcontact3d_petsc.so next to
// contact3d-mpi, loaded on every rank only when a scene asks for this route: linking PETSc into the
// executable made every rank map its hundred-odd libraries (hypre, SuperLU_DIST, HDF5, …) at start,
// 20 MiB of resident memory per process that the default route (MUMPS called directly) never uses.
//
// The module starts PETSc on the MPI that contact3d-mpi started (PetscInitialize after MPI_Init) and
// ends it when its PetscRoute is destroyed, before MPI_Finalize. Every method is collective: rank 0
// passes the data, the other ranks empty arguments, as in mumps_backend.cpp's protocol.
#pragma once

#include <Eigen/Dense>
#include <cstdint>
#include <memory>
#include <vector>

namespace contact3d::distributed {

// The upper triangle of [K 𝔹ᵀ; 𝔹 0] by rows, 0-based global indices, on rank 0 (empty elsewhere). The
// multipliers' diagonal is stored as an explicit zero (MUMPS's symmetric path expects the diagonal).
struct UpperCsr {
  std::int64_t n = 0, m = 0;
  std::vector<int> row_start{0}, cols;
  std::vector<double> vals;
};

// A near-null space attached to the route's matrix: how many vectors it holds, and ‖K·v‖_F over
// them as the ranks' rows of K give it (rank 0 checks it against its own K).
struct AttachedSpace {
  int vectors = 0;
  double residual = 0;
};

// What a factorization reports; Q (= −the Schur complement on the multipliers) on rank 0 only.
struct FactorSummary {
  std::int64_t n = 0, m = 0;
  double factor_entries = 0, flops = 0;
  AttachedSpace near_null_space;
  Eigen::MatrixXd Q;
};

// One factorization held by PETSc on every rank, until destroyed (collectively).
class PetscFactor {
 public:
  virtual ~PetscFactor() = default;
  // x = K⁻¹ rhs on the primal rows: rank 0 gives rhs over all n + m rows and gets the n primal
  // entries in `out`; the other ranks pass null pointers.
  virtual void solve(const Eigen::VectorXd* rhs, Eigen::VectorXd* out) = 0;
};

class PetscRoute {
 public:
  virtual ~PetscRoute() = default;  // ends PETSc
  // Factors `csr` (rank 0's, moved: freed once sent) with `modes` (rank 0: K's near-null space, may
  // be null or empty) attached; fills `summary`.
  virtual std::unique_ptr<PetscFactor> factor(UpperCsr csr, const Eigen::MatrixXd* modes, FactorSummary& summary) = 0;
};

}  // namespace contact3d::distributed

// The module's one entry point (C linkage, found by dlsym): starts PETSc and returns the route.
extern "C" contact3d::distributed::PetscRoute* contact3d_start_petsc_route();
