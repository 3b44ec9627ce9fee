#include "mesh/msh_writer.hpp"

#include <sys/stat.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <map>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "base/errors.hpp"

namespace contact3d {
namespace {

// Buffered output to a file; numbers via std::to_chars (shortest round-trip form for doubles).
class Output {
  // Written in place: an existing device, pipe or symbolic link (the rename would replace a link,
  // /dev/stdout included, instead of writing through it to its target).
  static bool write_in_place(const std::string& path) {
    struct stat st {};
    return ::lstat(path.c_str(), &st) == 0 && !S_ISREG(st.st_mode);
  }

 public:
  // Written to "<path>.partial" and renamed into place by close(): a full disk or a failed run
  // never leaves a truncated mesh under the file's name.
  explicit Output(const std::string& path) : path_(path), partial_(write_in_place(path) ? path : path + ".partial") {
    nothing_to_remove_ = partial_ == path_;
    f_ = std::fopen(partial_.c_str(), "wb");
    if (!f_) throw InputError("cannot write mesh file '" + path + "': " + std::strerror(errno));
    buf_.reserve(kFlushAt + 4096);
  }
  Output(const Output&) = delete;
  Output& operator=(const Output&) = delete;
  ~Output() {
    if (f_) std::fclose(f_);
    if (!nothing_to_remove_) std::remove(partial_.c_str());
  }

  Output& operator<<(std::string_view s) {
    buf_.append(s);
    return *this;
  }
  Output& operator<<(char c) {
    buf_.push_back(c);
    if (c == '\n' && buf_.size() >= kFlushAt) flush();
    return *this;
  }
  Output& operator<<(double v) { return number(v); }
  Output& operator<<(int v) { return number(v); }
  Output& operator<<(std::size_t v) { return number(v); }

  void close() {
    flush();
    std::FILE* f = f_;
    f_ = nullptr;
    if (std::fclose(f) != 0) throw InputError("cannot write mesh file '" + path_ + "': " + std::strerror(errno));
    if (partial_ != path_ && std::rename(partial_.c_str(), path_.c_str()) != 0)
      throw InputError("cannot write mesh file '" + path_ + "': " + std::strerror(errno));
    nothing_to_remove_ = true;
  }

 private:
  static constexpr std::size_t kFlushAt = 1 << 20;

  template <class T>
  Output& number(T v) {
    char tmp[64];
    const auto r = std::to_chars(tmp, tmp + sizeof tmp, v);
    buf_.append(tmp, r.ptr);
    return *this;
  }
  void flush() {
    if (!buf_.empty() && std::fwrite(buf_.data(), 1, buf_.size(), f_) != buf_.size())
      throw InputError("cannot write mesh file '" + path_ + "': " + std::strerror(errno));
    buf_.clear();
  }

  std::string path_, partial_;
  bool nothing_to_remove_ = false;
  std::FILE* f_ = nullptr;
  std::string buf_;
};

struct Entity {
  int tag = 0;
  int group = 0;  // physical tag, 0 = none
  std::array<double, 3> lo{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
                           std::numeric_limits<double>::infinity()};
  std::array<double, 3> hi{-std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity(),
                           -std::numeric_limits<double>::infinity()};
  void add(const Eigen::Vector3d& x) {
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], x[k]);
      hi[k] = std::max(hi[k], x[k]);
    }
  }
};

// The mesh with defaults filled in and checked, plus one entity per (dimension, group).
class Prepared {
 public:
  explicit Prepared(const Mesh& m) : m_(m) {
    const std::size_t n = m.nodes.size(), nt = m.triangles.size(), nk = m.tets.size();
    auto check_size = [](std::size_t got, std::size_t want, const char* what) {
      if (got != 0 && got != want)
        throw std::invalid_argument(std::string("write_msh: ") + what + " has " + std::to_string(got) +
                                    " entries, expected " + std::to_string(want) + " (or none)");
    };
    check_size(m.node_tags.size(), n, "Mesh::node_tags");
    check_size(m.triangle_tags.size(), nt, "Mesh::triangle_tags");
    check_size(m.triangle_group.size(), nt, "Mesh::triangle_group");
    check_size(m.tet_tags.size(), nk, "Mesh::tet_tags");
    check_size(m.tet_group.size(), nk, "Mesh::tet_group");
    for (std::size_t i = 0; i < n; ++i) {
      if (!m.nodes[i].allFinite())
        throw std::invalid_argument("write_msh: node " + std::to_string(i) + " has a non-finite coordinate");
      if (!m.node_tags.empty() && m.node_tags[i] == 0)
        throw std::invalid_argument("write_msh: node " + std::to_string(i) + " has tag 0");
    }
    auto check_nodes = [n](const auto& elems, const char* what) {
      for (std::size_t e = 0; e < elems.size(); ++e)
        for (int v : elems[e])
          if (v < 0 || static_cast<std::size_t>(v) >= n)
            throw std::invalid_argument(std::string("write_msh: ") + what + " " + std::to_string(e) +
                                        " refers to node index " + std::to_string(v) + " (the mesh has " +
                                        std::to_string(n) + " nodes)");
    };
    check_nodes(m.triangles, "triangle");
    check_nodes(m.tets, "tetrahedron");
    for (const auto& g : m.groups)
      if (g.name.find_first_of("\r\n") != std::string::npos)
        throw std::invalid_argument("write_msh: physical group name with a line break");

    // Default element tags continue after the largest given one.
    std::size_t base = 0;
    for (std::size_t t : m.triangle_tags) base = std::max(base, t);
    for (std::size_t t : m.tet_tags) base = std::max(base, t);
    if (m.triangle_tags.empty())
      for (std::size_t i = 0; i < nt; ++i) tri_tags_.push_back(++base);
    if (m.tet_tags.empty())
      for (std::size_t i = 0; i < nk; ++i) tet_tags_.push_back(++base);
    for (std::size_t t : (m.triangle_tags.empty() ? tri_tags_ : m.triangle_tags))
      if (t == 0) throw std::invalid_argument("write_msh: a triangle has element tag 0");
    for (std::size_t t : (m.tet_tags.empty() ? tet_tags_ : m.tet_tags))
      if (t == 0) throw std::invalid_argument("write_msh: a tetrahedron has element tag 0");

    for (std::size_t i = 0; i < nt; ++i) {
      Entity& e = entity(surfaces_, surface_of_group_, tri_group(i));
      for (int v : m.triangles[i]) e.add(m.nodes[static_cast<std::size_t>(v)]);
    }
    for (std::size_t i = 0; i < nk; ++i) {
      Entity& e = entity(volumes_, volume_of_group_, tet_group(i));
      for (int v : m.tets[i]) e.add(m.nodes[static_cast<std::size_t>(v)]);
    }
    // Nodes go into one block of the first volume (else surface) entity; a mesh without
    // elements gets a volume entity without physical tags to hold them.
    if (volumes_.empty() && surfaces_.empty() && n > 0) {
      Entity& e = entity(volumes_, volume_of_group_, 0);
      for (const auto& x : m.nodes) e.add(x);
    }
    if (!volumes_.empty()) {
      node_dim_ = 3;
      node_entity_ = volumes_.front().tag;
    } else if (!surfaces_.empty()) {
      node_dim_ = 2;
      node_entity_ = surfaces_.front().tag;
    }
  }

  const Mesh& mesh() const { return m_; }
  std::size_t node_tag(std::size_t i) const { return m_.node_tags.empty() ? i + 1 : m_.node_tags[i]; }
  std::size_t tri_tag(std::size_t i) const { return m_.triangle_tags.empty() ? tri_tags_[i] : m_.triangle_tags[i]; }
  std::size_t tet_tag(std::size_t i) const { return m_.tet_tags.empty() ? tet_tags_[i] : m_.tet_tags[i]; }
  int tri_group(std::size_t i) const { return m_.triangle_group.empty() ? 0 : m_.triangle_group[i]; }
  int tet_group(std::size_t i) const { return m_.tet_group.empty() ? 0 : m_.tet_group[i]; }
  int surface_entity(int group) const { return surface_of_group_.at(group); }
  int volume_entity(int group) const { return volume_of_group_.at(group); }
  const std::vector<Entity>& surfaces() const { return surfaces_; }
  const std::vector<Entity>& volumes() const { return volumes_; }
  int node_dim() const { return node_dim_; }
  int node_entity() const { return node_entity_; }

 private:
  static Entity& entity(std::vector<Entity>& list, std::map<int, int>& of_group, int group) {
    const auto it = of_group.find(group);
    if (it != of_group.end()) return list[static_cast<std::size_t>(it->second - 1)];
    Entity e;
    e.tag = static_cast<int>(list.size()) + 1;
    e.group = group;
    list.push_back(e);
    of_group.emplace(group, e.tag);
    return list.back();
  }

  const Mesh& m_;
  std::vector<std::size_t> tri_tags_, tet_tags_;
  std::vector<Entity> surfaces_, volumes_;
  std::map<int, int> surface_of_group_, volume_of_group_;
  int node_dim_ = 3, node_entity_ = 0;
};

void write_format(Output& out, std::string_view version) {
  out << "$MeshFormat\n" << version << " 0 8\n$EndMeshFormat\n";
}

void write_physical_names(Output& out, const Mesh& m) {
  if (m.groups.empty()) return;
  out << "$PhysicalNames\n" << m.groups.size() << '\n';
  for (const auto& g : m.groups) out << g.dim << ' ' << g.tag << " \"" << g.name << "\"\n";
  out << "$EndPhysicalNames\n";
}

void write_point(Output& out, const Eigen::Vector3d& x) { out << x[0] << ' ' << x[1] << ' ' << x[2]; }

// Runs of consecutive elements with the same group: (first, count).
template <class GroupOf>
std::vector<std::pair<std::size_t, std::size_t>> runs(std::size_t n, GroupOf group_of) {
  std::vector<std::pair<std::size_t, std::size_t>> out;
  for (std::size_t i = 0; i < n;) {
    std::size_t j = i + 1;
    while (j < n && group_of(j) == group_of(i)) ++j;
    out.push_back({i, j - i});
    i = j;
  }
  return out;
}

}  // namespace

void write_msh41(const Mesh& mesh, const std::string& path) {
  const Prepared p(mesh);
  const Mesh& m = mesh;
  Output out(path);
  write_format(out, "4.1");
  write_physical_names(out, m);

  out << "$Entities\n0 0 " << p.surfaces().size() << ' ' << p.volumes().size() << '\n';
  for (const auto* list : {&p.surfaces(), &p.volumes()}) {
    for (const Entity& e : *list) {
      out << e.tag;
      for (int k = 0; k < 3; ++k) out << ' ' << e.lo[k];
      for (int k = 0; k < 3; ++k) out << ' ' << e.hi[k];
      if (e.group != 0)
        out << " 1 " << e.group;
      else
        out << " 0";
      out << " 0\n";
    }
  }
  out << "$EndEntities\n";

  out << "$Nodes\n";
  const std::size_t n = m.nodes.size();
  if (n == 0) {
    out << "0 0 0 0\n";
  } else {
    std::size_t lo = std::numeric_limits<std::size_t>::max(), hi = 0;
    for (std::size_t i = 0; i < n; ++i) {
      lo = std::min(lo, p.node_tag(i));
      hi = std::max(hi, p.node_tag(i));
    }
    out << "1 " << n << ' ' << lo << ' ' << hi << '\n';
    out << p.node_dim() << ' ' << p.node_entity() << " 0 " << n << '\n';
    for (std::size_t i = 0; i < n; ++i) out << p.node_tag(i) << '\n';
    for (std::size_t i = 0; i < n; ++i) {
      write_point(out, m.nodes[i]);
      out << '\n';
    }
  }
  out << "$EndNodes\n";

  const auto tri_runs = runs(m.triangles.size(), [&](std::size_t i) { return p.tri_group(i); });
  const auto tet_runs = runs(m.tets.size(), [&](std::size_t i) { return p.tet_group(i); });
  std::size_t lo = std::numeric_limits<std::size_t>::max(), hi = 0;
  for (std::size_t i = 0; i < m.triangles.size(); ++i) {
    lo = std::min(lo, p.tri_tag(i));
    hi = std::max(hi, p.tri_tag(i));
  }
  for (std::size_t i = 0; i < m.tets.size(); ++i) {
    lo = std::min(lo, p.tet_tag(i));
    hi = std::max(hi, p.tet_tag(i));
  }
  if (hi == 0) lo = 0;
  out << "$Elements\n"
      << tri_runs.size() + tet_runs.size() << ' ' << m.triangles.size() + m.tets.size() << ' ' << lo << ' ' << hi
      << '\n';
  for (const auto& [first, count] : tri_runs) {
    out << "2 " << p.surface_entity(p.tri_group(first)) << " 2 " << count << '\n';
    for (std::size_t i = first; i < first + count; ++i) {
      out << p.tri_tag(i);
      for (int v : m.triangles[i]) out << ' ' << p.node_tag(static_cast<std::size_t>(v));
      out << '\n';
    }
  }
  for (const auto& [first, count] : tet_runs) {
    out << "3 " << p.volume_entity(p.tet_group(first)) << " 4 " << count << '\n';
    for (std::size_t i = first; i < first + count; ++i) {
      out << p.tet_tag(i);
      for (int v : m.tets[i]) out << ' ' << p.node_tag(static_cast<std::size_t>(v));
      out << '\n';
    }
  }
  out << "$EndElements\n";
  out.close();
}

void write_msh22(const Mesh& mesh, const std::string& path) {
  const Prepared p(mesh);
  const Mesh& m = mesh;
  Output out(path);
  write_format(out, "2.2");
  write_physical_names(out, m);

  out << "$Nodes\n" << m.nodes.size() << '\n';
  for (std::size_t i = 0; i < m.nodes.size(); ++i) {
    out << p.node_tag(i) << ' ';
    write_point(out, m.nodes[i]);
    out << '\n';
  }
  out << "$EndNodes\n";

  out << "$Elements\n" << m.triangles.size() + m.tets.size() << '\n';
  for (std::size_t i = 0; i < m.triangles.size(); ++i) {
    const int g = p.tri_group(i);
    out << p.tri_tag(i) << " 2 2 " << g << ' ' << p.surface_entity(g);
    for (int v : m.triangles[i]) out << ' ' << p.node_tag(static_cast<std::size_t>(v));
    out << '\n';
  }
  for (std::size_t i = 0; i < m.tets.size(); ++i) {
    const int g = p.tet_group(i);
    out << p.tet_tag(i) << " 4 2 " << g << ' ' << p.volume_entity(g);
    for (int v : m.tets[i]) out << ' ' << p.node_tag(static_cast<std::size_t>(v));
    out << '\n';
  }
  out << "$EndElements\n";
  out.close();
}

}  // namespace contact3d
