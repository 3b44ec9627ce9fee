// Small helpers for writing VTK XML UnstructuredGrid (.vtu, ASCII) and ParaView collection
// (.pvd) files, shared by the results writer and the per-step writer.
#pragma once

#include <charconv>
#include <cstddef>
#include <ostream>
#include <string>
#include <type_traits>

namespace contact3d::vtu {

// Appends `v` as text: integers exactly, floating point as printf's %.<precision>g would (the
// stream's precision; the same text as `out << v`, about five times faster through std::to_chars —
// a body of 390 000 tetrahedra is 5 million numbers per file).
template <class T>
void append_number(std::string& text, T v, int precision) {
  char buf[64];
  std::to_chars_result r;
  if constexpr (std::is_floating_point_v<T>)
    r = std::to_chars(buf, buf + sizeof buf, static_cast<double>(v), std::chars_format::general, precision);
  else
    r = std::to_chars(buf, buf + sizeof buf, v);
  text.append(buf, r.ptr);
}

// One <DataArray> of `count` tuples; value(i, c) gives component c of tuple i.
template <class Fn>
void data_array(std::ostream& out, const std::string& name, int components, std::size_t count, Fn value,
                const std::string& type = "Float64") {
  out << "        <DataArray type=\"" << type << "\" Name=\"" << name << "\" NumberOfComponents=\"" << components
      << "\" format=\"ascii\">\n";
  const int precision = static_cast<int>(out.precision());
  std::string text;
  for (std::size_t i = 0; i < count; ++i) {
    for (int c = 0; c < components; ++c) {
      append_number(text, value(i, c), precision);
      text += ' ';
    }
    text += '\n';
    if (text.size() > (1u << 16)) {
      out.write(text.data(), static_cast<std::streamsize>(text.size()));
      text.clear();
    }
  }
  out.write(text.data(), static_cast<std::streamsize>(text.size()));
  out << "        </DataArray>\n";
}

inline void begin_piece(std::ostream& out, std::size_t points, std::size_t cells) {
  out << "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
      << "  <UnstructuredGrid>\n    <Piece NumberOfPoints=\"" << points << "\" NumberOfCells=\"" << cells << "\">\n";
}

inline void end_piece(std::ostream& out) { out << "    </Piece>\n  </UnstructuredGrid>\n</VTKFile>\n"; }

// Points (3 coordinates) and cells of a single VTK type with `per_cell` vertices each.
template <class PointFn, class VertexFn>
void geometry(std::ostream& out, std::size_t points, PointFn point, std::size_t cells, int per_cell, VertexFn vertex,
              int vtk_type) {
  out << "      <Points>\n";
  data_array(out, "Points", 3, points, point);
  out << "      </Points>\n      <Cells>\n";
  data_array(
      out, "connectivity", 1, static_cast<std::size_t>(per_cell) * cells,
      [&](std::size_t k, int) { return vertex(k / per_cell, static_cast<int>(k % per_cell)); }, "Int64");
  data_array(
      out, "offsets", 1, cells, [&](std::size_t e, int) { return per_cell * (e + 1); }, "Int64");
  data_array(
      out, "types", 1, cells, [&](std::size_t, int) { return vtk_type; }, "UInt8");
  out << "      </Cells>\n";
}

}  // namespace contact3d::vtu
