# Energy-norm error measure of the benchmark (pipeline/energy_error.py): on the paper brick,
# n = 4 interpolated onto n = 8, a linear displacement field is reproduced exactly (interpolation
# and energy error ~ 0), a(u,u) of a linear field equals volume * eps:C:eps, a point outside the
# coarse mesh is an error, and the real n = 4 vs n = 8 error is in (0, 1). About 1 s.
add_test(NAME energy_error_self_test
  COMMAND ${CONTACT3D_PYTHON} ${CMAKE_SOURCE_DIR}/pipeline/energy_error.py --self-test
          --bin $<TARGET_FILE:contact3d>)
set_tests_properties(energy_error_self_test PROPERTIES TIMEOUT 120)
