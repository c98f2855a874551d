// The report's inline SVG: sample sets mapped by a kernel (the style of Fig. 7 of Peters & Dachsbacher 2019 and
// Fig. 13 of Peters 2021: primary sample space beside the directions it maps to) and line plots.
//
// Hand-rolled on purpose: Debian packages no C++ SVG plotting library, and the pieces are a few dozen lines. The
// points come from build/sample_sets (parse_sample_sets); nothing here runs a sampler.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "report.h"

namespace warpcheck::validation::report {
namespace {

std::string f2(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.2f", v);
  return b;
}

std::string point_color(double u0, double u1) {
  char b[16];
  std::snprintf(b, sizeof b, "#%02x%02x%02x", int(30 + 210 * u0), int(150 - 100 * std::abs(u0 - u1)),
                int(30 + 210 * u1));
  return b;
}

// Panel geometry shared by both sample-set drawings.
constexpr double kSquareX = 30, kSquareY = 34, kSide = 220, kDiskCx = 420, kDiskCy = 144, kDiskR = 110;

std::string frame_svg(const std::string& title, std::size_t valid, std::size_t declined, std::size_t outside) {
  std::ostringstream o;
  o << "<svg xmlns=\"http://www.w3.org/2000/svg\" class=\"sampleset\" width=\"560\" height=\"290\" "
       "viewBox=\"0 0 560 290\" role=\"img\"><title>"
    << html_escape(title) << "</title>"
    << "<text x=\"10\" y=\"18\" font-size=\"13\">" << html_escape(title) << "</text>"
    << "<rect x=\"" << kSquareX << "\" y=\"" << kSquareY << "\" width=\"" << kSide << "\" height=\"" << kSide
    << "\" fill=\"#fff\" stroke=\"#444\"/>"
    << "<text x=\"" << kSquareX << "\" y=\"" << kSquareY + kSide + 16 << "\" font-size=\"11\">primary sample space "
    << "(u0 right, u1 up)</text>"
    << "<circle cx=\"" << kDiskCx << "\" cy=\"" << kDiskCy << "\" r=\"" << kDiskR
    << "\" fill=\"#fff\" stroke=\"#444\"/>"
    << "<text x=\"" << kDiskCx - kDiskR << "\" y=\"" << kSquareY + kSide + 16 << "\" font-size=\"11\">"
    << "directions, bounding cap (equal-area, x = cap frame x)</text>"
    << "<text x=\"" << kDiskCx - kDiskR << "\" y=\"" << kSquareY + kSide + 30 << "\" font-size=\"11\">" << valid
    << " mapped, " << declined << " declined" << (outside ? ", " + std::to_string(outside) + " OUTSIDE the cap" : "")
    << "</text>";
  return o.str();
}

// Disk coordinates of a mapped point; points outside the cap are drawn on a ring just outside it.
std::pair<double, double> disk_xy(const MappedPoint& p) {
  double x = p.x, y = p.y;
  const double r = std::hypot(x, y);
  if (r > 1.06) x *= 1.06 / r, y *= 1.06 / r;
  return {kDiskCx + kDiskR * x, kDiskCy - kDiskR * y};
}

}  // namespace

std::string sample_set_svg(const std::vector<std::array<double, 2>>& u, const std::vector<MappedPoint>& mapped,
                           const std::string& title) {
  if (u.size() != mapped.size())
    throw std::invalid_argument("sample_set_svg: points and mapped points differ in number");
  std::size_t valid = 0, outside = 0;
  for (const auto& m : mapped) valid += m.valid, outside += m.valid && m.outside;
  std::ostringstream o;
  o << frame_svg(title, valid, mapped.size() - valid, outside);
  for (std::size_t i = 0; i < u.size(); ++i) {
    const auto& p = u[i];
    const std::string c = point_color(p[0], p[1]);
    o << "<circle cx=\"" << f2(kSquareX + kSide * p[0]) << "\" cy=\"" << f2(kSquareY + kSide * (1 - p[1]))
      << "\" r=\"1.5\" fill=\"" << c << "\"/>";
    if (!mapped[i].valid) continue;
    const auto [x, y] = disk_xy(mapped[i]);
    if (mapped[i].outside)
      o << "<path d=\"M" << f2(x - 3) << " " << f2(y - 3) << "l6 6m0 -6l-6 6\" stroke=\"#d00\" stroke-width=\"1.5\"/>";
    else
      o << "<circle cx=\"" << f2(x) << "\" cy=\"" << f2(y) << "\" r=\"1.5\" fill=\"" << c << "\"/>";
  }
  o << "</svg>";
  return o.str();
}

std::string grid_lines_svg(int lines, int line_samples, const std::vector<MappedPoint>& mapped,
                           const std::string& title) {
  if (lines < 1 || line_samples < 2 || mapped.size() != std::size_t(2 * lines * line_samples))
    throw std::invalid_argument("grid_lines_svg: " + std::to_string(mapped.size()) + " mapped points for " +
                                std::to_string(lines) + " + " + std::to_string(lines) + " lines of " +
                                std::to_string(line_samples));
  std::ostringstream body;
  std::size_t valid = 0, total = 0, outside = 0;
  for (int dir = 0; dir < 2; ++dir)
    for (int i = 0; i < lines; ++i) {
      const double fixed = lines > 1 ? double(i) / (lines - 1) : 0.5;
      const auto first = mapped.begin() + std::ptrdiff_t((dir * lines + i) * line_samples);
      const std::vector<MappedPoint> m(first, first + line_samples);
      const std::string c = dir == 0 ? point_color(fixed, 0.2) : point_color(0.2, fixed);
      // The line in primary sample space.
      const std::array<double, 2> ends[2] = {
          dir == 0 ? std::array<double, 2>{fixed, 0} : std::array<double, 2>{0, fixed},
          dir == 0 ? std::array<double, 2>{fixed, 1} : std::array<double, 2>{1, fixed}};
      body << "<polyline fill=\"none\" stroke=\"" << c << "\" stroke-width=\"1\" points=\"";
      for (const auto& p : ends) body << f2(kSquareX + kSide * p[0]) << "," << f2(kSquareY + kSide * (1 - p[1])) << " ";
      body << "\"/>";
      // Its image, broken where a sample is declined or the image jumps (a seam of the warp).
      std::string pts;
      int npts = 0;
      double px = 0, py = 0;
      auto flush = [&] {
        if (npts >= 2)
          body << "<polyline fill=\"none\" stroke=\"" << c << "\" stroke-width=\"1\" points=\"" << pts << "\"/>";
        pts.clear();
        npts = 0;
      };
      for (const auto& p : m) {
        ++total;
        if (!p.valid) {
          flush();
          continue;
        }
        ++valid;
        outside += p.outside;
        const auto [x, y] = disk_xy(p);
        if (npts && std::hypot(x - px, y - py) > 0.25 * kDiskR) flush();
        pts += f2(x) + "," + f2(y) + " ";
        ++npts;
        px = x, py = y;
      }
      flush();
    }
  return frame_svg(title, valid, total - valid, outside) + body.str() + "</svg>";
}

std::string svg_line_plot(const std::vector<Series>& series, const std::string& title, const std::string& xlabel,
                          const std::string& ylabel, bool log_x, bool log_y, int width, int height) {
  auto tx = [&](double v) { return log_x ? std::log10(v) : v; };
  auto ty = [&](double v) { return log_y ? std::log10(v) : v; };
  auto usable = [&](double x, double y) {
    return std::isfinite(x) && std::isfinite(y) && (!log_x || x > 0) && (!log_y || y > 0);
  };
  double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
  for (const auto& s : series)
    for (const auto& [x, y] : s.points)
      if (usable(x, y))
        x0 = std::min(x0, tx(x)), x1 = std::max(x1, tx(x)), y0 = std::min(y0, ty(y)), y1 = std::max(y1, ty(y));
  std::ostringstream o;
  o << "<svg xmlns=\"http://www.w3.org/2000/svg\" class=\"plot\" width=\"" << width << "\" height=\"" << height
    << "\" viewBox=\"0 0 " << width << " " << height << "\" role=\"img\"><title>" << html_escape(title)
    << "</title><text x=\"8\" y=\"16\" font-size=\"13\">" << html_escape(title) << "</text>";
  if (x0 > x1) {
    o << "<text x=\"60\" y=\"" << height / 2 << "\" font-size=\"12\">no plottable points</text></svg>";
    return o.str();
  }
  if (x1 - x0 < 1e-12) x0 -= 0.5, x1 += 0.5;
  if (y1 - y0 < 1e-12 * std::max(1.0, std::abs(y0)))
    y0 -= log_y ? 0.5 : 0.5 * std::max(std::abs(y0), 1e-300), y1 += log_y ? 0.5 : 0.5 * std::max(std::abs(y1), 1e-300);
  const double L = 70, R = width - 12, T = 28, B = height - 40;
  auto X = [&](double v) { return L + (tx(v) - x0) / (x1 - x0) * (R - L); };
  auto Y = [&](double v) { return B - (ty(v) - y0) / (y1 - y0) * (B - T); };
  o << "<rect x=\"" << L << "\" y=\"" << T << "\" width=\"" << R - L << "\" height=\"" << B - T
    << "\" fill=\"#fff\" stroke=\"#444\"/>";
  char buf[64];
  for (int k = 0; k <= 4; ++k) {  // ticks at 5 evenly spaced positions of the (transformed) axes
    const double fx = x0 + (x1 - x0) * k / 4, fy = y0 + (y1 - y0) * k / 4;
    const double vx = log_x ? std::pow(10, fx) : fx, vy = log_y ? std::pow(10, fy) : fy;
    std::snprintf(buf, sizeof buf, "%.3g", vx);
    o << "<text x=\"" << f2(L + (R - L) * k / 4) << "\" y=\"" << B + 14 << "\" font-size=\"10\" text-anchor=\"middle\">"
      << buf << "</text>";
    std::snprintf(buf, sizeof buf, "%.3g", vy);
    o << "<text x=\"" << L - 4 << "\" y=\"" << f2(B - (B - T) * k / 4 + 3) << "\" font-size=\"10\" text-anchor=\"end\">"
      << buf << "</text>";
    o << "<line x1=\"" << L << "\" x2=\"" << R << "\" y1=\"" << f2(B - (B - T) * k / 4) << "\" y2=\""
      << f2(B - (B - T) * k / 4) << "\" stroke=\"#ddd\"/>";
  }
  o << "<text x=\"" << (L + R) / 2 << "\" y=\"" << height - 6 << "\" font-size=\"11\" text-anchor=\"middle\">"
    << html_escape(xlabel) << (log_x ? " (log)" : "") << "</text>"
    << "<text x=\"12\" y=\"" << (T + B) / 2 << "\" font-size=\"11\" text-anchor=\"middle\" transform=\"rotate(-90 12 "
    << (T + B) / 2 << ")\">" << html_escape(ylabel) << (log_y ? " (log)" : "") << "</text>";
  static const char* colors[] = {"#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b"};
  for (std::size_t i = 0; i < series.size(); ++i) {
    const char* c = colors[i % 6];
    o << "<polyline fill=\"none\" stroke=\"" << c << "\" stroke-width=\"1.5\" points=\"";
    for (const auto& [x, y] : series[i].points)
      if (usable(x, y)) o << f2(X(x)) << "," << f2(Y(y)) << " ";
    o << "\"/>";
    for (const auto& [x, y] : series[i].points)
      if (usable(x, y))
        o << "<circle cx=\"" << f2(X(x)) << "\" cy=\"" << f2(Y(y)) << "\" r=\"2\" fill=\"" << c << "\"/>";
    o << "<text x=\"" << L + 8 << "\" y=\"" << T + 14 + 13 * i << "\" font-size=\"11\" fill=\"" << c << "\">"
      << html_escape(series[i].name) << "</text>";
  }
  o << "</svg>";
  return o.str();
}

}  // namespace warpcheck::validation::report
