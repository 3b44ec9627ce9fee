// Scene: everything a solve needs, read from a TOML file (pipeline/scenes/*.toml) with
// optional `--set key=value` overrides. Every option is declared once here with its default
// and unit; unknown keys, wrong types and non-finite numbers are InputErrors naming the key.
#pragma once

#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "fem/assembly.hpp"
#include "fem/elasticity.hpp"
#include "friction/friction_law.hpp"

namespace contact3d {

struct MeshSource {
  std::filesystem::path file;                 // an .msh file, or
  std::filesystem::path geo;                  // a gmsh .geo script meshed with -setnumber parameters, or
  std::map<std::string, double> parameters;
  std::string generator;                      // "paper_brick": the built-in five-tet brick
  int n = 4;                                  // generator resolution
};

enum class QpVariant { Mpgp, MpgpProjectedCG, Ssn };
// How Q = 𝔹K⁻¹𝔹ᵀ is formed: one K⁻¹ solve per row of 𝔹 (BlockSolve, the reference), from one
// factorization with the contact dofs ordered last (ContactLast: trailing block + dense
// trsm/syrk), or from the factor of [K 𝔹ᵀ; 𝔹 σI] (Augmented: multipliers last, Q = L₂₁L₂₁ᵀ).
// Auto picks by size (currently Augmented at every size measured).
enum class SchurMethod { Auto, BlockSolve, ContactLast, Augmented };
enum class QpScaling { None, Jacobi };
enum class FixedPointVariant { Plain, Anderson };

struct SolverSettings {
  double qp_rtol = 1e-6;              // ‖g̃‖ <= qp_rtol ‖h‖ (paper)
  int qp_max_iterations = 100000;
  double fixed_point_tol = 1e-4;      // err(k) <= this (paper)
  int fixed_point_max_iter = 50;
  QpVariant qp = QpVariant::Mpgp;
  QpScaling qp_scaling = QpScaling::Jacobi;  // "jacobi" (default) or "none" (the paper's plain MPGP)
  FixedPointVariant fixed_point = FixedPointVariant::Plain;
  int anderson_depth = 5;
  SchurMethod schur = SchurMethod::Auto;
  bool inexact_fixed_point = false;    // QP tolerance tied to err(k) in early fixed-point steps
  bool reference_factorization = false; // also time plain factorizations of K (time_s.reference_factorization: CHOLMOD's ordering; _nd: ours)
};

struct Scene {
  std::filesystem::path source;       // the scene file (relative paths are resolved against its folder)
  MeshSource mesh;
  Material material;
  Eigen::Vector3d body_force = Eigen::Vector3d::Zero();  // N/m³
  std::vector<std::string> clamped, contact;
  std::vector<Traction> tractions;
  double slip_bound = 0;              // g, Pa
  FrictionLaw law;
  double cell_size = 2;               // H: a length in m, or a multiple of h when relative
  bool cell_size_relative = true;
  SolverSettings solver;
  std::filesystem::path output_dir;
  std::string echo;                   // the scene as solved, TOML text (overrides applied)

  bool frictionless() const {
    return law.kind == FrictionLaw::Kind::None || slip_bound == 0 ||
           (law.kind == FrictionLaw::Kind::Constant && law.value == 0);
  }
};

// Reads the scene; `overrides` are "dotted.key=value" strings (value in TOML syntax; a bare
// word is taken as a string).
Scene load_scene(const std::filesystem::path& path, const std::vector<std::string>& overrides = {});
Scene parse_scene_text(const std::string& toml_text, const std::filesystem::path& base_dir,
                       const std::vector<std::string>& overrides = {});

}  // namespace contact3d
