#include "model/scene.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>
#include <utility>

#include <toml++/toml.h>

#include "base/errors.hpp"
#include "base/format.hpp"

namespace contact3d {
namespace {

using KeySet = std::set<std::string>;

void check_keys(const toml::table& t, const std::string& where, const KeySet& allowed) {
  for (const auto& [key, node] : t) {
    const std::string k(key.str());
    if (!allowed.count(k)) {
      std::string list;
      for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
      throw InputError("unknown key '" + (where.empty() ? k : where + "." + k) +
                       "' in the scene (allowed here: " + list + ")");
    }
  }
}

// The source name the scene file's text is parsed under: its values carry their line (not those of --set).
constexpr const char* kSceneSource = "scene";

// "scene key 'boundary.traction.value' (line 14)": the value's line in the scene file where it stands
// there (two [[boundary.traction]] entries were told apart by nothing).
std::string key_at(const std::string& name, const toml::node* n) {
  std::string text = "scene key '" + name + "'";
  if (!n) return text;
  const toml::source_region& at = n->source();
  if (at.path && *at.path == kSceneSource && at.begin.line > 0) text += " (line " + std::to_string(at.begin.line) + ")";
  return text;
}

const toml::table* table_at(const toml::table& root, const std::string& key) {
  const toml::node* n = root.get(key);
  if (!n) return nullptr;
  if (!n->is_table()) throw InputError("scene key '" + key + "' must be a table");
  return n->as_table();
}

double get_number(const toml::table& t, const std::string& where, const std::string& key, double fallback,
                  bool required = false) {
  const toml::node* n = t.get(key);
  if (!n) {
    if (required) throw InputError("scene key '" + where + "." + key + "' is required");
    return fallback;
  }
  std::optional<double> v = n->value<double>();
  if (!v || !(n->is_floating_point() || n->is_integer()))
    throw InputError(key_at(where + "." + key, n) + " must be a number");
  if (!std::isfinite(*v)) throw InputError(key_at(where + "." + key, n) + " must be finite, got " + number(*v));
  return *v;
}

int get_int(const toml::table& t, const std::string& where, const std::string& key, int fallback, int lo, int hi) {
  const double v = get_number(t, where, key, fallback);
  if (v != std::floor(v) || v < lo || v > hi)
    throw InputError(key_at(where + "." + key, t.get(key)) + " must be an integer in [" + std::to_string(lo) + ", " +
                     std::to_string(hi) + "], got " + number(v));
  return static_cast<int>(v);
}

std::string get_string(const toml::table& t, const std::string& where, const std::string& key,
                       const std::string& fallback) {
  const toml::node* n = t.get(key);
  if (!n) return fallback;
  if (!n->is_string()) throw InputError(key_at(where + "." + key, n) + " must be a string");
  std::string value = *n->value<std::string>();
  if (value.find('\0') != std::string::npos)  // a path would end there, silently
    throw InputError(key_at(where + "." + key, n) + " holds a NUL character (\\u0000)");
  return value;
}

// An enum by its name in the enum's table; absent: `value` keeps its default.
template <class E, std::size_t N>
void get_enum(const toml::table& t, const std::string& where, const std::string& key, const NameTable<E, N>& names,
              E& value) {
  const toml::node* n = t.get(key);
  if (!n) return;
  const std::string name = get_string(t, where, key, "");
  if (!value_of(name, names, value))
    throw InputError(where + "." + key + " must be " + names_list(names) + ", got '" + name + "'");
}

std::vector<std::string> get_strings(const toml::table& t, const std::string& where, const std::string& key) {
  const toml::node* n = t.get(key);
  if (!n) return {};
  if (n->is_string()) return {*n->value<std::string>()};
  if (!n->is_array()) throw InputError(key_at(where + "." + key, n) + " must be a list of group names");
  std::vector<std::string> out;
  for (const auto& e : *n->as_array()) {
    if (!e.is_string()) throw InputError(key_at(where + "." + key, n) + " must list strings");
    out.push_back(*e.value<std::string>());
  }
  return out;
}

Eigen::Vector3d get_vector(const toml::node* n, const std::string& name) {
  if (!n || !n->is_array() || n->as_array()->size() != 3)
    throw InputError(key_at(name, n) + " must be a list of three numbers");
  Eigen::Vector3d v;
  for (int k = 0; k < 3; ++k) {
    const auto x = (*n->as_array())[k].value<double>();
    if (!x) throw InputError(key_at(name, n) + " must be a list of three numbers");
    if (!std::isfinite(*x)) throw InputError(key_at(name, n) + " must be finite");
    v[k] = *x;
  }
  return v;
}

Eigen::Matrix3d get_matrix(const toml::node* n, const std::string& name) {
  if (!n || !n->is_array() || n->as_array()->size() != 3)
    throw InputError(key_at(name, n) + " must be a 3×3 matrix: three rows of three numbers");
  Eigen::Matrix3d m;
  for (int r = 0; r < 3; ++r) m.row(r) = get_vector(n->as_array()->get(r), name + " row " + std::to_string(r + 1));
  return m;
}

// The tables of an array of tables `[[where.key]]` (none when absent).
std::vector<const toml::table*> get_tables(const toml::table& t, const std::string& where, const std::string& key) {
  std::vector<const toml::table*> out;
  const toml::node* n = t.get(key);
  if (!n) return out;
  const bool empty_list = n->is_array() && n->as_array()->empty();
  if (!empty_list && !n->is_array_of_tables())
    throw InputError(where + "." + key + " must be an array of tables ([[" + where + "." + key + "]])");
  for (const auto& e : *n->as_array()) out.push_back(e.as_table());
  return out;
}

std::string get_group(const toml::table& t, const std::string& where) {
  const std::string group = get_string(t, where, "group", "");
  if (group.empty()) throw InputError(where + " needs a group");
  return group;
}

Material get_material(const toml::table& t, const std::string& where) {
  Material m;
  m.young = get_number(t, where, "young", 0, true);
  m.poisson = get_number(t, where, "poisson", 0, true);
  if (!(m.young > 0)) throw InputError(where + ".young must be > 0 (Pa), got " + number(m.young));
  if (!std::isnormal(m.young))  // 1e-310: the run blamed the contact cells' stability condition instead
    throw InputError(where + ".young = " + number(m.young) +
                     " is a subnormal number, below double precision's smallest normal one (" +
                     number(std::numeric_limits<double>::min(), 3) +
                     "): no stiffness can be computed from it; give the modulus in the scene's units (" +
                     "output.units, Pa by default)");
  if (!(m.poisson > -1 && m.poisson < 0.5))
    throw InputError(where + ".poisson must lie in (-1, 0.5), got " + number(m.poisson));
  return m;
}

// [material]: the default material, body force, and [[material.region]] per volume group.
void parse_material(const toml::table& mat, Scene& s) {
  check_keys(mat, "material", {"young", "poisson", "body_force", "region"});
  s.material = get_material(mat, "material");
  if (mat.contains("body_force")) s.body_force = get_vector(mat.get("body_force"), "material.body_force");
  for (const toml::table* t : get_tables(mat, "material", "region")) {
    check_keys(*t, "material.region", {"group", "young", "poisson", "body_force"});
    MaterialRegion region{get_group(*t, "material.region"), get_material(*t, "material.region"), {}};
    if (t->contains("body_force")) region.body_force = get_vector(t->get("body_force"), "material.region.body_force");
    s.regions.push_back(std::move(region));
  }
}

// [boundary]: clamped and contact groups, [[boundary.displacement]], [[boundary.traction]],
// [[boundary.pressure]].
void parse_boundary(const toml::table& bnd, Scene& s) {
  check_keys(bnd, "boundary", {"clamped", "contact", "traction", "pressure", "force", "displacement"});
  s.clamped = get_strings(bnd, "boundary", "clamped");
  s.contact = get_strings(bnd, "boundary", "contact");
  for (const toml::table* t : get_tables(bnd, "boundary", "displacement")) {
    const std::string where = "boundary.displacement";
    check_keys(*t, where, {"group", "x", "y", "z", "gradient"});
    PrescribedDisplacement d{get_group(*t, where), {}};
    const char* const axes[3] = {"x", "y", "z"};
    for (int c = 0; c < 3; ++c)
      if (t->contains(axes[c])) d.value[c] = get_number(*t, where, axes[c], 0, true);
    if (!d.value[0] && !d.value[1] && !d.value[2])
      throw InputError(where + " on '" + d.group + "' prescribes no component: give any of x, y, z (m)");
    if (t->contains("gradient")) d.gradient = get_matrix(t->get("gradient"), where + ".gradient");
    for (int c = 0; c < 3; ++c)
      if (!d.value[c] && !d.gradient.row(c).isZero())
        throw InputError(where + " on '" + d.group + "': gradient row " + std::to_string(c + 1) + " (u_" + axes[c] +
                         ") is not zero but " + axes[c] + " is not prescribed; give " + axes[c] +
                         " (its value at the origin, m) or leave that row zero");
    s.displacements.push_back(d);
  }
  if (s.clamped.empty() && s.displacements.empty() && s.contact.empty())
    throw InputError(
        "the scene has no boundary.clamped group, no [[boundary.displacement]] and no boundary.contact: "
        "something must keep the body from rigid motions");
  for (const toml::table* t : get_tables(bnd, "boundary", "traction")) {
    check_keys(*t, "boundary.traction", {"group", "value", "gradient"});
    Traction tr;
    tr.group = get_group(*t, "boundary.traction");
    if (!t->contains("value") && !t->contains("gradient"))
      throw InputError("boundary.traction on '" + tr.group + "' needs a value (Pa) and/or a gradient (Pa/m)");
    if (t->contains("value")) tr.value = get_vector(t->get("value"), "boundary.traction.value");
    if (t->contains("gradient")) tr.gradient = get_matrix(t->get("gradient"), "boundary.traction.gradient");
    s.tractions.push_back(tr);
  }
  for (const toml::table* t : get_tables(bnd, "boundary", "pressure")) {
    check_keys(*t, "boundary.pressure", {"group", "value", "gradient"});
    Traction tr;
    tr.group = get_group(*t, "boundary.pressure");
    if (!t->contains("value") && !t->contains("gradient"))
      throw InputError("boundary.pressure on '" + tr.group + "' needs a value (Pa) and/or a gradient (Pa/m)");
    tr.pressure = get_number(*t, "boundary.pressure", "value", 0, false);
    if (t->contains("gradient")) tr.pressure_gradient = get_vector(t->get("gradient"), "boundary.pressure.gradient");
    s.tractions.push_back(tr);
  }
  for (const toml::table* t : get_tables(bnd, "boundary", "force")) {
    check_keys(*t, "boundary.force", {"group", "value"});
    Traction tr;
    tr.group = get_group(*t, "boundary.force");
    if (!t->contains("value"))
      throw InputError("boundary.force on '" + tr.group + "' needs a value: the resultant [Fx, Fy, Fz] (N)");
    tr.total_force = get_vector(t->get("value"), "boundary.force.value");
    tr.given_as_force = true;
    s.tractions.push_back(tr);
  }
}

std::filesystem::path resolve(const std::filesystem::path& base, const std::string& p) {
  std::filesystem::path path(p);
  return path.is_absolute() ? path : (base / path).lexically_normal();
}

// solver.out_of_core_dir: an existing directory this process may write in (MUMPS's files go there;
// its name must fit MUMPS's 255 characters).
std::filesystem::path out_of_core_dir(const std::filesystem::path& base, const toml::table& solver) {
  const std::string given = get_string(solver, "solver", "out_of_core_dir", "");
  if (given.empty()) return {};
  const std::filesystem::path dir = resolve(base, given);
  std::error_code ec;
  if (!std::filesystem::is_directory(dir, ec) || access(dir.c_str(), W_OK | X_OK) != 0)
    throw InputError("solver.out_of_core_dir '" + dir.string() + "' is not a directory this process can write in");
  if (dir.string().size() > 255)
    throw InputError("solver.out_of_core_dir '" + dir.string() + "' is longer than MUMPS's 255 characters");
  return dir;
}

// Applies "a.b.c=value" to the table, creating tables on the way.
void apply_override(toml::table& root, const std::string& assignment) {
  const auto eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0) throw InputError("--set expects key=value, got '" + assignment + "'");
  const std::string key = assignment.substr(0, eq), text = assignment.substr(eq + 1);
  toml::table parsed;
  try {
    parsed = toml::parse("v = " + text);
  } catch (const toml::parse_error&) { parsed = toml::table{{"v", text}}; }
  toml::table* t = &root;
  std::stringstream ss(key);
  std::string part, next;
  std::getline(ss, part, '.');
  while (std::getline(ss, next, '.')) {
    if (!t->contains(part)) t->insert(part, toml::table{});
    toml::node* n = t->get(part);
    if (!n->is_table()) throw InputError("--set " + key + ": '" + part + "' is not a table");
    t = n->as_table();
    part = next;
  }
  t->insert_or_assign(part, *parsed.get("v"));
  // Choosing a mesh source on the command line replaces the scene's own (the built-in brick's size n with it).
  if (key == "mesh.file" || key == "mesh.geo" || key == "mesh.edp" || key == "mesh.generator") {
    if (key != "mesh.generator" && t->contains("generator")) t->erase("n");
    for (const char* other : {"file", "geo", "edp", "generator"})
      if ("mesh." + std::string(other) != key) t->erase(other);
    if (key == "mesh.file" || key == "mesh.generator") t->erase("parameters");  // the replaced script's
  }
}

FrictionLaw parse_law(const toml::table& fr) {
  FrictionLaw law;
  // Keys of every law are accepted whatever the law (so `--set friction.law=none` works on a
  // scene written for "ramp"); the chosen law's own keys are the ones read.
  check_keys(fr, "friction", {"model", "law", "slip_bound", "value", "high", "low", "t0", "param", "points"});
  // A [friction] that sets anything but no law was solved frictionless without a word (model =
  // "coulomb" with value = 0.3: friction_model "none" in summary.json, exit 0).
  if (!fr.empty() && !fr.contains("law")) {
    std::string given;
    for (const auto& [key, node] : fr) given += std::string(given.empty() ? "" : ", ") + std::string(key.str());
    throw InputError("friction.law is missing: [friction] sets " + given +
                     " but no law, which would solve the contact frictionless; add law = \"constant\" (with value "
                     "= F), \"ramp\" (high, low, t0, param), \"table\" (points) or \"none\"");
  }
  const std::string kind = get_string(fr, "friction", "law", "none");
  const std::string w = "friction";
  if (kind == "none") {
    law.kind = FrictionLaw::Kind::None;
  } else if (kind == "constant") {
    law.kind = FrictionLaw::Kind::Constant;
    law.value = get_number(fr, w, "value", 0, true);
  } else if (kind == "ramp") {
    law.kind = FrictionLaw::Kind::Ramp;
    law.high = get_number(fr, w, "high", 0.3);
    law.low = get_number(fr, w, "low", 0.2);
    law.t0 = get_number(fr, w, "t0", 1e-5);
    law.param = get_number(fr, w, "param", 6e4);
  } else if (kind == "table") {
    law.kind = FrictionLaw::Kind::Table;
    const toml::node* pts = fr.get("points");
    if (!pts || !pts->is_array()) throw InputError("friction.points must be a list of [t, F] pairs");
    for (const auto& p : *pts->as_array()) {
      if (!p.is_array() || p.as_array()->size() != 2)
        throw InputError("friction.points must be a list of [t, F] pairs");
      const auto t = (*p.as_array())[0].value<double>(), f = (*p.as_array())[1].value<double>();
      if (!t || !f) throw InputError("friction.points must hold numbers");
      law.points.emplace_back(*t, *f);
    }
  } else {
    throw InputError("friction.law must be one of none, constant, ramp, table; got '" + kind + "'");
  }
  law.validate();
  return law;
}

// [mesh]: exactly one source (a file, a gmsh .geo, a FreeFEM .edp or the built-in paper brick).
void parse_mesh(const toml::table& mesh, const std::filesystem::path& base, Scene& s) {
  check_keys(mesh, "mesh", {"file", "geo", "edp", "parameters", "generator", "n", "trusted"});
  if (mesh.contains("trusted")) {
    const auto v = mesh["trusted"].value<bool>();
    if (!v || !mesh["trusted"].is_boolean()) throw InputError("mesh.trusted must be true or false");
    s.mesh.trusted = *v;
  }
  const int sources = mesh.contains("file") + mesh.contains("geo") + mesh.contains("edp") + mesh.contains("generator");
  if (sources != 1) throw InputError("[mesh] needs exactly one of: file, geo, edp, generator");
  if (mesh.contains("file")) s.mesh.file = resolve(base, get_string(mesh, "mesh", "file", ""));
  if (mesh.contains("geo")) s.mesh.geo = resolve(base, get_string(mesh, "mesh", "geo", ""));
  if (mesh.contains("edp")) s.mesh.edp = resolve(base, get_string(mesh, "mesh", "edp", ""));
  s.mesh.generator = get_string(mesh, "mesh", "generator", "");
  if (!s.mesh.generator.empty() && s.mesh.generator != "paper_brick")
    throw InputError("mesh.generator must be 'paper_brick', got '" + s.mesh.generator + "'");
  if (mesh.contains("n") && s.mesh.generator.empty())  // `--set mesh.n=32` on a .geo scene meshed n = 16 silently
    throw InputError(key_at("mesh.n", mesh.get("n")) +
                     " is the size of the built-in brick (mesh.generator = "
                     "\"paper_brick\"), which this scene does not use: " +
                     (mesh.contains("file")
                          ? std::string("its mesh is a file, which has no size to set")
                          : "its mesh script takes its sizes from mesh.parameters (e.g. --set mesh.parameters.n=" +
                                std::to_string(mesh["n"].value<long long>().value_or(0)) +
                                " where the script reads n)"));
  s.mesh.n = get_int(mesh, "mesh", "n", 4, 1, 64);  // n = 64: 3.9M tets, ~2.4M dofs
  if (const toml::table* params = table_at(mesh, "parameters"))
    for (const auto& [k, v] : *params)
      s.mesh.parameters[std::string(k.str())] = get_number(*params, "mesh.parameters", std::string(k.str()), 0);
  // Parameters go to a mesh script; beside a file or the built-in brick they were ignored with exit 0
  // (`--set mesh.parameters.n=4` on a scene whose mesh is a file solved its n = 5 mesh, nothing said).
  if (mesh.contains("parameters") && (mesh.contains("file") || mesh.contains("generator")))
    throw InputError(key_at("mesh.parameters", mesh.get("parameters")) +
                     " is read by a mesh script (mesh.geo, mesh.edp), but this scene's mesh is " +
                     (mesh.contains("file") ? std::string("a file, which has no parameters to set")
                                            : std::string("the built-in brick, whose size is mesh.n")) +
                     ": they would be ignored; remove them, or mesh the geometry from its script");
}

// The keys of [friction] given that law `kind` under `model` does not read: the other laws' parameters,
// and slip_bound without a law or under Coulomb's model (whose bound is the normal pressure; 0 allowed).
std::vector<std::string> keys_the_law_does_not_read(const toml::table& fr, FrictionLaw::Kind kind,
                                                    FrictionModel model) {
  using Kind = FrictionLaw::Kind;
  const std::vector<std::pair<const char*, std::vector<Kind>>> readers = {
      {"value", {Kind::Constant}},
      {"high", {Kind::Ramp}},
      {"low", {Kind::Ramp}},
      {"t0", {Kind::Ramp}},
      {"param", {Kind::Ramp}},
      {"points", {Kind::Table}},
      {"slip_bound", {Kind::Constant, Kind::Ramp, Kind::Table}}};
  std::vector<std::string> unread;
  for (const auto& [key, kinds] : readers) {
    const bool read = std::find(kinds.begin(), kinds.end(), kind) != kinds.end() &&
                      (key != std::string("slip_bound") || model == FrictionModel::Tresca);
    if (fr.contains(key) && !read) unread.emplace_back(key);
  }
  return unread;
}

// [friction] (optional: none given is frictionless): the law of F, Tresca's bound g or Coulomb's.
void parse_friction(const toml::table* fr, Scene& s) {
  static const toml::table empty;
  s.law = parse_law(fr ? *fr : empty);
  const std::string model = fr ? get_string(*fr, "friction", "model", "tresca") : "tresca";
  if (!value_of(model, kFrictionModelNames, s.friction_model))
    throw InputError("friction.model must be " + names_list(kFrictionModelNames) + ", got '" + model + "'");
  s.slip_bound = fr ? get_number(*fr, "friction", "slip_bound", 0) : 0;
  if (s.slip_bound < 0) throw InputError("friction.slip_bound must be >= 0 (a stress), got " + number(s.slip_bound));
  if (s.friction_model == FrictionModel::Coulomb && s.slip_bound != 0)
    throw InputError(
        "friction.slip_bound is Tresca's given bound g; with model 'coulomb' the bound is the computed "
        "normal pressure: remove slip_bound (or set it to 0), or use model = \"tresca\"");
  if (fr) s.friction_keys_not_read = keys_the_law_does_not_read(*fr, s.law.kind, s.friction_model);
  if (s.friction_model == FrictionModel::Tresca && s.law.kind != FrictionLaw::Kind::None && fr &&
      !fr->contains("slip_bound"))
    throw InputError("friction.slip_bound (g, a stress in the scene's units) is required with law '" + s.law.name() +
                     "' (or model = \"coulomb\", whose bound is the normal pressure)");
}

// [contact]: the foundation plane and the cells' size H (a length, a multiple of h, or "auto").
void parse_contact(const toml::table& ct, Scene& s) {
  check_keys(ct, "contact", {"cell_size", "plane_point", "plane_normal"});
  const Eigen::Vector3d plane_point =
      ct.contains("plane_point") ? get_vector(ct.get("plane_point"), "contact.plane_point") : Eigen::Vector3d::Zero();
  const Eigen::Vector3d plane_normal = ct.contains("plane_normal")
                                           ? get_vector(ct.get("plane_normal"), "contact.plane_normal")
                                           : Eigen::Vector3d::UnitZ();
  s.foundation = FoundationFrame::from_plane(plane_point, plane_normal);
  if (const toml::node* n = ct.get("cell_size")) {
    s.cell_size_auto = n->is_string() && *n->value<std::string>() == "auto";
    if (s.cell_size_auto) {
      s.cell_size = 2;
      s.cell_size_relative = true;
    } else if (n->is_string()) {
      std::string v = *n->value<std::string>();
      if (v.empty() || v.back() != 'h')
        throw InputError("contact.cell_size must be a length (m), a multiple of h like \"2h\" or \"auto\", got '" + v +
                         "'");
      v.pop_back();
      try {
        std::size_t used = 0;
        s.cell_size = v.empty() ? 1.0 : std::stod(v, &used);
        if (!v.empty() && used != v.size()) throw std::invalid_argument(v);
      } catch (const std::exception&) { throw InputError("contact.cell_size: cannot read '" + v + "h'"); }
      s.cell_size_relative = true;
    } else {
      s.cell_size = get_number(ct, "contact", "cell_size", 0);
      s.cell_size_relative = false;
    }
    if (!(s.cell_size > 0) || !std::isfinite(s.cell_size)) throw InputError("contact.cell_size must be positive");
  }
}

// [solver]: every key a field of SolverSettings (scene.hpp), with its default there.
void parse_solver(const toml::table& sv, const std::filesystem::path& base, Scene& s) {
  check_keys(sv, "solver",
             {"qp_rtol", "qp_max_iterations", "fixed_point_tol", "fixed_point_max_iter", "qp", "qp_scaling",
              "qp_precision", "fixed_point", "anderson_depth", "fixed_point_tail_err", "fixed_point_newton",
              "fixed_point_prediction", "qp_rtol_per_err", "schur", "inexact_fixed_point", "reference_factorization",
              "out_of_core_dir", "qp_newton_systems", "qp_cg_preconditioner"});
  auto& o = s.solver;
  o.qp_rtol = get_number(sv, "solver", "qp_rtol", o.qp_rtol);
  o.qp.max_iterations = get_int(sv, "solver", "qp_max_iterations", o.qp.max_iterations, 1, 100000000);
  o.fixed_point_tol = get_number(sv, "solver", "fixed_point_tol", o.fixed_point_tol);
  o.fixed_point_max_iter = get_int(sv, "solver", "fixed_point_max_iter", o.fixed_point_max_iter, 1, 100000);
  o.anderson_depth = get_int(sv, "solver", "anderson_depth", o.anderson_depth, 1, 50);
  o.qp_rtol_per_err = get_number(sv, "solver", "qp_rtol_per_err", o.qp_rtol_per_err);
  o.fixed_point_tail_err = get_number(sv, "solver", "fixed_point_tail_err", o.fixed_point_tail_err);
  if (!(o.fixed_point_tail_err >= 0 && o.fixed_point_tail_err < 1))
    throw InputError("solver.fixed_point_tail_err must lie in [0, 1) (0: no tail, the relaxation to the end)");
  if (!(o.qp_rtol > 0 && o.qp_rtol < 1)) throw InputError("solver.qp_rtol must lie in (0, 1)");
  if (!(o.qp_rtol_per_err >= 0 && o.qp_rtol_per_err < 1))
    throw InputError("solver.qp_rtol_per_err must lie in [0, 1) (0: every step at qp_rtol)");
  if (!(o.fixed_point_tol > 0 && o.fixed_point_tol < 1)) throw InputError("solver.fixed_point_tol must lie in (0, 1)");
  get_enum(sv, "solver", "qp", kQpVariantNames, o.qp.variant);
  get_enum(sv, "solver", "qp_scaling", kQpScalingNames, o.qp.scaling);
  get_enum(sv, "solver", "qp_precision", kQpPrecisionNames, o.qp.precision);
  get_enum(sv, "solver", "qp_newton_systems", kNewtonSystemsNames, o.qp.newton_systems);
  get_enum(sv, "solver", "qp_cg_preconditioner", kCgPreconditionerNames, o.qp.cg_preconditioner);
  get_enum(sv, "solver", "schur", kDualMethodNames, o.dual_method);
  get_enum(sv, "solver", "fixed_point", kFixedPointVariantNames, o.fixed_point);
  for (const auto& [key, target] : {std::pair<const char*, bool*>{"inexact_fixed_point", &o.inexact_fixed_point},
                                    {"fixed_point_newton", &o.fixed_point_newton},
                                    {"fixed_point_prediction", &o.fixed_point_prediction},
                                    {"reference_factorization", &o.reference_factorization}}) {
    if (!sv.contains(key)) continue;
    const auto v = sv[key].value<bool>();
    if (!v || !sv[key].is_boolean()) throw InputError(std::string("solver.") + key + " must be true or false");
    *target = *v;
  }
  if (sv.contains("out_of_core_dir")) o.out_of_core_dir = out_of_core_dir(base, sv);
}

// [output]: the folder, the steps written and the units of the reports.
void parse_output(const toml::table& out, const std::filesystem::path& base, Scene& s) {
  check_keys(out, "output", {"dir", "steps", "units", "vtu"});
  if (out.contains("dir")) s.output.dir = resolve(base, get_string(out, "output", "dir", ""));
  get_enum(out, "output", "steps", kStepOutputNames, s.output.steps);
  get_enum(out, "output", "units", kUnitSystemNames, s.output.units);
  get_enum(out, "output", "vtu", kVtuFormatNames, s.output.vtu);
}

}  // namespace

Scene parse_scene_text(const std::string& text, const std::filesystem::path& base,
                       const std::vector<std::string>& overrides) {
  toml::table root;
  try {
    root = toml::parse(text, std::string_view(kSceneSource));
  } catch (const toml::parse_error& e) {
    std::ostringstream msg;
    msg << "scene is not valid TOML (line " << e.source().begin.line << "): " << e.description();
    throw InputError(msg.str());
  }
  for (const auto& o : overrides) apply_override(root, o);
  check_keys(root, "",
             {"mesh", "material", "boundary", "friction", "contact", "solver", "output", "crosscheck", "expect"});
  Scene s;
  std::ostringstream echo;
  echo << root;
  s.echo = echo.str();
  const toml::table* mesh = table_at(root, "mesh");
  if (!mesh) throw InputError("the scene has no [mesh] table");
  parse_mesh(*mesh, base, s);
  const toml::table* mat = table_at(root, "material");
  if (!mat) throw InputError("the scene has no [material] table");
  parse_material(*mat, s);
  const toml::table* bnd = table_at(root, "boundary");
  if (!bnd) throw InputError("the scene has no [boundary] table");
  parse_boundary(*bnd, s);
  parse_friction(table_at(root, "friction"), s);
  if (const toml::table* ct = table_at(root, "contact")) parse_contact(*ct, s);
  if (const toml::table* sv = table_at(root, "solver")) parse_solver(*sv, base, s);
  if (const toml::table* out = table_at(root, "output")) parse_output(*out, base, s);
  return s;
}

UnitLabels unit_labels(UnitSystem units) {
  switch (units) {
    case UnitSystem::MillimetreNewtonMegapascal:
      return {"mm", "N", "MPa"};
    case UnitSystem::MetreKilonewtonKilopascal:
      return {"m", "kN", "kPa"};
    case UnitSystem::MetreNewtonPascal:
      break;
  }
  return {"m", "N", "Pa"};
}

double pascal_per_stress_unit(UnitSystem units) {
  switch (units) {
    case UnitSystem::MillimetreNewtonMegapascal:
      return 1e6;
    case UnitSystem::MetreKilonewtonKilopascal:
      return 1e3;
    case UnitSystem::MetreNewtonPascal:
      break;
  }
  return 1;
}

namespace {

// The index in scene.regions of each tetrahedron's region, -1 outside every region. Throws InputError
// for a region whose group is missing, not a volume group, empty, or overlapping another.
std::vector<int> region_of_each_tet(const Scene& scene, const Mesh& mesh) {
  std::vector<int> region_of(mesh.tets.size(), -1);
  for (std::size_t k = 0; k < scene.regions.size(); ++k) {
    const auto& region = scene.regions[k];
    const PhysicalGroup* g = mesh.find_group(region.group, 3);
    if (g == nullptr)
      throw InputError("material.region '" + region.group +
                       "' is not a volume (3-D) group of the mesh; it has: " + mesh.describe_groups());
    const std::vector<std::size_t> tets = mesh.tets_of_group(g->tag);
    if (tets.empty()) throw InputError("material.region '" + region.group + "' holds no tetrahedra");
    for (const std::size_t e : tets) {
      if (region_of[e] >= 0)
        throw InputError("material.region '" + region.group + "' and '" + scene.regions[region_of[e]].group +
                         "' both claim tetrahedron " + std::to_string(mesh.tet_tags[e]) +
                         " (their volume groups overlap): give each tetrahedron one material, with regions that "
                         "do not overlap");
      region_of[e] = static_cast<int>(k);
    }
  }
  return region_of;
}

}  // namespace

TetMaterials tet_materials(const Scene& scene, const Mesh& mesh) {
  if (scene.regions.empty()) return TetMaterials(scene.material);
  const std::vector<int> region_of = region_of_each_tet(scene, mesh);
  std::vector<Material> per_tet(mesh.tets.size(), scene.material);
  for (std::size_t e = 0; e < per_tet.size(); ++e)
    if (region_of[e] >= 0) per_tet[e] = scene.regions[static_cast<std::size_t>(region_of[e])].material;
  return TetMaterials(std::move(per_tet));
}

BodyForce tet_body_forces(const Scene& scene, const Mesh& mesh) {
  const bool any = std::any_of(scene.regions.begin(), scene.regions.end(),
                               [](const MaterialRegion& r) { return r.body_force.has_value(); });
  if (!any) return BodyForce(scene.body_force);
  const std::vector<int> region_of = region_of_each_tet(scene, mesh);
  std::vector<Eigen::Vector3d> per_tet(mesh.tets.size(), scene.body_force);
  for (std::size_t e = 0; e < per_tet.size(); ++e)
    if (region_of[e] >= 0)
      if (const auto& own = scene.regions[static_cast<std::size_t>(region_of[e])].body_force) per_tet[e] = *own;
  return BodyForce(std::move(per_tet));
}

void resolve_total_forces(Scene& scene, const Mesh& mesh) {
  for (Traction& load : scene.tractions) {
    if (!load.total_force) continue;
    const Eigen::Vector3d force = *load.total_force;
    load.total_force.reset();
    if (!mesh.find_group(load.group, 2)) continue;  // missing, or not a surface: check_mesh_meaning names it
    double area = 0;
    for (const int t : mesh.triangles_of_group(load.group))
      area += triangle_area(mesh, mesh.triangles[static_cast<std::size_t>(t)]);
    if (!(area > 0))
      throw InputError("boundary.force on '" + load.group +
                       "': the group has no area to spread the force over (its triangles are degenerate)");
    load.value = force / area;
  }
}

MeshRoles mesh_roles(const Scene& scene) {
  MeshRoles roles{scene.clamped, scene.contact, {}, {}, {}};
  for (const auto& d : scene.displacements) roles.displaced.push_back(d.group);
  for (const auto& t : scene.tractions) roles.loaded.push_back(t.group);
  roles.user_point = [frame = scene.user_frame](const Eigen::Vector3d& x) { return frame.to_global_point(x); };
  return roles;
}

Scene load_scene(const std::filesystem::path& path, const std::vector<std::string>& overrides) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec))
    throw InputError("scene '" + path.string() + "' is a directory, not a scene file");
  if (std::filesystem::exists(path, ec) && !std::filesystem::is_regular_file(path, ec))
    throw InputError("scene '" + path.string() + "' is not a regular file");
  std::ifstream in(path);
  if (!in) throw InputError("cannot open scene file '" + path.string() + "'");
  std::stringstream buf;
  buf << in.rdbuf();
  Scene s;
  try {
    s = parse_scene_text(buf.str(), path.parent_path(), overrides);
  } catch (const InputError& e) {  // which file, where a command line names several (the scene, --mesh)
    throw InputError("scene '" + path.string() + "': " + e.what());
  }
  s.source = path;
  return s;
}

}  // namespace contact3d
