# Output integrity under faults (issue 13): full disk, failed rerun, SIGTERM/SIGINT, two solves
# on one folder, an unwritable summary.json.
add_test(NAME output_integrity
  COMMAND ${CONTACT3D_PYTHON} ${CMAKE_SOURCE_DIR}/tests/check_output_integrity.py $<TARGET_FILE:contact3d> ${CMAKE_SOURCE_DIR})
set_tests_properties(output_integrity PROPERTIES LABELS errors TIMEOUT 600)
