# End-to-end run of the command line on the paper's mesh (n = 4): mesh -> solve -> output files.
add_test(NAME cli_end_to_end_brick_n4
         COMMAND ${CONTACT3D_PYTHON} ${CMAKE_SOURCE_DIR}/tests/cli_end_to_end.py $<TARGET_FILE:contact3d> ${CMAKE_SOURCE_DIR})
