# Cross-validation against the independent FreeFEM reference (pipeline/crosscheck.py,
# pipeline/freefem/contact_ref.edp) on the paper brick at n = 4 (a few seconds in all).
#
# At n = 4 the two discretisations differ by design (contact3d: 2h x 2h multiplier cells,
# FreeFEM: nodal multipliers), measured: rel L2(Gc) 0.039 frictionless, 0.071 Tresca, 0.034
# slipdep (the scene's ramp law F(|u_t|), successive approximations on both sides); contact
# forces within 2.5% / 5% / 5.1%. The tolerances below sit just above that, so that the negative
# tests (FreeFEM tractions scaled by 1.1; for slipdep also FreeFEM's law with high and low
# swapped) must fail them. results/crosscheck/README.md has the sweeps.
set(CONTACT3D_CC ${CMAKE_SOURCE_DIR}/pipeline/crosscheck.py)
set(CONTACT3D_CC_SCENE ${CMAKE_SOURCE_DIR}/pipeline/scenes/paper_brick.toml)
set(CONTACT3D_CC_WORK ${CMAKE_BINARY_DIR}/crosscheck-tests)
set(CONTACT3D_CC_TOL_frictionless --tolerance 0.06 --force-tolerance 0.05)
set(CONTACT3D_CC_TOL_tresca --tolerance 0.10 --force-tolerance 0.08)
set(CONTACT3D_CC_TOL_slipdep --tolerance 0.05 --force-tolerance 0.08)

foreach(variant frictionless tresca slipdep)
  # contact3d and FreeFEM agree within the n = 4 tolerance
  add_test(NAME crosscheck_brick_n4_${variant}
    COMMAND ${CONTACT3D_PYTHON} ${CONTACT3D_CC} --bin $<TARGET_FILE:contact3d> --scene ${CONTACT3D_CC_SCENE}
            --n 4 --variant ${variant} ${CONTACT3D_CC_TOL_${variant}}
            --workdir ${CONTACT3D_CC_WORK}/${variant} --report ${CONTACT3D_CC_WORK}/${variant}.md)
  set_tests_properties(crosscheck_brick_n4_${variant} PROPERTIES TIMEOUT 120 LABELS crosscheck)

  # negative test: the same check with the FreeFEM tractions scaled by 1.1 must report a
  # difference beyond tolerance (exit 1 with "CROSSCHECK FAILED: ... exceeds tolerance"),
  # not pass and not crash
  add_test(NAME crosscheck_brick_n4_${variant}_detects_perturbation
    COMMAND ${CONTACT3D_PYTHON} ${CONTACT3D_CC} --bin $<TARGET_FILE:contact3d> --scene ${CONTACT3D_CC_SCENE}
            --n 4 --variant ${variant} ${CONTACT3D_CC_TOL_${variant}} --perturb-freefem-traction 1.1
            --workdir ${CONTACT3D_CC_WORK}/${variant}-perturbed --report ${CONTACT3D_CC_WORK}/${variant}-perturbed.md)
  set_tests_properties(crosscheck_brick_n4_${variant}_detects_perturbation PROPERTIES TIMEOUT 120 LABELS crosscheck
    PASS_REGULAR_EXPRESSION "CROSSCHECK FAILED: paper_brick n=4 ${variant}: .* exceeds tolerance"
    FAIL_REGULAR_EXPRESSION "error:")
endforeach()

# negative test of the solution-dependent coefficient itself: FreeFEM solves with the scene's ramp
# law turned upside down (high = 0.2, low = 0.3 instead of 0.3, 0.2); contact3d keeps the scene's
# law. Measured rel L2(Gc) 0.333 > 0.05 and dFt 0.205 > 0.08: the comparison sees the law.
add_test(NAME crosscheck_brick_n4_slipdep_detects_law_perturbation
  COMMAND ${CONTACT3D_PYTHON} ${CONTACT3D_CC} --bin $<TARGET_FILE:contact3d> --scene ${CONTACT3D_CC_SCENE}
          --n 4 --variant slipdep ${CONTACT3D_CC_TOL_slipdep}
          --perturb-freefem-law high=0.2 --perturb-freefem-law low=0.3
          --workdir ${CONTACT3D_CC_WORK}/slipdep-law-perturbed --report ${CONTACT3D_CC_WORK}/slipdep-law-perturbed.md)
set_tests_properties(crosscheck_brick_n4_slipdep_detects_law_perturbation PROPERTIES TIMEOUT 120 LABELS crosscheck
  PASS_REGULAR_EXPRESSION "CROSSCHECK FAILED: paper_brick n=4 slipdep: relative L2\\(Gc\\) difference of u .* exceeds tolerance"
  FAIL_REGULAR_EXPRESSION "error:")

# a failing solver is an error (exit 2, "error: ... contact3d exited with"), never a pass
add_test(NAME crosscheck_reports_failed_solver
  COMMAND ${CONTACT3D_PYTHON} ${CONTACT3D_CC} --bin /bin/false --scene ${CONTACT3D_CC_SCENE}
          --n 4 --variant frictionless --workdir ${CONTACT3D_CC_WORK}/failing --report ${CONTACT3D_CC_WORK}/failing.md)
set_tests_properties(crosscheck_reports_failed_solver PROPERTIES TIMEOUT 120 LABELS crosscheck
  PASS_REGULAR_EXPRESSION "error: n=4 frictionless: contact3d exited with 1")

# the FreeFEM reference on its own: lifted body == plain linear solve, no penetration,
# lambda_n >= 0, Tresca bound and slip direction, vanishing bound == frictionless; the scene's
# ramp law: converged successive approximations with bounds g F(|u_t|) of the result, and the
# law with high = low = 0.3 == Tresca F = 0.3
add_test(NAME crosscheck_freefem_selftest_n4
  COMMAND ${CONTACT3D_PYTHON} ${CONTACT3D_CC} --scene ${CONTACT3D_CC_SCENE} --n 4 --validate-freefem
          --workdir ${CONTACT3D_CC_WORK}/selftest)
set_tests_properties(crosscheck_freefem_selftest_n4 PROPERTIES TIMEOUT 120 LABELS crosscheck)

# The other direction of the FreeFEM-meshed pipeline: FreeFEM meshes the paper's brick
# (geo/paper_brick.edp, the paper's five-tet split), its reference solves its own .mesh, contact3d
# reads the same .mesh (FreeFEM's labels as groups); all three variants at n = 8 within 5%
# (measured 0.9%, 1.7%, 1.1% on u; forces within 2.1%).
add_test(NAME crosscheck_freefem_made_mesh_n8
  COMMAND ${CONTACT3D_PYTHON} ${CONTACT3D_CC} --bin $<TARGET_FILE:contact3d>
          --scene ${CMAKE_SOURCE_DIR}/pipeline/scenes/paper_brick_freefem.toml --n 8
          --workdir ${CONTACT3D_CC_WORK}/freefem-mesh --report ${CONTACT3D_CC_WORK}/freefem-mesh.md)
set_tests_properties(crosscheck_freefem_made_mesh_n8 PROPERTIES TIMEOUT 300 LABELS crosscheck)

# A FreeFEM mesh given as a binary Medit file (tests/scenes/freefem_cube_meshb.toml): the reference reads its
# labels from FreeFEM's ASCII copy. Converted by gmsh, as before, every label was lost and the cube refused
# as held by nothing. Frictionless, uniform pressure: the two agree to rounding (measured 2.5e-15).
add_test(NAME crosscheck_freefem_meshb_file
  COMMAND ${CONTACT3D_PYTHON} ${CONTACT3D_CC} --bin $<TARGET_FILE:contact3d>
          --scene ${CMAKE_SOURCE_DIR}/tests/scenes/freefem_cube_meshb.toml --variant frictionless --tolerance 1e-6
          --workdir ${CONTACT3D_CC_WORK}/freefem-meshb --report ${CONTACT3D_CC_WORK}/freefem-meshb.md)
set_tests_properties(crosscheck_freefem_meshb_file PROPERTIES TIMEOUT 120 LABELS crosscheck)

# A user's problem with every kind of condition the brick lacks (pipeline/scenes/capblock.toml: two
# materials, symmetry rollers, a prescribed top displacement, a side pressure, gravity, a curved
# contact face with an initial gap) against FreeFEM on the same gmsh mesh (h = 0.05), frictionless:
# measured rel L2(Gc) 0.0089, normal force 0.21%. Without the second material in FreeFEM the normal
# force differs by 33% and u by 0.050; without the side pressure u differs by 0.021 (its tangential
# part by 105%): both must fail the tolerances below. The friction variants converge with h
# (results/crosscheck/capblock_series.md) but differ by 19% in the tangential force at this h (the
# scene's own h = 0.025: 3.6%).
set(CONTACT3D_CC_CAP ${CMAKE_SOURCE_DIR}/pipeline/scenes/capblock.toml)
add_test(NAME crosscheck_capblock_frictionless
  COMMAND ${CONTACT3D_PYTHON} ${CONTACT3D_CC} --bin $<TARGET_FILE:contact3d> --scene ${CONTACT3D_CC_CAP}
          --mesh-param h=0.05 --variant frictionless --tolerance 0.015 --force-tolerance 0.02
          --workdir ${CONTACT3D_CC_WORK}/capblock --report ${CONTACT3D_CC_WORK}/capblock.md)
set_tests_properties(crosscheck_capblock_frictionless PROPERTIES TIMEOUT 120 LABELS crosscheck)
foreach(dropped regions pressure)
  add_test(NAME crosscheck_capblock_detects_missing_${dropped}
    COMMAND ${CONTACT3D_PYTHON} ${CONTACT3D_CC} --bin $<TARGET_FILE:contact3d> --scene ${CONTACT3D_CC_CAP}
            --mesh-param h=0.05 --variant frictionless --tolerance 0.015 --force-tolerance 0.02
            --perturb-freefem-drop ${dropped}
            --workdir ${CONTACT3D_CC_WORK}/capblock-no-${dropped} --report ${CONTACT3D_CC_WORK}/capblock-no-${dropped}.md)
  set_tests_properties(crosscheck_capblock_detects_missing_${dropped} PROPERTIES TIMEOUT 120 LABELS crosscheck
    PASS_REGULAR_EXPRESSION "CROSSCHECK FAILED: capblock h=0.05 frictionless: .* exceeds tolerance"
    FAIL_REGULAR_EXPRESSION "error:")
endforeach()

# A region's own body force (tests/scenes/capblock_heavy_layer.toml: capblock's aluminium layer given
# [0, 0, -6e8] N/m³, [material]'s gravity elsewhere), stated per tetrahedron on both sides: measured rel
# L2(Gc) 0.0088, normal force 0.056%. FreeFEM told the layer weighs as [material] says: 0.0172 and 3.5%,
# which the same tolerances reject.
set(CONTACT3D_CC_HEAVY ${CMAKE_SOURCE_DIR}/tests/scenes/capblock_heavy_layer.toml)
add_test(NAME crosscheck_capblock_region_body_force
  COMMAND ${CONTACT3D_PYTHON} ${CONTACT3D_CC} --bin $<TARGET_FILE:contact3d> --scene ${CONTACT3D_CC_HEAVY}
          --mesh-param h=0.05 --variant frictionless --tolerance 0.015 --force-tolerance 0.02
          --workdir ${CONTACT3D_CC_WORK}/capblock-heavy --report ${CONTACT3D_CC_WORK}/capblock-heavy.md)
set_tests_properties(crosscheck_capblock_region_body_force PROPERTIES TIMEOUT 120 LABELS crosscheck)
add_test(NAME crosscheck_capblock_detects_missing_region_body_force
  COMMAND ${CONTACT3D_PYTHON} ${CONTACT3D_CC} --bin $<TARGET_FILE:contact3d> --scene ${CONTACT3D_CC_HEAVY}
          --mesh-param h=0.05 --variant frictionless --tolerance 0.015 --force-tolerance 0.02
          --perturb-freefem-drop region_body_forces
          --workdir ${CONTACT3D_CC_WORK}/capblock-heavy-dropped --report ${CONTACT3D_CC_WORK}/capblock-heavy-dropped.md)
set_tests_properties(crosscheck_capblock_detects_missing_region_body_force PROPERTIES TIMEOUT 120 LABELS crosscheck
  PASS_REGULAR_EXPRESSION "CROSSCHECK FAILED: capblock_heavy_layer h=0.05 frictionless: .* exceeds tolerance"
  FAIL_REGULAR_EXPRESSION "error:")

# --set reaches both sides: the heavy layer given on the command line instead of in the scene agrees as
# above (before, only contact3d read it and FreeFEM solved the plain capblock: 0.0172 and 3.5%, a failure).
# A mesh parameter set beside the swept one goes to the mesher only (contact3d refused it beside the mesh
# file it is given: a helper's T-plate could not be cross-checked with its layers through the thickness set).
add_test(NAME crosscheck_set_reaches_freefem
  COMMAND ${CONTACT3D_PYTHON} ${CONTACT3D_CC} --bin $<TARGET_FILE:contact3d> --scene ${CONTACT3D_CC_CAP}
          --mesh-param h=0.05 --variant frictionless --tolerance 0.015 --force-tolerance 0.02
          "--set=material.region=[{group=\"layer\",young=7.0e10,poisson=0.33,body_force=[0.0,0.0,-6e8]}]"
          --set mesh.parameters.R=6.0
          --workdir ${CONTACT3D_CC_WORK}/capblock-set --report ${CONTACT3D_CC_WORK}/capblock-set.md)
set_tests_properties(crosscheck_set_reaches_freefem PROPERTIES TIMEOUT 120 LABELS crosscheck)

# A flat sole beside rounded edges (pipeline/scenes/filleted_block.toml: fillets of r = 20 mm, the top
# pushed down 20 um) against FreeFEM on the same gmsh mesh (h = 8 mm), frictionless: measured rel L2(Gc)
# 0.091, normal force 2.3%, with no cell across the sole's edge (model/contact_regions.hpp); with cells
# across it (the partition before the levels) 0.232 and 5.7%, which the tolerances below reject.
add_test(NAME crosscheck_filleted_block_frictionless
  COMMAND ${CONTACT3D_PYTHON} ${CONTACT3D_CC} --bin $<TARGET_FILE:contact3d>
          --scene ${CMAKE_SOURCE_DIR}/pipeline/scenes/filleted_block.toml --variant frictionless
          --tolerance 0.12 --force-tolerance 0.04
          --workdir ${CONTACT3D_CC_WORK}/filleted_block --report ${CONTACT3D_CC_WORK}/filleted_block.md)
set_tests_properties(crosscheck_filleted_block_frictionless PROPERTIES TIMEOUT 120 LABELS crosscheck)

# Line contact on a curved face with a gap (pipeline/scenes/roller.toml: a half-cylinder on its side,
# held only by the prescribed displacement of its top; the contact strip opens with the load) against
# FreeFEM on the same gmsh mesh (h = 0.04), Tresca F = 0.3: measured rel L2(Gc) 0.0088, normal force
# 0.05%, tangential 2.4%. Cells of 2h leave this strip unresolved (11% penetration), so
# contact.cell_size = "auto" solves it again with cells of 1.5h; with cells of 2h (contact.cell_size =
# "2h") it was 0.018, 3.8% and 3.1%. Frictionless: 8% penetration, not solved again, 0.015 and 3.4%.
add_test(NAME crosscheck_roller_tresca
  COMMAND ${CONTACT3D_PYTHON} ${CONTACT3D_CC} --bin $<TARGET_FILE:contact3d>
          --scene ${CMAKE_SOURCE_DIR}/pipeline/scenes/roller.toml
          --mesh-param h=0.04 --variant tresca --tolerance 0.015 --force-tolerance 0.04
          --workdir ${CONTACT3D_CC_WORK}/roller --report ${CONTACT3D_CC_WORK}/roller.md)
set_tests_properties(crosscheck_roller_tresca PROPERTIES TIMEOUT 180 LABELS crosscheck)

# Several contact zones with gaps between them (pipeline/scenes/wavy.toml: a block whose sole is a wave of
# 0.4 mm, pushed down 0.3 mm, touching in strips around the troughs) against FreeFEM on the same gmsh mesh,
# frictionless: measured rel L2(Gc) 0.032 at h = 0.02 and 0.011 at h = 0.01, normal force 0.10% and 0.11%
# (on a structured mesh of 56 457 nodes 0.0043 and 0.13%). Coulomb (the scene's ramp) at h = 0.02: 0.037,
# normal force 2.5%, tangential 14%.
add_test(NAME crosscheck_wavy_sole_frictionless
  COMMAND ${CONTACT3D_PYTHON} ${CONTACT3D_CC} --bin $<TARGET_FILE:contact3d>
          --scene ${CMAKE_SOURCE_DIR}/pipeline/scenes/wavy.toml
          --mesh-param h=0.02 --variant frictionless --tolerance 0.05 --force-tolerance 0.01
          --workdir ${CONTACT3D_CC_WORK}/wavy --report ${CONTACT3D_CC_WORK}/wavy.md)
set_tests_properties(crosscheck_wavy_sole_frictionless PROPERTIES TIMEOUT 120 LABELS crosscheck)

# Coulomb's bound F(|u_t|)·λ_n with the scene's ramp law (variant coulomb): FreeFEM's own successive
# approximations on the nodal slip and λ_n from the same sticking start. Measured at n = 4: rel L2(Gc)
# 0.033, normal force 2.7%, tangential 0.45% (n = 8: 0.0058; n = 12: 0.0039). With FreeFEM's ramp
# upside down the difference is 0.150 in u and 11% in the tangential force: it must fail.
add_test(NAME crosscheck_brick_n4_coulomb
  COMMAND ${CONTACT3D_PYTHON} ${CONTACT3D_CC} --bin $<TARGET_FILE:contact3d> --scene ${CONTACT3D_CC_SCENE}
          --n 4 --variant coulomb --tolerance 0.05 --force-tolerance 0.05
          --workdir ${CONTACT3D_CC_WORK}/coulomb --report ${CONTACT3D_CC_WORK}/coulomb.md)
set_tests_properties(crosscheck_brick_n4_coulomb PROPERTIES TIMEOUT 120 LABELS crosscheck)
add_test(NAME crosscheck_brick_n4_coulomb_detects_law_perturbation
  COMMAND ${CONTACT3D_PYTHON} ${CONTACT3D_CC} --bin $<TARGET_FILE:contact3d> --scene ${CONTACT3D_CC_SCENE}
          --n 4 --variant coulomb --tolerance 0.05 --force-tolerance 0.05
          --perturb-freefem-law high=0.2 --perturb-freefem-law low=0.3
          --workdir ${CONTACT3D_CC_WORK}/coulomb-law-perturbed --report ${CONTACT3D_CC_WORK}/coulomb-law-perturbed.md)
set_tests_properties(crosscheck_brick_n4_coulomb_detects_law_perturbation PROPERTIES TIMEOUT 120 LABELS crosscheck
  PASS_REGULAR_EXPRESSION "CROSSCHECK FAILED: paper_brick n=4 coulomb: relative L2\\(Gc\\) difference of u .* exceeds tolerance"
  FAIL_REGULAR_EXPRESSION "error:")

# A graded mesh (pipeline/scenes/hertz_quarter_graded.toml at h_pole = 0.01: 10 mm at the pole of the
# quarter hemisphere, up to 0.15 m away) with cells following it (contact/grid_boxes.hpp) against
# FreeFEM's nodal constraints on the same mesh: measured rel L2(Γc) of u 1.2e-3, normal force 1.1e-3
# (at 7 mm: 6.2e-4 and 6.5e-4). The comparison's negative tests are those of the brick and capblock above.
add_test(NAME crosscheck_hertz_graded_mesh_frictionless
  COMMAND ${CONTACT3D_PYTHON} ${CONTACT3D_CC} --bin $<TARGET_FILE:contact3d>
          --scene ${CMAKE_SOURCE_DIR}/pipeline/scenes/hertz_quarter_graded.toml --mesh-param h_pole=0.01
          --variant frictionless --tolerance 0.01 --force-tolerance 0.01
          --workdir ${CONTACT3D_CC_WORK}/hertz_graded --report ${CONTACT3D_CC_WORK}/hertz_graded.md)
set_tests_properties(crosscheck_hertz_graded_mesh_frictionless PROPERTIES TIMEOUT 300 LABELS crosscheck)

# A body held by contact alone along the foundation's normal (pipeline/scenes/gasket.toml: a quarter
# annular gasket pressed by a pressure, two symmetry planes, nothing holding it along z), frictionless,
# at h = 0.004: measured rel L2(Γc) of u 2.0e-5, normal force 8.5e-13. FreeFEM's reference starts its
# Newton steps with the nodes touching the plane active; started with none (as before), its first system
# was singular and its answer lifted the gasket off by 7e11 m, which this test caught.
add_test(NAME crosscheck_gasket_held_by_contact_frictionless
  COMMAND ${CONTACT3D_PYTHON} ${CONTACT3D_CC} --bin $<TARGET_FILE:contact3d>
          --scene ${CMAKE_SOURCE_DIR}/pipeline/scenes/gasket.toml
          --variant frictionless --tolerance 1e-3 --force-tolerance 1e-6
          --workdir ${CONTACT3D_CC_WORK}/gasket --report ${CONTACT3D_CC_WORK}/gasket.md)
set_tests_properties(crosscheck_gasket_held_by_contact_frictionless PROPERTIES TIMEOUT 120 LABELS crosscheck)

# Coulomb's bound F·λ_n with one coefficient (variant coulomb_constant, F = 0.3; to FreeFEM a table law
# whose two points have that F), the most common frictional problem a user states. Measured at n = 4:
# rel L2(Γc) of u 0.044, normal force 2.7%, tangential 2.9% (n = 8: 0.013, 0.8%, 1.4%). FreeFEM with
# F = 0.2 instead: 0.172 in u and 14.5% in the tangential force, which must fail.
add_test(NAME crosscheck_brick_n4_coulomb_constant
  COMMAND ${CONTACT3D_PYTHON} ${CONTACT3D_CC} --bin $<TARGET_FILE:contact3d> --scene ${CONTACT3D_CC_SCENE}
          --n 4 --variant coulomb_constant --F 0.3 --tolerance 0.05 --force-tolerance 0.05
          --workdir ${CONTACT3D_CC_WORK}/coulomb_constant --report ${CONTACT3D_CC_WORK}/coulomb_constant.md)
set_tests_properties(crosscheck_brick_n4_coulomb_constant PROPERTIES TIMEOUT 120 LABELS crosscheck)
add_test(NAME crosscheck_brick_n4_coulomb_constant_detects_coefficient_perturbation
  COMMAND ${CONTACT3D_PYTHON} ${CONTACT3D_CC} --bin $<TARGET_FILE:contact3d> --scene ${CONTACT3D_CC_SCENE}
          --n 4 --variant coulomb_constant --F 0.3 --tolerance 0.05 --force-tolerance 0.05
          --perturb-freefem-law F=0.2
          --workdir ${CONTACT3D_CC_WORK}/coulomb_constant-perturbed --report ${CONTACT3D_CC_WORK}/coulomb_constant-perturbed.md)
set_tests_properties(crosscheck_brick_n4_coulomb_constant_detects_coefficient_perturbation PROPERTIES TIMEOUT 120
  LABELS crosscheck
  PASS_REGULAR_EXPRESSION "CROSSCHECK FAILED: paper_brick n=4 coulomb_constant: relative L2\\(Gc\\) difference of u .* exceeds tolerance"
  FAIL_REGULAR_EXPRESSION "error:")

# Conditions that vary in space (pipeline/scenes/twisted_puck.toml: the top face lowered and turned by a
# prescribed u(x) = value + gradient·x, a pressure rising with depth on half the mantle, a shear traction
# growing with height on the other half), Coulomb F = 0.3, against FreeFEM evaluating the same fields at
# its own nodes and quadrature points. Measured at h = 0.05: rel L2(Γc) of u 0.014, normal force 1.1e-4,
# tangential 4.2e-3. FreeFEM with every gradient dropped (the values kept): 2.8 in u and 41% in the
# tangential force, which must fail.
add_test(NAME crosscheck_twisted_puck_coulomb
  COMMAND ${CONTACT3D_PYTHON} ${CONTACT3D_CC} --bin $<TARGET_FILE:contact3d>
          --scene ${CMAKE_SOURCE_DIR}/pipeline/scenes/twisted_puck.toml
          --variant coulomb --tolerance 0.03 --force-tolerance 0.02
          --workdir ${CONTACT3D_CC_WORK}/twisted_puck --report ${CONTACT3D_CC_WORK}/twisted_puck.md)
set_tests_properties(crosscheck_twisted_puck_coulomb PROPERTIES TIMEOUT 120 LABELS crosscheck)
add_test(NAME crosscheck_twisted_puck_detects_dropped_gradients
  COMMAND ${CONTACT3D_PYTHON} ${CONTACT3D_CC} --bin $<TARGET_FILE:contact3d>
          --scene ${CMAKE_SOURCE_DIR}/pipeline/scenes/twisted_puck.toml
          --variant coulomb --tolerance 0.03 --force-tolerance 0.02 --perturb-freefem-drop gradients
          --workdir ${CONTACT3D_CC_WORK}/twisted_puck-perturbed --report ${CONTACT3D_CC_WORK}/twisted_puck-perturbed.md)
set_tests_properties(crosscheck_twisted_puck_detects_dropped_gradients PROPERTIES TIMEOUT 120 LABELS crosscheck
  PASS_REGULAR_EXPRESSION "CROSSCHECK FAILED: twisted_puck scene coulomb: relative L2\\(Gc\\) difference of u .* exceeds tolerance"
  FAIL_REGULAR_EXPRESSION "error:")

# A moved foundation plane (tests/crosscheck_tilted.py): the twisted puck turned 0.6 rad and moved, its
# plane and its fields turned with it; contact3d solves it as given, FreeFEM the body moved back onto
# z = 0. Measured: the flat scene's figures to the printed digits (rel L2(Γc) of u 1.387e-2, Fn 1.094e-4,
# Ft 4.231e-3); with FreeFEM's gradients dropped 2.8 in u, which must fail.
add_test(NAME crosscheck_tilted_twisted_puck_coulomb
  COMMAND ${CONTACT3D_PYTHON} ${CMAKE_SOURCE_DIR}/tests/crosscheck_tilted.py $<TARGET_FILE:contact3d> ${CMAKE_SOURCE_DIR}
          ${CONTACT3D_CC_WORK}/tilted --variant coulomb --tolerance 0.03 --force-tolerance 0.02)
set_tests_properties(crosscheck_tilted_twisted_puck_coulomb PROPERTIES TIMEOUT 120 LABELS crosscheck)
add_test(NAME crosscheck_tilted_twisted_puck_detects_dropped_gradients
  COMMAND ${CONTACT3D_PYTHON} ${CMAKE_SOURCE_DIR}/tests/crosscheck_tilted.py $<TARGET_FILE:contact3d> ${CMAKE_SOURCE_DIR}
          ${CONTACT3D_CC_WORK}/tilted-perturbed --variant coulomb --tolerance 0.03 --force-tolerance 0.02
          --perturb-freefem-drop gradients)
set_tests_properties(crosscheck_tilted_twisted_puck_detects_dropped_gradients PROPERTIES TIMEOUT 120 LABELS crosscheck
  PASS_REGULAR_EXPRESSION "CROSSCHECK FAILED: twisted_puck_tilted scene coulomb: relative L2\\(Gc\\) difference of u .* exceeds tolerance"
  FAIL_REGULAR_EXPRESSION "error:")

# A body whose slide along the foundation only friction holds (tests/scenes/brick_free_to_slide.toml:
# the brick's end on a roller) is refused before FreeFEM runs — its frictionless Newton start would
# be singular and spend its 100 steps failing (a cylinder of 5 000 nodes: 75 s) — with the motion named.
add_test(NAME crosscheck_refuses_a_body_held_by_friction_alone
  COMMAND ${CONTACT3D_PYTHON} ${CONTACT3D_CC} --bin $<TARGET_FILE:contact3d>
          --scene ${CMAKE_SOURCE_DIR}/tests/scenes/brick_free_to_slide.toml --variant frictionless
          --workdir ${CONTACT3D_CC_WORK}/free-to-slide --report ${CONTACT3D_CC_WORK}/free-to-slide.md)
set_tests_properties(crosscheck_refuses_a_body_held_by_friction_alone PROPERTIES TIMEOUT 60 LABELS crosscheck
  PASS_REGULAR_EXPRESSION "the FreeFEM reference cannot hold a translation along \\(0, 1, 0\\)"
  FAIL_REGULAR_EXPRESSION "FreeFEM: [0-9]+ Newton steps")

# A block pushed by its rear face (x prescribed there, the contact nodes on that face sliding with the push),
# Coulomb F = 0.3: the reference's own audit leaves the slip of nodes whose x or y is prescribed out (it
# failed on them: "slip not aligned with lambda_t", 2.9e5 Pa), and the two agree (u on Γc 2.3e-5).
add_test(NAME crosscheck_pushed_slider_coulomb
  COMMAND ${CONTACT3D_PYTHON} ${CONTACT3D_CC} --bin $<TARGET_FILE:contact3d>
          --scene ${CMAKE_SOURCE_DIR}/tests/scenes/pushed_slider.toml --variant scene
          --workdir ${CONTACT3D_CC_WORK}/pushed-slider --report ${CONTACT3D_CC_WORK}/pushed-slider.md)
set_tests_properties(crosscheck_pushed_slider_coulomb PROPERTIES TIMEOUT 120 LABELS crosscheck
  FAIL_REGULAR_EXPRESSION "error:|FAILED")

# [[boundary.force]]: the top's load given as its resultant (N), which each side spreads over the group's
# area itself (contact3d in resolve_total_forces, crosscheck.py from the mesh it reads): the same answers as
# the traction it amounts to (rel L2(Gc) 5.8e-3, Fn 1.9e-2, as the traction's), and FreeFEM's load
# scaled by 1.1 is caught.
set(CONTACT3D_CC_FORCE "--set=boundary.traction=[]" "--set=boundary.force=[{group=\"load_top\",value=[3e6,0.0,-9e7]}]")
add_test(NAME crosscheck_total_force_reaches_freefem
  COMMAND ${CONTACT3D_PYTHON} ${CONTACT3D_CC} --bin $<TARGET_FILE:contact3d> --scene ${CONTACT3D_CC_SCENE}
          --n 4 --variant frictionless --tolerance 0.01 --force-tolerance 0.03 ${CONTACT3D_CC_FORCE}
          --workdir ${CONTACT3D_CC_WORK}/total-force --report ${CONTACT3D_CC_WORK}/total-force.md)
set_tests_properties(crosscheck_total_force_reaches_freefem PROPERTIES TIMEOUT 120 LABELS crosscheck)
add_test(NAME crosscheck_total_force_detects_perturbation
  COMMAND ${CONTACT3D_PYTHON} ${CONTACT3D_CC} --bin $<TARGET_FILE:contact3d> --scene ${CONTACT3D_CC_SCENE}
          --n 4 --variant frictionless --tolerance 0.01 --force-tolerance 0.03 ${CONTACT3D_CC_FORCE}
          --perturb-freefem-traction 1.1
          --workdir ${CONTACT3D_CC_WORK}/total-force-perturbed --report ${CONTACT3D_CC_WORK}/total-force-perturbed.md)
set_tests_properties(crosscheck_total_force_detects_perturbation PROPERTIES TIMEOUT 120 LABELS crosscheck
  PASS_REGULAR_EXPRESSION "CROSSCHECK FAILED: paper_brick n=4 frictionless: .* exceeds tolerance"
  FAIL_REGULAR_EXPRESSION "error:")
