// Tests of the VTU piece writer (solver/io/vtu_format.hpp): the ASCII text of each array, and in binary
// each array's tag pointing at its byte count and raw values in the appended section.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <sstream>
#include <string>

#include "io/vtu_format.hpp"

namespace contact3d {
namespace {

// Two points, one "cell" (a line), an array of doubles and one of Int32; the function counts its calls.
std::string tiny_piece(vtu::Encoding encoding, int& value_calls) {
  std::ostringstream out;
  out.precision(12);
  vtu::write_piece(out, encoding, 2, 1, [&](vtu::PieceWriter& piece) {
    piece.xml("      <PointData>\n");
    piece.data_array("pressure", 1, 2, [&](std::size_t i, int) {
      ++value_calls;
      return 0.5 + static_cast<double>(i);
    });
    piece.data_array(
        "status", 2, 2, [](std::size_t i, int c) { return static_cast<int>(10 * i + c); }, vtu::Type::Int32);
    piece.xml("      </PointData>\n");
  });
  return out.str();
}

// The raw bytes of the appended array whose tag has offset="<offset>" (after its UInt64 byte count).
template <class T>
T appended_value(const std::string& file, std::size_t array_offset, std::size_t index, std::uint64_t* bytes) {
  const std::size_t data = file.find('_', file.find("<AppendedData")) + 1;
  std::memcpy(bytes, file.data() + data + array_offset, sizeof *bytes);
  T v;
  std::memcpy(&v, file.data() + data + array_offset + sizeof *bytes + index * sizeof(T), sizeof v);
  return v;
}

TEST(VtuFormat, AsciiArraysHoldTheirNumbersAsText) {
  int calls = 0;
  const std::string file = tiny_piece(vtu::Encoding::Ascii, calls);
  EXPECT_EQ(calls, 2);
  EXPECT_NE(file.find("Name=\"pressure\" NumberOfComponents=\"1\" format=\"ascii\">\n0.5 \n1.5 \n"), std::string::npos);
  EXPECT_NE(file.find("type=\"Int32\" Name=\"status\" NumberOfComponents=\"2\" format=\"ascii\">\n0 1 \n10 11 \n"),
            std::string::npos);
  EXPECT_EQ(file.find("AppendedData"), std::string::npos);
  EXPECT_EQ(file.find("header_type"), std::string::npos);
  EXPECT_EQ(file.substr(file.size() - 11), "</VTKFile>\n");
}

TEST(VtuFormat, BinaryArraysPointAtTheirRawValuesOnce) {
  int calls = 0;
  const std::string file = tiny_piece(vtu::Encoding::Binary, calls);
  EXPECT_EQ(calls, 2) << "each value is computed once, for the appended section";
  EXPECT_NE(file.find("header_type=\"UInt64\""), std::string::npos);
  EXPECT_NE(file.find("<PointData>\n"), std::string::npos);
  EXPECT_EQ(file.find("<PointData>\n", file.find("<AppendedData")), std::string::npos) << "XML written once";
  // pressure at offset 0: 16 bytes of doubles; status after its 8-byte count and 16 bytes: offset 24.
  EXPECT_NE(file.find("Name=\"pressure\" NumberOfComponents=\"1\" format=\"appended\" offset=\"0\"/>"),
            std::string::npos);
  EXPECT_NE(file.find("Name=\"status\" NumberOfComponents=\"2\" format=\"appended\" offset=\"24\"/>"),
            std::string::npos);
  std::uint64_t bytes = 0;
  EXPECT_EQ(appended_value<double>(file, 0, 1, &bytes), 1.5);
  EXPECT_EQ(bytes, 16u);
  EXPECT_EQ(appended_value<std::int32_t>(file, 24, 3, &bytes), 11);
  EXPECT_EQ(bytes, 16u);
  const std::size_t end = file.find('_', file.find("<AppendedData")) + 1 + 24 + 8 + 16;
  EXPECT_EQ(file.substr(end), "\n  </AppendedData>\n</VTKFile>\n");
}

}  // namespace
}  // namespace contact3d
