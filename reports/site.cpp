// The report's site: index.html and one page per kernel (see report.h). Static and offline: every picture is a
// PNG beside the page or inline SVG, the style sheet and the small load-check script are inline.
#include <algorithm>
#include <boost/json.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <set>
#include <sstream>

#include "json_read.h"
#include "report.h"

namespace warpcheck::validation::report {
namespace fs = std::filesystem;
namespace json = boost::json;

std::string html_escape(const std::string& s) {
  std::string o;
  o.reserve(s.size());
  for (char c : s) switch (c) {
      case '&':
        o += "&amp;";
        break;
      case '<':
        o += "&lt;";
        break;
      case '>':
        o += "&gt;";
        break;
      case '"':
        o += "&quot;";
        break;
      case '\'':
        o += "&#39;";
        break;
      default:
        o += c;
    }
  return o;
}

std::string safe_name(const std::string& s) {
  std::string o;
  for (char c : s) o += (std::isalnum((unsigned char)c) || c == '.' || c == '-' || c == '_') ? c : '_';
  return o.empty() ? "_" : o;
}

namespace {

std::string num(double v, int digits = 3) {
  if (std::isnan(v)) return "NaN";
  char b[48];
  std::snprintf(b, sizeof b, "%.*g", digits, v);
  return b;
}

std::string read_text(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  if (!f) throw std::runtime_error("cannot read " + p.string());
  std::ostringstream s;
  s << f.rdbuf();
  return s.str();
}

void write_text(const fs::path& p, const std::string& text) {
  std::ofstream f(p, std::ios::binary | std::ios::trunc);
  f << text;
  if (!f) throw std::runtime_error("cannot write " + p.string());
}

// Style and the load check every page carries. The script records, into #wc-load-check, every image that did
// not decode, every error event (script errors, resources that failed) and every console.error/warn call, so a
// headless browser's --dump-dom shows them (the report's own test reads it).
const char* kHead = R"(<meta charset="utf-8">
<style>
body{font-family:sans-serif;margin:1.2em;color:#222;max-width:1400px}
table{border-collapse:collapse;margin:.5em 0}
td,th{border:1px solid #bbb;padding:2px 6px;font-size:12px;vertical-align:top}
th{background:#eee}
td.pass{background:#d8f0d8}
td.fail{background:#e0302a;color:#fff;font-weight:bold}
td.fail a{color:#fff}
td.known{background:repeating-linear-gradient(45deg,#ffd27a,#ffd27a 6px,#ffe9b8 6px,#ffe9b8 12px)}
td.knownpass{background:#d8f0d8;border:2px dashed #c88a00}
td.absent{background:#f4f4f4;color:#999}
.banner{padding:.6em 1em;font-size:1.2em;font-weight:bold;margin:.5em 0}
.banner.bad{background:#e0302a;color:#fff}.banner.good{background:#2e8b2e;color:#fff}
.banner.warn{background:#ffd27a}
.notrun{color:#8a5a00;background:#fff6e0;padding:.4em .8em;border-left:4px solid #c88a00}
code,pre{background:#f4f4f4;padding:1px 3px}
figure{display:inline-block;margin:.3em;text-align:center;font-size:11px;vertical-align:top}
img.map{width:200px;height:200px;image-rendering:pixelated}
.muted{color:#777}
</style>
<script>
(function(){
  var errors=[];
  window.addEventListener('error',function(e){
    var t=e.target; errors.push(t&&t!==window&&(t.src||t.href)?('resource failed: '+(t.src||t.href)):('error: '+e.message));
  },true);
  ['error','warn'].forEach(function(k){var f=console[k];console[k]=function(){errors.push('console.'+k+': '+Array.prototype.join.call(arguments,' '));f.apply(console,arguments);};});
  window.addEventListener('load',function(){
    var broken=[],n=0;
    for(var i=0;i<document.images.length;++i){var im=document.images[i];++n;if(!(im.complete&&im.naturalWidth>0))broken.push(im.getAttribute('src'));}
    var el=document.getElementById('wc-load-check');
    if(el) el.textContent='LOADCHECK '+JSON.stringify({images:n,broken:broken,errors:errors});
  });
})();
</script>
)";

std::string page_start(const std::string& title) {
  return "<!DOCTYPE html>\n<html lang=\"en\"><head><title>" + html_escape(title) + "</title>\n" + kHead +
         "</head><body>\n";
}
std::string page_end() { return "<pre id=\"wc-load-check\" hidden>LOADCHECK pending</pre>\n</body></html>\n"; }

std::string kernel_page(const std::string& kernel) { return "kernel-" + safe_name(kernel) + ".html"; }
std::string result_anchor(const TestResult& r) {
  return "r-" + safe_name(r.scalar) + "-" + safe_name(r.config) + "-" + safe_name(r.test);
}

std::string verdict(const TestResult& r) {
  if (r.passed) return r.known_limitation.empty() ? "pass" : "pass (known limitation case)";
  return r.known_limitation.empty() ? "FAIL" : "fail (known limitation)";
}
std::string cell_class(const TestResult& r) {
  if (r.passed) return r.known_limitation.empty() ? "pass" : "knownpass";
  return r.known_limitation.empty() ? "fail" : "known";
}
std::string cell_value(const TestResult& r) {
  if (r.p_value) return "p=" + num(*r.p_value);
  return std::isnan(r.statistic) ? "error" : num(r.statistic);
}

std::string not_run(const std::string& what, const std::string& command) {
  return "<p class=\"notrun\">Not run: " + html_escape(what) + ". Produce it with <code>" + html_escape(command) +
         "</code>.</p>\n";
}

// ---- chi2 maps ----------------------------------------------------------------------------------------------

std::string colorbar_svg(bool diverging, double lo, double hi, const std::string& id) {
  std::ostringstream o;
  o << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"200\" height=\"26\"><defs><linearGradient id=\"" << id
    << "\">";
  for (int k = 0; k <= 8; ++k) {
    const double t = k / 8.0;
    const Rgb c = diverging ? diverging_color(2 * t - 1) : sequential_color(t);
    o << "<stop offset=\"" << t << "\" stop-color=\"rgb(" << int(c[0]) << "," << int(c[1]) << "," << int(c[2])
      << ")\"/>";
  }
  o << "</linearGradient></defs><rect x=\"0\" y=\"0\" width=\"200\" height=\"10\" fill=\"url(#" << id
    << ")\"/><text x=\"0\" y=\"23\" font-size=\"10\">" << num(lo) << "</text><text x=\"200\" y=\"23\" "
    << "font-size=\"10\" text-anchor=\"end\">" << num(hi) << "</text></svg>";
  return o.str();
}

// Bars of signed residuals (o - e) / sqrt(e) of the grid's marginals (per radial row or per azimuth column):
// a coherent error too small to stand out bin by bin (1% too dense on a tenth of the cap) adds up in its row.
std::string marginal_bars_svg(const std::vector<double>& res, const std::string& title, const std::string& xlabel) {
  double m = 4;
  for (double v : res)
    if (std::isfinite(v)) m = std::max(m, std::abs(v));
  const double W = 260, H = 150, L = 34, T = 20, B = H - 26, mid = (T + B) / 2, bw = (W - L - 6) / double(res.size());
  std::ostringstream o;
  o << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << W << "\" height=\"" << H << "\" role=\"img\"><title>"
    << html_escape(title) << "</title><text x=\"2\" y=\"12\" font-size=\"11\">" << html_escape(title) << "</text>";
  for (double g : {-3.0, 3.0})
    o << "<line x1=\"" << L << "\" x2=\"" << W - 6 << "\" y1=\"" << mid - g / m * (B - T) / 2 << "\" y2=\""
      << mid - g / m * (B - T) / 2 << "\" stroke=\"#bbb\" stroke-dasharray=\"3 3\"/>";
  o << "<line x1=\"" << L << "\" x2=\"" << W - 6 << "\" y1=\"" << mid << "\" y2=\"" << mid << "\" stroke=\"#444\"/>"
    << "<text x=\"" << L - 3 << "\" y=\"" << T + 4 << "\" font-size=\"9\" text-anchor=\"end\">" << num(m, 2)
    << "</text><text x=\"" << L - 3 << "\" y=\"" << B + 3 << "\" font-size=\"9\" text-anchor=\"end\">" << num(-m, 2)
    << "</text><text x=\"" << L - 3 << "\" y=\"" << mid - 3.0 / m * (B - T) / 2 + 3
    << "\" font-size=\"9\" text-anchor=\"end\">3</text><text x=\"" << (L + W) / 2 << "\" y=\"" << H - 8
    << "\" font-size=\"10\" text-anchor=\"middle\">" << html_escape(xlabel) << "</text>";
  for (std::size_t i = 0; i < res.size(); ++i) {
    const double v = std::isfinite(res[i]) ? res[i] : (res[i] > 0 ? m : -m);
    const double h = std::abs(v) / m * (B - T) / 2;
    const Rgb c = diverging_color(v / m);
    o << "<rect x=\"" << L + bw * i + 0.5 << "\" y=\"" << (v > 0 ? mid - h : mid) << "\" width=\""
      << std::max(bw - 1, 0.5) << "\" height=\"" << h << "\" fill=\"rgb(" << int(c[0]) << "," << int(c[1]) << ","
      << int(c[2]) << ")\" stroke=\"" << (std::abs(v) > 3 ? "#000" : "none") << "\"><title>" << i << ": " << num(res[i])
      << "</title></rect>";
  }
  o << "</svg>";
  return o.str();
}

// The signed residuals (o - e) / sqrt(e) of one chi2 grid, the range of its counts, and the samples off the grid.
struct Residuals {
  std::vector<double> bins;
  double rmax = 0, vlo = 1e300, vhi = -1e300;  // largest finite |residual|; count range of the maps
  std::size_t worst = 0, zero_mass_hits = 0;
  std::optional<double> ring;  // residual of the samples off the grid, when the run's sample count is known
  double off_o = 0, off_e = 0;
};

Residuals residuals(const TestResult& r, std::optional<long long> samples) {
  const std::size_t n = std::size_t(r.map_rows) * r.map_cols;
  const double inf = std::numeric_limits<double>::infinity();
  Residuals s;
  s.bins.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double o = r.observed[i], e = r.expected[i];
    s.vlo = std::min({s.vlo, o, e}), s.vhi = std::max({s.vhi, o, e});
    if (e > 0)
      s.bins[i] = (o - e) / std::sqrt(e);
    else
      s.bins[i] = o > 0 ? inf : 0, s.zero_mass_hits += o > 0;
    if (std::abs(s.bins[i]) > std::abs(s.bins[s.worst])) s.worst = i;
    if (std::isfinite(s.bins[i])) s.rmax = std::max(s.rmax, std::abs(s.bins[i]));
  }
  if (!(s.vhi - s.vlo > 1e-9 * std::abs(s.vhi))) s.vlo = 0;
  // Samples off the grid (outside the bounding cap or declined): the run's sample count minus the grid's total,
  // against the expected n (1 - mass on the grid).
  if (samples) {
    double so = 0, se = 0;
    for (std::size_t i = 0; i < n; ++i) so += r.observed[i], se += r.expected[i];
    s.off_o = double(*samples) - so, s.off_e = std::max(0.0, double(*samples) - se);
    // Expected mass off the grid below one sample is quadrature noise, not a prediction: treat it as zero.
    if (s.off_e < 1) s.off_e = 0;
    s.ring = s.off_e > 0 ? (s.off_o - s.off_e) / std::sqrt(s.off_e) : s.off_o > 0.5 ? inf : 0;
    if (std::isfinite(*s.ring)) s.rmax = std::max(s.rmax, std::abs(*s.ring));
  }
  return s;
}

// Bar charts of the residuals of the grid's marginals, per radial row and per azimuth column.
std::string marginal_figures(const TestResult& r) {
  const int R = r.map_rows, A = r.map_cols;
  std::vector<double> ro(R, 0), re(R, 0), ao(A, 0), ae(A, 0), rr(R), ar(A);
  for (int i = 0; i < R; ++i)
    for (int j = 0; j < A; ++j) {
      const std::size_t k = std::size_t(i) * A + j;
      ro[i] += r.observed[k], re[i] += r.expected[k], ao[j] += r.observed[k], ae[j] += r.expected[k];
    }
  auto z = [](double o, double e) {
    return e > 0 ? (o - e) / std::sqrt(e) : o > 0 ? std::numeric_limits<double>::infinity() : 0.0;
  };
  for (int i = 0; i < R; ++i) rr[i] = z(ro[i], re[i]);
  for (int j = 0; j < A; ++j) ar[j] = z(ao[j], ae[j]);
  return "<figure>" + marginal_bars_svg(rr, "residual per radial row", "row (t from 0 at the centre to 1 at the rim)") +
         "</figure><figure>" + marginal_bars_svg(ar, "residual per azimuth column", "column (phi from 0 to 2 pi)") +
         "</figure>";
}

// Writes the PNGs and the EXR of one chi2 result; returns the HTML figure block.
std::string chi2_maps(const TestResult& r, std::optional<long long> samples, const fs::path& out, ReportSummary& sum) {
  const int R = r.map_rows, A = r.map_cols;
  const Residuals s = residuals(r, samples);
  // Residual scale: at least +-4 so that noise (|r| ~ 1) stays pale and a failure saturates.
  const double scale = std::max(4.0, s.rmax), vlo = s.vlo, vhi = s.vhi;
  const std::string base =
      "img/" + safe_name(r.kernel) + "__" + safe_name(r.scalar) + "__" + safe_name(r.config) + "__" + safe_name(r.test);
  auto seq = [&](double v) { return sequential_color((v - vlo) / (vhi - vlo > 0 ? vhi - vlo : 1)); };
  auto div = [&](double v) { return diverging_color(std::isfinite(v) ? v / scale : v > 0 ? 1 : -1); };
  write_png((out / (base + "-observed.png")).string(), polar_map(R, A, r.observed, 256, seq));
  write_png((out / (base + "-expected.png")).string(), polar_map(R, A, r.expected, 256, seq));
  write_png((out / (base + "-residual.png")).string(), polar_map(R, A, s.bins, 256, div, s.ring));
  std::vector<float> fo(r.observed.begin(), r.observed.end()), fe(r.expected.begin(), r.expected.end()),
      fr(s.bins.begin(), s.bins.end());
  write_exr((out / (base + ".exr")).string(), A, R, {{"observed", fo}, {"expected", fe}, {"residual", fr}});
  for (const char* x : {"-observed.png", "-expected.png", "-residual.png", ".exr"}) sum.files.push_back(base + x);

  const int wr = int(s.worst / A), wa = int(s.worst % A);
  std::ostringstream o;
  o << "<div class=\"maps\" id=\"maps-" << result_anchor(r) << "\"><h4>chi2 maps: " << html_escape(r.scalar) << " / "
    << html_escape(r.config) << " <span class=\"" << (r.failed() ? "fail" : "") << "\">(" << verdict(r)
    << ")</span></h4>";
  for (const char* which : {"observed", "expected", "residual"}) {
    const bool d = std::string(which) == "residual";
    o << "<figure><img class=\"map\" src=\"" << base << "-" << which << ".png\" alt=\"" << which << " map of "
      << html_escape(r.kernel + " " + r.scalar + " " + r.config) << "\"><figcaption>"
      << (d ? "signed residual (o - e) / sqrt(e)" : std::string(which) + " counts") << "<br>"
      << colorbar_svg(d, d ? -scale : vlo, d ? scale : vhi, "cb-" + safe_name(r.scalar + r.config) + which)
      << "</figcaption></figure>";
  }
  o << marginal_figures(r)
    << "<p class=\"muted\">Equal-area view of the bounding cap from above: radius sqrt(t), t = (1 - cos theta) / "
       "(1 - cos theta_max) in "
    << R << " rows; azimuth phi counter-clockwise from the cap frame's x axis (right) in " << A
    << " columns; every bin covers the same pixel area. Largest residual " << num(s.bins[s.worst]) << " in t in ["
    << num(double(wr) / R) << ", " << num(double(wr + 1) / R) << "), phi/2pi in [" << num(double(wa) / A) << ", "
    << num(double(wa + 1) / A) << ")"
    << (s.zero_mass_hits ? "; " + std::to_string(s.zero_mass_hits) + " bins with samples but zero expected mass" : "")
    << (s.ring ? ". The ring around the residual map: samples off the grid (outside the bounding cap or declined), " +
                     num(s.off_o, 6) + " observed against " + num(s.off_e, 6) + " expected" +
                     (s.off_o > 0.5 && s.off_e == 0 ? " (impossible under the pdf: saturated red)" : "")
               : std::string(""))
    << ". Exact values (32-bit float; the JSON has the 9-digit expected counts): <a href=\"" << base << ".exr\">"
    << safe_name(r.test) << ".exr</a> (channels observed, expected, residual; " << A << " x " << R
    << ", row = radial bin).</p></div>\n";
  return o.str();
}

// ---- sample sets ----------------------------------------------------------------------------------------------

// Up to the file's cases of this kernel, the configurations of this run first (the tool already ordered them).
std::string sample_sets(const std::string& kernel, const SampleSets* sets, const std::set<std::string>& configs_in_run,
                        const ReportOptions& opt) {
  if (!sets)
    return not_run((opt.sample_sets_path.empty() ? std::string("no sample-sets file given")
                                                 : opt.sample_sets_path + " does not exist"),
                   "build/sample_sets --out reports/sample-sets.json --from reports/results.json");
  std::vector<const SampleSetCase*> mine;
  for (const SampleSetCase& c : sets->cases)
    if (c.kernel == kernel) mine.push_back(&c);
  if (mine.empty())
    return "<p class=\"muted\">" + html_escape(opt.sample_sets_path) + " holds no sample set of " +
           html_escape(kernel) + ".</p>\n";
  std::stable_sort(mine.begin(), mine.end(), [&](const SampleSetCase* a, const SampleSetCase* b) {
    return configs_in_run.count(a->config) > configs_in_run.count(b->config);
  });
  std::ostringstream o;
  o << "<p class=\"muted\">Primary sample space (left) mapped by the kernel (right): a grid of " << sets->grid_lines
    << " + " << sets->grid_lines << " lines and " << sets->blue_u.size()
    << " blue-noise points (best candidate), coloured by (u0, u1). Red crosses: directions outside the bounding cap. "
       "From <code>"
    << html_escape(opt.sample_sets_path) << "</code>.</p>\n";
  for (const SampleSetCase* c : mine) {
    const std::string label = c->kernel + " / " + c->scalar + " / " + c->config;
    o << "<h4>" << html_escape(label) << "</h4><p class=\"muted\">" << html_escape(c->description) << "</p>";
    if (!c->error.empty()) {
      o << "<p class=\"notrun\">Could not build this case: " << html_escape(c->error) << "</p>";
      continue;
    }
    if (c->expect_no_sample) o << "<p>This geometry must give no sample; every point is declined.</p>";
    o << grid_lines_svg(sets->grid_lines, sets->grid_line_samples, c->grid, label + ": grid") << "\n"
      << sample_set_svg(sets->blue_u, c->blue, label + ": blue noise") << "\n";
  }
  return o.str();
}

// ---- data sections --------------------------------------------------------------------------------------------

std::string json_scalar(const json::value& v) {
  if (v.is_string()) return std::string(v.get_string());
  if (v.is_double()) return num(v.get_double(), 4);
  if (v.is_int64()) return std::to_string(v.get_int64());
  if (v.is_uint64()) return std::to_string(v.get_uint64());
  if (v.is_bool()) return v.get_bool() ? "true" : "false";
  if (v.is_null()) return "null";
  return json::serialize(v);
}

void flatten(const json::value& v, const std::string& path,
             std::vector<std::pair<std::string, const json::value*>>& out) {
  if (v.is_object()) {
    for (const auto& kv : v.get_object())
      flatten(kv.value(), path.empty() ? std::string(kv.key()) : path + "." + std::string(kv.key()), out);
  } else {
    out.emplace_back(path, &v);
  }
}

// One claims file as a table: per claim, each quantity with the paper's figure beside ours. A leaf whose
// path has a segment "paper..." is the paper's, "measured..." (or anything else) ours; the row key is the path
// with that segment's prefix removed (so measured.p99 and paper.p99 share a row).
std::string claims_table(const json::object& o) {
  std::ostringstream meta, t;
  t << "<table><tr><th>claim</th><th>quantity</th><th>paper</th><th>ours (measured)</th></tr>";
  for (const auto& kv : o) {
    const std::string claim(kv.key());
    if (!kv.value().is_object()) {
      meta << "<li><b>" << html_escape(claim) << "</b>: " << html_escape(json_scalar(kv.value())) << "</li>";
      continue;
    }
    std::vector<std::pair<std::string, const json::value*>> leaves;
    flatten(kv.value(), "", leaves);
    std::vector<std::string> keys;
    std::map<std::string, std::pair<std::string, std::string>> rows;  // key -> (paper, ours)
    for (const auto& [path, v] : leaves) {
      std::string key, seg;
      bool paper = false;
      std::stringstream ss(path);
      while (std::getline(ss, seg, '.')) {
        std::string s = seg;
        for (const char* p : {"paper", "measured"})
          if (s.rfind(p, 0) == 0) {
            paper = paper || std::string(p) == "paper";
            s = s.substr(std::string(p).size());
            if (!s.empty() && s[0] == '_') s = s.substr(1);
          }
        if (!s.empty()) key += (key.empty() ? "" : ".") + s;
      }
      if (key.empty()) key = "value";
      if (!rows.count(key)) keys.push_back(key);
      (paper ? rows[key].first : rows[key].second) = json_scalar(*v);
    }
    bool first = true;
    for (const auto& k : keys) {
      t << "<tr>"
        << (first ? "<td rowspan=\"" + std::to_string(keys.size()) + "\">" + html_escape(claim) + "</td>" : "")
        << "<td>" << html_escape(k) << "</td><td>" << html_escape(rows[k].first.empty() ? "-" : rows[k].first)
        << "</td><td>" << html_escape(rows[k].second.empty() ? "-" : rows[k].second) << "</td></tr>";
      first = false;
    }
  }
  t << "</table>";
  return "<ul>" + meta.str() + "</ul>" + t.str();
}

std::optional<json::value> load_json(const fs::path& p, std::string& error) {
  try {
    json::error_code ec;
    json::value v = json::parse(read_text(p), ec);
    if (ec) {
      error = p.string() + ": not valid JSON (" + ec.message() + ")";
      return std::nullopt;
    }
    return v;
  } catch (const std::exception& e) {
    error = e.what();
    return std::nullopt;
  }
}

std::string claims_section(const fs::path& data) {
  std::ostringstream o;
  o << "<h2 id=\"claims\">The papers' figures beside ours</h2>\n";
  struct Family {
    const char* dir;
    const char* title;
    const char* command;
  };
  const Family fams[] = {
      {"projected-cap", "Projected spherical caps (Peters &amp; Dachsbacher 2019): quintic error, Case-3 bounds",
       "build/projected_cap_claims"},
      {"polygon", "Polygons (Peters 2021): backward-error percentiles", "build/polygon_claims --cases 1000000"},
      {"sptd", "SPTD / LTC: timings and errors", "build/sptd_claims"},
  };
  std::set<std::string> shown;
  auto one = [&](const std::string& dir, const std::string& title, const std::string& command) {
    shown.insert(dir);
    const fs::path p = data / dir / "claims.json";
    o << "<h3>" << title << "</h3>";
    if (!fs::exists(p)) {
      o << not_run("data/" + dir + "/claims.json does not exist", command);
      return;
    }
    std::string err;
    const auto v = load_json(p, err);
    if (!v || !v->is_object()) {
      o << "<p class=\"notrun\">" << html_escape(err.empty() ? p.string() + " is not a JSON object" : err) << "</p>";
      return;
    }
    o << "<p class=\"muted\">From <code>data/" << html_escape(dir) << "/claims.json</code>.</p>"
      << claims_table(v->get_object());
  };
  for (const auto& f : fams) one(f.dir, f.title, f.command);
  if (fs::exists(data)) {  // any other family that writes claims
    std::vector<std::string> more;
    for (const auto& e : fs::directory_iterator(data))
      if (e.is_directory() && fs::exists(e.path() / "claims.json") && !shown.count(e.path().filename().string()))
        more.push_back(e.path().filename().string());
    std::sort(more.begin(), more.end());
    for (const auto& d : more) one(d, html_escape(d), "");
  }
  return o.str();
}

bool as_number(const json::value& n, double& out) {
  if (n.is_double()) return out = n.get_double(), true;
  if (n.is_int64()) return out = double(n.get_int64()), true;
  if (n.is_uint64()) return out = double(n.get_uint64()), true;
  return false;
}

// x, y of one history entry: an [x, y] array or an object with a count/time and an error member.
bool history_point(const json::value& v, double& x, double& y) {
  if (v.is_array() && v.get_array().size() >= 2)
    return as_number(v.get_array()[0], x) && as_number(v.get_array()[1], y);
  if (!v.is_object()) return false;
  const auto& o = v.get_object();
  bool hx = false, hy = false;
  for (const char* k : {"evaluations", "seconds", "chain", "index"})
    if (!hx && o.if_contains(k)) hx = as_number(o.at(k), x);
  for (const char* k : {"best", "worst_error", "error", "value", "best_error"})
    if (!hy && o.if_contains(k)) hy = as_number(o.at(k), y);
  return hx && hy;
}

// The .json files of a folder, sorted by name (none when the folder is missing).
std::vector<fs::path> json_files(const fs::path& dir) {
  std::vector<fs::path> files;
  if (fs::exists(dir))
    for (const auto& e : fs::directory_iterator(dir))
      if (e.path().extension() == ".json") files.push_back(e.path());
  std::sort(files.begin(), files.end());
  return files;
}

std::string worst_case_section(const fs::path& data) {
  std::ostringstream o;
  o << "<h2 id=\"worst\">Worst-case searches</h2>\n";
  const fs::path dir = data / "worst-cases";
  const std::vector<fs::path> files = json_files(dir);
  if (files.empty())
    return o.str() + not_run("no recorded worst case in data/worst-cases/",
                             "warpcheck worst-case --search NAME --seconds 600 --json data/worst-cases/NAME.json "
                             "(see docs/worst-case.md)");
  o << "<table><tr><th>search</th><th>worst error found</th><th>paper</th><th>evaluations</th><th>seconds</th>"
       "<th>kernel version</th><th>command</th></tr>";
  std::ostringstream plots;
  for (const auto& p : files) {
    std::string err;
    const auto v = load_json(p, err);
    if (!v || !v->is_object()) {
      o << "<tr><td>" << html_escape(p.filename().string()) << "</td><td colspan=\"6\" class=\"fail\">"
        << html_escape(err.empty() ? "not a JSON object" : err) << "</td></tr>";
      continue;
    }
    const auto& w = v->get_object();
    auto get = [&](const char* k) { return w.if_contains(k) ? json_scalar(w.at(k)) : std::string("-"); };
    o << "<tr><td>" << html_escape(get("search")) << "</td><td>" << html_escape(get("worst_error")) << "</td><td>"
      << html_escape(get("paper")) << "</td><td>" << html_escape(get("evaluations")) << "</td><td>"
      << html_escape(get("seconds")) << "</td><td>" << html_escape(get("kernel_version")) << "</td><td><code>"
      << html_escape(get("command")) << "</code></td></tr>";
    Series s{get("search"), {}};
    if (const auto* h = w.if_contains("history"); h && h->is_array())
      for (const auto& e : h->get_array()) {
        double x, y;
        if (history_point(e, x, y)) s.points.emplace_back(x, y);
      }
    if (!s.points.empty())
      plots << svg_line_plot({s}, "history of " + s.name, "evaluations", "worst error so far", true, true) << "\n";
    else
      plots << "<p class=\"muted\">" << html_escape(p.filename().string())
            << ": no \"history\" member (best-so-far per evaluation count) recorded in this file.</p>";
  }
  o << "</table>\n" << plots.str();
  return o.str();
}

std::string fuzz_section(const fs::path& data) {
  std::ostringstream o;
  o << "<h2 id=\"fuzz\">Fuzz campaigns</h2>\n";
  const fs::path p = data / "fuzz" / "summary.json";
  if (!fs::exists(p))
    return o.str() + not_run("data/fuzz/summary.json does not exist", "fuzz/campaign.sh --minutes 10 --jobs 1");
  std::string err;
  const auto v = load_json(p, err);
  if (!v || !v->is_object() || !v->get_object().if_contains("targets") || !v->get_object().at("targets").is_object())
    return o.str() + "<p class=\"notrun\">" +
           html_escape(err.empty() ? "data/fuzz/summary.json has no \"targets\" object" : err) + "</p>";
  const auto& root = v->get_object();
  if (root.if_contains("description"))
    o << "<p class=\"muted\">" << html_escape(json_scalar(root.at("description"))) << "</p>";
  o << "<table><tr><th>target</th><th>date</th><th>minutes</th><th>executions</th><th>exec/s</th><th>cov</th>"
       "<th>ft</th><th>corpus before / after</th><th>findings</th><th>command</th></tr>";
  for (const auto& kv : root.at("targets").get_object()) {
    if (!kv.value().is_object()) continue;
    const auto& t = kv.value().get_object();
    auto get = [&](const char* k) { return t.if_contains(k) ? json_scalar(t.at(k)) : std::string("-"); };
    std::size_t nfind = 0;
    std::string finds;
    if (const auto* f = t.if_contains("findings"); f && f->is_array()) {
      nfind = f->get_array().size();
      for (const auto& x : f->get_array())
        if (x.is_object() && x.get_object().if_contains("signature"))
          finds += "<li>" + html_escape(json_scalar(x.get_object().at("signature"))) + "</li>";
    }
    o << "<tr><td>" << html_escape(std::string(kv.key())) << "</td><td>" << html_escape(get("date")) << "</td><td>"
      << html_escape(get("minutes")) << "</td><td>" << html_escape(get("executions")) << "</td><td>"
      << html_escape(get("exec_per_s")) << "</td><td>" << html_escape(get("cov")) << "</td><td>"
      << html_escape(get("ft")) << "</td><td>" << html_escape(get("corpus_files_before")) << " / "
      << html_escape(get("corpus_files_after")) << "</td><td" << (nfind ? " class=\"known\"" : "") << ">" << nfind
      << (finds.empty() ? "" : "<details><summary>signatures</summary><ul>" + finds + "</ul></details>")
      << "</td><td><code>" << html_escape(get("command")) << "</code></td></tr>";
  }
  o << "</table>\n";
  return o.str();
}

// ---- coverage of lib/: data/coverage/summary.json, written by scripts/coverage.sh (coverage_summary.py) --------

std::string coverage_cells(const json::object& run) {
  std::string out;
  for (const char* kind : {"lines", "branches"}) {
    const std::vector<double> c = json_read::numbers(json_read::member(run, kind, "a run"), kind);
    if (c.size() != 2) throw std::runtime_error(std::string(kind) + " is not [reached, total]");
    out += "<td>" + (c[1] > 0 ? num(100 * c[0] / c[1], 3) + " % (" + num(c[0], 6) + "/" + num(c[1], 6) + ")" : "-") +
           "</td>";
  }
  return out;
}

std::string coverage_header_row(const std::string& what, const json::object& h) {
  return "<tr><td>" + what + "</td>" + coverage_cells(json_read::member(h, "tests", what).as_object()) +
         coverage_cells(json_read::member(h, "battery", what).as_object()) + "</tr>";
}

// The sampling-path lines with a branch the battery never takes, each with its reason; a line without one is
// marked as a failure is.
std::string coverage_untaken(const json::array& untaken) {
  std::ostringstream o;
  std::size_t unexplained = 0;
  for (const json::value& v : untaken) unexplained += v.as_object().at("reason").is_null();
  o << "<p>" << untaken.size() << " lines of lib/'s sample and pdf functions hold a branch that the battery never "
    << "takes; " << unexplained << " of them have no reason in <code>data/coverage/untaken-reasons.tsv</code>.</p>"
    << "<details><summary>the lines and why</summary><table><tr><th>where</th><th>code</th><th>branches "
       "untaken</th><th>tests take them</th><th>why the battery does not</th></tr>";
  for (const json::value& v : untaken) {
    const json::object& u = v.as_object();
    const bool why = !u.at("reason").is_null();
    o << "<tr><td>" << html_escape(json_read::string_of(u.at("file"), "file")) << ":"
      << num(json_read::number(u.at("line"), "line"), 6) << "</td><td><code>"
      << html_escape(json_read::string_of(u.at("code"), "code")) << "</code></td><td>"
      << num(json_read::number(u.at("branches_untaken"), "branches_untaken"), 6) << " of "
      << num(json_read::number(u.at("branches"), "branches"), 6) << "</td><td>"
      << (u.at("tests_take_them").as_bool() ? "yes" : "no") << "</td><td" << (why ? ">" : " class=\"fail\">")
      << html_escape(why ? json_read::string_of(u.at("reason"), "reason") : "not explained") << "</td></tr>";
  }
  o << "</table></details>\n";
  return o.str();
}

std::string coverage_section(const fs::path& data) {
  std::ostringstream o;
  o << "<h2 id=\"coverage\">Coverage of lib/</h2>\n";
  const fs::path p = data / "coverage" / "summary.json";
  if (!fs::exists(p)) return o.str() + not_run("data/coverage/summary.json does not exist", "scripts/coverage.sh");
  try {
    std::string err;
    const auto v = load_json(p, err);
    if (!v || !v->is_object()) throw std::runtime_error(err.empty() ? "not a JSON object" : err);
    const json::object& c = v->get_object();
    o << "<p class=\"muted\">Lines and branches of lib/ reached by the default tests and by the battery ("
      << html_escape(json_read::string_of(json_read::member(c, "battery_run", "the file"), "battery_run"))
      << "), measured at commit <code>" << html_escape(json_read::string_of(c.at("commit"), "commit"))
      << "</code> by <code>scripts/coverage.sh</code> (gcc --coverage, gcovr).</p>\n"
      << "<table><tr><th>header</th><th>lines, tests</th><th>branches, tests</th><th>lines, battery</th>"
         "<th>branches, battery</th></tr>";
    for (const json::value& h : json_read::member(c, "headers", "the file").as_array())
      o << coverage_header_row(html_escape(json_read::string_of(h.as_object().at("file"), "file")), h.as_object());
    o << coverage_header_row("all of lib/", json_read::member(c, "total", "the file").as_object()) << "</table>\n"
      << coverage_untaken(json_read::member(c, "untaken", "the file").as_array());
  } catch (const std::exception& e) {  // std::runtime_error of json_read, boost::system::system_error of as_*
    return o.str() + "<p class=\"notrun\">data/coverage/summary.json: " + html_escape(e.what()) + "</p>\n";
  }
  return o.str();
}

std::string bench_section(const fs::path& data) {
  std::ostringstream o;
  o << "<h2 id=\"bench\">Benchmarks</h2>\n";
  const fs::path dir = data / "bench";
  const std::vector<fs::path> files = json_files(dir);
  if (files.empty())
    return o.str() + not_run("no Google Benchmark JSON in data/bench/",
                             "build/<benchmark> --benchmark_format=json --benchmark_out=data/bench/<name>.json");
  for (const auto& p : files) {
    std::string err;
    const auto v = load_json(p, err);
    o << "<h3>" << html_escape(p.filename().string()) << "</h3>";
    if (!v || !v->is_object() || !v->get_object().if_contains("benchmarks") ||
        !v->get_object().at("benchmarks").is_array()) {
      o << "<p class=\"notrun\">" << html_escape(err.empty() ? "no \"benchmarks\" array" : err) << "</p>";
      continue;
    }
    if (const auto* c = v->get_object().if_contains("context"); c && c->is_object()) {
      const auto& co = c->get_object();
      o << "<p class=\"muted\">";
      for (const char* k : {"date", "host_name", "num_cpus", "mhz_per_cpu", "library_build_type"})
        if (co.if_contains(k)) o << k << ": " << html_escape(json_scalar(co.at(k))) << "; ";
      o << "</p>";
    }
    o << "<table><tr><th>benchmark</th><th>real time</th><th>cpu time</th><th>unit</th><th>iterations</th>"
         "<th>items/s</th></tr>";
    for (const auto& b : v->get_object().at("benchmarks").get_array()) {
      if (!b.is_object()) continue;
      const auto& bo = b.get_object();
      auto get = [&](const char* k) { return bo.if_contains(k) ? json_scalar(bo.at(k)) : std::string("-"); };
      o << "<tr><td>" << html_escape(get("name")) << "</td><td>" << html_escape(get("real_time")) << "</td><td>"
        << html_escape(get("cpu_time")) << "</td><td>" << html_escape(get("time_unit")) << "</td><td>"
        << html_escape(get("iterations")) << "</td><td>" << html_escape(get("items_per_second")) << "</td></tr>";
    }
    o << "</table>\n";
  }
  return o.str();
}

// ---- maps over geometry: data/polygon/geometry-map.json and data/projected-cap/geometry-map.json, measured by
// build/geometry_maps (validation/tools/geometry_maps.cpp); drawn here, never computed.

const json::value& member(const json::object& o, const char* key) { return json_read::member(o, key, "the map"); }

std::string rgb(const Rgb& c) {
  return "rgb(" + std::to_string(int(c[0])) + "," + std::to_string(int(c[1])) + "," + std::to_string(int(c[2])) + ")";
}

// The plot frame shared by both maps: 520 x 300, plot area [L, R] x [T, B], a vertical colour bar right of it.
struct Frame {
  static constexpr double W = 520, H = 300, L = 50, R = W - 70, T = 24, B = H - 36;
};

std::string svg_frame_start(const std::string& title, const std::string& heading) {
  std::ostringstream o;
  o << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << Frame::W << "\" height=\"" << Frame::H
    << "\" role=\"img\"><title>" << title << "</title><text x=\"6\" y=\"15\" font-size=\"12\">" << heading
    << "</text><rect x=\"" << Frame::L << "\" y=\"" << Frame::T << "\" width=\"" << Frame::R - Frame::L
    << "\" height=\"" << Frame::B - Frame::T << "\" fill=\"#fff\" stroke=\"#444\"/>";
  return o.str();
}

// Axis labels and the sequential colour bar labelled lo_label (bottom) to hi_label (top); closes the SVG.
std::string svg_frame_end(const std::string& xlabel, const std::string& ylabel, const std::string& lo_label,
                          const std::string& hi_label) {
  const double L = Frame::L, R = Frame::R, T = Frame::T, B = Frame::B;
  std::ostringstream o;
  o << "<text x=\"" << (L + R) / 2 << "\" y=\"" << Frame::H - 6 << "\" font-size=\"11\" text-anchor=\"middle\">"
    << xlabel << "</text><text x=\"12\" y=\"" << (T + B) / 2
    << "\" font-size=\"11\" text-anchor=\"middle\" transform=\"rotate(-90 12 " << (T + B) / 2 << ")\">" << ylabel
    << "</text>";
  for (int k = 0; k <= 8; ++k)
    o << "<rect x=\"" << R + 12 << "\" y=\"" << B - (B - T) * (k + 1) / 9.0 << "\" width=\"14\" height=\""
      << (B - T) / 9.0 + 0.5 << "\" fill=\"" << rgb(sequential_color(k / 8.0)) << "\"/>";
  o << "<text x=\"" << R + 30 << "\" y=\"" << B << "\" font-size=\"10\">" << lo_label << "</text><text x=\"" << R + 30
    << "\" y=\"" << T + 8 << "\" font-size=\"10\">" << hi_label << "</text></svg>";
  return o.str();
}

// The polygon backward error (Peters 2021 Sec. 3.6, Eq. 7) over sector geometry, one map per recorded iteration
// count: each case placed by its sector's opening angle and the target's position xi within the sector, coloured
// by log10 of its backward error.
std::string polygon_backward_error_maps(const json::object& m) {
  const std::vector<double> angle = json_read::numbers(member(m, "opening_angle_degrees"), "opening_angle_degrees"),
                            xi = json_read::numbers(member(m, "xi"), "xi");
  const std::string scalar = json_read::string_of(member(m, "scalar"), "scalar");
  const long long cases = (long long)json_read::number(member(m, "cases"), "cases"),
                  seed = (long long)json_read::number(member(m, "seed"), "seed");
  const json::value& errors = member(m, "backward_error");
  if (!errors.is_array()) throw std::runtime_error("backward_error is not an array");
  const double lo = -17, hi = 0;  // log10 colour range: double's rounding up to a whole-sector error
  const double L = Frame::L, R = Frame::R, T = Frame::T, B = Frame::B;
  std::string out;
  for (const json::value& e : errors.get_array()) {
    if (!e.is_object()) throw std::runtime_error("backward_error entry is not an object");
    const long long iterations = (long long)json_read::number(member(e.get_object(), "iterations"), "iterations");
    const std::vector<double> err = json_read::numbers(member(e.get_object(), "values"), "backward_error values");
    if (angle.size() != std::size_t(cases) || xi.size() != angle.size() || err.size() != angle.size())
      throw std::runtime_error("opening_angle_degrees, xi and values do not all hold one entry per case");
    std::ostringstream o;
    o << svg_frame_start("polygon backward error, " + std::to_string(iterations) + " iterations",
                         "backward error |A_delta| / sector area after " + std::to_string(iterations) +
                             " iteration(s), " + html_escape(scalar) + ", " + std::to_string(cases) +
                             " random decentral sectors (seed " + std::to_string(seed) + ")");
    double worst = 0;
    for (std::size_t i = 0; i < err.size(); ++i) {
      const double l = err[i] > 0 ? std::log10(err[i]) : lo;
      worst = std::max(worst, err[i]);
      o << "<circle cx=\"" << L + angle[i] / 180 * (R - L) << "\" cy=\"" << B - xi[i] * (B - T)
        << "\" r=\"1.8\" fill=\"" << rgb(sequential_color((std::clamp(l, lo, hi) - lo) / (hi - lo))) << "\"/>";
    }
    for (int k = 0; k <= 4; ++k)
      o << "<text x=\"" << L + (R - L) * k / 4 << "\" y=\"" << B + 13 << "\" font-size=\"10\" text-anchor=\"middle\">"
        << 45 * k << "</text><text x=\"" << L - 4 << "\" y=\"" << B - (B - T) * k / 4 + 3
        << "\" font-size=\"10\" text-anchor=\"end\">" << k / 4.0 << "</text>";
    o << svg_frame_end("sector opening angle (degrees)", "xi (target / sector area)", "1e" + num(lo), "1e" + num(hi))
      << "<p class=\"muted\">Largest of these " << cases << ": " << num(worst) << ".</p>";
    out += o.str();
  }
  return out;
}

// The Case-3 density ratio (Peters & Dachsbacher 2019 Sec. 3.5: max / min of Alg. 4's density over the cut disk)
// on a grid over distance d / r (log axis) and the centre's depth below the horizon / r_y (0: on the horizon,
// 1: Case 4); cells that are not Case 3 are null. Colour: log2 of the ratio over [0, 1] (ratio 1 to 2), the
// bound's range for d >= 1.094 r; the caption gives the largest ratio / the paper's bound, which must stay <= 1.
std::string case3_ratio_map(const json::object& m) {
  const long long nx = (long long)json_read::number(member(m, "nx"), "nx"),
                  ny = (long long)json_read::number(member(m, "ny"), "ny");
  const std::vector<double> xr = json_read::numbers(member(m, "log10_distance_range"), "log10_distance_range"),
                            yr = json_read::numbers(member(m, "depth_range"), "depth_range");
  const json::value &ratios = member(m, "ratio"), &bounds = member(m, "bound");
  if (nx < 1 || ny < 1 || xr.size() != 2 || yr.size() != 2 || !ratios.is_array() || !bounds.is_array() ||
      ratios.get_array().size() != std::size_t(nx) || bounds.get_array().size() != std::size_t(nx))
    throw std::runtime_error("nx, ny, the ranges and the ratio / bound rows do not agree");
  const double L = Frame::L, R = Frame::R, T = Frame::T, B = Frame::B, cw = (R - L) / nx, ch = (B - T) / ny;
  std::ostringstream dots;
  double worst_over_bound = 0, lo_ratio = 1e300, hi_ratio = 0;
  for (long long i = 0; i < nx; ++i) {
    const std::vector<double> ratio = json_read::numbers(ratios.get_array()[i], "ratio row"),
                              bound = json_read::numbers(bounds.get_array()[i], "bound row");
    if (ratio.size() != std::size_t(ny) || bound.size() != std::size_t(ny))
      throw std::runtime_error("a ratio or bound row does not hold ny entries");
    for (long long j = 0; j < ny; ++j) {
      if (std::isnan(ratio[j])) continue;
      worst_over_bound = std::max(worst_over_bound, ratio[j] / bound[j]);
      lo_ratio = std::min(lo_ratio, ratio[j]), hi_ratio = std::max(hi_ratio, ratio[j]);
      dots << "<rect x=\"" << L + i * cw << "\" y=\"" << B - (j + 1) * ch << "\" width=\"" << cw + 0.3 << "\" height=\""
           << ch + 0.3 << "\" fill=\"" << rgb(sequential_color(std::clamp(std::log2(ratio[j]), 0.0, 1.0))) << "\"/>";
    }
  }
  std::ostringstream o;
  o << svg_frame_start("Case-3 density ratio over geometry",
                       "Case-3 density ratio max/min of Alg. 4 (" +
                           html_escape(json_read::string_of(member(m, "scalar"), "scalar")) + "), " +
                           std::to_string(nx) + " x " + std::to_string(ny) + " geometries")
    << dots.str();
  for (int k = int(std::floor(xr[0])); k <= int(std::floor(xr[1])); ++k)
    o << "<text x=\"" << L + (R - L) * (k - xr[0]) / (xr[1] - xr[0]) << "\" y=\"" << B + 13
      << "\" font-size=\"10\" text-anchor=\"middle\">1e" << k << "</text>";
  for (int k = 0; k <= 4; ++k)
    o << "<text x=\"" << L - 4 << "\" y=\"" << B - (B - T) * k / 4 + 3 << "\" font-size=\"10\" text-anchor=\"end\">"
      << yr[0] + (yr[1] - yr[0]) * k / 4.0 << "</text>";
  o << svg_frame_end("distance / radius", "depth of the centre / r_y", "1", "2+") << "<p class=\"muted\">Ratio from "
    << num(lo_ratio) << " to " << num(hi_ratio) << "; largest ratio / paper's bound: " << num(worst_over_bound)
    << " (must be &lt;= 1 up to rounding). The worst case over the continuous geometry is the search "
       "projected-cap-case3-ratio.</p>";
  return o.str();
}

// data/<dir>/geometry-map.json drawn by `render`, or a note saying why it cannot be.
std::string geometry_map(const fs::path& data, const std::string& dir, std::string (*render)(const json::object&)) {
  const std::string name = "data/" + dir + "/geometry-map.json";
  const fs::path p = data / dir / "geometry-map.json";
  if (!fs::exists(p)) return not_run(name + " does not exist", "build/geometry_maps");
  std::string err;
  const auto v = load_json(p, err);
  if (!v || !v->is_object()) err = err.empty() ? p.string() + " is not a JSON object" : err;
  try {
    if (err.empty()) return "<p class=\"muted\">From <code>" + name + "</code>.</p>\n" + render(v->get_object());
  } catch (const std::exception& e) {
    err = p.string() + ": " + e.what();
  }
  return "<p class=\"notrun\">" + html_escape(err) + "</p>\n";
}

std::string geometry_maps_section(const fs::path& data) {
  return "<h2 id=\"geometry-maps\">Maps over geometry</h2>\n<h3>Polygon backward error (Peters 2021 Sec. 3.6)</h3>\n" +
         geometry_map(data, "polygon", polygon_backward_error_maps) +
         "<h3>Case-3 density ratio (Peters &amp; Dachsbacher 2019 Sec. 3.5)</h3>\n" +
         geometry_map(data, "projected-cap", case3_ratio_map) + "\n";
}

// The results grouped by kernel, kernels and tests in order of first appearance.
struct Grouped {
  std::vector<std::string> kernels, tests;
  std::map<std::string, std::vector<const TestResult*>> by_kernel;
};

Grouped group(const BatteryRun& run, ReportSummary& sum) {
  Grouped g;
  for (const TestResult& r : run.results) {
    if (!g.by_kernel.count(r.kernel)) g.kernels.push_back(r.kernel);
    g.by_kernel[r.kernel].push_back(&r);
    if (std::find(g.tests.begin(), g.tests.end(), r.test) == g.tests.end()) g.tests.push_back(r.test);
    sum.failures += r.failed();
    sum.known_limitation_failures += !r.passed && !r.known_limitation.empty();
  }
  sum.kernels = g.kernels.size();
  return g;
}

std::string results_table(const std::vector<const TestResult*>& rs) {
  std::ostringstream p;
  p << "<h2>Results</h2><table><tr><th>scalar</th><th>config</th><th>test</th><th>statistic</th>"
       "<th>p-value</th><th>verdict</th><th>detail</th></tr>";
  for (const TestResult* r : rs)
    p << "<tr id=\"" << result_anchor(*r) << "\"><td>" << html_escape(r->scalar) << "</td><td>"
      << html_escape(r->config) << "</td><td>" << html_escape(r->test) << "</td><td>"
      << (std::isnan(r->statistic) ? "null" : num(r->statistic, 6)) << "</td><td>"
      << (r->p_value ? num(*r->p_value, 4) : "-") << "</td><td class=\"" << cell_class(*r) << "\">" << verdict(*r)
      << "</td><td>" << html_escape(r->detail)
      << (r->known_limitation.empty() ? "" : "<br><i>known limitation: " + html_escape(r->known_limitation) + "</i>")
      << (r->map_rows ? " <a href=\"#maps-" + result_anchor(*r) + "\">maps</a>" : "") << "</td></tr>";
  p << "</table>\n";
  return p.str();
}

// A power figure as the smallest relative error caught: "0.21%", "not seen" (no test sees the alternative), "n/a"
// (not defined for the case).
std::string eps_text(const PowerFigure& f) {
  if (std::isnan(f.eps)) return "n/a";
  if (std::isinf(f.eps)) return "not seen";
  return num(100 * f.eps, 2) + "%";
}

const CasePower* power_of(const BatteryRun& run, const std::string& k, const std::string& sc, const std::string& cf) {
  for (const CasePower& c : run.power)
    if (c.kernel == k && c.scalar == sc && c.config == cf) return &c;
  return nullptr;
}

// The kernel page's power table: per case, the smallest relative density error of each alternative the battery
// rejects with probability 0.9 at the run's sample count and level (power.h).
std::string power_table(const std::string& k, const BatteryRun& run) {
  std::ostringstream p;
  p << "<h2 id=\"power\">Power</h2><p class=\"muted\">The smallest relative density error the battery rejects with "
       "probability 0.9 at the run's sample count and the correction's first-step level, per standard alternative: "
       "region (the innermost 10% of the mass too dense), tilt (a smooth radial tilt), wedge (the first column "
       "of the grid too dense); and the test that reaches it.</p><table><tr><th>scalar</th><th>config</th>"
       "<th>samples</th><th>level</th><th>region</th><th>tilt</th><th>wedge</th></tr>";
  bool any = false;
  for (const CasePower& c : run.power) {
    if (c.kernel != k) continue;
    any = true;
    p << "<tr><td>" << html_escape(c.scalar) << "</td><td>" << html_escape(c.config) << "</td><td>" << c.samples
      << "</td><td>" << num(c.level, 3) << "</td>";
    for (const PowerFigure& f : c.figures)
      p << "<td>" << eps_text(f) << (f.test.empty() ? "" : " <span class=\"muted\">" + html_escape(f.test) + "</span>")
        << "</td>";
    p << "</tr>";
  }
  p << "</table>\n";
  return any ? p.str() : "";
}

void write_kernel_page(const std::string& k, const std::vector<const TestResult*>& rs, const BatteryRun& run,
                       const ReportOptions& opt, const SampleSets* sets, ReportSummary& sum) {
  const fs::path out(opt.out_dir);
  std::ostringstream p;
  p << page_start("warpcheck: " + k) << "<p><a href=\"index.html\">&larr; all kernels</a></p><h1>" << html_escape(k)
    << "</h1>\n";
  std::size_t kf = 0;
  for (const TestResult* r : rs) kf += r->failed();
  p << "<div class=\"banner " << (kf ? "bad" : "good") << "\">"
    << (kf ? std::to_string(kf) + " test(s) FAILED" : "all tests passed (or are documented known limitations)")
    << "</div>\n"
    << results_table(rs) << power_table(k, run) << "<h2>chi2 maps</h2>\n";
  // Failing maps first: that is where a reader looks.
  std::vector<const TestResult*> maps;
  for (const TestResult* r : rs)
    if (r->map_rows > 0) maps.push_back(r);
  std::stable_sort(maps.begin(), maps.end(),
                   [](const TestResult* a, const TestResult* b) { return a->failed() > b->failed(); });
  for (const TestResult* r : maps) p << chi2_maps(*r, run.samples, out, sum);
  if (maps.empty())
    p << "<p class=\"muted\">No chi2 maps in these results (results written before maps were recorded, or a "
         "no-sample geometry).</p>";
  std::set<std::string> configs;
  for (const TestResult* r : rs) configs.insert(r->config);
  p << "<h2>Sample sets</h2>\n" << sample_sets(k, sets, configs, opt) << page_end();
  write_text(out / kernel_page(k), p.str());
  sum.files.push_back(kernel_page(k));
}

// The index's head: the run's parameters, a banner when it is incomplete, and the failing tests first.
std::string run_summary(const BatteryRun& run, const ReportOptions& opt, const ReportSummary& sum) {
  std::ostringstream x;
  x << "<p>Results: <code>" << html_escape(opt.results_path) << "</code>; significance alpha = " << num(run.alpha)
    << " family-wise, " << to_string(run.correction) << " correction across " << run.statistical_tests()
    << " statistical tests" << (run.samples ? "; " + std::to_string(*run.samples) + " samples per case" : "")
    << (run.seed ? "; seed " + std::to_string(*run.seed) : "") << ".</p>\n";
  if (run.complete && !*run.complete)
    x << "<div class=\"banner warn\">This run is INCOMPLETE (\"complete\": false): the battery was interrupted; "
         "cases it did not reach are missing, and so are the power figures (written when a run completes).</div>\n";
  std::vector<const TestResult*> failing;
  for (const TestResult& r : run.results)
    if (r.failed()) failing.push_back(&r);
  if (failing.empty())
    return x.str() + "<div class=\"banner good\">All " + std::to_string(run.results.size()) + " tests passed" +
           (sum.known_limitation_failures
                ? " (" + std::to_string(sum.known_limitation_failures) + " failures are documented known limitations)"
                : "") +
           ".</div>\n";
  x << "<div class=\"banner bad\" id=\"failing\">" << failing.size() << " of " << run.results.size()
    << " tests FAILED</div>\n<ul class=\"failing\">";
  for (const TestResult* r : failing)
    x << "<li><a href=\"" << kernel_page(r->kernel) << "#" << result_anchor(*r) << "\">" << html_escape(r->kernel)
      << " / " << html_escape(r->scalar) << " / " << html_escape(r->config) << ": " << html_escape(r->test) << "</a> "
      << (r->p_value ? "p = " + num(*r->p_value)
                     : "statistic " + (std::isnan(r->statistic) ? std::string("null") : num(r->statistic)))
      << " <span class=\"muted\">" << html_escape(r->detail) << "</span>"
      << (r->map_rows ? " <a href=\"" + kernel_page(r->kernel) + "#maps-" + result_anchor(*r) + "\">(residual map)</a>"
                      : "")
      << "</li>";
  x << "</ul>\n";
  return x.str();
}

// The pass/fail matrix: one row per kernel x scalar x configuration, one column per test.
std::string matrix(const Grouped& g, const BatteryRun& run) {
  std::ostringstream x;
  x << "<h2 id=\"matrix\">Pass/fail matrix</h2>\n<p class=\"muted\">Cells: p-value for statistical tests (judged "
       "together at alpha with the correction above), the statistic (relative error) for deterministic ones. "
       "Legend: <span style=\"background:#d8f0d8\">pass</span>, <span style=\"background:#e0302a;color:#fff\">"
       "FAIL</span>, <span style=\"background:#ffd27a\">fail, documented known limitation (striped)</span>, "
       "<span style=\"border:2px dashed #c88a00\">pass on a known-limitation case</span>. Hover a cell for its "
       "detail; click a kernel for its page. Power: the smallest relative density error rejected with probability "
       "0.9 (region: the innermost 10% of the mass too dense; tilt: a smooth radial tilt; wedge: a thin azimuthal "
       "wedge too dense).</p>\n<table><tr><th>kernel</th><th>scalar</th><th>config</th>";
  for (const auto& t : g.tests) x << "<th>" << html_escape(t) << "</th>";
  if (!run.power.empty()) x << "<th>power: region</th><th>tilt</th><th>wedge</th>";
  x << "</tr>\n";
  for (const std::string& k : g.kernels) {
    const std::vector<const TestResult*>& rs = g.by_kernel.at(k);
    std::vector<std::pair<std::string, std::string>> rows;  // (scalar, config), order of appearance
    for (const TestResult* r : rs)
      if (std::find(rows.begin(), rows.end(), std::make_pair(r->scalar, r->config)) == rows.end())
        rows.emplace_back(r->scalar, r->config);
    for (const auto& [sc, cf] : rows) {
      x << "<tr><td><a href=\"" << kernel_page(k) << "\">" << html_escape(k) << "</a></td><td>" << html_escape(sc)
        << "</td><td>" << html_escape(cf) << "</td>";
      for (const auto& t : g.tests) {
        const TestResult* hit = nullptr;
        for (const TestResult* r : rs)
          if (r->scalar == sc && r->config == cf && r->test == t) hit = r;
        if (!hit) {
          x << "<td class=\"absent\">&middot;</td>";
          continue;
        }
        x << "<td class=\"" << cell_class(*hit) << "\" title=\""
          << html_escape(verdict(*hit) + ": " + hit->detail +
                         (hit->known_limitation.empty() ? "" : " [known limitation: " + hit->known_limitation + "]"))
          << "\"><a href=\"" << kernel_page(k) << "#" << result_anchor(*hit) << "\">" << cell_value(*hit)
          << "</a></td>";
      }
      if (const CasePower* c = run.power.empty() ? nullptr : power_of(run, k, sc, cf))
        for (const PowerFigure& f : c->figures)
          x << "<td class=\"power\" title=\"" << html_escape(f.test.empty() ? "" : "by " + f.test) << "\">"
            << eps_text(f) << "</td>";
      else if (!run.power.empty())
        x << "<td class=\"absent\">&middot;</td><td class=\"absent\">&middot;</td><td class=\"absent\">&middot;</td>";
      x << "</tr>\n";
    }
  }
  x << "</table>\n";
  return x.str();
}

void write_index(const BatteryRun& run, const ReportOptions& opt, const Grouped& g, ReportSummary& sum) {
  std::ostringstream x;
  x << page_start("warpcheck report") << "<h1>warpcheck validation report</h1>\n" << run_summary(run, opt, sum);
  x << "<p><a href=\"#matrix\">matrix</a> | <a href=\"#claims\">paper vs ours</a> | <a href=\"#worst\">worst cases</a>"
       " | <a href=\"#fuzz\">fuzz</a> | <a href=\"#bench\">benchmarks</a> | <a href=\"#geometry-maps\">maps over "
       "geometry</a> | <a href=\"#coverage\">coverage</a></p>\n"
    << matrix(g, run);
  if (opt.data_dir.empty()) {
    x << "<h2 id=\"claims\">Data</h2>" << not_run("no data directory given", "warpcheck report --data data ...")
      << "<span id=\"worst\"></span><span id=\"fuzz\"></span><span id=\"bench\"></span><span "
         "id=\"geometry-maps\"></span><span id=\"coverage\"></span>";
  } else {
    const fs::path data(opt.data_dir);
    x << claims_section(data) << worst_case_section(data) << fuzz_section(data) << bench_section(data)
      << geometry_maps_section(data) << coverage_section(data);
  }
  x << page_end();
  write_text(fs::path(opt.out_dir) / "index.html", x.str());
  sum.files.push_back("index.html");
}

}  // namespace

ReportSummary write_report(const ReportOptions& opt) {
  if (opt.out_dir.empty()) throw std::invalid_argument("write_report: no output directory");
  const BatteryRun run = parse_battery_json(read_text(opt.results_path));
  fs::create_directories(fs::path(opt.out_dir) / "img");
  ReportSummary sum;
  sum.results = run.results.size();
  const Grouped g = group(run, sum);
  std::optional<SampleSets> sets;
  if (!opt.sample_sets_path.empty() && fs::exists(opt.sample_sets_path))
    sets = parse_sample_sets(read_text(opt.sample_sets_path));
  for (const std::string& k : g.kernels)
    write_kernel_page(k, g.by_kernel.at(k), run, opt, sets ? &*sets : nullptr, sum);
  write_index(run, opt, g, sum);
  return sum;
}

}  // namespace warpcheck::validation::report
