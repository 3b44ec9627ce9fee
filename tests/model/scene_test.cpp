// Scene parsing: overrides, defaults, and the inputs that must be refused with a message.
#include <gtest/gtest.h>

#include "base/errors.hpp"
#include "mesh/brick_generator.hpp"
#include "model/scene.hpp"
#include "test_support.hpp"

using namespace contact3d;

namespace {
Scene parse(const std::vector<std::string>& overrides) {
  return parse_scene_text(contact3d::testing::paper_scene_text(), ".", overrides);
}
std::string error_of(const std::vector<std::string>& overrides) {
  try {
    parse(overrides);
  } catch (const InputError& e) { return e.what(); }
  return "";
}
}  // namespace

TEST(Scene, DefaultsAndOverrides) {
  const Scene s = parse({});
  EXPECT_TRUE(s.cell_size_relative);
  EXPECT_DOUBLE_EQ(s.cell_size, 2.0);
  EXPECT_EQ(s.solver.qp.scaling, QpScaling::Jacobi);
  EXPECT_EQ(s.solver.qp.newton_systems, NewtonSystems::Auto);
  EXPECT_EQ(parse({"solver.qp_newton_systems=\"reduced\""}).solver.qp.newton_systems, NewtonSystems::Reduced);
  EXPECT_EQ(parse({}).solver.qp.cg_preconditioner, CgPreconditioner::Lumped);
  EXPECT_EQ(parse({"solver.qp_cg_preconditioner=\"diagonal\""}).solver.qp.cg_preconditioner,
            CgPreconditioner::Diagonal);
  EXPECT_FALSE(s.frictionless());
  EXPECT_TRUE(parse({"friction.law=\"none\""}).frictionless());
  EXPECT_TRUE(parse({"friction.law=\"constant\"", "friction.value=0"}).frictionless());
  EXPECT_TRUE(s.cell_size_auto);  // "auto": 2h, and 1.5h when 2h leaves the contact zone unresolved
  EXPECT_TRUE(parse({"contact.cell_size=\"auto\""}).cell_size_auto);
  EXPECT_FALSE(parse({"contact.cell_size=\"2h\""}).cell_size_auto);
  EXPECT_FALSE(parse({"contact.cell_size=0.25"}).cell_size_auto);
  EXPECT_DOUBLE_EQ(parse({"contact.cell_size=\"3h\""}).cell_size, 3.0);
  EXPECT_DOUBLE_EQ(parse({"contact.cell_size=0.25"}).cell_size, 0.25);
  EXPECT_EQ(parse({"mesh.file=\"x.msh\""}).mesh.generator, "");  // a new mesh source replaces the old
  EXPECT_TRUE(parse({"boundary.traction=[]"}).tractions.empty());
}

// output.steps = "auto" writes every step of a short run on a small mesh, not of a long fixed point
// (68 steps of a 7 920-node plate wrote 570 MB of steps/).
TEST(Scene, AutoStepOutputIsBoundedByNodesTimesSteps) {
  EXPECT_EQ(resolved(StepOutput::Auto, 4913, 7), StepOutput::All);
  EXPECT_EQ(resolved(StepOutput::Auto, 7920, 68), StepOutput::Final);
  EXPECT_EQ(resolved(StepOutput::Auto, 400000, 1), StepOutput::Final);
  EXPECT_EQ(resolved(StepOutput::All, 7920, 68), StepOutput::All);
  EXPECT_EQ(resolved(StepOutput::Final, 10, 2), StepOutput::Final);
}

TEST(Scene, RefusesWhatMakesNoSense) {
  EXPECT_NE(error_of({"contact.cell_size=\"2xyzh\""}).find("cell_size"), std::string::npos);
  EXPECT_NE(error_of({"material.poisson=0.5"}).find("poisson"), std::string::npos);
  EXPECT_NE(error_of({"material.young=nan"}).find("young"), std::string::npos);
  EXPECT_NE(error_of({"friction.slip_bound=-1"}).find("slip_bound"), std::string::npos);
  EXPECT_NE(error_of({"solver.qp_scaling=\"diagonal\""}).find("qp_scaling"), std::string::npos);
  EXPECT_NE(error_of({"solver.qp_precision=\"half\""}).find("qp_precision"), std::string::npos);
  EXPECT_NE(error_of({"solver.qp_newton_systems=\"dense\""}).find("qp_newton_systems"), std::string::npos);
  EXPECT_NE(error_of({"solver.qp_cg_preconditioner=\"ilu\""}).find("qp_cg_preconditioner"), std::string::npos);
  EXPECT_NE(error_of({"mesh.n=65"}).find("mesh.n"), std::string::npos);
  EXPECT_NE(error_of({"frobnicate=1"}).find("frobnicate"), std::string::npos);
}

// [[boundary.force]]: a resultant in N spread uniformly over its group's area (the paper brick's top
// group 'load_top'); the traction it becomes carries that resultant, in the user's frame.
TEST(Scene, TotalForceBecomesTheTractionThatCarriesIt) {
  const Scene scene = parse({"boundary.traction=[]", "boundary.force=[{group=\"load_top\", value=[3e6, 0.0, -9e7]}]"});
  ASSERT_EQ(scene.tractions.size(), 1u);
  ASSERT_TRUE(scene.tractions[0].total_force.has_value());
  EXPECT_STREQ(scene.tractions[0].scene_key(), "boundary.force");
  const Mesh mesh = make_paper_brick({scene.mesh.n});
  Scene resolved = scene;
  resolve_total_forces(resolved, mesh);
  double area = 0;
  for (const int t : mesh.triangles_of_group("load_top")) area += triangle_area(mesh, mesh.triangles[t]);
  EXPECT_FALSE(resolved.tractions[0].total_force.has_value());
  EXPECT_LT((resolved.tractions[0].value * area - Eigen::Vector3d(3e6, 0, -9e7)).norm(), 1e-6);
  EXPECT_NE(error_of({"boundary.force=[{group=\"load_top\"}]"}).find("needs a value"), std::string::npos);
  EXPECT_NE(error_of({"boundary.force=[{group=\"load_top\", value=[1.0, 2.0]}]"}).find("boundary.force.value"),
            std::string::npos);
  EXPECT_NE(error_of({"boundary.force=[{group=\"load_top\", value=[1.0, 2.0, 3.0], gradient=1}]"}).find("gradient"),
            std::string::npos);
}
