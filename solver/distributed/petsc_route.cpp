// The PETSc route (petsc_route.hpp), built as the module libcontact3d_petsc.so: PETSc's Mat/MatFactor
// objects around MUMPS, on the MPI_COMM_WORLD that contact3d-mpi started.
#include "distributed/petsc_route.hpp"

#include <petscmat.h>

#include <cmath>
#include <stdexcept>
#include <string>
#include <type_traits>

#include "distributed/mumps_errors.hpp"

namespace contact3d::distributed {
namespace {

static_assert(std::is_same_v<PetscInt, int> && std::is_same_v<PetscScalar, double>,
              "UpperCsr's int indices and double values are PETSc's (Debian's 32-bit real PETSc)");

void check(PetscErrorCode ierr, const char* what) {
  if (ierr != 0)
    throw std::runtime_error(std::string("PETSc/MUMPS failed in ") + what + " (error " + std::to_string(ierr) + ")");
}

int comm_rank() {
  int r = 0;
  MPI_Comm_rank(PETSC_COMM_WORLD, &r);
  return r;
}
int comm_size() {
  int s = 1;
  MPI_Comm_size(PETSC_COMM_WORLD, &s);
  return s;
}

// PETSc's MUMPS interface records a failed analysis or factorization in the factor and returns
// success (with -mat_mumps_icntl_4 1 and INFOG(1) = -13 the run went on to form Q from it and was refused
// for (5.1)): the factor's error state is checked after each, and MUMPS's INFOG(1) reported as the
// direct route reports it. INFOG(1) is global, so every rank throws alike.
void require_factored(Mat F, const char* what) {
  MatFactorError state = MAT_FACTOR_NOERROR;
  check(MatFactorGetError(F, &state), "MatFactorGetError");
  if (state == MAT_FACTOR_NOERROR) return;
  PetscInt infog1 = 0, infog2 = 0;
  check(MatMumpsGetInfog(F, 1, &infog1), "MatMumpsGetInfog(1)");
  check(MatMumpsGetInfog(F, 2, &infog2), "MatMumpsGetInfog(2)");
  throw_if_mumps_failed(infog1, infog2, what);
  throw std::runtime_error(std::string("PETSc/MUMPS failed in ") + what + " (PETSc's factor error " +
                           std::to_string(static_cast<int>(state)) + ", INFOG(1) = " + std::to_string(infog1) + ")");
}

// Rank 0's modes (rows = K's dofs; absent or empty: none) as A's near-null space: each rank gets the
// rows it owns ([first[r], first[r + 1]), zero on the multipliers' rows). Returns the number of
// vectors A then carries, read back from A, and ‖K·modes‖_F as A's rows of K give it (rank 0
// checks it against its own K: the layout test of the scatter). Collective.
AttachedSpace attach_near_null_space(Mat A, const Eigen::MatrixXd* modes, PetscInt n, const std::vector<int>& first,
                                     const std::vector<int>& locals) {
  const int rank = comm_rank(), size = comm_size();
  int k = modes ? static_cast<int>(modes->cols()) : 0;
  MPI_Bcast(&k, 1, MPI_INT, 0, PETSC_COMM_WORLD);
  if (k == 0) return {};
  std::vector<PetscScalar> packed;  // rank 0: every row, k values each, zero past K's dofs
  std::vector<int> counts(size), offsets(size);
  for (int r = 0; r < size; ++r) {
    counts[r] = k * locals[r];
    offsets[r] = k * first[r];
  }
  if (rank == 0) {
    packed.assign(static_cast<std::size_t>(k) * first[size], 0.0);
    for (PetscInt i = 0; i < n; ++i)
      for (int c = 0; c < k; ++c) packed[static_cast<std::size_t>(k) * i + c] = (*modes)(i, c);
  }
  std::vector<PetscScalar> mine(static_cast<std::size_t>(counts[rank]));
  MPI_Scatterv(packed.data(), counts.data(), offsets.data(), MPIU_SCALAR, mine.data(), counts[rank], MPIU_SCALAR, 0,
               PETSC_COMM_WORLD);
  std::vector<Vec> vectors(static_cast<std::size_t>(k), nullptr);
  for (int c = 0; c < k; ++c) {
    check(MatCreateVecs(A, &vectors[c], nullptr), "MatCreateVecs");
    PetscScalar* a = nullptr;
    check(VecGetArray(vectors[c], &a), "VecGetArray");
    for (int i = 0; i < locals[rank]; ++i) a[i] = mine[static_cast<std::size_t>(k) * i + c];
    check(VecRestoreArray(vectors[c], &a), "VecRestoreArray");
  }
  MatNullSpace space = nullptr;
  check(MatNullSpaceCreate(PETSC_COMM_WORLD, PETSC_FALSE, k, vectors.data(), &space), "MatNullSpaceCreate");
  check(MatSetNearNullSpace(A, space), "MatSetNearNullSpace");
  MatNullSpaceDestroy(&space);
  for (Vec& v : vectors) VecDestroy(&v);
  AttachedSpace out;
  MatNullSpace attached = nullptr;
  check(MatGetNearNullSpace(A, &attached), "MatGetNearNullSpace");
  PetscBool has_constant = PETSC_FALSE;
  PetscInt count = 0;
  const Vec* held = nullptr;
  if (attached) check(MatNullSpaceGetVecs(attached, &has_constant, &count, &held), "MatNullSpaceGetVecs");
  out.vectors = static_cast<int>(count);
  double squares = 0;  // this rank's rows of K·v (the rows below n), over the attached vectors
  Vec product = nullptr;
  check(MatCreateVecs(A, nullptr, &product), "MatCreateVecs");
  for (PetscInt c = 0; c < count; ++c) {
    check(MatMult(A, held[c], product), "MatMult");
    const PetscScalar* y = nullptr;
    check(VecGetArrayRead(product, &y), "VecGetArrayRead");
    for (int i = 0; i < locals[rank] && first[rank] + i < n; ++i) squares += y[i] * y[i];
    check(VecRestoreArrayRead(product, &y), "VecRestoreArrayRead");
  }
  VecDestroy(&product);
  MPI_Allreduce(MPI_IN_PLACE, &squares, 1, MPI_DOUBLE, MPI_SUM, PETSC_COMM_WORLD);
  out.residual = std::sqrt(squares);
  return out;
}

// PETSc's objects of one factorization; x_root: the whole vector on rank 0 (empty elsewhere).
class MumpsThroughPetsc final : public PetscFactor {
 public:
  Mat A = nullptr, F = nullptr;
  Vec b = nullptr, x = nullptr, x_root = nullptr;
  VecScatter to_root = nullptr;
  IS schur = nullptr;
  PetscInt n = 0;

  ~MumpsThroughPetsc() override {
    VecScatterDestroy(&to_root);
    VecDestroy(&x_root);
    VecDestroy(&x);
    VecDestroy(&b);
    MatDestroy(&F);
    MatDestroy(&A);
    ISDestroy(&schur);
  }

  void solve(const Eigen::VectorXd* rhs, Eigen::VectorXd* out) override {
    if (rhs) {
      PetscScalar* a = nullptr;
      check(VecGetArray(x_root, &a), "VecGetArray");
      for (Eigen::Index i = 0; i < rhs->size(); ++i) a[i] = (*rhs)[i];
      check(VecRestoreArray(x_root, &a), "VecRestoreArray");
    }
    check(VecScatterBegin(to_root, x_root, b, INSERT_VALUES, SCATTER_REVERSE), "VecScatterBegin");
    check(VecScatterEnd(to_root, x_root, b, INSERT_VALUES, SCATTER_REVERSE), "VecScatterEnd");
    check(MatSolve(F, b, x), "MatSolve (MUMPS)");
    check(VecScatterBegin(to_root, x, x_root, INSERT_VALUES, SCATTER_FORWARD), "VecScatterBegin");
    check(VecScatterEnd(to_root, x, x_root, INSERT_VALUES, SCATTER_FORWARD), "VecScatterEnd");
    if (out) {
      const PetscScalar* a = nullptr;
      check(VecGetArrayRead(x_root, &a), "VecGetArrayRead");
      *out = Eigen::Map<const Eigen::VectorXd>(a, n);
      check(VecRestoreArrayRead(x_root, &a), "VecRestoreArrayRead");
    }
  }
};

class Route final : public PetscRoute {
 public:
  Route() { check(PetscInitializeNoArguments(), "PetscInitialize"); }
  ~Route() override { PetscFinalize(); }  // MPI stays: PETSc did not start it
  Route(const Route&) = delete;
  Route& operator=(const Route&) = delete;

  std::unique_ptr<PetscFactor> factor(UpperCsr csr, const Eigen::MatrixXd* modes, FactorSummary& summary) override {
    const int rank = comm_rank(), size = comm_size();
    auto fz = std::make_unique<MumpsThroughPetsc>();
    std::int64_t dims[2] = {csr.n, csr.m};
    MPI_Bcast(dims, 2, MPI_INT64_T, 0, PETSC_COMM_WORLD);
    summary.n = dims[0];
    summary.m = dims[1];
    fz->n = static_cast<PetscInt>(dims[0]);
    const PetscInt m = static_cast<PetscInt>(dims[1]);
    PetscInt N = fz->n + m, local = PETSC_DECIDE;
    check(PetscSplitOwnership(PETSC_COMM_WORLD, &local, &N), "PetscSplitOwnership");
    // Rank r owns rows [first[r], first[r + 1]): send each its rows.
    std::vector<int> locals(size), first(size + 1, 0);
    int my_local = static_cast<int>(local);
    MPI_Allgather(&my_local, 1, MPI_INT, locals.data(), 1, MPI_INT, PETSC_COMM_WORLD);
    for (int r = 0; r < size; ++r) first[r + 1] = first[r] + locals[r];
    std::vector<int> nnz_count(size, 0), nnz_offset(size, 0), len_offset(size, 0);
    std::vector<PetscInt> row_len;
    if (rank == 0) {
      row_len.resize(N);
      for (PetscInt i = 0; i < N; ++i) row_len[i] = csr.row_start[i + 1] - csr.row_start[i];
      for (int r = 0; r < size; ++r) {
        nnz_offset[r] = csr.row_start[first[r]];
        nnz_count[r] = csr.row_start[first[r + 1]] - csr.row_start[first[r]];
        len_offset[r] = first[r];
      }
    }
    int my_nnz = 0;
    MPI_Scatter(nnz_count.data(), 1, MPI_INT, &my_nnz, 1, MPI_INT, 0, PETSC_COMM_WORLD);
    std::vector<PetscInt> my_len(local), my_cols(my_nnz);
    std::vector<PetscScalar> my_vals(my_nnz);
    MPI_Scatterv(row_len.data(), locals.data(), len_offset.data(), MPIU_INT, my_len.data(), my_local, MPIU_INT, 0,
                 PETSC_COMM_WORLD);
    MPI_Scatterv(csr.cols.data(), nnz_count.data(), nnz_offset.data(), MPIU_INT, my_cols.data(), my_nnz, MPIU_INT, 0,
                 PETSC_COMM_WORLD);
    MPI_Scatterv(csr.vals.data(), nnz_count.data(), nnz_offset.data(), MPIU_SCALAR, my_vals.data(), my_nnz, MPIU_SCALAR,
                 0, PETSC_COMM_WORLD);
    std::vector<int>().swap(csr.cols);  // rank 0: the whole matrix is sent; keep only this rank's rows
    std::vector<double>().swap(csr.vals);
    std::vector<PetscInt> my_start(local + 1, 0);
    for (PetscInt i = 0; i < local; ++i) my_start[i + 1] = my_start[i] + my_len[i];
    check(MatCreateMPISBAIJWithArrays(PETSC_COMM_WORLD, 1, local, local, N, N, my_start.data(), my_cols.data(),
                                      my_vals.data(), &fz->A),
          "MatCreateMPISBAIJWithArrays");
    summary.near_null_space = attach_near_null_space(fz->A, modes, fz->n, first, locals);
    check(MatGetFactor(fz->A, MATSOLVERMUMPS, MAT_FACTOR_CHOLESKY, &fz->F), "MatGetFactor (MUMPS Cholesky)");
    // The multipliers are the Schur set; MUMPS centralizes the Schur complement on rank 0, so the
    // other ranks pass an empty set.
    check(ISCreateStride(PETSC_COMM_SELF, rank == 0 ? m : 0, fz->n, 1, &fz->schur), "ISCreateStride");
    check(MatFactorSetSchurIS(fz->F, fz->schur), "MatFactorSetSchurIS");
    MatFactorInfo info;
    check(MatFactorInfoInitialize(&info), "MatFactorInfoInitialize");
    check(MatCholeskyFactorSymbolic(fz->F, fz->A, nullptr, &info), "the MUMPS analysis");
    require_factored(fz->F, "MUMPS's analysis");
    check(MatCholeskyFactorNumeric(fz->F, fz->A, &info), "the MUMPS factorization");
    require_factored(fz->F, "MUMPS's factorization");
    Mat S = nullptr;
    check(MatFactorCreateSchurComplement(fz->F, &S, nullptr), "MatFactorCreateSchurComplement");
    if (rank == 0) {
      const PetscScalar* s = nullptr;
      check(MatDenseGetArrayRead(S, &s), "MatDenseGetArrayRead");
      summary.Q = -Eigen::Map<const Eigen::MatrixXd>(s, m, m);  // S = −𝔹K⁻¹𝔹ᵀ (column-major, full)
      check(MatDenseRestoreArrayRead(S, &s), "MatDenseRestoreArrayRead");
    }
    MatDestroy(&S);
    check(MatMumpsSetIcntl(fz->F, 26, 0), "MatMumpsSetIcntl(26)");  // solves: the interior problem K⁻¹
    PetscInt entries = 0;
    check(MatMumpsGetInfog(fz->F, 29, &entries), "MatMumpsGetInfog(29)");
    summary.factor_entries = mumps_count(entries);
    PetscReal flops = 0;
    check(MatMumpsGetRinfog(fz->F, 3, &flops), "MatMumpsGetRinfog(3)");
    summary.flops = flops;
    check(MatCreateVecs(fz->A, &fz->x, &fz->b), "MatCreateVecs");
    check(VecScatterCreateToZero(fz->x, &fz->to_root, &fz->x_root), "VecScatterCreateToZero");
    return fz;
  }
};

}  // namespace
}  // namespace contact3d::distributed

extern "C" contact3d::distributed::PetscRoute* contact3d_start_petsc_route() {
  return new contact3d::distributed::Route();
}
