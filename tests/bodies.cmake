# Issue #4: coarse body scenes solved end to end (converged, KKT residuals <= 1e-3, small
# ‖w_hn⁺‖), and the CLI rejecting a partition that violates (5.1) with exit code 2.
add_test(NAME bodies_holed_coarse
  COMMAND ${CONTACT3D_PYTHON} ${CMAKE_SOURCE_DIR}/pipeline/bodies_report.py check --bin $<TARGET_FILE:contact3d>
          --scene ${CMAKE_SOURCE_DIR}/pipeline/scenes/holed.toml --out ${CMAKE_BINARY_DIR}/bodies/holed
          --set mesh.parameters.h=0.15)
add_test(NAME bodies_ufoot_coarse
  COMMAND ${CONTACT3D_PYTHON} ${CMAKE_SOURCE_DIR}/pipeline/bodies_report.py check --bin $<TARGET_FILE:contact3d>
          --scene ${CMAKE_SOURCE_DIR}/pipeline/scenes/ufoot.toml --out ${CMAKE_BINARY_DIR}/bodies/ufoot
          --set mesh.parameters.h=0.15)
# The example of a body held by contact alone in every direction (nothing prescribed; friction holds
# the slides and the turn about the normal, Coulomb's bound): solved end to end from its scene file.
add_test(NAME bodies_free_brick_coarse
  COMMAND ${CONTACT3D_PYTHON} ${CMAKE_SOURCE_DIR}/pipeline/bodies_report.py check --bin $<TARGET_FILE:contact3d>
          --scene ${CMAKE_SOURCE_DIR}/pipeline/scenes/free_brick.toml --out ${CMAKE_BINARY_DIR}/bodies/free_brick
          --set mesh.parameters.n=4)
add_test(NAME bodies_stability_rejected
  COMMAND ${CONTACT3D_PYTHON} ${CMAKE_SOURCE_DIR}/pipeline/bodies_report.py stability --bin $<TARGET_FILE:contact3d>
          --scene ${CMAKE_SOURCE_DIR}/pipeline/scenes/wedge.toml --out ${CMAKE_BINARY_DIR}/bodies/wedge_unstable)
# Random bodies (pipeline/random_bodies.py), seeds 20 to 35: every outcome agrees with what the loads
# demand (converge, refuse a frictionless slide, or either). Seed 27, a holed plate held by contact
# alone with u_x held on its sides and sheared (Coulomb, F = 0.83), was refused as tipping before the
# equality solve kept the balance conditions that do not depend on the motions' basis.
add_test(NAME random_bodies_seeds_20_to_35
  COMMAND ${CONTACT3D_PYTHON} ${CMAKE_SOURCE_DIR}/pipeline/random_bodies.py --bin $<TARGET_FILE:contact3d>
          --seeds 20 35 --out ${CMAKE_BINARY_DIR}/random_bodies/random_bodies.md)
set_tests_properties(random_bodies_seeds_20_to_35 PROPERTIES TIMEOUT 600)
