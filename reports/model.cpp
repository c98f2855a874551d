// The report's model: battery results JSON -> BatteryRun (see report.h). Boost.JSON (compiled once, in
// boost_json_impl.cpp).
#include <boost/json.hpp>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "report.h"

namespace warpcheck::validation::report {
namespace {

namespace json = boost::json;

[[noreturn]] void bad(const std::string& what) { throw std::runtime_error("battery results JSON: " + what); }

const json::value& member(const json::object& o, const char* key, const std::string& where) {
  const json::value* v = o.if_contains(key);
  if (!v) bad(where + ": missing \"" + key + "\"");
  return *v;
}

// A JSON number (int64, uint64 or double) as double; null as NaN when allowed.
std::optional<double> number(const json::value& v, const std::string& what, bool null_ok) {
  if (v.is_double()) return v.get_double();
  if (v.is_int64()) return double(v.get_int64());
  if (v.is_uint64()) return double(v.get_uint64());
  if (v.is_null() && null_ok) return std::nullopt;
  bad(what + " is not a number");
}

std::string string_of(const json::value& v, const std::string& what) {
  if (!v.is_string()) bad(what + " is not a string");
  return std::string(v.get_string());
}

std::vector<double> numbers(const json::value& v, const std::string& what) {
  if (!v.is_array()) bad(what + " is not an array");
  std::vector<double> out;
  out.reserve(v.get_array().size());
  for (const auto& x : v.get_array()) out.push_back(*number(x, what + " element", false));
  return out;
}

}  // namespace

BatteryRun parse_battery_json(const std::string& text) {
  json::error_code ec;
  // battery.h writes +-Infinity as 1e999 (valid JSON); Boost.JSON 1.81 reads it as +-inf.
  const json::value root = json::parse(text, ec);
  if (ec) bad("not valid JSON (" + ec.message() + ")");
  if (!root.is_object()) bad("top level is not an object");
  const json::object& o = root.get_object();
  BatteryRun run;
  run.alpha = *number(member(o, "alpha", "top level"), "alpha", false);
  run.correction = string_of(member(o, "correction", "top level"), "correction");
  run.statistical_tests = (long long)*number(member(o, "statistical_tests", "top level"), "statistical_tests", false);
  if (const auto* v = o.if_contains("samples")) run.samples = (long long)*number(*v, "samples", false);
  if (const auto* v = o.if_contains("seed")) run.seed = (long long)*number(*v, "seed", false);
  if (const auto* v = o.if_contains("complete")) {
    if (!v->is_bool()) bad("complete is not a boolean");
    run.complete = v->get_bool();
  }
  const json::value& results = member(o, "results", "top level");
  if (!results.is_array()) bad("results is not an array");
  std::size_t i = 0;
  for (const json::value& rv : results.get_array()) {
    const std::string where = "results[" + std::to_string(i++) + "]";
    if (!rv.is_object()) bad(where + " is not an object");
    const json::object& r = rv.get_object();
    Result x;
    x.kernel = string_of(member(r, "kernel", where), where + ".kernel");
    x.scalar = string_of(member(r, "scalar", where), where + ".scalar");
    x.config = string_of(member(r, "config", where), where + ".config");
    x.test = string_of(member(r, "test", where), where + ".test");
    x.statistic = number(member(r, "statistic", where), where + ".statistic", true);
    x.p_value = number(member(r, "p_value", where), where + ".p_value", true);
    const json::value& passed = member(r, "passed", where);
    if (!passed.is_bool()) bad(where + ".passed is not a boolean");
    x.passed = passed.get_bool();
    if (const auto* d = r.if_contains("detail")) x.detail = string_of(*d, where + ".detail");
    if (const auto* k = r.if_contains("known_limitation"))
      x.known_limitation = string_of(*k, where + ".known_limitation");
    if (const auto* m = r.if_contains("map")) {
      if (!m->is_object()) bad(where + ".map is not an object");
      const json::object& mo = m->get_object();
      x.map_rows = int(*number(member(mo, "rows", where + ".map"), where + ".map.rows", false));
      x.map_cols = int(*number(member(mo, "cols", where + ".map"), where + ".map.cols", false));
      x.observed = numbers(member(mo, "observed", where + ".map"), where + ".map.observed");
      x.expected = numbers(member(mo, "expected", where + ".map"), where + ".map.expected");
      const std::size_t n = std::size_t(x.map_rows) * std::size_t(x.map_cols);
      if (x.map_rows <= 0 || x.map_cols <= 0 || x.observed.size() != n || x.expected.size() != n)
        bad(where + ".map: rows x cols does not match the lengths of observed / expected");
    }
    run.results.push_back(std::move(x));
  }
  return run;
}

}  // namespace warpcheck::validation::report
