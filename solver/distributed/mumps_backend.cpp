// The MUMPS implementation of backend.hpp (built into contact3d-mpi when PETSc, MPI and MUMPS are
// installed): MUMPS called directly with our pivot order (DirectMumps), or through PETSc's
// interface in the PETSc module (petsc_route.hpp, opened on demand) — see backend.hpp for why both.
//
// Protocol: rank 0 broadcasts a Command; every rank then runs the same collective code. The data a
// command needs is prepared on rank 0 before the command is sent, so an exception on rank 0 can
// never leave the other ranks inside a half-done collective; where a rank's own work can fail in
// the middle (assembling its share of K), every rank agrees on the outcome (on_every_rank) before
// the next collective.
#include <dlfcn.h>
#include <dmumps_c.h>
#include <mpi.h>
#include <sys/resource.h>
#include <sys/statvfs.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <exception>
#include <filesystem>
#include <functional>
#include <new>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "base/errors.hpp"
#include "base/format.hpp"
#include "base/memory.hpp"
#include "distributed/backend.hpp"
#include "distributed/mumps_errors.hpp"
#include "distributed/petsc_route.hpp"
#include "fem/assembly.hpp"
#include "fem/mesh_part.hpp"
#include "linalg/blas_buffers.hpp"
#include "linalg/sparse_cholesky.hpp"

namespace contact3d::distributed {
namespace {

enum Command : int {
  kStop = 0,
  kFactorThroughPetsc = 1,
  kSolve = 2,
  kRelease = 3,
  kMemory = 4,
  kAssembleAndFactor = 5
};

// Commands travel by a nonblocking broadcast on every rank (collectives must match). Rank 0
// waits for it at once; a serving rank polls it with short sleeps, so that while rank 0 runs the
// QP or writes files the idle ranks do not spin on a core (Open MPI's blocking wait busy-polls).
void broadcast(Command c) {
  int code = c;
  MPI_Request request;
  MPI_Ibcast(&code, 1, MPI_INT, 0, MPI_COMM_WORLD, &request);
  MPI_Wait(&request, MPI_STATUS_IGNORE);
}

int receive_command() {
  int code = kStop, done = 0;
  MPI_Request request;
  MPI_Ibcast(&code, 1, MPI_INT, 0, MPI_COMM_WORLD, &request);
  for (MPI_Test(&request, &done, MPI_STATUS_IGNORE); !done; MPI_Test(&request, &done, MPI_STATUS_IGNORE))
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  return code;
}

int comm_rank() {
  int r = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &r);
  return r;
}
int comm_size() {
  int s = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &s);
  return s;
}

// This rank's machine: the ranks that share its memory (MPI_COMM_TYPE_SHARED), how many they are and
// the lowest world rank among them, which names the machine.
struct Machine {
  int ranks = 1;
  std::uint64_t id = 0;
};
Machine this_machine() {
  Machine machine{comm_size(), 0};
  MPI_Comm shared = MPI_COMM_NULL;
  if (MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, 0, MPI_INFO_NULL, &shared) != MPI_SUCCESS)
    return machine;
  MPI_Comm_size(shared, &machine.ranks);
  int mine = comm_rank(), first = mine;
  MPI_Allreduce(&mine, &first, 1, MPI_INT, MPI_MIN, shared);
  MPI_Comm_free(&shared);
  machine.id = static_cast<std::uint64_t>(first);
  return machine;
}

// The PETSc route's matrix (petsc_route.hpp), built on rank 0 from its K and 𝔹.
UpperCsr augmented_upper(const Eigen::SparseMatrix<double>& K, const Eigen::SparseMatrix<double>& B) {
  UpperCsr a;
  a.n = K.rows();
  a.m = B.rows();
  const Eigen::SparseMatrix<double, Eigen::RowMajor> Kr = K;
  const Eigen::SparseMatrix<double> Bc = B;  // column j of 𝔹 = the multipliers coupled to dof j
  for (Eigen::Index i = 0; i < a.n; ++i) {
    for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(Kr, i); it; ++it)
      if (it.col() >= i) {
        a.cols.push_back(static_cast<int>(it.col()));
        a.vals.push_back(it.value());
      }
    for (Eigen::SparseMatrix<double>::InnerIterator it(Bc, i); it; ++it) {
      a.cols.push_back(static_cast<int>(a.n + it.row()));
      a.vals.push_back(it.value());
    }
    a.row_start.push_back(static_cast<int>(a.cols.size()));
  }
  for (Eigen::Index r = 0; r < a.m; ++r) {
    a.cols.push_back(static_cast<int>(a.n + r));
    a.vals.push_back(0.0);
    a.row_start.push_back(static_cast<int>(a.cols.size()));
  }
  return a;
}

// MUMPS called directly, for what PETSc's interface cannot pass to a Cholesky/Schur factorization:
// our nested dissection as the pivot order (ICNTL(7) = 1, PERM_IN on rank 0, the multipliers last).
// The matrix goes in as each rank's rows in triplets (ICNTL(18) = 3); the Schur complement on the
// multipliers comes back on rank 0 (ICNTL(19) = 1: the lower triangle by rows); a solve with
// ICNTL(26) = 0 solves the interior problem, K⁻¹ on the primal rows. Every call is collective.
struct DirectMumps {
  DMUMPS_STRUC_C id{};
  std::vector<MUMPS_INT> rows, cols, pivot_position, schur_variables;
  std::vector<double> values;

  DirectMumps() {
    id.comm_fortran = static_cast<MUMPS_INT>(MPI_Comm_c2f(MPI_COMM_WORLD));
    id.par = 1;  // rank 0 works too
    // SYM = 1 (no pivoting): what is factored is K, positive definite once the constraints hold
    // the rigid motions (checked before factorizing); the multipliers' zero block is the Schur set
    // and never pivoted. 13% faster than SYM = 2 on the n = 24 brick, the same answer.
    id.sym = 1;
    run(-1, "initialization");
    id.icntl[0] = id.icntl[1] = id.icntl[2] = -1;  // ICNTL(1-3): no output streams; INFOG tells
    id.icntl[3] = 0;
  }
  ~DirectMumps() {
    id.job = -2;
    dmumps_c(&id);
  }
  DirectMumps(const DirectMumps&) = delete;
  DirectMumps& operator=(const DirectMumps&) = delete;

  // INFOG(1) < 0 on every rank alike, so every rank throws in the same place.
  void run(int job, const char* what) {
    id.job = job;
    dmumps_c(&id);
    if (id.infog[0] < 0)
      throw std::runtime_error(std::string("MUMPS failed in ") + what + " (INFOG(1) = " + std::to_string(id.infog[0]) +
                               ", INFOG(2) = " + std::to_string(id.infog[1]) + ")");
  }
};

// The numeric factorization with MUMPS's workspace relaxed by 5% over its analysis estimate
// (ICNTL(14), default 20%): with SYM = 1 and our pivot order nothing is delayed, so the estimate
// holds and the default's reserve is resident memory for nothing (80 MB on rank 0 at n = 32). Should a
// factorization still run short (INFOG(1) = −8 or −9), it is repeated with 25% and then 100%, as
// MUMPS's guide advises. INFOG(1) is global, so every rank takes the same branch.
void factorize_with_growing_workspace(DirectMumps& d, const std::string& out_of_core_dir) {
  for (const int percent : {5, 25, 100}) {
    d.id.icntl[13] = percent;
    d.id.job = 2;
    dmumps_c(&d.id);
    if (d.id.infog[0] != -8 && d.id.infog[0] != -9) break;
  }
  // −70 … −79 and −90: MUMPS could not create, write or read its out-of-core files.
  if (const int code = d.id.infog[0]; (code <= -70 && code >= -79) || code == -90)
    throw InputError("MUMPS could not write its factor to files in solver.out_of_core_dir '" + out_of_core_dir +
                     "' (INFOG(1) = " + std::to_string(code) + "): the directory must exist on every machine, be " +
                     "writable and have room for the factor, about " +
                     number(8.0 * mumps_count(d.id.infog[2]) / (1 << 30), 3) + " GiB over all ranks");
  throw_if_mumps_failed(d.id.infog[0], d.id.infog[1], "MUMPS's factorization");
}

// MUMPS writes its factor into files in the out-of-core directory while it factors; a disk that
// fills on the way left a rank waiting in MUMPS's asynchronous writes for good (4 of 7 runs on a
// 4 MiB tmpfs, the others ending in INFOG(1) = −90). So after the analysis every rank checks that
// its share of the factor (INFO(3), in entries) fits, with a tenth to spare, in the room the
// directory's file system has, summed over the ranks that write to that file system on one machine (ranks on
// other machines writing to one shared network file system are not summed: a limit of this check).
// Every rank gets the same list and throws the same InputError. A file system statvfs cannot read
// is left to MUMPS's own error.
struct FactorFileRoom {
  double need_bytes = 0, free_bytes = -1;      // free −1: unknown
  std::uint64_t machine = 0, file_system = 0;  // this_machine().id, the file system's id
};
void require_room_for_factor_files(const DMUMPS_STRUC_C& id, const std::string& dir, const Machine& machine) {
  FactorFileRoom mine;
  mine.need_bytes = 8.0 * mumps_count(id.info[2]);
  mine.machine = machine.id;
  struct statvfs fs {};
  if (statvfs(dir.c_str(), &fs) == 0) {
    mine.free_bytes = static_cast<double>(fs.f_bavail) * static_cast<double>(fs.f_frsize);
    mine.file_system = static_cast<std::uint64_t>(fs.f_fsid);
  }
  std::vector<FactorFileRoom> all(static_cast<std::size_t>(comm_size()));
  MPI_Allgather(&mine, sizeof mine, MPI_BYTE, all.data(), sizeof mine, MPI_BYTE, MPI_COMM_WORLD);
  for (std::size_t r = 0; r < all.size(); ++r) {
    if (all[r].free_bytes < 0) continue;
    double need = 0;
    for (const FactorFileRoom& other : all)
      if (other.free_bytes >= 0 && other.machine == all[r].machine && other.file_system == all[r].file_system)
        need += other.need_bytes;
    if (1.1 * need <= all[r].free_bytes) continue;
    throw InputError("solver.out_of_core_dir '" + dir + "' has " + number(all[r].free_bytes / (1 << 30), 3) +
                     " GiB free on rank " + std::to_string(r) + "'s machine, and the factor MUMPS would write there " +
                     "takes about " + number(need / (1 << 30), 3) + " GiB (its analysis; a tenth more is asked to " +
                     "spare): point it to a disk with room, or free some");
  }
}

// MUMPS's analysis estimates each rank's memory for the numerical factorization (INFO(15) in core,
// INFO(17) with the factor on disk; MB). A rank that cannot get it failed inside the factorization after
// its minutes of work ("out of memory in the factorization stage", no size given) or met the system's
// OOM killer; refused here instead, on every rank alike, naming the rank, the estimate and what it
// can get — as the serial build refuses a CHOLMOD factor from its analysis. The ranks on one machine
// share its memory: their sum is checked against it too.
struct RankMemory {
  double need_bytes = 0, available_bytes = 0;  // this process's (its address-space limit too); 0: unknown
  double machine_bytes = 0;                    // the machine's (or container's) available memory; 0: unknown
  std::uint64_t machine = 0;                   // this_machine().id
};
std::vector<RankMemory> gather_factorization_memory(const DMUMPS_STRUC_C& id, bool out_of_core,
                                                    const Machine& machine) {
  RankMemory mine;
  mine.need_bytes = 1e6 * mumps_count(out_of_core ? id.info[16] : id.info[14]);
  mine.available_bytes = static_cast<double>(available_memory_bytes());
  mine.machine_bytes = static_cast<double>(machine_available_bytes());
  mine.machine = machine.id;
  std::vector<RankMemory> all(static_cast<std::size_t>(comm_size()));
  MPI_Allgather(&mine, sizeof mine, MPI_BYTE, all.data(), sizeof mine, MPI_BYTE, MPI_COMM_WORLD);
  return all;
}
void require_memory_for_factorization(const std::vector<RankMemory>& ranks, bool out_of_core) {
  const std::string cure = std::string("; run more ranks, on more machines") +
                           (out_of_core ? "" : ", keep the factor on disk (solver.out_of_core_dir)") +
                           ", or use a coarser mesh";
  for (std::size_t r = 0; r < ranks.size(); ++r) {
    const RankMemory& rank = ranks[r];
    if (rank.available_bytes <= 0) continue;
    if (rank.need_bytes > rank.available_bytes)
      throw InputError("not enough memory for the factorization: MUMPS's analysis estimates " +
                       number(rank.need_bytes / (1 << 30), 3) + " GiB on rank " + std::to_string(r) +
                       ", which can get only " + number(rank.available_bytes / (1 << 30), 3) + " GiB" + cure);
    double on_machine = 0;
    int sharing = 0;
    for (const RankMemory& other : ranks)
      if (other.machine == rank.machine) on_machine += other.need_bytes, ++sharing;
    if (sharing > 1 && rank.machine_bytes > 0 && on_machine > rank.machine_bytes)
      throw InputError("not enough memory for the factorization: MUMPS's analysis estimates " +
                       number(on_machine / (1 << 30), 3) + " GiB for the " + std::to_string(sharing) +
                       " ranks on rank " + std::to_string(r) + "'s machine, which has " +
                       number(rank.machine_bytes / (1 << 30), 3) + " GiB available" + cure);
  }
}

// One factorization, on every rank between a factorizing command (kAssembleAndFactor, kFactorThroughPetsc) and
// kRelease: MUMPS called directly, or PETSc's objects in the PETSc module.
struct Factorization : FactorSummary {
  std::unique_ptr<DirectMumps> direct;
  std::unique_ptr<PetscFactor> petsc;
};

// This rank's entries of one triangle of [K 𝔹ᵀ; 𝔹 0] for MUMPS (1-based; each off-diagonal pair once).
struct Triplets {
  std::vector<MUMPS_INT> rows, cols;
  std::vector<double> values;
  void add(std::int64_t row, std::int64_t col, double value) {
    rows.push_back(static_cast<MUMPS_INT>(row + 1));
    cols.push_back(static_cast<MUMPS_INT>(col + 1));
    values.push_back(value);
  }
};

// The direct route: this rank's entries, and on rank 0 the pivot order of K's dofs (`order`).
// The entries move into MUMPS's arrays (no second copy of this rank's share).
void factor_direct(Factorization& fz, const std::vector<int>& order, Triplets share, const std::string& out_of_core_dir,
                   const std::function<void(const std::string&)>* report) {
  const bool root = comm_rank() == 0;
  const std::int64_t N = fz.n + fz.m;
  fz.direct = std::make_unique<DirectMumps>();
  DirectMumps& d = *fz.direct;
  const std::size_t nnz = share.values.size();
  d.rows = std::move(share.rows);
  d.cols = std::move(share.cols);
  d.values = std::move(share.values);
  DMUMPS_STRUC_C& id = d.id;
  id.icntl[17] = 3;  // ICNTL(18): distributed triplets
  id.nnz_loc = static_cast<MUMPS_INT8>(nnz);
  id.irn_loc = d.rows.data();
  id.jcn_loc = d.cols.data();
  id.a_loc = d.values.data();
  id.icntl[6] = 1;   // ICNTL(7): the pivot order PERM_IN
  id.icntl[18] = 1;  // ICNTL(19): the Schur complement, centralized on the host
  id.icntl[25] = 0;  // ICNTL(26): solves on the interior problem
  if (!out_of_core_dir.empty()) {
    id.icntl[21] = 1;  // ICNTL(22): the factor in files in OOC_TMPDIR, read back by every solve
    std::snprintf(id.ooc_tmpdir, sizeof id.ooc_tmpdir, "%s", out_of_core_dir.c_str());
  }
  if (root) {
    id.n = static_cast<MUMPS_INT>(N);
    d.pivot_position.resize(static_cast<std::size_t>(N));
    for (std::size_t k = 0; k < order.size(); ++k)
      d.pivot_position[static_cast<std::size_t>(order[k])] = static_cast<MUMPS_INT>(k + 1);
    d.schur_variables.resize(static_cast<std::size_t>(fz.m));
    for (std::int64_t j = 0; j < fz.m; ++j) {
      d.pivot_position[static_cast<std::size_t>(fz.n + j)] = static_cast<MUMPS_INT>(fz.n + j + 1);
      d.schur_variables[static_cast<std::size_t>(j)] = static_cast<MUMPS_INT>(fz.n + j + 1);
    }
    id.perm_in = d.pivot_position.data();
    id.size_schur = static_cast<MUMPS_INT>(fz.m);
    id.listvar_schur = d.schur_variables.data();
    fz.Q.setZero(fz.m, fz.m);  // MUMPS writes the Schur complement here: Q is made in place
    id.schur = fz.Q.data();
    id.schur_lld = static_cast<MUMPS_INT>(fz.m);
  }
  id.icntl[13] = 5;  // ICNTL(14): the first factorization's workspace relaxation, for the analysis's estimates
  d.run(1, "the MUMPS analysis");
  const Machine machine = this_machine();  // collective: every rank, before anything a rank may skip
  const std::vector<RankMemory> memory = gather_factorization_memory(id, !out_of_core_dir.empty(), machine);
  // Rank 0 alone prints: a failed print (stdout on a full disk) must not leave it out of the
  // collectives below while the other ranks factor (they waited for good).
  if (root && report && *report) {
    try {
      double most = 0;
      for (const RankMemory& r : memory) most = std::max(most, r.need_bytes);
      (*report)("  factor (MUMPS, " + std::to_string(memory.size()) + " rank(s)): about " +
                number(mumps_count(id.infog[2]), 3) + " entries (" +
                number(8.0 * mumps_count(id.infog[2]) / (1 << 30), 3) + " GiB over all ranks" +
                (out_of_core_dir.empty() ? "" : ", written to solver.out_of_core_dir") + "), " +
                number(id.rinfog[0] / 1e9, 3) + " GFlop; at most " + number(most / (1 << 30), 3) +
                " GiB of memory on a rank (its analysis)");
    } catch (...) {
      // stdout is broken (a full disk, a closed pipe): rank 0's next print, outside the collectives, says so
    }
  }
  require_memory_for_factorization(memory, !out_of_core_dir.empty());
  if (!out_of_core_dir.empty()) require_room_for_factor_files(id, out_of_core_dir, machine);
  factorize_with_growing_workspace(d, out_of_core_dir);
  // The solves use only the factor (no iterative refinement, ICNTL(10) = 0): the matrix can go.
  std::vector<MUMPS_INT>().swap(d.rows);
  std::vector<MUMPS_INT>().swap(d.cols);
  std::vector<double>().swap(d.values);
  fz.factor_entries = mumps_count(id.infog[28]);
  fz.flops = id.rinfog[2];
  if (root) {
    // S = −𝔹K⁻¹𝔹ᵀ, its lower triangle by rows = the upper triangle of the column-major Q: mirror
    // and negate in place (no second m × m array on rank 0).
    Eigen::MatrixXd& Q = fz.Q;
    for (Eigen::Index j = 0; j < fz.m; ++j) {
      for (Eigen::Index i = 0; i < j; ++i) Q(j, i) = Q(i, j) = -Q(i, j);
      Q(j, j) = -Q(j, j);
    }
  }
}

// Point to point in pieces of at most 2^30 entries (MPI's counts are ints).
constexpr std::size_t kPiece = std::size_t(1) << 30;
template <class T>
void send_vector(const std::vector<T>& v, MPI_Datatype type, int to) {
  for (std::size_t first = 0; first < v.size(); first += kPiece)
    MPI_Send(v.data() + first, static_cast<int>(std::min(kPiece, v.size() - first)), type, to, 0, MPI_COMM_WORLD);
}
template <class T>
void receive_vector(std::vector<T>& v, MPI_Datatype type) {
  for (std::size_t first = 0; first < v.size(); first += kPiece)
    MPI_Recv(v.data() + first, static_cast<int>(std::min(kPiece, v.size() - first)), type, 0, 0, MPI_COMM_WORLD,
             MPI_STATUS_IGNORE);
}

// Runs `work` on every rank and agrees on the outcome before the next collective, so that a rank
// that fails (out of memory while assembling, a module it cannot open) never leaves the others
// waiting inside MUMPS or PETSc: every rank throws — the failing one its own exception, the others
// the same kind (bad_alloc, InputError, or runtime_error) with the first failing rank's message,
// since only rank 0 prints errors.
template <class Work>
void on_every_rank(Work work, const char* doing) {
  int failure = 0;  // 3: out of memory, 2: an input error, 1: another error
  std::exception_ptr mine;
  std::string message;
  try {
    work();
  } catch (const std::bad_alloc&) {
    failure = 3;
    mine = std::current_exception();
    message = "out of memory";
  } catch (const InputError& e) {
    failure = 2;
    mine = std::current_exception();
    message = e.what();
  } catch (const std::exception& e) {
    failure = 1;
    mine = std::current_exception();
    message = e.what();
  } catch (...) {
    failure = 1;
    mine = std::current_exception();
  }
  int worst = 0;
  MPI_Allreduce(&failure, &worst, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  if (worst == 0) return;
  const int rank = comm_rank();
  int first = 0;  // the lowest failing rank tells the others what went wrong
  const int mine_or_none = failure ? rank : comm_size();
  MPI_Allreduce(&mine_or_none, &first, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  int length = static_cast<int>(message.size());
  MPI_Bcast(&length, 1, MPI_INT, first, MPI_COMM_WORLD);
  message.resize(static_cast<std::size_t>(length));
  MPI_Bcast(message.data(), length, MPI_CHAR, first, MPI_COMM_WORLD);
  if (mine) std::rethrow_exception(mine);
  if (worst == 3) throw std::bad_alloc();
  const std::string what = "rank " + std::to_string(first) + " failed " + doing + ": " + message;
  if (worst == 2) throw InputError(what);
  throw std::runtime_error(what);
}

// A MeshPart as flat arrays for MPI (about 56 bytes per tet): header {nodes, tets, first_node,
// last_node}, coordinates, dof numbers, corners, E and ν.
struct PartMessage {
  std::int64_t header[4] = {0, 0, 0, 0};
  std::vector<double> xyz, young_poisson;
  std::vector<int> free_index, corners;

  void allocate() {
    xyz.resize(static_cast<std::size_t>(3 * header[0]));
    free_index.resize(static_cast<std::size_t>(3 * header[0]));
    corners.resize(static_cast<std::size_t>(4 * header[1]));
    young_poisson.resize(static_cast<std::size_t>(2 * header[1]));
  }
  explicit PartMessage(const MeshPart& part) {
    header[0] = part.dofs.n_nodes;
    header[1] = static_cast<std::int64_t>(part.mesh.tets.size());
    header[2] = part.first_node;
    header[3] = part.last_node;
    allocate();
    for (std::size_t v = 0; v < part.mesh.nodes.size(); ++v)
      for (int c = 0; c < 3; ++c) xyz[3 * v + c] = part.mesh.nodes[v][c];
    free_index = part.dofs.free_index;
    for (std::size_t e = 0; e < part.mesh.tets.size(); ++e) {
      for (int a = 0; a < 4; ++a) corners[4 * e + a] = part.mesh.tets[e][a];
      young_poisson[2 * e] = part.materials[e].young;
      young_poisson[2 * e + 1] = part.materials[e].poisson;
    }
  }
  PartMessage() = default;
  MeshPart unpack(int n_free) {
    MeshPart part;
    part.mesh.nodes.resize(static_cast<std::size_t>(header[0]));
    for (std::size_t v = 0; v < part.mesh.nodes.size(); ++v)
      part.mesh.nodes[v] = Eigen::Vector3d(xyz[3 * v], xyz[3 * v + 1], xyz[3 * v + 2]);
    part.mesh.tets.resize(static_cast<std::size_t>(header[1]));
    part.materials.resize(part.mesh.tets.size());
    for (std::size_t e = 0; e < part.mesh.tets.size(); ++e) {
      for (int a = 0; a < 4; ++a) part.mesh.tets[e][a] = corners[4 * e + a];
      part.materials[e] = Material{young_poisson[2 * e], young_poisson[2 * e + 1]};
    }
    part.dofs.n_nodes = static_cast<int>(header[0]);
    part.dofs.n_free = n_free;
    part.dofs.free_index = std::move(free_index);
    part.first_node = static_cast<int>(header[2]);
    part.last_node = static_cast<int>(header[3]);
    return part;
  }
};

// Rank 0 → rank `to`: a status (0: a part follows, 1: none, rank 0 failed), the header, the
// receiver's answer whether it could allocate the part, then the arrays (not when it could not: it
// says so in on_every_rank).
void send_part(const PartMessage* message, int to) {
  std::int64_t status_and_header[5] = {message ? 0 : 1, 0, 0, 0, 0};
  if (message) std::copy(message->header, message->header + 4, status_and_header + 1);
  MPI_Send(status_and_header, 5, MPI_INT64_T, to, 0, MPI_COMM_WORLD);
  if (!message) return;
  int allocated = 0;
  MPI_Recv(&allocated, 1, MPI_INT, to, 0, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
  if (!allocated) return;
  send_vector(message->xyz, MPI_DOUBLE, to);
  send_vector(message->free_index, MPI_INT, to);
  send_vector(message->corners, MPI_INT, to);
  send_vector(message->young_poisson, MPI_DOUBLE, to);
}

// The other side of send_part; throws (after answering rank 0) when there is no part.
MeshPart receive_part(int n_free) {
  std::int64_t status_and_header[5];
  MPI_Recv(status_and_header, 5, MPI_INT64_T, 0, 0, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
  if (status_and_header[0] != 0) throw std::runtime_error("rank 0 failed while cutting the mesh into parts");
  PartMessage message;
  std::copy(status_and_header + 1, status_and_header + 5, message.header);
  int allocated = 1;
  try {
    message.allocate();
  } catch (const std::bad_alloc&) { allocated = 0; }
  MPI_Send(&allocated, 1, MPI_INT, 0, 0, MPI_COMM_WORLD);
  if (!allocated) throw std::bad_alloc();
  receive_vector(message.xyz, MPI_DOUBLE);
  receive_vector(message.free_index, MPI_INT);
  receive_vector(message.corners, MPI_INT);
  receive_vector(message.young_poisson, MPI_DOUBLE);
  return message.unpack(n_free);
}

// The lower triangle of the columns of K for nodes [first_node, last_node) of `mesh`, as triplets.
// `extra_entries`: room for what the caller adds after (rank 0: 𝔹, the multipliers' diagonal, the
// springs), so that adding them does not double the three arrays that stay beside MUMPS's factor.
Triplets lower_columns(const Mesh& mesh, const DofMap& dofs, const TetMaterials& materials, int first_node,
                       int last_node, std::size_t extra_entries = 0) {
  const Eigen::SparseMatrix<double> columns = assemble_stiffness_columns(mesh, dofs, materials, first_node, last_node);
  const int first_dof = first_free_dof(dofs, first_node);
  Triplets share;
  share.rows.reserve(static_cast<std::size_t>(columns.nonZeros() / 2 + columns.cols()) + extra_entries);
  share.cols.reserve(share.rows.capacity());
  share.values.reserve(share.rows.capacity());
  for (Eigen::Index c = 0; c < columns.cols(); ++c) {
    const std::int64_t j = first_dof + c;
    for (Eigen::SparseMatrix<double>::InnerIterator it(columns, c); it; ++it)
      if (it.row() >= j) share.add(it.row(), j, it.value());
  }
  return share;
}

// Rank 0's side of the assembly: one part of the mesh to each other rank (the tets around its
// nodes, cut one at a time), then its own columns from the whole mesh.
Triplets send_parts_and_assemble(const StiffnessSource& source, std::size_t extra_entries) {
  const int size = comm_size();
  const std::vector<int> split = split_nodes_by_dofs(source.dofs, size);  // rank r: [split[r], split[r + 1])
  int r = 1;
  try {
    for (; r < size; ++r) {
      const PartMessage message(cut_mesh_part(source.mesh, source.dofs, source.materials,
                                              split[static_cast<std::size_t>(r)],
                                              split[static_cast<std::size_t>(r) + 1]));
      send_part(&message, r);
    }
  } catch (...) {
    for (; r < size; ++r) send_part(nullptr, r);  // the ranks still waiting learn there is no part
    throw;
  }
  return lower_columns(source.mesh, source.dofs, source.materials, split[0], split[1], extra_entries);
}

// kAssembleAndFactor, collective: every rank assembles its share of K (rank 0 sends each its part of
// the mesh); rank 0 adds 𝔹 and the multipliers' zero diagonal and gives the pivot order (`source`,
// `B` and `order` are read on rank 0 only).
std::unique_ptr<Factorization> assemble_and_factor(const StiffnessSource* source, const Eigen::SparseMatrix<double>* B,
                                                   const std::vector<int>& order, std::string out_of_core_dir,
                                                   const std::function<void(const std::string&)>* report = nullptr) {
  auto fz = std::make_unique<Factorization>();
  std::int64_t dims[3] = {source ? source->dofs.n_free : 0, B ? B->rows() : 0,
                          static_cast<std::int64_t>(out_of_core_dir.size())};
  MPI_Bcast(dims, 3, MPI_INT64_T, 0, MPI_COMM_WORLD);
  out_of_core_dir.resize(static_cast<std::size_t>(dims[2]));
  MPI_Bcast(out_of_core_dir.data(), static_cast<int>(dims[2]), MPI_CHAR, 0, MPI_COMM_WORLD);
  fz->n = dims[0];
  fz->m = dims[1];
  // OpenBLAS retries for good where it cannot map its threads' work space (ulimit -v): a rank short of
  // address space hung in MUMPS's first product (rank 0 checks its own at the solve's start).
  on_every_rank(reserve_blas_buffers, "to map OpenBLAS's work space");
  Triplets share;
  on_every_rank(
      [&] {
        if (source) {
          share = send_parts_and_assemble(*source,
                                          static_cast<std::size_t>(B->nonZeros() + fz->m) + source->springs.size());
          for (int j = 0; j < B->outerSize(); ++j)
            for (Eigen::SparseMatrix<double>::InnerIterator it(*B, j); it; ++it)
              share.add(fz->n + it.row(), j, it.value());
          for (std::int64_t r = 0; r < fz->m; ++r) share.add(fz->n + r, fz->n + r, 0.0);
          for (const auto& [dof, spring] : source->springs) share.add(dof, dof, spring);  // MUMPS sums duplicates
        } else {
          MeshPart part = receive_part(static_cast<int>(fz->n));
          share = lower_columns(part.mesh, part.dofs, TetMaterials(std::move(part.materials)), part.first_node,
                                part.last_node);
        }
      },
      "while assembling its share of K");
  // The assembly's many small lists, freed, would stay resident beside MUMPS's factor, and MUMPS's
  // workspaces, too large for the heap's holes, would be put beside them: the guard trims the heap
  // and gives MUMPS's large blocks their own mappings (n = 16 brick, 2 ranks: peak 151 / 129 →
  // 147 / 127 MiB per rank; n = 24: 550 / 543 → 545 / 545, the same factorization time).
  const LargeBlocksFromSystem mumps_workspaces;
  factor_direct(*fz, order, std::move(share), out_of_core_dir, report);
  return fz;
}

// The PETSc module (petsc_route.hpp): opened by the first kFactorThroughPetsc on every rank, PETSc
// started then and ended by ~Session. Process state, as PETSc's own is (one PetscInitialize per
// process); the module stays loaded to the end of the process.
struct PetscModule {
  PetscRoute* (*start)() = nullptr;
  std::unique_ptr<PetscRoute> route;
};
PetscModule& petsc_module() {
  static PetscModule module;
  return module;
}

// libcontact3d_petsc.so in the executable's own directory (symbolic links resolved).
std::string petsc_module_path() {
  std::string exe(4096, '\0');
  const ssize_t length = readlink("/proc/self/exe", exe.data(), exe.size() - 1);
  exe.resize(length > 0 ? static_cast<std::size_t>(length) : 0);
  const std::size_t slash = exe.rfind('/');
  return (slash == std::string::npos ? std::string(".") : exe.substr(0, slash)) + "/libcontact3d_petsc.so";
}

void open_petsc_module() {
  PetscModule& module = petsc_module();
  if (module.start) return;
  const std::string path = petsc_module_path();
  void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (!handle) {
    const std::string why = dlerror();
    std::error_code ec;
    if (!std::filesystem::exists(path, ec))
      throw InputError("solver.schur = \"mumps_petsc\" needs the PETSc module " + path +
                       " (built with contact3d-mpi by `make build-mpi`): " + why);
    // The module is there; what fails is loading it or the libraries it links (PETSc, HDF5, ...).
    // (dlerror's text starts with the path, so only the loader's own phrases are matched)
    const bool unmapped = why.find("failed to map segment") != std::string::npos ||
                          why.find("annot allocate memory") != std::string::npos;
    throw InputError("solver.schur = \"mumps_petsc\": the PETSc module " + path + " could not be loaded: " + why +
                     (unmapped ? " — the process could not map a library into memory: its address-space limit "
                                 "(ulimit -v) or the machine's memory is too small for PETSc's libraries"
                               : ""));
  }
  module.start = reinterpret_cast<PetscRoute* (*)()>(dlsym(handle, "contact3d_start_petsc_route"));
  if (!module.start) throw InputError(path + " is not contact3d's PETSc module (no contact3d_start_petsc_route)");
}

// kFactorThroughPetsc, collective. On rank 0 `csr` holds the whole matrix and `modes` K's
// near-null space (may be null); elsewhere both are empty. Every rank opens the module before any
// starts PETSc, whose start is collective.
std::unique_ptr<Factorization> factor_through_petsc(UpperCsr csr, const Eigen::MatrixXd* modes) {
  on_every_rank(reserve_blas_buffers, "to map OpenBLAS's work space");  // as assemble_and_factor
  on_every_rank(open_petsc_module, "to open the PETSc module");
  PetscModule& module = petsc_module();
  if (!module.route) module.route.reset(module.start());
  auto fz = std::make_unique<Factorization>();
  fz->petsc = module.route->factor(std::move(csr), modes, *fz);
  return fz;
}

// The direct route of solve(): the right-hand side and the solution on rank 0.
void solve_direct(Factorization& fz, const Eigen::VectorXd* rhs, Eigen::VectorXd* out) {
  DMUMPS_STRUC_C& id = fz.direct->id;
  Eigen::VectorXd x;
  if (rhs) {
    x = *rhs;
    id.rhs = x.data();
    id.nrhs = 1;
    id.lrhs = static_cast<MUMPS_INT>(x.size());
  }
  id.icntl[19] = 0;  // ICNTL(20): dense right-hand side on the host
  id.icntl[20] = 0;  // ICNTL(21): the solution back on the host
  fz.direct->run(3, "the MUMPS solve");
  if (out) *out = x.head(fz.n);
}

// kSolve, collective: x = K⁻¹ rhs on the primal rows (rank 0 gives rhs over all N rows).
void solve(Factorization& fz, const Eigen::VectorXd* rhs, Eigen::VectorXd* out) {
  if (fz.direct) return solve_direct(fz, rhs, out);
  fz.petsc->solve(rhs, out);
}

double peak_rss_mib() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_maxrss) / 1024.0;
}

std::vector<double> gather_memory() {
  double mine = peak_rss_mib();
  std::vector<double> all(comm_size());
  MPI_Gather(&mine, 1, MPI_DOUBLE, all.data(), 1, MPI_DOUBLE, 0, MPI_COMM_WORLD);
  return all;
}

// Our nested dissection of K's dofs from the node graph, which is freed before the factorization.
std::vector<int> pivot_order(const StiffnessSource& source) {
  const NodeGraph graph = free_node_graph(source.mesh, source.dofs);
  return nested_dissection_order(graph.first_dof, graph.adj_start, graph.adj);
}

// Rank 0's side of the dual problem: every method sends the command, then runs the collective.
class MumpsDualProblem final : public DualProblem {
 public:
  MumpsDualProblem(const DualProblemInput& in, StageClock& clock, const MumpsOptions& options)
      : B_(in.B), f_(in.f), face_dofs_(in.face_dofs) {
    const MumpsRoute route = options.route;
    method = route == MumpsRoute::Direct ? "mumps" : "mumps_petsc";
    backend = route == MumpsRoute::Direct ? "mumps" : "petsc-mumps";
    if (route == MumpsRoute::Direct) {
      // No K on this process: the ranks assemble their columns; the order comes from the node graph.
      if (!in.stiffness_source)
        throw std::invalid_argument("the direct MUMPS route assembles K from a StiffnessSource");
      const std::vector<int> order = pivot_order(*in.stiffness_source);
      broadcast(kAssembleAndFactor);
      fz_ = assemble_and_factor(in.stiffness_source, &in.B, order, options.out_of_core_dir, &in.report);
    } else {
      // ‖K·modes‖ from rank 0's K, to check the ranks' copy of the near-null space against.
      const double expected_residual = in.near_null_space.cols() > 0 ? (in.K * in.near_null_space).norm() : 0.0;
      UpperCsr csr = augmented_upper(in.K, in.B);
      if (in.release_K) in.release_K();  // the ranks' shares come from csr: K need not stay for the factorization
      broadcast(kFactorThroughPetsc);
      fz_ = factor_through_petsc(std::move(csr), &in.near_null_space);
      const double residual = fz_->near_null_space.residual;
      if (std::abs(residual - expected_residual) > 1e-10 * std::max(expected_residual, 1e-300)) {
        release_factor();  // collective: the other ranks free theirs too
        throw std::logic_error("the near-null space on the ranks is not K's: ‖K·R‖ = " + std::to_string(residual) +
                               " there, " + std::to_string(expected_residual) + " on rank 0");
      }
      near_null_space = fz_->near_null_space.vectors;
    }
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
  if (MPI_Init(&argc, &argv) != MPI_SUCCESS) throw std::runtime_error("MPI_Init failed");
  started_ = true;
  rank_ = comm_rank();
  size_ = comm_size();
  if (size_ > 1) blas_ = share_cores_among_ranks(this_machine().ranks);
}

void Session::finish(int exit_code) {
  if (!started_ || rank_ != 0 || finished_) return;
  broadcast(kStop);
  MPI_Bcast(&exit_code, 1, MPI_INT, 0, MPI_COMM_WORLD);
  finished_ = true;
}

Session::~Session() {
  if (!started_) return;
  finish(0);
  petsc_module().route.reset();  // PETSc ends before MPI, on every rank that started it
  MPI_Finalize();
}

int Session::serve() {
  std::unique_ptr<Factorization> fz;
  for (;;) {
    const int code = receive_command();
    try {
      switch (code) {
        case kFactorThroughPetsc:
          fz = factor_through_petsc(UpperCsr(), nullptr);
          break;
        case kAssembleAndFactor:
          fz = assemble_and_factor(nullptr, nullptr, {}, "");
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
        default: {  // kStop, then rank 0's exit code
          int exit_code = 0;
          MPI_Bcast(&exit_code, 1, MPI_INT, 0, MPI_COMM_WORLD);
          return exit_code;
        }
      }
    } catch (const std::exception&) {
      // Rank 0 sees the same failure in the same collective and reports it; keep serving.
    }
  }
}

std::unique_ptr<DualProblem> make_mumps_dual_problem(const DualProblemInput& input, StageClock& clock,
                                                     const MumpsOptions& options) {
  if (options.route == MumpsRoute::ThroughPetsc && !options.out_of_core_dir.empty())
    throw InputError("solver.out_of_core_dir works with MUMPS called directly (solver.schur = \"mumps\")");
  return std::make_unique<MumpsDualProblem>(input, clock, options);
}

int ranks() { return comm_size(); }

std::string core_binding_note() {
  const int usable = usable_cores();
  const long online = sysconf(_SC_NPROCESSORS_ONLN);
  if (online <= 0 || static_cast<long>(usable) * comm_size() >= online) return "";
  return "each of the " + std::to_string(comm_size()) + " rank(s) may use " + std::to_string(usable) + " of the " +
         std::to_string(online) + " cores (mpirun's binding): with fewer ranks than cores, `mpirun --bind-to none` " +
         "lets MUMPS's BLAS threads use the others";
}

std::vector<double> peak_memory_per_rank_mib() {
  broadcast(kMemory);
  return gather_memory();
}

}  // namespace contact3d::distributed
