// Checked reads of a parsed JSON document for the report's inputs (sample sets, geometry maps): each throws
// std::runtime_error that names what was expected and where.
#pragma once

#include <boost/json.hpp>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

namespace warpcheck::validation::report::json_read {

inline const boost::json::value& member(const boost::json::object& o, const char* key, const std::string& where) {
  const boost::json::value* v = o.if_contains(key);
  if (!v) throw std::runtime_error(where + " has no \"" + key + "\"");
  return *v;
}

// A JSON number (int64, uint64 or double) as double.
inline double number(const boost::json::value& v, const std::string& what) {
  if (!v.is_number()) throw std::runtime_error(what + " is not a number");
  return v.to_number<double>();
}

// A JSON array of numbers; null reads as NaN (no value there).
inline std::vector<double> numbers(const boost::json::value& v, const std::string& what) {
  if (!v.is_array()) throw std::runtime_error(what + " is not an array");
  std::vector<double> out;
  for (const boost::json::value& x : v.get_array())
    out.push_back(x.is_null() ? std::numeric_limits<double>::quiet_NaN() : number(x, what + " entry"));
  return out;
}

inline std::string string_of(const boost::json::value& v, const std::string& what) {
  if (!v.is_string()) throw std::runtime_error(what + " is not a string");
  return std::string(v.get_string());
}

}  // namespace warpcheck::validation::report::json_read
