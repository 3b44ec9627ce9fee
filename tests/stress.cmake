# A fast subset of the stress suite (pipeline/stress.py; the whole suite is `make stress`):
# unit invariance at E = 1 Pa, body size 1e-3 m, lift-off, and the (5.1) rejection of H = 0.25h.
add_test(NAME stress.subset
  COMMAND ${CONTACT3D_PYTHON} ${CMAKE_SOURCE_DIR}/pipeline/stress.py --bin $<TARGET_FILE:contact3d>
          --out ${CMAKE_BINARY_DIR}/stress_subset --only units_E=1Pa size_L0.001m lift_off H_too_fine g_zero)
set_tests_properties(stress.subset PROPERTIES TIMEOUT 900 LABELS stress)
