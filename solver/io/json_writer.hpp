// A minimal streaming JSON writer (objects, arrays, numbers, strings) for summary.json.
// Non-finite numbers are written as null, so a result file never carries NaN.
#pragma once

#include <ostream>
#include <string>
#include <vector>

namespace contact3d {

class JsonWriter {
 public:
  explicit JsonWriter(std::ostream& out) : out_(out) {}
  JsonWriter& begin_object(const std::string& key = "");
  JsonWriter& end_object();
  JsonWriter& begin_array(const std::string& key = "");
  JsonWriter& end_array();
  JsonWriter& value(const std::string& key, double v);
  JsonWriter& value(const std::string& key, long long v);
  JsonWriter& value(const std::string& key, int v) { return value(key, static_cast<long long>(v)); }
  JsonWriter& value(const std::string& key, bool v);
  JsonWriter& value(const std::string& key, const std::string& v);
  JsonWriter& value(const std::string& key, const char* v) { return value(key, std::string(v)); }
  JsonWriter& element(double v) { return value("", v); }
  JsonWriter& element(const std::string& v) { return value("", v); }

  static std::string quote(const std::string& s);

 private:
  void prefix(const std::string& key);
  std::ostream& out_;
  std::vector<bool> first_{true};
};

}  // namespace contact3d
