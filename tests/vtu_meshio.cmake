# ParaView output read back with meshio: array names, sizes and values of body.vtu and
# contact.vtu against contact_nodes.csv, and solution.pvd against history.csv (brick, n = 4).
add_test(NAME vtu_meshio_brick
  COMMAND ${CONTACT3D_PYTHON} ${CMAKE_SOURCE_DIR}/tests/check_vtu.py --bin $<TARGET_FILE:contact3d>
          --scene ${CMAKE_SOURCE_DIR}/pipeline/scenes/paper_brick.toml --n 4)
set_tests_properties(vtu_meshio_brick PROPERTIES TIMEOUT 120)

# run_scene.py end to end with figures (brick, n = 4): every figure, report.md with its tables.
add_test(NAME run_scene_figures_brick
  COMMAND ${CONTACT3D_PYTHON} ${CMAKE_SOURCE_DIR}/tests/check_figures.py --bin $<TARGET_FILE:contact3d>
          --scene ${CMAKE_SOURCE_DIR}/pipeline/scenes/paper_brick.toml)
set_tests_properties(run_scene_figures_brick PROPERTIES TIMEOUT 120)

# solution.pvd as ParaView groups it (time step -> parts), every file read by VTK's own XML reader
# (python3-vtk9): body and contact face at every step with every field, stress tensor, signs; a
# negative check rejects the old collection layout; output.vtu = binary gives the same arrays in VTK,
# meshio and pipeline/c3d/vtu.py.
add_test(NAME pvd_vtk_reader_brick
  COMMAND ${CONTACT3D_PYTHON} ${CMAKE_SOURCE_DIR}/tests/check_pvd_vtk.py --bin $<TARGET_FILE:contact3d>
          --scene ${CMAKE_SOURCE_DIR}/pipeline/scenes/paper_brick.toml --n 4)
set_tests_properties(pvd_vtk_reader_brick PROPERTIES TIMEOUT 120)
# The written contact tractions integrate over Γc to summary.json's contact force, on a curved face too.
add_test(NAME contact_tractions_integrate_to_the_contact_force
         COMMAND ${CONTACT3D_PYTHON} ${CMAKE_SOURCE_DIR}/tests/contact_tractions_integrate.py $<TARGET_FILE:contact3d>
                 ${CMAKE_SOURCE_DIR} ${CMAKE_BINARY_DIR}/cli-tests/tractions-integrate)
set_tests_properties(contact_tractions_integrate_to_the_contact_force PROPERTIES TIMEOUT 120)
