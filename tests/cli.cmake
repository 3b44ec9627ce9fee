# End-to-end run of the command line on the paper's mesh (n = 4): mesh -> solve -> output files.
add_test(NAME cli_end_to_end_brick_n4
         COMMAND ${CONTACT3D_PYTHON} ${CMAKE_SOURCE_DIR}/tests/cli_end_to_end.py $<TARGET_FILE:contact3d> ${CMAKE_SOURCE_DIR})

# The FreeFEM-meshed pipeline ([mesh] edp): FreeFem++ meshes the paper brick at n = 4, our Medit
# reader reads it, and the solve equals the built-in generator's (same n_p, n_d, it, n_mult, u).
add_test(NAME freefem_meshed_brick_n4
         COMMAND ${CONTACT3D_PYTHON} ${CMAKE_SOURCE_DIR}/tests/freefem_mesh_pipeline.py $<TARGET_FILE:contact3d> ${CMAKE_SOURCE_DIR} 4)

# A symmetry plane ([[boundary.displacement]] y = 0) on half the FreeFEM-meshed brick equals the
# whole brick on its half, with balanced resultant forces (issue 14).
add_test(NAME symmetry_half_brick_n4
         COMMAND ${CONTACT3D_PYTHON} ${CMAKE_SOURCE_DIR}/tests/symmetry_half_brick.py $<TARGET_FILE:contact3d> ${CMAKE_SOURCE_DIR} 4)
