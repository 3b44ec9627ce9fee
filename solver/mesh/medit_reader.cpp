#include "mesh/medit_reader.hpp"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <map>
#include <set>
#include <string_view>

#include <sys/stat.h>

#include "base/errors.hpp"

namespace contact3d {
namespace {

// What the format's sections hold, before the indices are checked and the Mesh is built.
struct MeditData {
  int dimension = 0;
  bool has_vertices = false, has_end = false;
  std::vector<Eigen::Vector3d> vertices;
  std::vector<std::array<long long, 4>> tets;
  std::vector<long long> tet_labels;
  std::vector<std::array<long long, 3>> triangles;
  std::vector<long long> triangle_labels;
  std::string tets_where, triangles_where;  // where each section started (for index errors)
  bool second_order = false;                // TetrahedraP2 / TrianglesP2 read by their corners
};

// Sections that carry nothing a P1 tetrahedral solve uses, skipped in both encodings, with the
// number of integers and reals per entry (ASCII; a 3D mesh: a normal or tangent is 3 reals) and
// their binary keyword codes (libMeshb's): the edges, the surface mesher's geometry (corners,
// ridges, required entities) and the normals and tangents that MMG and other remeshers write.
struct Skipped {
  const char* name;
  int code, ints, reals;
};
constexpr Skipped kSkipped[] = {{"Edges", 5, 3, 0},
                                {"EdgesP2", 25, 4, 0},
                                {"Corners", 13, 1, 0},
                                {"Ridges", 14, 1, 0},
                                {"RequiredVertices", 15, 1, 0},
                                {"RequiredEdges", 16, 1, 0},
                                {"RequiredTriangles", 17, 1, 0},
                                {"RequiredQuadrilaterals", 18, 1, 0},
                                {"RequiredTetrahedra", 12, 1, 0},  // MMG's code for it
                                {"TangentAtEdgeVertices", 19, 3, 0},
                                {"NormalAtVertices", 20, 2, 0},
                                {"NormalAtTriangleVertices", 21, 3, 0},
                                {"NormalAtQuadrilateralVertices", 22, 3, 0},
                                {"Tangents", 59, 0, 3},
                                {"Normals", 60, 0, 3},
                                {"TangentAtVertices", 61, 2, 0}};
// Element sections contact3d cannot use: named in the error.
struct Rejected {
  const char* name;
  int code;
  const char* what;
};
constexpr Rejected kRejected[] = {{"Quadrilaterals", 7, "quadrilaterals"},
                                  {"Prisms", 9, "prisms"},
                                  {"Hexahedra", 10, "hexahedra"},
                                  {"QuadrilateralsQ2", 27, "second-order quadrilaterals"},
                                  {"Pyramids", 49, "pyramids"}};

bool same_word(std::string_view a, std::string_view b) {
  return a.size() == b.size() &&
         std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) { return std::tolower(x) == std::tolower(y); });
}

[[noreturn]] void rejected(const std::string& where, const char* what) {
  throw InputError(where + ": the mesh holds " + std::string(what) +
                   "; contact3d reads tetrahedra and triangles only (first order, or second order by their corners)");
}

// ------------------------------------------------------------------------------- ASCII
class AsciiParser {
 public:
  AsciiParser(std::string_view text, std::string name) : text_(text), name_(std::move(name)) {}

  MeditData parse() {
    std::string_view word;
    while (next(word)) {
      const std::string where = name_ + ", line " + std::to_string(line_) + ", section " + std::string(word);
      if (same_word(word, "MeshVersionFormatted")) {
        const long long v = integer(where);
        if (v < 1 || v > 4) fail(where, "version " + std::to_string(v) + " (expected 1 to 4)");
      } else if (same_word(word, "Dimension")) {
        data_.dimension = static_cast<int>(integer(where));
        if (data_.dimension != 3)
          fail(where,
               "dimension " + std::to_string(data_.dimension) + ": contact3d needs a 3-D mesh (a FreeFEM mesh3)");
      } else if (same_word(word, "Vertices")) {
        vertices(where);
      } else if (same_word(word, "Tetrahedra")) {
        data_.tets_where = where;
        elements<4>(where, data_.tets, data_.tet_labels);
      } else if (same_word(word, "Triangles")) {
        data_.triangles_where = where;
        elements<3>(where, data_.triangles, data_.triangle_labels);
      } else if (same_word(word, "TetrahedraP2")) {  // 4 corners, then 6 mid-edge vertices
        data_.tets_where = where;
        data_.second_order = true;
        elements<4, 10>(where, data_.tets, data_.tet_labels);
      } else if (same_word(word, "TrianglesP2")) {  // 3 corners, then 3 mid-edge vertices
        data_.triangles_where = where;
        data_.second_order = true;
        elements<3, 6>(where, data_.triangles, data_.triangle_labels);
      } else if (same_word(word, "End")) {
        data_.has_end = true;
        break;
      } else {
        other(word, where);
      }
    }
    return std::move(data_);
  }

 private:
  std::string_view text_;
  std::string name_;
  std::size_t pos_ = 0;
  int line_ = 1;
  MeditData data_;

  [[noreturn]] void fail(const std::string& where, const std::string& what) const {
    throw InputError(where + ": " + what);
  }

  // The next whitespace-separated token, skipping `#` comments; false at the end.
  bool next(std::string_view& token) {
    while (pos_ < text_.size()) {
      const char c = text_[pos_];
      if (c == '\n') ++line_;
      if (c == '#') {
        while (pos_ < text_.size() && text_[pos_] != '\n') ++pos_;
      } else if (std::isspace(static_cast<unsigned char>(c))) {
        ++pos_;
      } else {
        break;
      }
    }
    if (pos_ >= text_.size()) return false;
    const std::size_t start = pos_;
    while (pos_ < text_.size() && !std::isspace(static_cast<unsigned char>(text_[pos_])) && text_[pos_] != '#') ++pos_;
    token = text_.substr(start, pos_ - start);
    return true;
  }

  std::string here() const { return name_ + ", line " + std::to_string(line_); }

  long long integer(const std::string& where) {
    std::string_view t;
    if (!next(t)) fail(where, "the file ends inside the section");
    std::string s(t);
    char* end = nullptr;
    errno = 0;
    const long long v = std::strtoll(s.c_str(), &end, 10);
    if (end != s.c_str() + s.size() || errno == ERANGE)
      fail(here() + " (in " + where.substr(where.rfind("section")) + ")", "expected an integer, found '" + s + "'");
    return v;
  }

  double real(const std::string& where) {
    std::string_view t;
    if (!next(t)) fail(where, "the file ends inside the section");
    std::string s(t);
    char* end = nullptr;
    const double v = std::strtod(s.c_str(), &end);
    if (end != s.c_str() + s.size())
      fail(here() + " (in " + where.substr(where.rfind("section")) + ")", "expected a number, found '" + s + "'");
    if (!std::isfinite(v))
      fail(here() + " (in " + where.substr(where.rfind("section")) + ")", "coordinate '" + s + "' is not finite");
    return v;
  }

  // A section's entry count, bounded by what the rest of the file can hold (two characters a value).
  std::size_t count(const std::string& where, int values_per_entry) {
    const long long n = integer(where);
    const std::size_t room = (text_.size() - pos_) / (2 * static_cast<std::size_t>(values_per_entry)) + 1;
    if (n < 0 || static_cast<unsigned long long>(n) > room)
      fail(where, "entry count " + std::to_string(n) + " does not fit in the rest of the file");
    return static_cast<std::size_t>(n);
  }

  void vertices(const std::string& where) {
    if (data_.dimension != 3) fail(where, "Vertices before 'Dimension 3'");
    data_.has_vertices = true;
    const std::size_t n = count(where, 4);
    data_.vertices.reserve(n);
    for (std::size_t k = 0; k < n; ++k) {
      Eigen::Vector3d x;
      for (int c = 0; c < 3; ++c) x[c] = real(where);
      integer(where);  // the vertex's label: unused
      data_.vertices.push_back(x);
    }
  }

  // Entries of `Read` vertices and a label; the first N vertices are kept (the corners).
  template <std::size_t N, std::size_t Read = N>
  void elements(const std::string& where, std::vector<std::array<long long, N>>& out, std::vector<long long>& labels) {
    const std::size_t n = count(where, static_cast<int>(Read) + 1);
    out.reserve(out.size() + n);
    for (std::size_t k = 0; k < n; ++k) {
      std::array<long long, N> e{};
      for (std::size_t a = 0; a < Read; ++a) {
        const long long v = integer(where);
        if (a < N) e[a] = v;
      }
      out.push_back(e);
      labels.push_back(integer(where));
    }
  }

  void other(std::string_view word, const std::string& where) {
    for (const auto& r : kRejected)
      if (same_word(word, r.name)) {
        if (integer(where) > 0) rejected(where, r.what);
        return;
      }
    for (const auto& s : kSkipped)
      if (same_word(word, s.name)) {
        const std::size_t n = count(where, s.ints + s.reals);
        for (std::size_t k = 0; k < n; ++k)
          for (int j = 0; j < s.ints + s.reals; ++j) j < s.ints ? (void)integer(where) : (void)real(where);
        return;
      }
    // A binary file read as text has no words: quote its start only, cut before a UTF-8 continuation byte.
    std::size_t quoted = std::min<std::size_t>(word.size(), 40);
    while (quoted < word.size() && quoted > 0 && (static_cast<unsigned char>(word[quoted]) & 0xC0) == 0x80) --quoted;
    fail(here(), "unknown keyword '" + std::string(word.substr(0, quoted)) + (quoted < word.size() ? "..." : "") +
                     "' (expected a Medit section such as Vertices, "
                     "Tetrahedra, Triangles or End)");
  }
};

// ------------------------------------------------------------------------------ binary
class BinaryParser {
 public:
  BinaryParser(std::string_view data, std::string name) : d_(data), name_(std::move(name)) {}

  MeditData parse() {
    const std::uint32_t code = raw32(0);
    swap_ = code != 1;
    if (swap_ && bswap32(code) != 1) fail(0, "not a Medit binary file");
    const long long version = i32(4);
    if (version < 1 || version > 4) fail(4, "version " + std::to_string(version) + " (expected 1 to 4)");
    version_ = static_cast<int>(version);
    std::size_t pos = 8;
    std::set<std::size_t> visited;
    while (true) {
      if (!visited.insert(pos).second) fail(pos, "the keyword chain loops back");
      const long long kwd = i32(pos);
      const std::size_t next_pos = position(pos + 4);
      const std::size_t body = pos + 4 + (version_ >= 3 ? 8 : 4);
      const std::string where = name_ + ", byte offset " + std::to_string(pos) + ", keyword " + std::to_string(kwd);
      if (kwd == 54) {  // End
        data_.has_end = true;
        break;
      }
      if (next_pos <= pos)
        fail(pos, "keyword " + std::to_string(kwd) + " gives byte " + std::to_string(next_pos) +
                      " as the next keyword's position, not after its own (corrupt file)");
      if (next_pos > d_.size())
        fail(pos,
             "keyword " + std::to_string(kwd) + " points to byte " + std::to_string(next_pos) + ", outside the file");
      section(kwd, body, next_pos, where);
      pos = next_pos;
    }
    return std::move(data_);
  }

 private:
  std::string_view d_;
  std::string name_;
  bool swap_ = false;
  int version_ = 2;
  MeditData data_;

  [[noreturn]] void fail(std::size_t at, const std::string& what) const {
    throw InputError(name_ + ", byte offset " + std::to_string(at) + ": " + what);
  }
  static std::uint32_t bswap32(std::uint32_t v) { return __builtin_bswap32(v); }
  static std::uint64_t bswap64(std::uint64_t v) { return __builtin_bswap64(v); }
  void need(std::size_t at, std::size_t bytes) const {
    if (at > d_.size() || bytes > d_.size() - at) fail(at, "the file ends early (truncated?)");
  }
  std::uint32_t raw32(std::size_t at) const {
    need(at, 4);
    std::uint32_t v;
    std::memcpy(&v, d_.data() + at, 4);
    return v;
  }
  std::uint64_t raw64(std::size_t at) const {
    need(at, 8);
    std::uint64_t v;
    std::memcpy(&v, d_.data() + at, 8);
    return swap_ ? bswap64(v) : v;
  }
  long long i32(std::size_t at) const {
    const std::uint32_t v = swap_ ? bswap32(raw32(at)) : raw32(at);
    return static_cast<std::int32_t>(v);
  }
  long long integer(std::size_t& at) const {  // an index or label: 64-bit from version 4 on
    const long long v = version_ >= 4 ? static_cast<long long>(raw64(at)) : i32(at);
    at += version_ >= 4 ? 8 : 4;
    return v;
  }
  double real(std::size_t& at) const {
    double v;
    if (version_ == 1) {
      const std::uint32_t bits = swap_ ? bswap32(raw32(at)) : raw32(at);
      float f;
      std::memcpy(&f, &bits, 4);
      v = f;
      at += 4;
    } else {
      const std::uint64_t bits = raw64(at);
      std::memcpy(&v, &bits, 8);
      at += 8;
    }
    if (!std::isfinite(v)) fail(at, "a coordinate is not finite");
    return v;
  }
  std::size_t position(std::size_t at) const {
    const long long p = version_ >= 3 ? static_cast<long long>(raw64(at)) : i32(at);
    if (p < 0) fail(at, "negative keyword position");
    return static_cast<std::size_t>(p);
  }
  std::size_t count(std::size_t& at, std::size_t end, std::size_t entry_bytes) const {
    const long long n = integer(at);
    if (n < 0 || static_cast<unsigned long long>(n) > (end - std::min(end, at)) / entry_bytes)
      fail(at, "entry count " + std::to_string(n) + " does not fit in its section");
    return static_cast<std::size_t>(n);
  }

  void section(long long kwd, std::size_t at, std::size_t end, const std::string& where) {
    const std::size_t ib = version_ >= 4 ? 8 : 4, rb = version_ == 1 ? 4 : 8;
    switch (kwd) {
      case 3:
        data_.dimension = static_cast<int>(i32(at));
        if (data_.dimension != 3)
          fail(at, "dimension " + std::to_string(data_.dimension) + ": contact3d needs a 3-D mesh (a FreeFEM mesh3)");
        return;
      case 4: {
        if (data_.dimension != 3) fail(at, "Vertices before 'Dimension 3'");
        data_.has_vertices = true;
        const std::size_t n = count(at, end, 3 * rb + ib);
        data_.vertices.reserve(n);
        for (std::size_t k = 0; k < n; ++k) {
          Eigen::Vector3d x;
          for (int c = 0; c < 3; ++c) x[c] = real(at);
          integer(at);
          data_.vertices.push_back(x);
        }
        return;
      }
      case 8:
        data_.tets_where = where;
        elements<4>(at, end, data_.tets, data_.tet_labels);
        return;
      case 6:
        data_.triangles_where = where;
        elements<3>(at, end, data_.triangles, data_.triangle_labels);
        return;
      case 30:  // TetrahedraP2: 4 corners, then 6 mid-edge vertices
        data_.tets_where = where;
        data_.second_order = true;
        elements<4, 10>(at, end, data_.tets, data_.tet_labels);
        return;
      case 24:  // TrianglesP2: 3 corners, then 3 mid-edge vertices
        data_.triangles_where = where;
        data_.second_order = true;
        elements<3, 6>(at, end, data_.triangles, data_.triangle_labels);
        return;
      default:
        break;
    }
    for (const auto& r : kRejected)
      if (r.code == kwd) {
        std::size_t a = at;
        if (integer(a) > 0) rejected(where, r.what);
        return;
      }
    for (const auto& s : kSkipped)
      if (s.code == kwd) return;  // the chain of positions skips it
    fail(at, "keyword code " + std::to_string(kwd) +
                 " is not a section contact3d knows (Vertices 4, Triangles 6, "
                 "Tetrahedra 8, ...)");
  }

  template <std::size_t N, std::size_t Read = N>
  void elements(std::size_t at, std::size_t end, std::vector<std::array<long long, N>>& out,
                std::vector<long long>& labels) {
    const std::size_t ib = version_ >= 4 ? 8 : 4;
    const std::size_t n = count(at, end, (Read + 1) * ib);
    for (std::size_t k = 0; k < n; ++k) {
      std::array<long long, N> e{};
      for (std::size_t a = 0; a < Read; ++a) {
        const long long v = integer(at);
        if (a < N) e[a] = v;
      }
      out.push_back(e);
      labels.push_back(integer(at));
    }
  }
};

// ------------------------------------------------------------------------ the Mesh
Mesh build_mesh(MeditData&& d, const std::string& name) {
  if (d.dimension == 0) throw InputError(name + ": no 'Dimension 3' section (is this a Medit mesh?)");
  if (!d.has_vertices) throw InputError(name + ": no Vertices section");
  if (d.tets.empty()) throw InputError(name + ": no Tetrahedra section (a volume mesh is needed)");
  if (!d.has_end) throw InputError(name + ": the file ends without 'End' (truncated?)");
  Mesh mesh;
  const long long nv = static_cast<long long>(d.vertices.size());
  mesh.nodes = std::move(d.vertices);
  mesh.node_tags.resize(mesh.nodes.size());
  for (std::size_t v = 0; v < mesh.node_tags.size(); ++v) mesh.node_tags[v] = v + 1;
  auto index = [&](long long v, const std::string& where, std::size_t k) {
    if (v < 1 || v > nv)
      throw InputError(where + ": entry " + std::to_string(k + 1) + " names vertex " + std::to_string(v) +
                       ", but the mesh has vertices 1 to " + std::to_string(nv));
    return static_cast<int>(v - 1);
  };
  std::map<std::pair<int, long long>, bool> labels;
  for (std::size_t k = 0; k < d.tets.size(); ++k) {
    std::array<int, 4> t{};
    for (int a = 0; a < 4; ++a) t[a] = index(d.tets[k][a], d.tets_where, k);
    mesh.tets.push_back(t);
    mesh.tet_tags.push_back(k + 1);
    mesh.tet_group.push_back(static_cast<int>(d.tet_labels[k]));
    labels[{3, d.tet_labels[k]}] = true;
  }
  for (std::size_t k = 0; k < d.triangles.size(); ++k) {
    std::array<int, 3> t{};
    for (int a = 0; a < 3; ++a) t[a] = index(d.triangles[k][a], d.triangles_where, k);
    mesh.triangles.push_back(t);
    mesh.triangle_tags.push_back(k + 1);
    mesh.triangle_group.push_back(static_cast<int>(d.triangle_labels[k]));
    labels[{2, d.triangle_labels[k]}] = true;
  }
  for (const auto& [key, used] : labels) {
    if (key.second < INT32_MIN || key.second > INT32_MAX)
      throw InputError(name + ": label " + std::to_string(key.second) + " is out of range");
    mesh.groups.push_back(PhysicalGroup{key.first, static_cast<int>(key.second), std::to_string(key.second)});
  }
  if (d.second_order) {  // P1 on the corners
    drop_unused_nodes(mesh);
    mesh.read_by_corner_nodes = true;
  }
  return mesh;
}

bool is_binary(std::string_view data) {
  if (data.size() < 4) return false;
  std::uint32_t v;
  std::memcpy(&v, data.data(), 4);
  return v == 1 || __builtin_bswap32(v) == 1;
}

}  // namespace

Mesh parse_medit(std::string_view contents, const std::string& source_name) {
  if (source_name.size() >= 6 && source_name.compare(source_name.size() - 6, 6, ".meshb") == 0 && !is_binary(contents))
    throw InputError(source_name +
                     ": not a Medit binary file (a .meshb starts with libMeshb's code 1 in either byte order; "
                     "an ASCII Medit mesh is named .mesh)");
  MeditData d =
      is_binary(contents) ? BinaryParser(contents, source_name).parse() : AsciiParser(contents, source_name).parse();
  return build_mesh(std::move(d), source_name);
}

bool is_medit_path(const std::string& path) {
  std::string lower = path;
  std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char c) { return std::tolower(c); });
  auto ends_with = [&](const std::string& suffix) {
    return lower.size() >= suffix.size() && lower.compare(lower.size() - suffix.size(), suffix.size(), suffix) == 0;
  };
  return ends_with(".mesh") || ends_with(".meshb");
}

bool is_medit_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  char head[64] = {};
  in.read(head, sizeof head);
  const std::string_view bytes(head, static_cast<std::size_t>(std::max<std::streamsize>(in.gcount(), 0)));
  if (bytes.size() >= 4) {
    const unsigned char* b = reinterpret_cast<const unsigned char*>(head);
    const bool code_one =
        (b[0] == 1 && b[1] == 0 && b[2] == 0 && b[3] == 0) || (b[0] == 0 && b[1] == 0 && b[2] == 0 && b[3] == 1);
    if (code_one) return true;  // binary Medit
  }
  const std::size_t start = bytes.find_first_not_of(" \t\r\n");
  if (start != std::string_view::npos) {
    const std::string_view text = bytes.substr(start);
    if (text.starts_with("$MeshFormat") || text.starts_with("$Comments")) return false;
    if (text.starts_with("MeshVersionFormatted") || text.starts_with("#")) return true;
  }
  return is_medit_path(path);  // unreadable or undecided: the reader named by the path says why
}

Mesh read_medit(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) throw InputError("cannot open mesh file '" + path + "': " + std::strerror(errno));
  if (S_ISDIR(st.st_mode)) throw InputError("cannot read mesh file '" + path + "': it is a directory");
  if (!S_ISREG(st.st_mode)) throw InputError("cannot read mesh file '" + path + "': it is not a regular file");
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) throw InputError("cannot open mesh file '" + path + "': " + std::strerror(errno));
  std::string data(static_cast<std::size_t>(st.st_size), '\0');
  data.resize(std::fread(data.data(), 1, data.size(), f));
  const bool bad = std::ferror(f) != 0;
  std::fclose(f);
  if (bad) throw InputError("cannot read mesh file '" + path + "'");
  return parse_medit(data, path);
}

}  // namespace contact3d
