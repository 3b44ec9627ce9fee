// RunFolder: the output folder of one solve, kept honest. Opening it takes an exclusive lock (a
// second solve into the same folder is refused while the first runs, as is one whose steps/ folder
// another running solve writes in), removes the previous run's results (so a failed or killed rerun never leaves a
// summary.json of another solve behind) and leaves a RUNNING marker; finish() removes the marker once every file,
// summary.json last, is in place. A folder holds a finished solve iff it has summary.json and no RUNNING file, and a
// converged one iff it has no NOT_CONVERGED file either.
#pragma once

#include <filesystem>
#include <string>

namespace contact3d {

class RunFolder {
 public:
  // Creates the folder if needed; throws InputError when it cannot be written or is locked.
  explicit RunFolder(const std::filesystem::path& dir, const std::string& what);
  ~RunFolder();
  RunFolder(const RunFolder&) = delete;
  RunFolder& operator=(const RunFolder&) = delete;

  const std::filesystem::path& path() const { return dir_; }
  // The solve's files are all written: remove the RUNNING marker. A run that stopped without
  // converging (exit 1) first leaves NOT_CONVERGED, naming its exit (`not_converged`), beside its
  // last iterate, so that its folder is not taken for a solution.
  void finish(const std::string& not_converged = {});

 private:
  void clear_for_this_run(const std::string& what);

  std::filesystem::path dir_;
  int lock_fd_ = -1;
};

// The files a solve writes into its folder (summary.json first: removed first, written last).
const char* const kRunOutputs[] = {"summary.json",      "history.csv",  "contact_nodes.csv",
                                   "contact_cells.csv", "body.vtu",     "contact.vtu",
                                   "contact_cells.vtu", "solution.pvd", "NOT_CONVERGED"};
// The first line's start of the report.md that `make pipeline` (pipeline/run_scene.py) writes beside
// them: removed with them, where a report.md of another kind stays (it may be the user's).
inline constexpr const char* kRunReportTitle = "# Run report: ";

}  // namespace contact3d
