// The codec benchmark's rate-distortion plot as a self-contained SVG (no
// plotting tool needed): one log-log panel per mesh, bytes received against
// relative RMS (solid) and Hausdorff (dashed) distance; our embedded stream,
// issue I's ordering and the meshoptimizer + Draco LOD chain.
#pragma once

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "bench/codec/measurements.h"

namespace meshstream::bench {

struct SvgSeries {
  std::string name, color;
  bool dashed = false;
  bool markers = false;
  std::vector<std::pair<double, double>> points;  // (bytes, relative distance), both > 0
};

inline void svg_panel(std::ostream& out, double x0, double y0, double w, double h,
                      const std::string& title, const std::vector<SvgSeries>& series) {
  double xmin = 1e300, xmax = 0, ymin = 1e300, ymax = 0;
  for (const SvgSeries& s : series) {
    for (auto [x, y] : s.points) {
      if (x <= 0 || y <= 0) continue;
      xmin = std::min(xmin, x), xmax = std::max(xmax, x), ymin = std::min(ymin, y),
      ymax = std::max(ymax, y);
    }
  }
  if (xmax <= 0) return;
  const double lx0 = std::floor(std::log10(xmin)), lx1 = std::ceil(std::log10(xmax));
  const double ly0 = std::floor(std::log10(ymin)), ly1 = std::ceil(std::log10(ymax));
  const double left = x0 + 58, right = x0 + w - 12, top = y0 + 26, bottom = y0 + h - 36;
  auto px = [&](double x) {
    return left + (std::log10(x) - lx0) / std::max(1.0, lx1 - lx0) * (right - left);
  };
  auto py = [&](double y) {
    return bottom - (std::log10(y) - ly0) / std::max(1.0, ly1 - ly0) * (bottom - top);
  };
  out << "<text x='" << (left + right) / 2 << "' y='" << y0 + 16
      << "' text-anchor='middle' font-size='13' font-weight='bold'>" << title << "</text>\n";
  out << "<rect x='" << left << "' y='" << top << "' width='" << right - left << "' height='"
      << bottom - top << "' fill='none' stroke='#444'/>\n";
  for (double e = lx0; e <= lx1; ++e) {
    const double x = left + (e - lx0) / std::max(1.0, lx1 - lx0) * (right - left);
    out << "<line x1='" << x << "' y1='" << top << "' x2='" << x << "' y2='" << bottom
        << "' stroke='#ddd'/><text x='" << x << "' y='" << bottom + 14
        << "' text-anchor='middle' font-size='10'>1e" << int(e) << "</text>\n";
  }
  for (double e = ly0; e <= ly1; ++e) {
    const double y = bottom - (e - ly0) / std::max(1.0, ly1 - ly0) * (bottom - top);
    out << "<line x1='" << left << "' y1='" << y << "' x2='" << right << "' y2='" << y
        << "' stroke='#ddd'/><text x='" << left - 4 << "' y='" << y + 3
        << "' text-anchor='end' font-size='10'>1e" << int(e) << "</text>\n";
  }
  out << "<text x='" << (left + right) / 2 << "' y='" << bottom + 28
      << "' text-anchor='middle' font-size='10'>bytes received</text>\n";
  out << "<text x='" << x0 + 12 << "' y='" << (top + bottom) / 2
      << "' font-size='10' transform='rotate(-90 " << x0 + 12 << ' ' << (top + bottom) / 2
      << ")' text-anchor='middle'>distance / bbox diagonal</text>\n";
  for (const SvgSeries& s : series) {
    std::ostringstream path;
    bool first = true;
    for (auto [x, y] : s.points) {
      if (x <= 0 || y <= 0) continue;
      path << (first ? "M" : " L") << px(x) << ',' << py(y);
      first = false;
    }
    if (first) continue;
    out << "<path d='" << path.str() << "' fill='none' stroke='" << s.color << "' stroke-width='"
        << (s.dashed ? 1.2 : 2) << "'" << (s.dashed ? " stroke-dasharray='5,3'" : "") << "/>\n";
    if (s.markers) {
      for (auto [x, y] : s.points)
        if (x > 0 && y > 0)
          out << "<circle cx='" << px(x) << "' cy='" << py(y) << "' r='3' fill='" << s.color
              << "'/>\n";
    }
  }
}

// Writes `path`; returns false when no mesh has a curve.
inline bool write_svg_plot(const std::filesystem::path& path,
                           const std::vector<MeshMeasurements>& all) {
  std::vector<const MeshMeasurements*> meshes;
  for (const auto& m : all)
    if (!m.chain_curve.empty() || !m.ours_curve.empty()) meshes.push_back(&m);
  if (meshes.empty()) return false;
  const int cols = meshes.size() < 3 ? int(meshes.size()) : 3;
  const int rows = int((meshes.size() + cols - 1) / cols);
  const double w = 420, h = 320, legend = 40;
  std::ofstream out(path);
  out << "<svg xmlns='http://www.w3.org/2000/svg' width='" << cols * w << "' height='"
      << rows * h + legend
      << "' font-family='sans-serif'>\n<rect width='100%' height='100%' fill='white'/>\n";
  struct Key {
    const char* name;
    const char* color;
    bool dashed;
  };
  const Key keys[] = {
      {"ours RMS", "#1f77b4", false},          {"ours Hausdorff", "#1f77b4", true},
      {"issue I order RMS", "#2ca02c", false}, {"issue I order Hausdorff", "#2ca02c", true},
      {"LOD chain RMS", "#d62728", false},     {"LOD chain Hausdorff", "#d62728", true}};
  double kx = 10;
  for (const Key& k : keys) {
    out << "<line x1='" << kx << "' y1='20' x2='" << kx + 26 << "' y2='20' stroke='" << k.color
        << "' stroke-width='2'" << (k.dashed ? " stroke-dasharray='5,3'" : "") << "/><text x='"
        << kx + 30 << "' y='24' font-size='12'>" << k.name << "</text>\n";
    kx += 40 + 7.5 * std::string(k.name).size();
  }
  for (size_t i = 0; i < meshes.size(); ++i) {
    const MeshMeasurements& m = *meshes[i];
    auto curve = [](const std::vector<RdPoint>& c, bool hausdorff) {
      std::vector<std::pair<double, double>> p;
      for (const RdPoint& q : c)
        p.push_back({double(q.bytes), hausdorff ? q.rel_hausdorff : q.rel_rms});
      return p;
    };
    std::vector<SvgSeries> series = {
        {"", "#d62728", false, true, curve(m.chain_curve, false)},
        {"", "#d62728", true, true, curve(m.chain_curve, true)},
        {"", "#2ca02c", false, false, curve(m.plain_curve, false)},
        {"", "#2ca02c", true, false, curve(m.plain_curve, true)},
        {"", "#1f77b4", false, false, curve(m.ours_curve, false)},
        {"", "#1f77b4", true, false, curve(m.ours_curve, true)},
    };
    svg_panel(out, (i % cols) * w, legend + (i / cols) * h, w, h, m.name, series);
  }
  out << "</svg>\n";
  return bool(out);
}

}  // namespace meshstream::bench
