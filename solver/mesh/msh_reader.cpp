// gmsh MSH reader (4.1 ASCII/binary, 2.2 ASCII/binary). The whole file is read into memory and
// parsed in place with std::from_chars; ASCII records are line-checked so that errors can name
// the offending line. Line numbers are only computed when an error is raised; in binary files
// errors name the byte offset.
#include "mesh/msh_reader.hpp"

#include <algorithm>
#include <array>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <map>
#include <set>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>
#include <vector>

#include <sys/stat.h>

#include "base/errors.hpp"

namespace contact3d {
namespace {

static_assert(sizeof(std::size_t) == 8, "the MSH reader assumes a 64-bit size_t");

bool is_space(char c) { return c == ' ' || c == '\n' || c == '\t' || c == '\r' || c == '\f' || c == '\v'; }
bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v'; }

constexpr const char* kCoordinateNames[3] = {"the x coordinate of a node", "the y coordinate of a node",
                                             "the z coordinate of a node"};

// ---------------------------------------------------------------------------------------------
// gmsh element types

constexpr int kPoint = 15;
constexpr int kLine2 = 1;
constexpr int kTri3 = 2;
constexpr int kTet4 = 4;
// Second order (gmsh -order 2): read by their corner nodes, which gmsh lists first.
constexpr int kLine3 = 8;
constexpr int kTri6 = 9;
constexpr int kTet10 = 11;
constexpr int kMaxElementNodes = 10;

bool is_tet(int type) { return type == kTet4 || type == kTet10; }
bool is_triangle(int type) { return type == kTri3 || type == kTri6; }
bool is_line(int type) { return type == kLine2 || type == kLine3; }
bool is_second_order(int type) { return type == kLine3 || type == kTri6 || type == kTet10; }

// Bytes of a node record in binary MSH 2.2: int node-number, 3 double coordinates.
constexpr std::size_t kNode22Bytes = 4 + 3 * 8;

// Number of nodes of the element types this reader accepts (kept or skipped), 0 otherwise.
int accepted_type_nodes(int type) {
  switch (type) {
    case kPoint:
      return 1;
    case kLine2:
      return 2;
    case kTri3:
      return 3;
    case kTet4:
      return 4;
    case kLine3:
      return 3;
    case kTri6:
      return 6;
    case kTet10:
      return 10;
    default:
      return 0;
  }
}

const char* element_type_name(int type) {
  switch (type) {
    case 1:
      return "2-node line";
    case 2:
      return "3-node triangle";
    case 3:
      return "4-node quadrangle";
    case 4:
      return "4-node tetrahedron";
    case 5:
      return "8-node hexahedron";
    case 6:
      return "6-node prism";
    case 7:
      return "5-node pyramid";
    case 8:
      return "3-node line";
    case 9:
      return "6-node triangle";
    case 10:
      return "9-node quadrangle";
    case 11:
      return "10-node tetrahedron";
    case 12:
      return "27-node hexahedron";
    case 13:
      return "18-node prism";
    case 14:
      return "14-node pyramid";
    case 15:
      return "1-node point";
    case 16:
      return "8-node quadrangle";
    case 17:
      return "20-node hexahedron";
    case 18:
      return "15-node prism";
    case 19:
      return "13-node pyramid";
    case 20:
      return "9-node triangle";
    case 21:
      return "10-node triangle";
    case 22:
      return "12-node triangle";
    case 23:
      return "15-node triangle";
    case 24:
      return "15-node triangle";
    case 25:
      return "21-node triangle";
    case 26:
      return "4-node line";
    case 27:
      return "5-node line";
    case 28:
      return "6-node line";
    case 29:
      return "20-node tetrahedron";
    case 30:
      return "35-node tetrahedron";
    case 31:
      return "56-node tetrahedron";
    case 92:
      return "64-node hexahedron";
    case 93:
      return "125-node hexahedron";
    default:
      return nullptr;
  }
}

bool is_higher_order_simplex(int type) {
  switch (type) {
    case 8:
    case 9:
    case 11:
    case 20:
    case 21:
    case 22:
    case 23:
    case 24:
    case 25:
    case 26:
    case 27:
    case 28:
    case 29:
    case 30:
    case 31:
      return true;
    default:
      return false;
  }
}

std::string unsupported_type_message(long long type) {
  const char* name = (type >= 0 && type <= 1000) ? element_type_name(static_cast<int>(type)) : nullptr;
  std::string msg =
      "element type " + std::to_string(type) + " (" + (name ? name : "unknown to this reader") + ") is not supported; ";
  if (name && is_higher_order_simplex(static_cast<int>(type)))
    msg += "mesh with first- or second-order elements (gmsh -order 1 or 2; second order is read by its corners)";
  else
    msg +=
        "contact3d reads 4-node tetrahedra (type 4) and 3-node triangles (type 2), their second-order forms "
        "(types 11 and 9) by their corners, and skips points and lines; mesh the volume with tetrahedra only "
        "(no Recombine)";
  return msg;
}

// ---------------------------------------------------------------------------------------------
// Node tag -> 0-based index

class NodeIndex {
 public:
  // Builds the map; returns the position of a duplicated tag, or -1.
  long long build(const std::vector<std::size_t>& tags) {
    dense_.clear();
    sparse_.clear();
    std::size_t max_tag = 0;
    for (std::size_t t : tags) max_tag = std::max(max_tag, t);
    use_dense_ = max_tag <= 2 * tags.size() + 1024;
    if (use_dense_) {
      dense_.assign(max_tag + 1, -1);
      for (std::size_t i = 0; i < tags.size(); ++i) {
        if (dense_[tags[i]] >= 0) return static_cast<long long>(i);
        dense_[tags[i]] = static_cast<int>(i);
      }
    } else {
      sparse_.resize(tags.size());
      for (std::size_t i = 0; i < tags.size(); ++i) sparse_[i] = {tags[i], static_cast<int>(i)};
      std::sort(sparse_.begin(), sparse_.end());
      for (std::size_t i = 1; i < sparse_.size(); ++i)
        if (sparse_[i].first == sparse_[i - 1].first) return std::max(sparse_[i].second, sparse_[i - 1].second);
    }
    return -1;
  }

  int find(std::size_t tag) const {
    if (use_dense_) return tag < dense_.size() ? dense_[tag] : -1;
    auto it = std::lower_bound(sparse_.begin(), sparse_.end(), std::pair<std::size_t, int>{tag, -1});
    return (it != sparse_.end() && it->first == tag) ? it->second : -1;
  }

 private:
  bool use_dense_ = true;
  std::vector<int> dense_;
  std::vector<std::pair<std::size_t, int>> sparse_;
};

// ---------------------------------------------------------------------------------------------
// Parser

class Parser {
 public:
  Parser(std::string_view data, const std::string& name)
      : name_(name), begin_(data.data()), p_(data.data()), end_(data.data() + data.size()) {}

  Mesh parse();

 private:
  // ---- errors
  std::size_t line_of(const char* pos) const { return 1 + static_cast<std::size_t>(std::count(begin_, pos, '\n')); }
  std::string where(const char* pos) const {
    if (binary_) return name_ + ", byte offset " + std::to_string(pos - begin_);
    return name_ + ", line " + std::to_string(line_of(pos));
  }
  [[noreturn]] void fail(const char* pos, const std::string& msg) const {
    std::string full = where(pos) + ": " + msg;
    if (!section_.empty()) full += " (in $" + std::string(section_) + ")";
    throw InputError(full);
  }
  static std::string quote(std::string_view tok) {
    std::string out = "'";
    const std::size_t n = std::min<std::size_t>(tok.size(), 40);
    for (std::size_t i = 0; i < n; ++i) {
      const unsigned char c = static_cast<unsigned char>(tok[i]);
      out += (c >= 32 && c < 127) ? static_cast<char>(c) : '?';
    }
    if (tok.size() > n) out += "...";
    return out + "'";
  }

  // ---- ASCII scanning
  void skip_ws() {
    while (p_ < end_ && is_space(*p_)) ++p_;
  }
  void skip_blank() {
    while (p_ < end_ && is_blank(*p_)) ++p_;
  }
  // The token at p_ (after blanks on the current line); empty at the end of a line.
  std::string_view peek_token() {
    skip_blank();
    const char* e = p_;
    while (e < end_ && !is_space(*e)) ++e;
    return {p_, static_cast<std::size_t>(e - p_)};
  }
  [[noreturn]] void fail_missing(std::string_view what) {
    if (p_ >= end_) fail(p_, "unexpected end of file; expected " + std::string(what));
    fail(p_, "expected " + std::string(what) + ", but the line ends here");
  }
  [[noreturn]] void fail_bad_token(const char* s, std::string_view what) {
    const char* e = s;
    while (e < end_ && !is_space(*e)) ++e;
    const std::string_view tok(s, static_cast<std::size_t>(e - s));
    std::string msg = "expected " + std::string(what) + ", found " + quote(tok);
    if (!tok.empty() && tok[0] == '$') msg += " (the section ends before the count given in its header is reached)";
    fail(s, msg);
  }
  // Moves to the first token of the next record (skipping line breaks and blank lines).
  void next_record() { skip_ws(); }
  // Requires the rest of the current line to be blank and moves past its line break.
  void end_record(const char* after) {
    skip_blank();
    if (p_ < end_ && *p_ != '\n') {
      const char* e = p_;
      while (e < end_ && !is_space(*e)) ++e;
      fail(p_, std::string("unexpected ") + quote({p_, static_cast<std::size_t>(e - p_)}) + " after " + after +
                   " (the line has more values than expected)");
    }
    if (p_ < end_) ++p_;
  }

  // Unsigned integer on the current line.
  std::uint64_t unsigned_value(std::string_view what) {
    skip_blank();
    if (p_ >= end_ || *p_ == '\n') fail_missing(what);
    const char* s = p_;
    std::uint64_t v = 0;
    auto [q, ec] = std::from_chars(s, end_, v);
    if (ec == std::errc::result_out_of_range && (q >= end_ || is_space(*q)))
      fail(s, std::string(what) + " " + quote({s, static_cast<std::size_t>(q - s)}) + " is out of range");
    if (ec != std::errc() || (q < end_ && !is_space(*q))) {
      if (*s == '-') {
        const char* e = s;
        while (e < end_ && !is_space(*e)) ++e;
        fail(s, "expected " + std::string(what) + " (a non-negative integer), found " +
                    quote({s, static_cast<std::size_t>(e - s)}));
      }
      fail_bad_token(s, what);
    }
    p_ = q;
    return v;
  }
  // Signed int on the current line.
  int int_value(std::string_view what) {
    skip_blank();
    if (p_ >= end_ || *p_ == '\n') fail_missing(what);
    const char* s = p_;
    long long v = 0;
    auto [q, ec] = std::from_chars(s, end_, v);
    if (ec == std::errc() && (q >= end_ || is_space(*q)) &&
        (v < std::numeric_limits<int>::min() || v > std::numeric_limits<int>::max()))
      ec = std::errc::result_out_of_range;
    if (ec == std::errc::result_out_of_range && (q >= end_ || is_space(*q)))
      fail(s, std::string(what) + " " + quote({s, static_cast<std::size_t>(q - s)}) + " is out of range");
    if (ec != std::errc() || (q < end_ && !is_space(*q))) fail_bad_token(s, what);
    p_ = q;
    return static_cast<int>(v);
  }
  // Finite double on the current line.
  double real_value(std::string_view what, bool require_finite = true) {
    skip_blank();
    if (p_ >= end_ || *p_ == '\n') fail_missing(what);
    const char* s = p_;
    const char* b = s;
    if (*b == '+' && b + 1 < end_ && b[1] != '+' && b[1] != '-') ++b;
    double v = 0;
    auto [q, ec] = std::from_chars(b, end_, v);
    if (ec == std::errc::result_out_of_range && (q >= end_ || is_space(*q))) {
      // Underflow (e.g. 1e-400) is harmless; overflow is not.
      const std::string tok(b, q);
      errno = 0;
      v = std::strtod(tok.c_str(), nullptr);
      if (std::isfinite(v)) ec = std::errc();
    }
    if (ec == std::errc::result_out_of_range && (q >= end_ || is_space(*q)))
      fail(s, std::string(what) + " " + quote({s, static_cast<std::size_t>(q - s)}) + " is out of range");
    if (ec != std::errc() || (q < end_ && !is_space(*q))) fail_bad_token(s, what);
    if (require_finite && !std::isfinite(v))
      fail(s, std::string(what) + " is not a finite number: " + quote({s, static_cast<std::size_t>(q - s)}));
    p_ = q;
    return v;
  }
  // A count on the current line, guarded against the remaining file size: a record of the
  // counted kind takes at least `min_bytes` bytes.
  std::size_t count_value(std::string_view what, std::size_t min_bytes) {
    skip_blank();
    const char* s = p_;
    const std::uint64_t n = unsigned_value(what);
    check_count(s, n, min_bytes, what);
    return static_cast<std::size_t>(n);
  }
  void check_count(const char* pos, std::uint64_t n, std::size_t min_bytes, std::string_view what) const {
    const auto remaining = static_cast<std::uint64_t>(end_ - p_);
    if (n > remaining / min_bytes)
      fail(pos, std::string(what) + " " + std::to_string(n) +
                    " is larger than the rest of the file can hold (truncated file or corrupt "
                    "count)");
  }
  // Whether the data at p_ is the line `end_tag` (after at most a few whitespace bytes). In
  // binary sections this tells "the count promises more records than the section holds" apart
  // from corrupt data; the bounded look-ahead keeps each call O(1).
  bool at_section_end(std::string_view end_tag) const {
    const char* s = p_;
    for (int k = 0; k < 4 && s < end_ && is_space(*s); ++k) ++s;
    const std::string_view rest(s, static_cast<std::size_t>(end_ - s));
    return rest.substr(0, end_tag.size()) == end_tag &&
           (rest.size() == end_tag.size() || is_space(rest[end_tag.size()]));
  }
  // "$EndXxx" (after optional whitespace), then the end of its line.
  void expect_section_end(std::string_view end_tag) {
    skip_ws();
    const std::string_view tok = peek_token();
    if (tok != end_tag) {
      if (p_ >= end_) fail(p_, "unexpected end of file; expected " + std::string(end_tag));
      std::string msg = "expected " + std::string(end_tag) + ", found " + quote(tok);
      if (tok.empty() || tok[0] != '$') msg += " (the section holds more data than the counts in its header say)";
      fail(p_, msg);
    }
    p_ += tok.size();
    end_record(std::string(end_tag).c_str());
  }

  // ---- binary scanning (little-endian; ints are 4 bytes, size_t fields size_bytes_)
  template <class T>
  T raw(const char* what) {
    if (static_cast<std::size_t>(end_ - p_) < sizeof(T))
      fail(p_, std::string("unexpected end of file in binary data; expected ") + what);
    T v;
    std::memcpy(&v, p_, sizeof(T));
    p_ += sizeof(T);
    return v;
  }
  std::uint64_t raw_size(const char* what) {
    if (size_bytes_ == 8) return raw<std::uint64_t>(what);
    return raw<std::uint32_t>(what);
  }
  int raw_int(const char* what) { return raw<std::int32_t>(what); }
  std::size_t raw_count(const char* what, std::size_t min_bytes) {
    const char* s = p_;
    const std::uint64_t n = raw_size(what);
    check_count(s, n, min_bytes, what);
    return static_cast<std::size_t>(n);
  }

  // ---- sections
  void read_mesh_format();
  void read_physical_names();
  void read_entities();
  void read_partitioned_entities();
  std::vector<int> read_entity_ints(const char* what, std::size_t count);
  void check_every_partition_present() const;
  void read_nodes41();
  std::size_t read_node_block41(std::size_t announced, std::size_t so_far);
  void read_elements41();
  std::size_t read_element_block41(std::size_t announced, std::size_t so_far);
  void store_element(int type, std::uint64_t tag, int group, const std::array<int, kMaxElementNodes>& idx);
  void repeat_for_extra_physicals(const char* block_pos, int entity, std::size_t first_triangle,
                                  const std::vector<int>& phys);
  void read_nodes22();
  void read_elements22();
  std::size_t read_binary_element_block22(std::size_t announced, std::size_t so_far);
  void read_ascii_element22();
  void keep_element22(int type, std::uint64_t tag, int physical, int elementary,
                      const std::array<int, kMaxElementNodes>& idx);
  void skip_section(const char* header_pos, std::string_view name);
  void finish_nodes(const char* section_pos);
  void note_used_group(int dim, int tag) {
    if (tag == 0 || (dim == last_used_.first && tag == last_used_.second)) return;
    last_used_ = {dim, tag};
    if (used_set_.insert({dim, tag}).second) used_order_.push_back({dim, tag});
  }
  int node_ref(std::size_t tag, const char* pos, std::size_t element_tag) const {
    const int idx = nodes_.find(tag);
    if (idx < 0)
      fail(pos, "element " + std::to_string(element_tag) + " refers to node " + std::to_string(tag) +
                    ", which $Nodes does not define");
    return idx;
  }
  // The nn node tags ending an ASCII element record (both MSH versions), as node indices.
  void read_ascii_element_nodes(int nn, std::array<int, kMaxElementNodes>& idx, std::size_t element_tag) {
    for (int k = 0; k < nn; ++k) {
      skip_blank();
      const char* npos = p_;
      idx[k] = node_ref(static_cast<std::size_t>(unsigned_value("a node tag of an element")), npos, element_tag);
    }
    end_record("the nodes of an element");
  }
  void reserve_more_tets(std::size_t n) {
    const std::size_t need = mesh_.tets.size() + n;
    if (need > mesh_.tets.capacity()) {
      const std::size_t cap = std::max(need, 2 * mesh_.tets.capacity());
      mesh_.tets.reserve(cap);
      mesh_.tet_tags.reserve(cap);
      mesh_.tet_group.reserve(cap);
    }
  }
  void reserve_more_triangles(std::size_t n) {
    const std::size_t need = mesh_.triangles.size() + n;
    if (need > mesh_.triangles.capacity()) {
      const std::size_t cap = std::max(need, 2 * mesh_.triangles.capacity());
      mesh_.triangles.reserve(cap);
      mesh_.triangle_tags.reserve(cap);
      mesh_.triangle_group.reserve(cap);
    }
  }
  // Appends copies of triangles [first, last) once for each of the extra physical tags.
  void duplicate_triangles(std::size_t first, std::size_t last, const std::vector<int>& phys) {
    for (std::size_t k = 1; k < phys.size(); ++k) {
      reserve_more_triangles(last - first);
      for (std::size_t i = first; i < last; ++i) {
        const std::array<int, 3> tri = mesh_.triangles[i];
        const std::size_t tag = mesh_.triangle_tags[i];
        mesh_.triangles.push_back(tri);
        mesh_.triangle_tags.push_back(tag);
        mesh_.triangle_group.push_back(phys[k]);
      }
    }
  }
  const std::vector<int>& entity_physicals(int dim, int tag, const char* pos) const;

  std::string name_;
  const char* begin_;
  const char* p_;
  const char* end_;
  std::string_view section_;
  bool binary_ = false;
  int version_ = 0;  // 41 or 22
  std::size_t size_bytes_ = 8;

  Mesh mesh_;
  NodeIndex nodes_;
  bool have_format_ = false, have_names_ = false, have_entities_ = false;
  bool have_nodes_ = false, have_elements_ = false;
  std::vector<PhysicalGroup> named_;
  std::set<std::pair<int, int>> named_set_;
  std::set<std::pair<int, int>> used_set_;
  std::vector<std::pair<int, int>> used_order_;
  std::pair<int, int> last_used_{-1, 0};
  std::array<std::map<int, std::vector<int>>, 4> entities_;  // physical tags per entity
  // A partitioned file (gmsh -part N): the partitions, and those of each volume entity and of the
  // volumes whose blocks held tetrahedra (a file of gmsh -part_split holds one partition's only).
  std::size_t partitions_ = 0;
  std::map<int, std::vector<int>> volume_partitions_;
  std::set<int> partitions_with_tets_;
  std::array<std::set<int>, 4> partition_interfaces_;  // pieces of a volume between two partitions
  std::vector<int> no_physicals_;
  bool second_order_ = false;  // the file holds second-order elements (kLine3, kTri6, kTet10)
  // MSH 2.2: whether the last element kept was a tetrahedron, and its elementary entity (gmsh
  // writes a tetrahedron once per physical group, as consecutive records).
  bool prev_tet22_ = false;
  int prev_elementary22_ = 0;
};

Mesh Parser::parse() {
  skip_ws();
  {
    const std::string_view tok = peek_token();
    if (tok != "$MeshFormat")
      fail(p_, "not a gmsh MSH file: expected $MeshFormat at the start, found " + quote(tok) +
                   " (supported formats: MSH 4.1, 2.2)");
    p_ += tok.size();
    end_record("$MeshFormat");
    read_mesh_format();
  }
  for (;;) {
    skip_ws();
    if (p_ >= end_) break;
    const char* header = p_;
    const std::string_view tok = peek_token();
    if (tok.size() < 2 || tok[0] != '$')
      fail(header, "expected a section header such as $Nodes or $Elements, found " + quote(tok));
    p_ += tok.size();
    // Exactly one line break ends the header line; binary data may follow it directly.
    end_record("the section header");
    const std::string_view name = tok.substr(1);
    if (name == "MeshFormat") {
      fail(header, "second $MeshFormat section");
    } else if (name == "PhysicalNames") {
      if (have_names_) fail(header, "second $PhysicalNames section");
      read_physical_names();
    } else if (name == "Entities" && version_ == 41) {
      if (have_entities_) fail(header, "second $Entities section");
      if (have_elements_) fail(header, "$Entities must come before $Elements");
      read_entities();
    } else if (name == "PartitionedEntities") {
      if (version_ != 41) fail(header, "$PartitionedEntities in an MSH 2.2 file");
      if (!have_entities_) fail(header, "$PartitionedEntities must come after $Entities");
      if (have_nodes_ || have_elements_) fail(header, "$PartitionedEntities must come before $Nodes and $Elements");
      if (partitions_ > 0) fail(header, "second $PartitionedEntities section");
      read_partitioned_entities();
    } else if (name == "Nodes") {
      if (have_nodes_) fail(header, "second $Nodes section");
      if (version_ == 41)
        read_nodes41();
      else
        read_nodes22();
      finish_nodes(header);
    } else if (name == "Elements") {
      if (have_elements_) fail(header, "second $Elements section");
      if (!have_nodes_) fail(header, "$Elements comes before $Nodes");
      if (version_ == 41)
        read_elements41();
      else
        read_elements22();
    } else if (name == "ParametricNodes") {  // MSH 2 only; skipped, it left "$Elements comes before $Nodes"
      fail(header,
           "$ParametricNodes (gmsh's -save_parametric in MSH 2) is not read: save the mesh without "
           "-save_parametric, or as MSH 4.1 (-format msh41), whose parametric nodes are read");
    } else if (name.size() > 3 && name.substr(0, 3) == "End") {
      fail(header, "unexpected " + quote(tok) + " without a matching section start");
    } else {
      skip_section(header, name);
    }
  }
  if (!have_nodes_) fail(end_, "the file has no $Nodes section");
  if (!have_elements_) fail(end_, "the file has no $Elements section");
  check_every_partition_present();
  // A finding about the whole file names its last line (end_ itself is the empty line after a final '\n').
  const char* last_line = end_ > begin_ && end_[-1] == '\n' ? end_ - 1 : end_;
  if (version_ == 22 && !named_.empty() && used_order_.empty())
    fail(last_line, "every element has physical tag 0 although $PhysicalNames names " + std::to_string(named_.size()) +
                        " group(s): the file was saved with all elements (gmsh's Mesh.SaveAll, -save_all), which in "
                        "MSH 2.2 drops their physical groups; save it without SaveAll, or as MSH 4.1");

  mesh_.groups = named_;
  for (const auto& [dim, tag] : used_order_)
    if (!named_set_.count({dim, tag})) mesh_.groups.push_back(PhysicalGroup{dim, tag, ""});
  if (second_order_) {  // P1 on the corners
    drop_unused_nodes(mesh_);
    mesh_.read_by_corner_nodes = true;
  }
  return std::move(mesh_);
}

void Parser::read_mesh_format() {
  section_ = "MeshFormat";
  next_record();
  const char* vpos = p_;
  const std::string_view vtok = peek_token();
  if (vtok.empty()) fail_missing("the format version");
  const double version = real_value("the format version");
  if (std::abs(version - 4.1) < 1e-9) {
    version_ = 41;
  } else if (std::abs(version - 2.2) < 1e-9) {
    version_ = 22;
  } else {
    fail(vpos, "MSH format version " + std::string(vtok) +
                   " is not supported (supported: 4.1, 2.2); re-export the mesh with "
                   "gmsh -format msh41 (or msh22)");
  }
  skip_blank();
  const char* tpos = p_;
  const int file_type = int_value("the file type (0 = ASCII, 1 = binary)");
  if (file_type != 0 && file_type != 1)
    fail(tpos, "file type " + std::to_string(file_type) + " is neither 0 (ASCII) nor 1 (binary)");
  skip_blank();
  const char* dpos = p_;
  const int data_size = int_value("the data size");
  end_record("the format line");
  if (file_type == 1) {
    // MSH 4.1: data-size is sizeof(size_t) of the writer (8 or 4); MSH 2.2: it is the size of
    // the node coordinates, which this reader takes as doubles.
    if (version_ == 22 && data_size != 8)
      fail(dpos, "data size " + std::to_string(data_size) +
                     " is not supported in binary MSH 2.2 (expected 8: coordinates are doubles)");
    if (data_size != 8 && data_size != 4)
      fail(dpos, "data size " + std::to_string(data_size) + " is not supported (expected 8 or 4)");
    size_bytes_ = static_cast<std::size_t>(data_size);
    binary_ = true;
    const char* opos = p_;
    const std::int32_t one = raw<std::int32_t>("the endianness marker (int 1)");
    if (one != 1) {
      if (one == 0x01000000) fail(opos, "big-endian binary MSH files are not supported");
      fail(opos, "corrupt binary header: the endianness marker is " + std::to_string(one) + ", expected 1");
    }
  }
  expect_section_end("$EndMeshFormat");
  have_format_ = true;
  section_ = {};
}

void Parser::read_physical_names() {
  section_ = "PhysicalNames";
  have_names_ = true;
  next_record();
  const std::size_t n = count_value("the number of physical names", 6);
  end_record("the number of physical names");
  named_.reserve(named_.size() + n);
  for (std::size_t i = 0; i < n; ++i) {
    next_record();
    const char* rec = p_;
    const char* dpos = p_;
    const int dim = int_value("the dimension of a physical group");
    if (dim < 0 || dim > 3) fail(dpos, "physical group dimension " + std::to_string(dim) + " is not 0, 1, 2 or 3");
    const int tag = int_value("the tag of a physical group");
    skip_blank();
    const char* s = p_;
    const char* eol = std::find(s, end_, '\n');
    const char* e = eol;
    while (e > s && is_blank(e[-1])) --e;
    std::string name;
    if (s < e && *s == '"') {
      if (e - s < 2 || e[-1] != '"')
        fail(s, "the name of physical group " + std::to_string(tag) + " lacks its closing quote");
      name.assign(s + 1, e - 1);
    } else {
      name.assign(s, e);
    }
    if (name.empty() && s == e) fail(s, "expected the name of physical group " + std::to_string(tag));
    if (!named_set_.insert({dim, tag}).second)
      fail(rec, "physical group " + std::to_string(tag) + " of dimension " + std::to_string(dim) + " is named twice");
    named_.push_back(PhysicalGroup{dim, tag, std::move(name)});
    p_ = eol < end_ ? eol + 1 : end_;
  }
  expect_section_end("$EndPhysicalNames");
  section_ = {};
}

const std::vector<int>& Parser::entity_physicals(int dim, int tag, const char* pos) const {
  if (!have_entities_) return no_physicals_;
  const auto it = entities_[dim].find(tag);
  if (it == entities_[dim].end()) {
    static const char* kinds[] = {"point", "curve", "surface", "volume"};
    fail(pos, "the block refers to " + std::string(kinds[dim]) + " entity " + std::to_string(tag) + ", which " +
                  (partitions_ > 0 ? "$PartitionedEntities" : "$Entities") + " does not define");
  }
  return it->second;
}

void Parser::read_entities() {
  section_ = "Entities";
  have_entities_ = true;
  static const char* kinds[] = {"points", "curves", "surfaces", "volumes"};
  std::array<std::size_t, 4> counts{};
  if (!binary_) next_record();
  for (int d = 0; d < 4; ++d) {
    const std::string what = std::string("the number of ") + kinds[d];
    // An entity record takes at least 10 characters in ASCII, 28 bytes in binary.
    counts[d] = binary_ ? raw_count(what.c_str(), 28) : count_value(what, 10);
  }
  if (!binary_) end_record("the entity counts");
  for (int d = 0; d < 4; ++d) {
    for (std::size_t i = 0; i < counts[d]; ++i) {
      std::vector<int> phys;
      const char* rec;
      int tag;
      if (binary_) {
        rec = p_;
        tag = raw_int("an entity tag");
        for (int k = 0; k < (d == 0 ? 3 : 6); ++k) (void)raw<double>("entity coordinates");
        const std::size_t np = raw_count("the number of physical tags", 4);
        phys.resize(np);
        for (std::size_t k = 0; k < np; ++k) phys[k] = raw_int("a physical tag");
        if (d > 0) {
          const std::size_t nb = raw_count("the number of bounding entities", 4);
          p_ += nb * 4;  // guarded by raw_count
        }
      } else {
        next_record();
        rec = p_;
        tag = int_value(std::string("the tag of one of the ") + kinds[d]);
        for (int k = 0; k < (d == 0 ? 3 : 6); ++k)
          (void)real_value(d == 0 ? "a point coordinate" : "a bounding-box coordinate", false);
        const std::size_t np = count_value("the number of physical tags", 2);
        phys.resize(np);
        for (std::size_t k = 0; k < np; ++k) phys[k] = int_value("a physical tag");
        if (d > 0) {
          const std::size_t nb = count_value("the number of bounding entities", 2);
          for (std::size_t k = 0; k < nb; ++k) (void)int_value("a bounding entity tag");
        }
        end_record("an entity");
      }
      for (int t : phys) note_used_group(d, t);
      if (!entities_[d].emplace(tag, std::move(phys)).second)
        fail(rec, std::string("entity ") + std::to_string(tag) + " is defined twice among the " + kinds[d]);
    }
  }
  expect_section_end("$EndEntities");
  section_ = {};
}

// A partitioned MSH 4.1 file (gmsh -part N): the mesh's blocks refer to the partitioned entities,
// each a piece of a model entity (its parent) in one or more partitions, with the parent's physical
// tags. They replace $Entities' entities for the blocks. The interfaces between partitions (pieces
// of a volume that are surfaces, curves or points: parentDim > dim) take no physical group, and
// their triangles, inside the body, are read and dropped.
void Parser::read_partitioned_entities() {
  section_ = "PartitionedEntities";
  static const char* kinds[] = {"points", "curves", "surfaces", "volumes"};
  if (!binary_) next_record();
  partitions_ = binary_ ? raw_count("the number of partitions", 1) : count_value("the number of partitions", 1);
  if (partitions_ == 0) fail(p_, "a partitioned mesh with 0 partitions");
  if (!binary_) end_record("the number of partitions");
  if (!binary_) next_record();
  const std::size_t ghosts =
      binary_ ? raw_count("the number of ghost entities", 8) : count_value("the number of ghost entities", 4);
  if (!binary_) end_record("the number of ghost entities");
  for (std::size_t g = 0; g < ghosts; ++g) {
    if (!binary_) next_record();
    (void)read_entity_ints("a ghost entity", 2);
    if (!binary_) end_record("a ghost entity");
  }
  std::array<std::size_t, 4> counts{};
  if (!binary_) next_record();
  for (int d = 0; d < 4; ++d) {
    const std::string what = std::string("the number of partitioned ") + kinds[d];
    counts[d] = binary_ ? raw_count(what.c_str(), 40) : count_value(what, 14);
  }
  if (!binary_) end_record("the partitioned entity counts");
  std::array<std::map<int, std::vector<int>>, 4> pieces;
  for (int d = 0; d < 4; ++d) {
    for (std::size_t i = 0; i < counts[d]; ++i) {
      if (!binary_) next_record();
      const char* rec = p_;
      const std::vector<int> head = read_entity_ints("the tag and parent of a partitioned entity", 3);
      const std::size_t np = binary_ ? raw_count("the number of partitions of an entity", 4)
                                     : count_value("the number of partitions of an entity", 2);
      std::vector<int> parts = read_entity_ints("a partition tag", np);
      for (int k = 0; k < (d == 0 ? 3 : 6); ++k)
        binary_ ? (void)raw<double>("entity coordinates") : (void)real_value("a bounding-box coordinate", false);
      const std::size_t nphys =
          binary_ ? raw_count("the number of physical tags", 4) : count_value("the number of physical tags", 2);
      std::vector<int> phys = read_entity_ints("a physical tag", nphys);
      if (d > 0) {
        const std::size_t nb = binary_ ? raw_count("the number of bounding entities", 4)
                                       : count_value("the number of bounding entities", 2);
        (void)read_entity_ints("a bounding entity tag", nb);
      }
      if (!binary_) end_record("a partitioned entity");
      if (head[1] != d) {  // an interface between partitions: inside the body, no group
        phys.clear();
        partition_interfaces_[d].insert(head[0]);
      }
      for (int t : phys) note_used_group(d, t);
      if (d == 3) volume_partitions_[head[0]] = std::move(parts);
      if (!pieces[d].emplace(head[0], std::move(phys)).second)
        fail(rec,
             std::string("partitioned entity ") + std::to_string(head[0]) + " is defined twice among the " + kinds[d]);
    }
  }
  entities_ = std::move(pieces);
  expect_section_end("$EndPartitionedEntities");
  section_ = {};
}

// `count` integers of an entity record (4 bytes each in binary).
std::vector<int> Parser::read_entity_ints(const char* what, std::size_t count) {
  std::vector<int> values(count);
  for (std::size_t k = 0; k < count; ++k) values[k] = binary_ ? raw_int(what) : int_value(what);
  return values;
}

// A file of one partition out of several (gmsh -part_split writes one per partition) is a piece of
// the body: refused, not solved as if it were the whole.
void Parser::check_every_partition_present() const {
  // No tetrahedra at all: the mesh checks say so.
  if (partitions_ <= 1 || partitions_with_tets_.empty() || partitions_with_tets_.size() >= partitions_) return;
  std::string held;
  for (int p : partitions_with_tets_) held += (held.empty() ? "" : ", ") + std::to_string(p);
  throw InputError(name_ + ": the mesh is partitioned into " + std::to_string(partitions_) +
                   " parts but its tetrahedra lie in partition(s) " + held +
                   " only: a file of one partition (gmsh -part_split) is a piece of the body; save the whole mesh " +
                   "in one file (gmsh -part N without -part_split, or no partitions)");
}

void Parser::read_nodes41() {
  section_ = "Nodes";
  std::size_t num_blocks, num_nodes;
  if (binary_) {
    num_blocks = raw_count("the number of node blocks", 3 * 4 + size_bytes_);
    num_nodes = raw_count("the number of nodes", size_bytes_ + 24);
    (void)raw_size("the minimum node tag");
    (void)raw_size("the maximum node tag");
  } else {
    next_record();
    num_blocks = count_value("the number of node blocks", 8);
    const char* npos = p_;
    num_nodes = count_value("the number of nodes", 8);
    if (num_nodes > static_cast<std::size_t>(std::numeric_limits<int>::max()))
      fail(npos, "too many nodes (" + std::to_string(num_nodes) + ")");
    (void)unsigned_value("the minimum node tag");
    (void)unsigned_value("the maximum node tag");
    end_record("the $Nodes header");
  }
  if (num_nodes > static_cast<std::size_t>(std::numeric_limits<int>::max()))
    fail(p_, "too many nodes (" + std::to_string(num_nodes) + ")");
  mesh_.nodes.reserve(num_nodes);
  mesh_.node_tags.reserve(num_nodes);
  std::size_t total = 0;
  for (std::size_t b = 0; b < num_blocks; ++b) total += read_node_block41(num_nodes, total);
  if (total != num_nodes)
    fail(p_, "the $Nodes header announces " + std::to_string(num_nodes) + " nodes but its blocks hold " +
                 std::to_string(total));
  expect_section_end("$EndNodes");
  section_ = {};
}

// One MSH 4.1 node block (its header, its node tags, then their coordinates), `so_far` of the
// `announced` nodes read before it; returns its node count.
std::size_t Parser::read_node_block41(std::size_t announced, std::size_t so_far) {
  int dim, parametric;
  std::size_t n;
  const char* bpos;
  if (binary_) {
    bpos = p_;
    dim = raw_int("an entity dimension");
    (void)raw_int("an entity tag");
    parametric = raw_int("the parametric flag");
    if (dim < 0 || dim > 3) fail(bpos, "entity dimension " + std::to_string(dim) + " in a node block");
    if (parametric != 0 && parametric != 1)
      fail(bpos, "parametric flag " + std::to_string(parametric) + " in a node block");
    const std::size_t per_node = size_bytes_ + 8 * (3 + (parametric ? dim : 0));
    n = raw_count("the number of nodes in the block", per_node);
  } else {
    next_record();
    bpos = p_;
    const char* dpos = p_;
    dim = int_value("the entity dimension of a node block");
    if (dim < 0 || dim > 3) fail(dpos, "entity dimension " + std::to_string(dim) + " in a node block");
    (void)int_value("the entity tag of a node block");
    const char* ppos = p_;
    parametric = int_value("the parametric flag of a node block");
    if (parametric != 0 && parametric != 1)
      fail(ppos, "parametric flag " + std::to_string(parametric) + " (expected 0 or 1)");
    n = count_value("the number of nodes in the block", 8);
    end_record("the node block header");
  }
  if (n > announced - so_far)
    fail(bpos,
         "the node blocks hold more nodes than the " + std::to_string(announced) + " announced in the $Nodes header");
  const int params = parametric ? dim : 0;
  const std::size_t first = mesh_.node_tags.size();
  for (std::size_t i = 0; i < n; ++i) {
    const char* tpos;
    std::uint64_t tag;
    if (binary_) {
      tpos = p_;
      tag = raw_size("a node tag");
    } else {
      next_record();
      tpos = p_;
      tag = unsigned_value("a node tag");
      end_record("a node tag (one tag per line)");
    }
    if (tag == 0) fail(tpos, "node tag 0 is not valid (tags start at 1)");
    mesh_.node_tags.push_back(static_cast<std::size_t>(tag));
  }
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t tag = mesh_.node_tags[first + i];
    Eigen::Vector3d x;
    if (binary_) {
      const char* cpos = p_;
      for (int k = 0; k < 3; ++k) x[k] = raw<double>("a node coordinate");
      if (!x.allFinite()) fail(cpos, "node " + std::to_string(tag) + " has a non-finite coordinate");
      p_ += 8 * static_cast<std::size_t>(params);  // guarded by raw_count
    } else {
      next_record();
      for (int k = 0; k < 3; ++k) x[k] = real_value(kCoordinateNames[k]);
      for (int k = 0; k < params; ++k) (void)real_value("a parametric coordinate", false);
      end_record("the coordinates of a node");
    }
    mesh_.nodes.push_back(x);
  }
  return n;
}

void Parser::read_nodes22() {
  section_ = "Nodes";
  next_record();
  const char* npos = p_;
  // A node takes at least 8 characters in ASCII ("1 0 0 0\n"), exactly kNode22Bytes in binary.
  const std::size_t n = count_value("the number of nodes", binary_ ? kNode22Bytes : 8);
  if (n > static_cast<std::size_t>(std::numeric_limits<int>::max()))
    fail(npos, "too many nodes (" + std::to_string(n) + ")");
  end_record("the number of nodes");
  mesh_.nodes.reserve(n);
  mesh_.node_tags.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    const char* tpos;
    std::uint64_t tag;
    Eigen::Vector3d x;
    if (binary_) {
      // Binary: int node-number, then 3 doubles; the count line is ASCII.
      tpos = p_;
      if (at_section_end("$EndNodes"))
        fail(tpos, "the $Nodes header announces " + std::to_string(n) + " nodes but the section ends after " +
                       std::to_string(i));
      const int t = raw_int("a node tag");
      if (t <= 0) fail(tpos, "node tag " + std::to_string(t) + " is not valid (tags start at 1)");
      tag = static_cast<std::uint64_t>(t);
      const char* cpos = p_;
      for (int k = 0; k < 3; ++k) x[k] = raw<double>("a node coordinate");
      if (!x.allFinite()) fail(cpos, "node " + std::to_string(tag) + " has a non-finite coordinate");
    } else {
      next_record();
      tpos = p_;
      tag = unsigned_value("a node tag");
      if (tag == 0) fail(tpos, "node tag 0 is not valid (tags start at 1)");
      for (int k = 0; k < 3; ++k) x[k] = real_value(kCoordinateNames[k]);
      end_record("the coordinates of a node");
    }
    mesh_.node_tags.push_back(static_cast<std::size_t>(tag));
    mesh_.nodes.push_back(x);
  }
  expect_section_end("$EndNodes");
  section_ = {};
}

void Parser::finish_nodes(const char* section_pos) {
  const long long dup = nodes_.build(mesh_.node_tags);
  if (dup >= 0) {
    section_ = "Nodes";
    fail(section_pos,
         "node tag " + std::to_string(mesh_.node_tags[static_cast<std::size_t>(dup)]) + " is defined twice");
  }
  have_nodes_ = true;
}

void Parser::read_elements41() {
  section_ = "Elements";
  have_elements_ = true;
  std::size_t num_blocks, num_elements;
  if (binary_) {
    num_blocks = raw_count("the number of element blocks", 12 + size_bytes_);
    num_elements = raw_count("the number of elements", 2 * size_bytes_);
    (void)raw_size("the minimum element tag");
    (void)raw_size("the maximum element tag");
  } else {
    next_record();
    num_blocks = count_value("the number of element blocks", 8);
    num_elements = count_value("the number of elements", 4);
    (void)unsigned_value("the minimum element tag");
    (void)unsigned_value("the maximum element tag");
    end_record("the $Elements header");
  }
  std::size_t total = 0;
  for (std::size_t b = 0; b < num_blocks; ++b) total += read_element_block41(num_elements, total);
  if (total != num_elements)
    fail(p_, "the $Elements header announces " + std::to_string(num_elements) + " elements but its blocks hold " +
                 std::to_string(total));
  expect_section_end("$EndElements");
  section_ = {};
}

// One MSH 4.1 element block (its header, then its elements), `so_far` of the `announced` elements
// read before it; returns its element count.
std::size_t Parser::read_element_block41(std::size_t announced, std::size_t so_far) {
  int dim, etag, type;
  const char* bpos = p_;
  if (binary_) {
    dim = raw_int("an entity dimension");
    etag = raw_int("an entity tag");
    type = raw_int("an element type");
  } else {
    next_record();
    bpos = p_;
    dim = int_value("the entity dimension of an element block");
    etag = int_value("the entity tag of an element block");
    type = int_value("the element type of an element block");
  }
  if (dim < 0 || dim > 3) fail(bpos, "entity dimension " + std::to_string(dim) + " in an element block");
  const int nn = accepted_type_nodes(type);
  if (nn == 0) fail(bpos, unsupported_type_message(type));
  const std::size_t min_bytes =
      binary_ ? (1 + static_cast<std::size_t>(nn)) * size_bytes_ : 2 * (1 + static_cast<std::size_t>(nn));
  std::size_t n;
  if (binary_) {
    n = raw_count("the number of elements in the block", min_bytes);
  } else {
    n = count_value("the number of elements in the block", min_bytes);
    end_record("the element block header");
  }
  if (n > announced - so_far)
    fail(bpos, "the element blocks hold more elements than the " + std::to_string(announced) +
                   " announced in the $Elements header");
  const std::vector<int>& phys = entity_physicals(dim, etag, bpos);
  const int group = phys.empty() ? 0 : phys[0];
  const bool partition_interface = partition_interfaces_[dim].count(etag) > 0;  // none unless partitioned
  if (is_tet(type) && n > 0)
    if (const auto it = volume_partitions_.find(etag); it != volume_partitions_.end())
      partitions_with_tets_.insert(it->second.begin(), it->second.end());

  if (is_tet(type)) reserve_more_tets(n);
  if (is_triangle(type)) reserve_more_triangles(n);
  const std::size_t first_tri = mesh_.triangles.size(), first_tet = mesh_.tets.size();
  std::array<int, kMaxElementNodes> idx{};
  for (std::size_t i = 0; i < n; ++i) {
    std::uint64_t tag;
    const char* epos;
    if (binary_) {
      epos = p_;
      tag = raw_size("an element tag");
      for (int k = 0; k < nn; ++k) {
        const char* npos = p_;
        idx[k] = node_ref(static_cast<std::size_t>(raw_size("a node tag")), npos, tag);
      }
    } else {
      next_record();
      epos = p_;
      tag = unsigned_value("an element tag");
      read_ascii_element_nodes(nn, idx, tag);
    }
    if (tag == 0) fail(epos, "element tag 0 is not valid (tags start at 1)");
    if (!partition_interface) store_element(type, tag, group, idx);
  }
  if (is_second_order(type)) second_order_ = true;
  if (is_triangle(type) && phys.size() > 1) repeat_for_extra_physicals(bpos, etag, first_tri, phys);
  if (is_tet(type))  // a volume entity in several physical groups: each tet keeps them all
    for (std::size_t k = 1; k < phys.size(); ++k)
      for (std::size_t e = first_tet; e < mesh_.tets.size(); ++e) mesh_.tet_extra_groups.emplace_back(e, phys[k]);
  return n;
}

// A tetrahedron or a triangle with its nodes idx (other accepted types are read and dropped).
void Parser::store_element(int type, std::uint64_t tag, int group, const std::array<int, kMaxElementNodes>& idx) {
  if (is_tet(type)) {
    mesh_.tets.push_back({idx[0], idx[1], idx[2], idx[3]});
    mesh_.tet_tags.push_back(static_cast<std::size_t>(tag));
    mesh_.tet_group.push_back(group);
  } else if (is_triangle(type)) {
    mesh_.triangles.push_back({idx[0], idx[1], idx[2]});
    mesh_.triangle_tags.push_back(static_cast<std::size_t>(tag));
    mesh_.triangle_group.push_back(group);
  }
}

// A surface entity with several physical tags: its triangles (from first_triangle on) stored again
// once per extra tag. Each copy stores the block again, so the total is bounded by the file size:
// a small crafted file cannot demand a huge allocation.
void Parser::repeat_for_extra_physicals(const char* block_pos, int entity, std::size_t first_triangle,
                                        const std::vector<int>& phys) {
  const std::size_t block = mesh_.triangles.size() - first_triangle;
  const std::size_t limit = static_cast<std::size_t>(end_ - begin_) + (std::size_t{1} << 20);
  const std::size_t room = limit - std::min(limit, mesh_.triangles.size());
  if (block > 0 && phys.size() - 1 > room / block)
    fail(block_pos, "surface entity " + std::to_string(entity) + " has " + std::to_string(phys.size()) +
                        " physical tags; storing its " + std::to_string(block) +
                        " triangles once per tag is more than this "
                        "reader allows for a file of this size");
  duplicate_triangles(first_triangle, mesh_.triangles.size(), phys);
}

void Parser::read_elements22() {
  section_ = "Elements";
  have_elements_ = true;
  next_record();
  // An element takes at least 8 characters in ASCII, 8 bytes in binary (a point without tags).
  const std::size_t n = count_value("the number of elements", 8);
  end_record("the number of elements");
  prev_tet22_ = false;
  prev_elementary22_ = 0;
  if (binary_) {
    // Blocks: gmsh 4 writes one block per element; older writers group elements of a type.
    std::size_t total = 0;
    while (total < n) {
      const char* block_pos = p_;
      if (at_section_end("$EndElements"))
        fail(block_pos, "the $Elements header announces " + std::to_string(n) + " elements but its blocks hold " +
                            std::to_string(total));
      total += read_binary_element_block22(n, total);
    }
  } else {
    for (std::size_t i = 0; i < n; ++i) read_ascii_element22();
  }
  expect_section_end("$EndElements");
  section_ = {};
}

// One binary MSH 2.2 block (`so_far` of the `announced` elements read before it): a header of 3 ints (element type,
// number of elements in the block, number of tags per element), then per element: int element number, the tags, the
// node numbers. Returns its element count.
std::size_t Parser::read_binary_element_block22(std::size_t announced, std::size_t so_far) {
  const char* bpos = p_;
  const int type = raw_int("the element type of an element block");
  const int nn = accepted_type_nodes(type);
  if (nn == 0) fail(bpos, unsupported_type_message(type));
  const char* cpos = p_;
  const int count = raw_int("the number of elements in the block");
  const char* tpos = p_;
  const int ntags = raw_int("the number of tags per element of the block");
  if (count < 0) fail(cpos, "the number of elements in the block is negative (" + std::to_string(count) + ")");
  if (ntags < 0) fail(tpos, "the number of tags per element is negative (" + std::to_string(ntags) + ")");
  // The block must fit in the rest of the file: first without tags (else the file is
  // truncated or the count corrupt), then with them (else the tag count is corrupt).
  const std::size_t bare = 4 * (1 + static_cast<std::size_t>(nn));
  check_count(cpos, static_cast<std::uint64_t>(count), bare, "the number of elements in the block");
  if (count > 0) {
    const std::size_t left = static_cast<std::size_t>(end_ - p_) / static_cast<std::size_t>(count) - bare;
    if (static_cast<std::size_t>(ntags) > left / 4)
      fail(tpos, "the number of tags per element " + std::to_string(ntags) +
                     " is larger than the rest of the file can hold (truncated file or corrupt "
                     "count)");
  }
  if (static_cast<std::size_t>(count) > announced - so_far)
    fail(cpos, "the element blocks hold more elements than the " + std::to_string(announced) +
                   " announced in the $Elements header");
  if (is_tet(type)) reserve_more_tets(static_cast<std::size_t>(count));
  if (is_triangle(type)) reserve_more_triangles(static_cast<std::size_t>(count));
  std::array<int, kMaxElementNodes> idx{};
  for (int i = 0; i < count; ++i) {
    const char* epos = p_;
    const int tag = raw_int("an element tag");
    if (tag <= 0) fail(epos, "element tag " + std::to_string(tag) + " is not valid (tags start at 1)");
    int physical = 0, elementary = 0;
    for (int k = 0; k < ntags; ++k) {
      const int t = raw_int("an element tag (physical or elementary)");
      if (k == 0) physical = t;
      if (k == 1) elementary = t;
    }
    for (int k = 0; k < nn; ++k) {
      const char* npos = p_;
      const int v = raw_int("a node tag of an element");
      if (v < 0)
        fail(npos, "element " + std::to_string(tag) + " refers to node " + std::to_string(v) +
                       ", which $Nodes does not define");
      idx[k] = node_ref(static_cast<std::size_t>(v), npos, static_cast<std::size_t>(tag));
    }
    keep_element22(type, static_cast<std::uint64_t>(tag), physical, elementary, idx);
  }
  return static_cast<std::size_t>(count);
}

// One ASCII MSH 2.2 element record: tag, type, number of tags, the tags, the node tags.
void Parser::read_ascii_element22() {
  next_record();
  const char* epos = p_;
  const std::uint64_t tag = unsigned_value("an element tag");
  if (tag == 0) fail(epos, "element tag 0 is not valid (tags start at 1)");
  skip_blank();
  const char* tpos = p_;
  const int type = int_value("an element type");
  const int nn = accepted_type_nodes(type);
  if (nn == 0) fail(tpos, unsupported_type_message(type));
  const std::size_t ntags = count_value("the number of tags of an element", 2);
  int physical = 0, elementary = 0;
  for (std::size_t k = 0; k < ntags; ++k) {
    const int t = int_value("an element tag (physical or elementary)");
    if (k == 0) physical = t;
    if (k == 1) elementary = t;
  }
  std::array<int, kMaxElementNodes> idx{};
  read_ascii_element_nodes(nn, idx, tag);
  keep_element22(type, tag, physical, elementary, idx);
}

// Stores one MSH 2.2 element of an accepted type whose nodes are in idx; a tetrahedron repeated
// for another physical group (the same nodes, the same elementary entity, right after) once.
void Parser::keep_element22(int type, std::uint64_t tag, int physical, int elementary,
                            const std::array<int, kMaxElementNodes>& idx) {
  const int dim = is_tet(type) ? 3 : is_triangle(type) ? 2 : is_line(type) ? 1 : 0;
  note_used_group(dim, physical);
  if (is_second_order(type)) second_order_ = true;
  if (is_tet(type)) {
    const std::array<int, 4> tet{idx[0], idx[1], idx[2], idx[3]};
    if (prev_tet22_ && elementary == prev_elementary22_ && mesh_.tets.back() == tet) {
      if (physical != 0 && physical != mesh_.tet_group.back())
        mesh_.tet_extra_groups.emplace_back(mesh_.tets.size() - 1, physical);
      return;
    }
    store_element(type, tag, physical, idx);
    prev_tet22_ = true;
    prev_elementary22_ = elementary;
  } else {
    prev_tet22_ = false;
    store_element(type, tag, physical, idx);
  }
}

void Parser::skip_section(const char* header_pos, std::string_view name) {
  const std::string end_tag = "$End" + std::string(name);
  const std::string_view rest(p_, static_cast<std::size_t>(end_ - p_));
  std::size_t from = 0;
  for (;;) {
    const std::size_t pos = rest.find(end_tag, from);
    if (pos == std::string_view::npos)
      fail(header_pos, "section $" + std::string(name) + " is not closed by " + end_tag);
    const char* at = p_ + pos;
    const char* after = at + end_tag.size();
    if ((at == begin_ || at[-1] == '\n') && (after == end_ || is_space(*after))) {
      p_ = after;
      end_record(end_tag.c_str());
      return;
    }
    from = pos + 1;
  }
}

}  // namespace

Mesh parse_msh(std::string_view contents, const std::string& source_name) {
  return Parser(contents, source_name).parse();
}

Mesh read_msh(const std::string& path) {
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) throw InputError("cannot open mesh file '" + path + "': " + std::strerror(errno));
  std::string data;
  struct stat st {};
  if (::fstat(::fileno(f), &st) == 0) {
    if (S_ISDIR(st.st_mode)) {
      std::fclose(f);
      throw InputError("cannot read mesh file '" + path + "': it is a directory");
    }
    if (!S_ISREG(st.st_mode) && !S_ISFIFO(st.st_mode)) {  // /dev/zero would be read forever
      std::fclose(f);
      throw InputError("cannot read mesh file '" + path + "': it is not a regular file (a device or socket)");
    }
    // Regular files: one read straight into a buffer of the file's size.
    if (S_ISREG(st.st_mode) && st.st_size > 0) {
      data.resize(static_cast<std::size_t>(st.st_size));
      data.resize(std::fread(data.data(), 1, data.size(), f));
    }
  }
  // Anything else (pipes, a file that grew meanwhile): the rest in chunks.
  char chunk[1 << 16];
  std::size_t got;
  while ((got = std::fread(chunk, 1, sizeof chunk, f)) > 0) data.append(chunk, got);
  const bool bad = std::ferror(f) != 0;
  const int err = errno;
  std::fclose(f);
  if (bad) throw InputError("cannot read mesh file '" + path + "': " + std::strerror(err));
  return parse_msh(data, path);
}

}  // namespace contact3d
