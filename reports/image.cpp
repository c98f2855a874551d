// The report's images: colour maps, the equal-area polar view of a chi2 grid, PNG (libpng) and OpenEXR
// (32-bit FLOAT channels through Imf::OutputFile; Imf::RgbaOutputFile would round to half) writing.
#include <png.h>

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "report.h"

namespace warpcheck::validation::report {
namespace {

Rgb lerp_stops(const std::vector<std::pair<double, Rgb>>& stops, double t) {
  if (!(t > stops.front().first)) return stops.front().second;  // also NaN
  if (t >= stops.back().first) return stops.back().second;
  for (std::size_t i = 1; i < stops.size(); ++i)
    if (t <= stops[i].first) {
      const double f = (t - stops[i - 1].first) / (stops[i].first - stops[i - 1].first);
      Rgb c;
      for (int k = 0; k < 3; ++k)
        c[k] = std::uint8_t(std::lround(stops[i - 1].second[k] + f * (stops[i].second[k] - stops[i - 1].second[k])));
      return c;
    }
  return stops.back().second;
}

}  // namespace

Rgb sequential_color(double t) {
  // Five stops read off matplotlib's viridis (its published endpoints and quartiles); linear in between.
  static const std::vector<std::pair<double, Rgb>> stops = {
      {0.0, {68, 1, 84}}, {0.25, {59, 82, 139}}, {0.5, {33, 145, 140}}, {0.75, {94, 201, 98}}, {1.0, {253, 231, 37}}};
  return lerp_stops(stops, t);
}

Rgb diverging_color(double t) {
  // Blue (negative: fewer samples than expected) -> white -> red (more samples than expected).
  static const std::vector<std::pair<double, Rgb>> stops = {{-1.0, {33, 102, 172}},
                                                            {-0.5, {146, 197, 222}},
                                                            {0.0, {247, 247, 247}},
                                                            {0.5, {244, 165, 130}},
                                                            {1.0, {178, 24, 43}}};
  return lerp_stops(stops, t);
}

Image polar_map(int rows, int cols, const std::vector<double>& values, int size,
                const std::function<Rgb(double)>& color, std::optional<double> ring) {
  if (rows <= 0 || cols <= 0 || values.size() != std::size_t(rows) * std::size_t(cols) || size <= 0)
    throw std::invalid_argument("polar_map: rows x cols does not match the values");
  Image im;
  im.width = im.height = size;
  im.rgba.assign(std::size_t(size) * size * 4, 0);
  const double half = 0.5 * size;
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const double px = (x + 0.5 - half) / half, py = (half - (y + 0.5)) / half;  // +y up
      double rho2 = px * px + py * py;
      std::uint8_t* p = &im.rgba[(std::size_t(y) * size + x) * 4];
      if (ring) {
        if (rho2 >= 1) continue;
        if (rho2 >= 0.93 * 0.93) {  // the off-grid ring
          const Rgb c = color(*ring);
          p[0] = c[0], p[1] = c[1], p[2] = c[2], p[3] = 255;
          continue;
        }
        rho2 /= 0.9 * 0.9;
        if (rho2 >= 1) continue;  // a transparent gap between the disk and the ring
      }
      if (rho2 >= 1) continue;
      double phi = std::atan2(py, px);
      if (phi < 0) phi += 2 * M_PI;
      const int r = std::min(rows - 1, int(rho2 * rows));  // t = rho^2
      const int a = std::min(cols - 1, int(phi / (2 * M_PI) * cols));
      const Rgb c = color(values[std::size_t(r) * cols + a]);
      p[0] = c[0], p[1] = c[1], p[2] = c[2], p[3] = 255;
    }
  return im;
}

void write_png(const std::string& path, const Image& image) {
  if (image.width <= 0 || image.height <= 0 || image.rgba.size() != std::size_t(image.width) * image.height * 4)
    throw std::invalid_argument("write_png: bad image");
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) throw std::runtime_error("cannot write " + path);
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (!png || !info) {
    png_destroy_write_struct(&png, &info);
    std::fclose(f);
    throw std::runtime_error("libpng: out of memory");
  }
  if (setjmp(png_jmpbuf(png))) {  // libpng's error path
    png_destroy_write_struct(&png, &info);
    std::fclose(f);
    throw std::runtime_error("libpng failed writing " + path);
  }
  png_init_io(png, f);
  png_set_IHDR(png, info, png_uint_32(image.width), png_uint_32(image.height), 8, PNG_COLOR_TYPE_RGBA,
               PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  for (int y = 0; y < image.height; ++y)
    png_write_row(png, const_cast<png_bytep>(&image.rgba[std::size_t(y) * image.width * 4]));
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  if (std::fclose(f) != 0) throw std::runtime_error("cannot write " + path);
}

void write_exr(const std::string& path, int width, int height,
               const std::vector<std::pair<std::string, std::vector<float>>>& channels) {
  try {
    Imf::Header header(width, height);
    Imf::FrameBuffer fb;
    for (const auto& [name, values] : channels) {
      if (values.size() != std::size_t(width) * std::size_t(height))
        throw std::invalid_argument("write_exr: channel " + name + " has the wrong size");
      header.channels().insert(name, Imf::Channel(Imf::FLOAT));
      fb.insert(name, Imf::Slice(Imf::FLOAT, (char*)values.data(), sizeof(float), sizeof(float) * std::size_t(width)));
    }
    Imf::OutputFile out(path.c_str(), header);
    out.setFrameBuffer(fb);
    out.writePixels(height);
  } catch (const std::invalid_argument&) {
    throw;
  } catch (const std::exception& e) {
    throw std::runtime_error("OpenEXR failed writing " + path + ": " + e.what());
  }
}

std::vector<float> read_exr_channel(const std::string& path, const std::string& channel, int& width, int& height) {
  try {
    Imf::InputFile in(path.c_str());
    const Imath::Box2i dw = in.header().dataWindow();
    width = dw.max.x - dw.min.x + 1;
    height = dw.max.y - dw.min.y + 1;
    if (!in.header().channels().findChannel(channel)) throw std::runtime_error("no channel " + channel);
    std::vector<float> v(std::size_t(width) * height);
    Imf::FrameBuffer fb;
    fb.insert(channel, Imf::Slice(Imf::FLOAT, (char*)(v.data() - dw.min.x - std::ptrdiff_t(dw.min.y) * width),
                                  sizeof(float), sizeof(float) * std::size_t(width)));
    in.setFrameBuffer(fb);
    in.readPixels(dw.min.y, dw.max.y);
    return v;
  } catch (const std::exception& e) {
    throw std::runtime_error("OpenEXR failed reading " + path + ": " + e.what());
  }
}

}  // namespace warpcheck::validation::report
