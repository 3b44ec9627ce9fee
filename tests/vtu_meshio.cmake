# ParaView output read back with meshio: array names, sizes and values of body.vtu and
# contact.vtu against contact_nodes.csv, and solution.pvd against history.csv (brick, n = 4).
add_test(NAME vtu_meshio_brick
  COMMAND ${CONTACT3D_PYTHON} ${CMAKE_SOURCE_DIR}/tests/check_vtu.py --bin $<TARGET_FILE:contact3d>
          --scene ${CMAKE_SOURCE_DIR}/pipeline/scenes/paper_brick.toml --n 4)
set_tests_properties(vtu_meshio_brick PROPERTIES TIMEOUT 120)
