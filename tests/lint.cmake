# Python lint of the pipeline and the test drivers (pyflakes: unused names, undefined names,
# f-strings without placeholders). Part of `make test`, so CI runs it.
add_test(NAME python_lint
  COMMAND ${CONTACT3D_PYTHON} -m pyflakes ${CMAKE_SOURCE_DIR}/pipeline ${CMAKE_SOURCE_DIR}/tests ${CMAKE_SOURCE_DIR}/fuzz)
