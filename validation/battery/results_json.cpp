// The results file (results.h): BatteryRun <-> JSON on Boost.JSON's value tree. Two things are done here
// rather than by Boost.JSON 1.81: numbers are read with std::from_chars (Boost's own conversion is off by an
// ulp or more for about a quarter of 17-digit doubles) and written with std::to_chars, and infinity is
// written as 1e999 (Boost writes the invalid token Infinity).
#include <boost/json.hpp>
#include <boost/json/basic_parser_impl.hpp>
#include <charconv>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "warpcheck/validation/results.h"

namespace warpcheck::validation {

const char* to_string(Correction c) { return c == Correction::kSidak ? "sidak" : "holm"; }

std::size_t BatteryRun::statistical_tests() const {
  std::size_t m = 0;
  for (const TestResult& r : results) m += r.p_value.has_value();
  return m;
}

namespace {

namespace json = boost::json;

// ---- Writing ------------------------------------------------------------------------------------------------

// A double as JSON: NaN as null, so that to_json can store any statistic.
json::value number_or_null(double v) { return std::isnan(v) ? json::value(nullptr) : json::value(v); }

json::value map_value(const TestResult& r) {
  json::array observed, expected;
  for (double o : r.observed) observed.push_back(std::uint64_t(o));  // counts
  for (double e : r.expected) expected.push_back(e);
  return json::object{{"rows", r.map_rows}, {"cols", r.map_cols}, {"observed", observed}, {"expected", expected}};
}

// A result's members before "passed", and after it.
json::object result_head(const TestResult& r) {
  json::object o{{"kernel", r.kernel}, {"scalar", r.scalar}, {"config", r.config}, {"test", r.test}};
  o["statistic"] = number_or_null(r.statistic);
  o["p_value"] = r.p_value ? number_or_null(*r.p_value) : json::value(nullptr);
  return o;
}
json::object result_tail(const TestResult& r) {
  json::object o{{"detail", r.detail}};
  if (!r.known_limitation.empty()) o["known_limitation"] = r.known_limitation;
  if (r.map_rows > 0) o["map"] = map_value(r);
  return o;
}

json::object power_value(const CasePower& c) {
  json::array figures;
  for (const PowerFigure& f : c.figures)
    figures.push_back(json::object{{"alternative", f.alternative}, {"eps", number_or_null(f.eps)}, {"test", f.test}});
  return json::object{{"kernel", c.kernel}, {"scalar", c.scalar}, {"config", c.config}, {"samples", c.samples},
                      {"level", c.level},   {"target", c.target}, {"figures", figures}};
}

// Compact JSON of v; doubles in the shortest form std::from_chars reads back exactly, +-infinity as +-1e999.
void write(const json::value& v, std::string& out) {
  if (v.is_object()) {
    out += '{';
    bool first = true;
    for (const auto& kv : v.get_object()) {
      if (!first) out += ',';
      first = false;
      out += json::serialize(kv.key()) + ':';
      write(kv.value(), out);
    }
    out += '}';
  } else if (v.is_array()) {
    out += '[';
    for (std::size_t i = 0; i < v.get_array().size(); ++i) {
      if (i) out += ',';
      write(v.get_array()[i], out);
    }
    out += ']';
  } else if (v.is_double() && std::isinf(v.get_double())) {
    out += v.get_double() > 0 ? "1e999" : "-1e999";
  } else if (v.is_double() && v.get_double() == 0) {
    out += std::signbit(v.get_double()) ? "-0.0" : "0";  // "-0" would read back as the integer 0
  } else if (v.is_double()) {
    char buf[32];
    out.append(buf, std::to_chars(buf, buf + sizeof buf, v.get_double()).ptr);
  } else {
    out += json::serialize(v);  // strings (escaped), integers, booleans, null
  }
}

// ---- Reading ------------------------------------------------------------------------------------------------

// A basic_parser handler that builds the value tree as json::parse does, except that every number with a
// fraction or exponent is converted from its text by std::from_chars (correctly rounded). Text out of double's
// range (1e999) keeps Boost's conversion, +-infinity or 0.
struct ExactNumbers {
  static constexpr std::size_t max_array_size = -1, max_object_size = -1, max_string_size = -1, max_key_size = -1;
  json::value_stack stack;
  std::string number;  // the parts of a number split across buffers

  bool on_document_begin(json::error_code&) { return stack.reset(), true; }
  bool on_document_end(json::error_code&) { return true; }
  bool on_array_begin(json::error_code&) { return true; }
  bool on_array_end(std::size_t n, json::error_code&) { return stack.push_array(n), true; }
  bool on_object_begin(json::error_code&) { return true; }
  bool on_object_end(std::size_t n, json::error_code&) { return stack.push_object(n), true; }
  bool on_string_part(json::string_view s, std::size_t, json::error_code&) { return stack.push_chars(s), true; }
  bool on_string(json::string_view s, std::size_t, json::error_code&) { return stack.push_string(s), true; }
  bool on_key_part(json::string_view s, std::size_t, json::error_code&) { return stack.push_chars(s), true; }
  bool on_key(json::string_view s, std::size_t, json::error_code&) { return stack.push_key(s), true; }
  bool on_number_part(json::string_view s, json::error_code&) { return number.append(s.data(), s.size()), true; }
  bool on_int64(std::int64_t i, json::string_view, json::error_code&) {
    number.clear();
    return stack.push_int64(i), true;
  }
  bool on_uint64(std::uint64_t u, json::string_view, json::error_code&) {
    number.clear();
    return stack.push_uint64(u), true;
  }
  bool on_double(double d, json::string_view s, json::error_code&) {
    number.append(s.data(), s.size());
    double exact = 0;
    const char* const last = number.data() + number.size();
    const auto [end, ec] = std::from_chars(number.data(), last, exact);
    number.clear();
    return stack.push_double(ec == std::errc() && end == last ? exact : d), true;
  }
  bool on_bool(bool b, json::error_code&) { return stack.push_bool(b), true; }
  bool on_null(json::error_code&) { return stack.push_null(), true; }
  bool on_comment_part(json::string_view, json::error_code&) { return true; }
  bool on_comment(json::string_view, json::error_code&) { return true; }
};

[[noreturn]] void bad(const std::string& what) { throw std::runtime_error("battery results JSON: " + what); }

json::value parse_exact(const std::string& text) {
  json::basic_parser<ExactNumbers> parser(json::parse_options{});
  json::error_code ec;
  const std::size_t used = parser.write_some(false, text.data(), text.size(), ec);
  if (ec) bad("not valid JSON (" + ec.message() + ")");
  if (used != text.size()) bad("not valid JSON (text after the top-level value)");
  return parser.handler().stack.release();
}

const json::value& member(const json::object& o, const char* key, const std::string& where) {
  const json::value* v = o.if_contains(key);
  if (!v) bad(where + ": missing \"" + key + "\"");
  return *v;
}

// A JSON number (int64, uint64 or double) as double; null as NaN when allowed.
double number(const json::value& v, const std::string& what, bool null_ok = false) {
  if (v.is_double()) return v.get_double();
  if (v.is_int64()) return double(v.get_int64());
  if (v.is_uint64()) return double(v.get_uint64());
  if (v.is_null() && null_ok) return std::numeric_limits<double>::quiet_NaN();
  bad(what + " is not a number");
}

std::uint64_t count(const json::value& v, const std::string& what) {
  if (v.is_uint64()) return v.get_uint64();
  if (v.is_int64() && v.get_int64() >= 0) return std::uint64_t(v.get_int64());
  bad(what + " is not a non-negative integer");
}

std::string string_of(const json::value& v, const std::string& what) {
  if (!v.is_string()) bad(what + " is not a string");
  return std::string(v.get_string());
}

bool bool_of(const json::value& v, const std::string& what) {
  if (!v.is_bool()) bad(what + " is not a boolean");
  return v.get_bool();
}

std::vector<double> numbers(const json::value& v, const std::string& what) {
  if (!v.is_array()) bad(what + " is not an array");
  std::vector<double> out;
  out.reserve(v.get_array().size());
  for (const auto& x : v.get_array()) out.push_back(number(x, what + " element"));
  return out;
}

void read_map(const json::value& m, const std::string& where, TestResult& x) {
  if (!m.is_object()) bad(where + " is not an object");
  const json::object& mo = m.get_object();
  x.map_rows = int(number(member(mo, "rows", where), where + ".rows"));
  x.map_cols = int(number(member(mo, "cols", where), where + ".cols"));
  x.observed = numbers(member(mo, "observed", where), where + ".observed");
  x.expected = numbers(member(mo, "expected", where), where + ".expected");
  const std::size_t n = std::size_t(x.map_rows) * std::size_t(x.map_cols);
  if (x.map_rows <= 0 || x.map_cols <= 0 || x.observed.size() != n || x.expected.size() != n)
    bad(where + ": rows x cols does not match the lengths of observed / expected");
}

// The case a result or a power entry belongs to: its kernel, scalar and config members.
void read_case(const json::object& o, const std::string& where, std::string& kernel, std::string& scalar,
               std::string& config) {
  kernel = string_of(member(o, "kernel", where), where + ".kernel");
  scalar = string_of(member(o, "scalar", where), where + ".scalar");
  config = string_of(member(o, "config", where), where + ".config");
}

TestResult read_result(const json::value& rv, const std::string& where) {
  if (!rv.is_object()) bad(where + " is not an object");
  const json::object& r = rv.get_object();
  TestResult x;
  read_case(r, where, x.kernel, x.scalar, x.config);
  x.test = string_of(member(r, "test", where), where + ".test");
  x.statistic = number(member(r, "statistic", where), where + ".statistic", true);
  const json::value& p = member(r, "p_value", where);
  if (!p.is_null()) x.p_value = number(p, where + ".p_value");
  x.passed = bool_of(member(r, "passed", where), where + ".passed");
  if (const auto* d = r.if_contains("detail")) x.detail = string_of(*d, where + ".detail");
  if (const auto* k = r.if_contains("known_limitation"))
    x.known_limitation = string_of(*k, where + ".known_limitation");
  if (const auto* m = r.if_contains("map")) read_map(*m, where + ".map", x);
  return x;
}

CasePower read_power(const json::value& v, const std::string& where) {
  if (!v.is_object()) bad(where + " is not an object");
  const json::object& o = v.get_object();
  CasePower c;
  read_case(o, where, c.kernel, c.scalar, c.config);
  c.samples = count(member(o, "samples", where), where + ".samples");
  c.level = number(member(o, "level", where), where + ".level");
  c.target = number(member(o, "target", where), where + ".target");
  const json::value& figures = member(o, "figures", where);
  if (!figures.is_array()) bad(where + ".figures is not an array");
  for (const json::value& fv : figures.get_array()) {
    const std::string at = where + ".figures[" + std::to_string(c.figures.size()) + "]";
    if (!fv.is_object()) bad(at + " is not an object");
    const json::object& f = fv.get_object();
    c.figures.push_back({string_of(member(f, "alternative", at), at + ".alternative"),
                         string_of(member(f, "test", at), at + ".test"),
                         number(member(f, "eps", at), at + ".eps", true)});
  }
  return c;
}

Correction correction_of(const json::value& v) {
  const std::string c = string_of(v, "correction");
  if (c != to_string(Correction::kHolm) && c != to_string(Correction::kSidak))
    bad("correction is \"" + c + "\", not \"holm\" or \"sidak\"");
  return c == to_string(Correction::kHolm) ? Correction::kHolm : Correction::kSidak;
}

ShardOf read_shard(const json::value& v) {
  if (!v.is_object()) bad("shard is not an object");
  const json::object& o = v.get_object();
  ShardOf s;
  s.index = count(member(o, "index", "shard"), "shard.index");
  s.count = count(member(o, "count", "shard"), "shard.count");
  s.cases = count(member(o, "cases", "shard"), "shard.cases");
  s.case_list = string_of(member(o, "case_list", "shard"), "shard.case_list");
  if (s.count == 0 || s.index >= s.count) bad("shard.index is not below shard.count");
  return s;
}

// A result as {head,"passed":<flag>,tail}: the text on either side of the flag.
std::pair<std::string, std::string> result_parts(const TestResult& r) {
  std::string head, tail;
  write(result_head(r), head);
  write(result_tail(r), tail);
  head.back() = ',';   // {head} -> {head,
  tail.front() = ',';  // {tail} -> ,tail}
  return {head + "\"passed\":", std::move(tail)};
}

}  // namespace

std::string to_json(const BatteryRun& run, ResultTexts* texts) {
  json::object head{
      {"alpha", run.alpha}, {"correction", to_string(run.correction)}, {"statistical_tests", run.statistical_tests()}};
  if (run.samples) head["samples"] = *run.samples;
  if (run.seed) head["seed"] = *run.seed;
  if (run.complete) head["complete"] = *run.complete;
  if (run.shard)
    head["shard"] = json::object{{"index", run.shard->index},
                                 {"count", run.shard->count},
                                 {"cases", run.shard->cases},
                                 {"case_list", run.shard->case_list}};
  std::string out;
  write(head, out);
  out.pop_back();  // reopen the object for the results, one per line
  out += ",\"results\":[";
  for (std::size_t i = 0; i < run.results.size(); ++i) {
    const TestResult& r = run.results[i];
    std::pair<std::string, std::string> fresh;
    if (texts && i == texts->parts.size()) texts->parts.push_back(result_parts(r));
    const auto& [before, after] = texts ? texts->parts[i] : (fresh = result_parts(r));
    out += i ? ",\n" : "\n";
    out += before;
    out += r.passed ? "true" : "false";
    out += after;
  }
  out += "\n]";
  if (!run.power.empty()) {
    out += ",\"power\":[";
    for (std::size_t i = 0; i < run.power.size(); ++i) {
      out += i ? ",\n" : "\n";
      write(power_value(run.power[i]), out);
    }
    out += "\n]";
  }
  out += "}\n";
  return out;
}

BatteryRun parse_battery_json(const std::string& text) {
  const json::value root = parse_exact(text);
  if (!root.is_object()) bad("top level is not an object");
  const json::object& o = root.get_object();
  BatteryRun run;
  run.alpha = number(member(o, "alpha", "top level"), "alpha");
  run.correction = correction_of(member(o, "correction", "top level"));
  if (const auto* v = o.if_contains("samples")) run.samples = count(*v, "samples");
  if (const auto* v = o.if_contains("seed")) run.seed = count(*v, "seed");
  if (const auto* v = o.if_contains("complete")) run.complete = bool_of(*v, "complete");
  if (const auto* v = o.if_contains("shard")) run.shard = read_shard(*v);
  const json::value& results = member(o, "results", "top level");
  if (!results.is_array()) bad("results is not an array");
  for (const json::value& rv : results.get_array())
    run.results.push_back(read_result(rv, "results[" + std::to_string(run.results.size()) + "]"));
  if (const auto* p = o.if_contains("power")) {
    if (!p->is_array()) bad("power is not an array");
    for (const json::value& cv : p->get_array())
      run.power.push_back(read_power(cv, "power[" + std::to_string(run.power.size()) + "]"));
  }
  return run;
}

}  // namespace warpcheck::validation
