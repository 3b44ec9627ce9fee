# Python lint of the pipeline and the test drivers (pyflakes: unused names, undefined names,
# f-strings without placeholders). Part of `make test`, so CI runs it.
add_test(NAME python_lint
  COMMAND ${CONTACT3D_PYTHON} -m pyflakes ${CMAKE_SOURCE_DIR}/pipeline ${CMAKE_SOURCE_DIR}/tests ${CMAKE_SOURCE_DIR}/fuzz)
# Includes only point down the layers of solver/ (base -> mesh -> ... -> io -> app).
add_test(NAME include_layers COMMAND ${CONTACT3D_PYTHON} ${CMAKE_SOURCE_DIR}/tests/check_layers.py ${CMAKE_SOURCE_DIR})
# The C++ layout is .clang-format's (Google, 120 columns): a change that drifts from it fails here.
find_program(CLANG_FORMAT NAMES clang-format clang-format-14)
if(CLANG_FORMAT)
  file(GLOB_RECURSE CONTACT3D_FORMATTED_SOURCES CONFIGURE_DEPENDS
    ${CMAKE_SOURCE_DIR}/solver/*.cpp ${CMAKE_SOURCE_DIR}/solver/*.hpp ${CMAKE_SOURCE_DIR}/tests/*.cpp
    ${CMAKE_SOURCE_DIR}/tests/*.hpp ${CMAKE_SOURCE_DIR}/fuzz/*.cpp ${CMAKE_SOURCE_DIR}/pipeline/bench/*.cpp)
  add_test(NAME cpp_format COMMAND ${CLANG_FORMAT} --dry-run -Werror ${CONTACT3D_FORMATTED_SOURCES})
endif()
