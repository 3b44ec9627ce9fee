#include "io/json_writer.hpp"

#include <cmath>
#include <cstdio>

namespace contact3d {

std::string JsonWriter::quote(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    switch (c) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\t':
        out += "\\t";
        break;
      case '\r':
        out += "\\r";
        break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          char buf[8];
          std::snprintf(buf, sizeof buf, "\\u%04x", c);
          out += buf;
        } else {
          out += c;
        }
    }
  }
  return out + "\"";
}

void JsonWriter::prefix(const std::string& key) {
  if (!first_.back()) out_ << ",";
  first_.back() = false;
  out_ << "\n" << std::string(2 * (first_.size() - 1), ' ');
  if (!key.empty()) out_ << quote(key) << ": ";
}

JsonWriter& JsonWriter::begin_object(const std::string& key) {
  if (first_.size() > 1 || !key.empty()) prefix(key);
  out_ << "{";
  first_.push_back(true);
  return *this;
}
JsonWriter& JsonWriter::end_object() {
  first_.pop_back();
  out_ << "\n" << std::string(2 * (first_.size() - 1), ' ') << "}";
  return *this;
}
JsonWriter& JsonWriter::begin_array(const std::string& key) {
  prefix(key);
  out_ << "[";
  first_.push_back(true);
  return *this;
}
JsonWriter& JsonWriter::end_array() {
  first_.pop_back();
  out_ << "]";
  return *this;
}
JsonWriter& JsonWriter::value(const std::string& key, double v) {
  prefix(key);
  if (std::isfinite(v)) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.10g", v);
    out_ << buf;
  } else {
    out_ << "null";
  }
  return *this;
}
JsonWriter& JsonWriter::value(const std::string& key, long long v) {
  prefix(key);
  out_ << v;
  return *this;
}
JsonWriter& JsonWriter::value(const std::string& key, bool v) {
  prefix(key);
  out_ << (v ? "true" : "false");
  return *this;
}
JsonWriter& JsonWriter::value(const std::string& key, const std::string& v) {
  prefix(key);
  out_ << quote(v);
  return *this;
}

}  // namespace contact3d
