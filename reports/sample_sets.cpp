// Reads the sample sets build/sample_sets writes (validation/tools/sample_sets.cpp documents the JSON).
#include <boost/json.hpp>
#include <stdexcept>

#include "json_read.h"
#include "report.h"

namespace warpcheck::validation::report {
namespace json = boost::json;

namespace {

constexpr const char* kPrefix = "sample sets: ";
[[noreturn]] void bad(const std::string& what) { throw std::runtime_error(what); }

using json_read::member;
using json_read::number;

// [x, y] inside the cap, [x, y, 1] outside it, null when the sampler declined.
std::vector<MappedPoint> mapped_points(const json::value& v, const std::string& where) {
  if (!v.is_array()) bad(where + " is not an array");
  std::vector<MappedPoint> out;
  for (const json::value& p : v.get_array()) {
    MappedPoint m;
    if (!p.is_null()) {
      if (!p.is_array() || p.get_array().size() < 2 || p.get_array().size() > 3) bad(where + ": a point is not [x, y]");
      const json::array& a = p.get_array();
      m.x = number(a[0], where), m.y = number(a[1], where);
      m.valid = true, m.outside = a.size() == 3;
    }
    out.push_back(m);
  }
  return out;
}

SampleSetCase sample_set_case(const json::value& v, const SampleSets& s, std::size_t index) {
  const std::string where = "case " + std::to_string(index);
  if (!v.is_object()) bad(where + " is not an object");
  const json::object& o = v.get_object();
  SampleSetCase c;
  auto text = [&](const char* key) { return std::string(member(o, key, where).as_string()); };
  c.kernel = text("kernel"), c.scalar = text("scalar"), c.config = text("config"), c.description = text("description");
  if (o.contains("error")) {
    c.error = text("error");
    return c;
  }
  c.expect_no_sample = member(o, "expect_no_sample", where).as_bool();
  c.grid = mapped_points(member(o, "grid", where), where + " grid");
  c.blue = mapped_points(member(o, "blue", where), where + " blue");
  if (c.grid.size() != std::size_t(2 * s.grid_lines * s.grid_line_samples))
    bad(where + " (" + c.kernel + " " + c.scalar + " " + c.config + ") has " + std::to_string(c.grid.size()) +
        " grid points, not 2 x grid_lines x grid_line_samples");
  if (c.blue.size() != s.blue_u.size())
    bad(where + " (" + c.kernel + ") has " + std::to_string(c.blue.size()) + " blue-noise points, not " +
        std::to_string(s.blue_u.size()));
  return c;
}

}  // namespace

namespace {

SampleSets sample_sets(const json::object& o) {
  SampleSets s;
  s.grid_lines = int(member(o, "grid_lines", "the file").as_int64());
  s.grid_line_samples = int(member(o, "grid_line_samples", "the file").as_int64());
  if (s.grid_lines < 1 || s.grid_line_samples < 2) bad("grid_lines must be >= 1 and grid_line_samples >= 2");
  const json::value& blue = member(member(o, "blue_noise", "the file").as_object(), "u", "blue_noise");
  for (const json::value& p : blue.as_array()) {
    const json::array& a = p.as_array();
    if (a.size() != 2) bad("a blue-noise point is not [u0, u1]");
    s.blue_u.push_back({number(a[0], "blue_noise"), number(a[1], "blue_noise")});
  }
  const json::array& cases = member(o, "cases", "the file").as_array();
  for (std::size_t i = 0; i < cases.size(); ++i) s.cases.push_back(sample_set_case(cases[i], s, i));
  return s;
}

}  // namespace

// Every error names the file's kind once: "sample sets: <what>".
SampleSets parse_sample_sets(const std::string& text) {
  std::error_code ec;
  const json::value v = json::parse(text, ec);
  if (ec || !v.is_object()) throw std::runtime_error("sample sets: not a JSON object");
  try {
    return sample_sets(v.get_object());
  } catch (const boost::system::system_error& e) {  // a Boost.JSON accessor (as_array, ...) on the wrong type
    throw std::runtime_error(std::string("sample sets: a member has the wrong type (") + e.what() + ")");
  } catch (const std::runtime_error& e) {
    throw std::runtime_error(std::string("sample sets: ") + e.what());
  }
}

}  // namespace warpcheck::validation::report
