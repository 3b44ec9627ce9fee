#include "io/pvd_writer.hpp"

#include <cstdio>
#include <string>
#include <vector>

#include "base/errors.hpp"
#include "io/atomic_file.hpp"

namespace contact3d {
namespace {

std::string step_file(const char* what, int k) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "steps/%s_%03d.vtu", what, k);
  return buf;
}

// body_007.vtu, contact_012.vtu: the names step_file writes (three or more digits), and the
// .partial file a killed write leaves of one (io/atomic_file.hpp).
bool is_step_file_name(std::string name) {
  const std::string partial = ".partial", suffix = ".vtu";
  if (name.size() > partial.size() && name.compare(name.size() - partial.size(), partial.size(), partial) == 0)
    name.resize(name.size() - partial.size());
  for (const std::string prefix : {"body_", "contact_"}) {
    if (name.size() < prefix.size() + 3 + suffix.size() || name.rfind(prefix, 0) != 0 ||
        name.compare(name.size() - suffix.size(), suffix.size(), suffix) != 0)
      continue;
    const std::string digits = name.substr(prefix.size(), name.size() - prefix.size() - suffix.size());
    if (digits.find_first_not_of("0123456789") == std::string::npos) return true;
  }
  return false;
}

struct TimeStep {
  int k;
  std::string body, contact;  // files relative to the run folder; contact empty without Γc
};

void write_pvd(const std::filesystem::path& file, const std::vector<TimeStep>& steps) {
  write_file(file, [&](std::ostream& pvd) {
    pvd << "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
        << "  <Collection>\n";
    for (const auto& s : steps) {
      pvd << "    <DataSet timestep=\"" << s.k << "\" group=\"\" part=\"0\" name=\"body\" file=\"" << s.body
          << "\"/>\n";
      if (!s.contact.empty())
        pvd << "    <DataSet timestep=\"" << s.k << "\" group=\"\" part=\"1\" name=\"contact\" file=\"" << s.contact
            << "\"/>\n";
    }
    pvd << "  </Collection>\n</VTKFile>\n";
  });
}

}  // namespace

void remove_step_files(const std::filesystem::path& dir) {
  const std::filesystem::path steps_dir = dir / "steps";
  std::error_code ec;
  if (!std::filesystem::is_directory(steps_dir, ec)) return;
  std::vector<std::filesystem::path> ours;
  for (const auto& entry : std::filesystem::directory_iterator(steps_dir, ec))
    if (entry.is_regular_file(ec) && is_step_file_name(entry.path().filename().string())) ours.push_back(entry.path());
  for (const auto& file : ours) std::filesystem::remove(file, ec);
  std::filesystem::remove(steps_dir, ec);  // only when empty
}

int write_solution_collection(const std::filesystem::path& dir, const VtuContext& ctx) {
  const SolveResult& res = ctx.res;
  const bool has_face = !res.face.triangles.empty();
  const std::filesystem::path steps_dir = dir / "steps";
  std::error_code ec;  // an earlier run's step files are gone: the RunFolder removed them (remove_step_files)
  const int count = std::max<int>(1, static_cast<int>(res.steps.size()));
  std::vector<TimeStep> steps;
  if (!steps_written(res)) {
    steps.push_back({count, "body.vtu", has_face ? "contact.vtu" : ""});
  } else {
    std::filesystem::create_directories(steps_dir, ec);
    if (ec) throw InputError("cannot create '" + steps_dir.string() + "': " + ec.message());
    for (int k = 1; k < count; ++k) {
      TimeStep t{k, step_file("body", k), has_face ? step_file("contact", k) : ""};
      write_state_vtus(dir / t.body, dir / t.contact, ctx, step_state(res.steps[k - 1]));
      steps.push_back(std::move(t));
    }
    steps.push_back({count, "body.vtu", has_face ? "contact.vtu" : ""});  // the last step is the answer
  }
  write_pvd(dir / "solution.pvd", steps);
  return static_cast<int>(steps.size());
}

}  // namespace contact3d
