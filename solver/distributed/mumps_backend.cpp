// The PETSc + MUMPS implementation of backend.hpp (compiled only with CONTACT3D_PETSC=ON).
//
// Protocol: rank 0 broadcasts a Command; every rank then runs the same collective code. The data a
// command needs is prepared on rank 0 before the command is sent, so an exception on rank 0 can
// never leave the other ranks inside a half-done collective.
#include <petscmat.h>
#include <sys/resource.h>

#include <chrono>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <thread>

#include "base/errors.hpp"
#include "distributed/backend.hpp"

namespace contact3d::distributed {
namespace {

enum Command : int { kStop = 0, kFactor = 1, kSolve = 2, kRelease = 3, kMemory = 4 };

// Commands travel by a nonblocking broadcast on every rank (collectives must match). Rank 0
// waits for it at once; a serving rank polls it with short sleeps, so that while rank 0 runs the
// QP or writes files the idle ranks do not spin on a core (Open MPI's blocking wait busy-polls).
void broadcast(Command c) {
  int code = c;
  MPI_Request request;
  MPI_Ibcast(&code, 1, MPI_INT, 0, PETSC_COMM_WORLD, &request);
  MPI_Wait(&request, MPI_STATUS_IGNORE);
}

int receive_command() {
  int code = kStop, done = 0;
  MPI_Request request;
  MPI_Ibcast(&code, 1, MPI_INT, 0, PETSC_COMM_WORLD, &request);
  for (MPI_Test(&request, &done, MPI_STATUS_IGNORE); !done; MPI_Test(&request, &done, MPI_STATUS_IGNORE))
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  return code;
}

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

// The upper triangle of [K 𝔹ᵀ; 𝔹 0] in CSR (global indices), built on rank 0. The multipliers'
// diagonal is stored as an explicit zero (MUMPS's symmetric indefinite path expects the diagonal).
struct UpperCsr {
  std::int64_t n = 0, m = 0;
  std::vector<PetscInt> row_start{0}, cols;
  std::vector<PetscScalar> vals;
};

UpperCsr augmented_upper(const Eigen::SparseMatrix<double>& K, const Eigen::SparseMatrix<double>& B) {
  UpperCsr a;
  a.n = K.rows();
  a.m = B.rows();
  const Eigen::SparseMatrix<double, Eigen::RowMajor> Kr = K;
  const Eigen::SparseMatrix<double> Bc = B;  // column j of 𝔹 = the multipliers coupled to dof j
  for (Eigen::Index i = 0; i < a.n; ++i) {
    for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(Kr, i); it; ++it)
      if (it.col() >= i) {
        a.cols.push_back(static_cast<PetscInt>(it.col()));
        a.vals.push_back(it.value());
      }
    for (Eigen::SparseMatrix<double>::InnerIterator it(Bc, i); it; ++it) {
      a.cols.push_back(static_cast<PetscInt>(a.n + it.row()));
      a.vals.push_back(it.value());
    }
    a.row_start.push_back(static_cast<PetscInt>(a.cols.size()));
  }
  for (Eigen::Index r = 0; r < a.m; ++r) {
    a.cols.push_back(static_cast<PetscInt>(a.n + r));
    a.vals.push_back(0.0);
    a.row_start.push_back(static_cast<PetscInt>(a.cols.size()));
  }
  return a;
}

// One factorization, on every rank between kFactor and kRelease.
struct Factorization {
  Mat A = nullptr, F = nullptr;
  Vec b = nullptr, x = nullptr, x_root = nullptr;  // x_root: the whole vector on rank 0 (empty elsewhere)
  VecScatter to_root = nullptr;
  IS schur = nullptr;
  PetscInt n = 0, m = 0;
  double factor_entries = 0, flops = 0;
  Eigen::MatrixXd Q;  // rank 0: −(Schur complement)

  ~Factorization() {
    VecScatterDestroy(&to_root);
    VecDestroy(&x_root);
    VecDestroy(&x);
    VecDestroy(&b);
    MatDestroy(&F);
    MatDestroy(&A);
    ISDestroy(&schur);
  }
};

// kFactor, collective. On rank 0 `csr` holds the whole matrix; elsewhere it is empty.
std::unique_ptr<Factorization> factor(const UpperCsr& csr) {
  const int rank = comm_rank(), size = comm_size();
  auto fz = std::make_unique<Factorization>();
  std::int64_t dims[2] = {csr.n, csr.m};
  MPI_Bcast(dims, 2, MPI_INT64_T, 0, PETSC_COMM_WORLD);
  fz->n = static_cast<PetscInt>(dims[0]);
  fz->m = static_cast<PetscInt>(dims[1]);
  PetscInt N = fz->n + fz->m, local = PETSC_DECIDE;
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
      nnz_offset[r] = static_cast<int>(csr.row_start[first[r]]);
      nnz_count[r] = static_cast<int>(csr.row_start[first[r + 1]] - csr.row_start[first[r]]);
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
  std::vector<PetscInt> my_start(local + 1, 0);
  for (PetscInt i = 0; i < local; ++i) my_start[i + 1] = my_start[i] + my_len[i];
  check(MatCreateMPISBAIJWithArrays(PETSC_COMM_WORLD, 1, local, local, N, N, my_start.data(), my_cols.data(),
                                    my_vals.data(), &fz->A),
        "MatCreateMPISBAIJWithArrays");
  check(MatGetFactor(fz->A, MATSOLVERMUMPS, MAT_FACTOR_CHOLESKY, &fz->F), "MatGetFactor (MUMPS Cholesky)");
  // The multipliers are the Schur set; MUMPS centralizes the Schur complement on rank 0, so the
  // other ranks pass an empty set.
  check(ISCreateStride(PETSC_COMM_SELF, rank == 0 ? fz->m : 0, fz->n, 1, &fz->schur), "ISCreateStride");
  check(MatFactorSetSchurIS(fz->F, fz->schur), "MatFactorSetSchurIS");
  MatFactorInfo info;
  check(MatFactorInfoInitialize(&info), "MatFactorInfoInitialize");
  check(MatCholeskyFactorSymbolic(fz->F, fz->A, nullptr, &info), "the MUMPS analysis");
  check(MatCholeskyFactorNumeric(fz->F, fz->A, &info), "the MUMPS factorization");
  Mat S = nullptr;
  check(MatFactorCreateSchurComplement(fz->F, &S, nullptr), "MatFactorCreateSchurComplement");
  if (rank == 0) {
    const PetscScalar* s = nullptr;
    check(MatDenseGetArrayRead(S, &s), "MatDenseGetArrayRead");
    fz->Q = -Eigen::Map<const Eigen::MatrixXd>(s, fz->m, fz->m);  // S = −𝔹K⁻¹𝔹ᵀ (column-major, full)
    check(MatDenseRestoreArrayRead(S, &s), "MatDenseRestoreArrayRead");
  }
  MatDestroy(&S);
  check(MatMumpsSetIcntl(fz->F, 26, 0), "MatMumpsSetIcntl(26)");  // solves: the interior problem K⁻¹
  PetscInt entries = 0;
  check(MatMumpsGetInfog(fz->F, 29, &entries), "MatMumpsGetInfog(29)");
  fz->factor_entries = entries >= 0 ? double(entries) : -1e6 * double(entries);
  PetscReal flops = 0;
  check(MatMumpsGetRinfog(fz->F, 3, &flops), "MatMumpsGetRinfog(3)");
  fz->flops = flops;
  check(MatCreateVecs(fz->A, &fz->x, &fz->b), "MatCreateVecs");
  check(VecScatterCreateToZero(fz->x, &fz->to_root, &fz->x_root), "VecScatterCreateToZero");
  return fz;
}

// kSolve, collective: x = K⁻¹ rhs on the primal rows (rank 0 gives rhs over all N rows).
void solve(Factorization& fz, const Eigen::VectorXd* rhs, Eigen::VectorXd* out) {
  if (rhs) {
    PetscScalar* a = nullptr;
    VecGetArray(fz.x_root, &a);
    for (Eigen::Index i = 0; i < rhs->size(); ++i) a[i] = (*rhs)[i];
    VecRestoreArray(fz.x_root, &a);
  }
  check(VecScatterBegin(fz.to_root, fz.x_root, fz.b, INSERT_VALUES, SCATTER_REVERSE), "VecScatterBegin");
  check(VecScatterEnd(fz.to_root, fz.x_root, fz.b, INSERT_VALUES, SCATTER_REVERSE), "VecScatterEnd");
  check(MatSolve(fz.F, fz.b, fz.x), "MatSolve (MUMPS)");
  check(VecScatterBegin(fz.to_root, fz.x, fz.x_root, INSERT_VALUES, SCATTER_FORWARD), "VecScatterBegin");
  check(VecScatterEnd(fz.to_root, fz.x, fz.x_root, INSERT_VALUES, SCATTER_FORWARD), "VecScatterEnd");
  if (out) {
    const PetscScalar* a = nullptr;
    VecGetArrayRead(fz.x_root, &a);
    *out = Eigen::Map<const Eigen::VectorXd>(a, fz.n);
    VecRestoreArrayRead(fz.x_root, &a);
  }
}

double peak_rss_mib() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_maxrss) / 1024.0;
}

std::vector<double> gather_memory() {
  double mine = peak_rss_mib();
  std::vector<double> all(comm_size());
  MPI_Gather(&mine, 1, MPI_DOUBLE, all.data(), 1, MPI_DOUBLE, 0, PETSC_COMM_WORLD);
  return all;
}

// Rank 0's side of the dual problem: every method sends the command, then runs the collective.
class MumpsDualProblem final : public DualProblem {
 public:
  MumpsDualProblem(const DualProblemInput& in, StageClock& clock) : B_(in.B), f_(in.f), face_dofs_(in.face_dofs) {
    method = "mumps";
    backend = "petsc-mumps";
    const UpperCsr csr = augmented_upper(in.K, in.B);
    broadcast(kFactor);
    fz_ = factor(csr);
    factor_nonzeros = fz_->factor_entries;
    clock.lap("factorization");
    Q_ = std::move(fz_->Q);
    Eigen::VectorXd u0;
    full_solve(f_, u0);  // K⁻¹f
    h_ = B_ * u0;
    if (in.offset.size() == h_.size()) h_ += in.offset;
    clock.lap("dual");
  }
  ~MumpsDualProblem() override { release_factor(); }

  Eigen::VectorXd face_displacement(const Eigen::VectorXd& lambda) const override {
    return gather(displacement(lambda), face_dofs_);
  }

  Eigen::VectorXd displacement(const Eigen::VectorXd& lambda) const override {
    if (!fz_) throw std::logic_error("DualProblem: the factor was released");
    Eigen::VectorXd w;
    full_solve(lambda.size() == 0 ? f_ : Eigen::VectorXd(f_ - B_.transpose() * lambda), w);
    return w;
  }

  void release_factor() override {
    if (!fz_) return;
    broadcast(kRelease);
    fz_.reset();
  }

 private:
  void full_solve(const Eigen::VectorXd& rhs_primal, Eigen::VectorXd& out) const {
    Eigen::VectorXd rhs = Eigen::VectorXd::Zero(fz_->n + fz_->m);
    rhs.head(fz_->n) = rhs_primal;
    broadcast(kSolve);
    solve(*fz_, &rhs, &out);
  }

  const Eigen::SparseMatrix<double>& B_;
  Eigen::VectorXd f_;
  std::vector<int> face_dofs_;
  std::unique_ptr<Factorization> fz_;
};

}  // namespace

bool available() { return true; }

Session::Session(int& argc, char**& argv) {
  if (PetscInitialize(&argc, &argv, nullptr, nullptr) != 0) throw std::runtime_error("PetscInitialize failed");
  started_ = true;
  rank_ = comm_rank();
  size_ = comm_size();
}

Session::~Session() {
  if (!started_) return;
  if (rank_ == 0) broadcast(kStop);
  PetscFinalize();
}

void Session::serve() {
  std::unique_ptr<Factorization> fz;
  for (;;) {
    const int code = receive_command();
    try {
      switch (code) {
        case kFactor:
          fz = factor(UpperCsr());
          break;
        case kSolve:
          if (fz) solve(*fz, nullptr, nullptr);
          break;
        case kRelease:
          fz.reset();
          break;
        case kMemory:
          gather_memory();
          break;
        default:
          return;  // kStop
      }
    } catch (const std::exception&) {
      // Rank 0 sees the same failure in the same collective and reports it; keep serving.
    }
  }
}

std::unique_ptr<DualProblem> make_mumps_dual_problem(const DualProblemInput& input, StageClock& clock) {
  return std::make_unique<MumpsDualProblem>(input, clock);
}

int ranks() { return comm_size(); }

std::vector<double> peak_memory_per_rank_mib() {
  broadcast(kMemory);
  return gather_memory();
}

}  // namespace contact3d::distributed
