# Python lint of the pipeline and the test drivers (pyflakes: unused names, undefined names,
# f-strings without placeholders). Part of `make test`, so CI runs it.
add_test(NAME python_lint
  COMMAND ${CONTACT3D_PYTHON} -m pyflakes ${CMAKE_SOURCE_DIR}/pipeline ${CMAKE_SOURCE_DIR}/tests ${CMAKE_SOURCE_DIR}/fuzz)
# Includes only point down the layers of solver/ (base -> mesh -> ... -> io -> app).
add_test(NAME include_layers COMMAND ${CONTACT3D_PYTHON} ${CMAKE_SOURCE_DIR}/tests/check_layers.py ${CMAKE_SOURCE_DIR})
