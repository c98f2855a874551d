// reports/report.h: the HTML report (`warpcheck report`).
//
// write_report() turns a battery results JSON (`warpcheck validate --json`, results.h) and whatever
// the data directory holds (claims, geometry maps, worst cases, fuzz summary, benchmarks) into a static, offline site:
//   index.html        pass/fail matrix (kernel x scalar x config by test), the failing list first, alpha and
//                     correction; then the data sections (claims beside the paper, worst cases, fuzz, bench)
//   kernel-<k>.html   one page per kernel: its results, per chi2 test the observed / expected / signed
//                     residual maps (PNG in the page, 32-bit float OpenEXR beside it), and the sample sets
//                     build/sample_sets computed (a grid and a blue-noise set mapped by the kernel) as inline SVG
// A missing optional input gives a section that says "not run" and the command that produces it.
//
// The pieces are exposed so tests can check them one by one.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "warpcheck/validation/results.h"

namespace warpcheck::validation::report {

// ---- Images ----------------------------------------------------------------------------------------------------

struct Image {
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgba;  // row-major, 4 bytes per pixel
};

using Rgb = std::array<std::uint8_t, 3>;
// Sequential colour map for counts, t in [0, 1] (dark blue -> yellow, piecewise linear through viridis-like
// stops), and a diverging one for residuals, t in [-1, 1] (blue -> white -> red).
Rgb sequential_color(double t);
Rgb diverging_color(double t);

// A chi2 grid drawn as the bounding cap seen from above in an equal-area projection: pixel (x, y) of a
// size x size image at disk radius rho = sqrt(t), azimuth phi (counter-clockwise from +x, +y up) shows
// values[row(t) * cols + col(phi)] through color(value); equal-area bins therefore cover equal pixel areas.
// Outside the disk the image is transparent. With `ring`, the disk is drawn at 90% of the radius and a ring
// around it shows color(*ring): the samples that fell off the grid (outside the bounding cap, or declined).
Image polar_map(int rows, int cols, const std::vector<double>& values, int size,
                const std::function<Rgb(double)>& color, std::optional<double> ring = std::nullopt);

// Writes an 8-bit RGBA PNG (libpng). Throws std::runtime_error on failure.
void write_png(const std::string& path, const Image& image);
// Writes a scanline OpenEXR file with one 32-bit FLOAT channel per (name, values) (values row-major, width x
// height). Throws std::runtime_error (after catching OpenEXR's exceptions) on failure.
void write_exr(const std::string& path, int width, int height,
               const std::vector<std::pair<std::string, std::vector<float>>>& channels);
// Reads a channel back (for tests): the values, row-major.
std::vector<float> read_exr_channel(const std::string& path, const std::string& channel, int& width, int& height);

// ---- Sample sets -------------------------------------------------------------------------------------------------

// The sample sets build/sample_sets wrote (validation/tools/sample_sets.cpp documents the JSON): points of primary
// sample space and the directions a case's sampler maps them to, in the bounding cap's equal-area view.
struct MappedPoint {
  double x = 0, y = 0;   // sqrt(t) (cos phi, sin phi) in the bounding cap's frame
  bool valid = false;    // the sampler returned a direction
  bool outside = false;  // the direction lies outside the bounding cap (t > 1)
};
struct SampleSetCase {
  std::string kernel, scalar, config, description, error;  // error: the case could not be built
  bool expect_no_sample = false;
  std::vector<MappedPoint> grid, blue;  // grid: grid_lines u0 = const lines, then as many u1 = const lines
};
struct SampleSets {
  int grid_lines = 0, grid_line_samples = 0;
  std::vector<std::array<double, 2>> blue_u;  // the blue-noise points in primary sample space
  std::vector<SampleSetCase> cases;
};
// Throws std::runtime_error naming what is missing or inconsistent.
SampleSets parse_sample_sets(const std::string& json_text);

// Inline SVG of a sample set: primary sample space on the left, the mapped directions on the right (unit
// disk = bounding cap), points coloured by their (u0, u1) so the correspondence shows. The grid version draws
// each line and its image as polylines, broken where a point is declined or the image jumps.
std::string sample_set_svg(const std::vector<std::array<double, 2>>& u, const std::vector<MappedPoint>& mapped,
                           const std::string& title);
std::string grid_lines_svg(int lines, int line_samples, const std::vector<MappedPoint>& mapped,
                           const std::string& title);

// ---- Plots ---------------------------------------------------------------------------------------------------

struct Series {
  std::string name;
  std::vector<std::pair<double, double>> points;
};
// A self-contained inline SVG line plot (axes, ticks, legend). Non-finite points and, on log axes,
// non-positive ones are skipped.
std::string svg_line_plot(const std::vector<Series>& series, const std::string& title, const std::string& xlabel,
                          const std::string& ylabel, bool log_x, bool log_y, int width = 520, int height = 300);

// ---- The site ----------------------------------------------------------------------------------------------------

struct ReportOptions {
  std::string out_dir;           // created if missing
  std::string results_path;      // battery JSON (required)
  std::string data_dir;          // claims, worst cases, fuzz, bench; empty: no data sections read
  std::string sample_sets_path;  // build/sample_sets's JSON; empty or missing: the pages say how to produce it
};

struct ReportSummary {
  std::size_t kernels = 0, results = 0, failures = 0, known_limitation_failures = 0;
  std::vector<std::string> files;  // every file written, relative to out_dir
};

ReportSummary write_report(const ReportOptions& options);

// HTML-escapes text (&, <, >, ", ').
std::string html_escape(const std::string& s);
// A file name for a kernel page / image prefix: [A-Za-z0-9._-] kept, anything else '_'.
std::string safe_name(const std::string& s);

}  // namespace warpcheck::validation::report
