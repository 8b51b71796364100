// attribute_rd_bench (issue 18, point 5): for every model of
// ../shared/models, the rate-distortion curve of our stream's prefixes
// against an LOD chain, for the positions and for each attribute.
//
// Input as attribute_bench's (bench/peers/draco_attribute_mesh.h: Draco's
// reader, welded, the first normal, UV and colour set). Ours: the stream of
// the default options (positions 12 bits, normals 8, UV 12, colours 8; no
// texture records: the images are not part of these bytes on either side),
// fed record by record to one IncrementalDecoder, measured at about 10
// log-spaced record boundaries and at the largest boundary within each
// chain level's cumulative bytes.
//
// The chain: meshoptimizer's meshopt_simplify (Debian's 0.18 has no
// attribute-aware simplifier: meshopt_simplifyWithAttributes came in 0.20)
// on Draco's points, i.e. the glTF-style vertex buffer split at seams, to
// 1/64, 1/16, 1/4 of the triangles and the full mesh, with no error limit.
// Its vertex classification keeps attribute seams (a seam vertex only
// collapses along its seam), and every kept vertex keeps its own original
// attributes. Each level is Draco-coded at the same quantization, its bytes
// counted cumulatively (a client downloads the levels in turn), decoded by
// Draco and measured.
//
// Error measures (each against the original, unquantized mesh):
//   - positions: the symmetric RMS surface distance (common/metrics,
//     50 000 samples a side) over the original's bounding-box diagonal;
//   - attributes: N points spread by area on the original (systematic
//     sampling, sample_surface_area). At each, the original's value
//     interpolated linearly over its triangle (barycentric, per corner where
//     the attribute is per corner) against the shown mesh's value
//     interpolated the same way at the closest point of its surface (the
//     exact closest point, TriangleBvh); RMS over the samples of
//       normals: the angle between the two (degrees),
//       texture coordinates: the Euclidean distance in UV units (1e-3 is one
//         texel of a 1 000-texel texture),
//       colours: the Euclidean RGB distance in 8-bit steps (0..255 a channel).
//     Near a UV seam the closest point may land across it (another chart),
//     and on coincident or two-sided parts on the other side: both sides pay
//     that alike, and the full-rate rows (both exactly the quantized input)
//     show the measure's floor per model.
//
// The prefixes measured also include the first display (the end of record
// 1) and the end of the low-bits record (the base's values exact).
//
// Usage: attribute_rd_bench [MODELS_DIR] [--out FILE.md] [--report-dir DIR] [--samples N]
//                           [--base-color-bits B] [--only SUBSTRING]
#include <draco/io/mesh_io.h>
#include <draco/mesh/mesh_cleanup.h>
#include <meshoptimizer.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "bench/model_files.h"
#include "bench/peers/draco_attribute_mesh.h"
#include "common/codec/attribute_codec.h"
#include "common/codec/container.h"
#include "common/codec/decoder.h"
#include "common/codec/encoder.h"
#include "common/mesh/import.h"
#include "common/metrics/bvh.h"
#include "common/metrics/distance.h"
#include "common/metrics/surface_sampling.h"

namespace fs = std::filesystem;
using namespace meshstream;
using namespace meshstream::bench;

namespace {

// The attribute errors of one shown mesh (-1: the attribute is absent from
// the original).
struct AttributeErrors {
  double normal_degrees = -1, uv = -1, color = -1;
};

struct Point {
  uint64_t bytes = 0;
  uint32_t faces = 0;
  double rel_rms = 0;
  AttributeErrors att;
};

Vec3d to_d(const Vec3f& v) { return {v.x, v.y, v.z}; }

// Barycentric coordinates of p (on or near triangle abc) in it.
std::array<double, 3> barycentric(Vec3d p, Vec3d a, Vec3d b, Vec3d c) {
  const Vec3d v0 = b - a, v1 = c - a, v2 = p - a;
  const double d00 = dot(v0, v0), d01 = dot(v0, v1), d11 = dot(v1, v1);
  const double d20 = dot(v2, v0), d21 = dot(v2, v1);
  const double den = d00 * d11 - d01 * d01;
  if (!(std::abs(den) > 0)) return {1.0 / 3, 1.0 / 3, 1.0 / 3};
  const double v = (d11 * d20 - d01 * d21) / den, w = (d00 * d21 - d01 * d20) / den;
  return {1 - v - w, v, w};
}

// An attribute of `m` at corner k of face f, as doubles (n components), or
// false when the mesh does not have it.
template <class T>
bool value_at_corner(const std::vector<T>& per_vertex, const CornerAttribute<T>& per_corner,
                     const Mesh& m, uint32_t f, int k, T& out) {
  if (!per_corner.empty()) {
    out = per_corner.at_corner(3 * size_t(f) + k);
    return true;
  }
  if (per_vertex.size() == m.positions.size() && !per_vertex.empty()) {
    out = per_vertex[m.triangles[f][k]];
    return true;
  }
  return false;
}

// The attributes of `m` interpolated at point p of face f.
struct Sampled {
  bool has_n = false, has_uv = false, has_c = false;
  Vec3d n{};
  double uv[2] = {0, 0};
  double c[3] = {0, 0, 0};
};

Sampled sample_attributes(const Mesh& m, uint32_t f, Vec3d p) {
  const Triangle& t = m.triangles[f];
  const auto w =
      barycentric(p, to_d(m.positions[t[0]]), to_d(m.positions[t[1]]), to_d(m.positions[t[2]]));
  Sampled s;
  s.has_n = s.has_uv = s.has_c = true;
  for (int k = 0; k < 3; ++k) {
    Vec3f n;
    Vec2f uv;
    Vec4f c;
    if (s.has_n && value_at_corner(m.normals, m.corner_normals, m, f, k, n)) {
      const Vec3d nd = normalized(to_d(n));
      s.n = s.n + nd * w[k];
    } else {
      s.has_n = false;
    }
    if (s.has_uv && value_at_corner(m.texcoords, m.corner_texcoords, m, f, k, uv)) {
      s.uv[0] += w[k] * uv.x;
      s.uv[1] += w[k] * uv.y;
    } else {
      s.has_uv = false;
    }
    if (s.has_c && value_at_corner(m.colors, m.corner_colors, m, f, k, c)) {
      s.c[0] += w[k] * c.x;
      s.c[1] += w[k] * c.y;
      s.c[2] += w[k] * c.z;
    } else {
      s.has_c = false;
    }
  }
  return s;
}

// The original, prepared once: its attribute samples (point and value) and
// its surface for the position distance.
struct Reference {
  std::vector<Vec3d> points;
  std::vector<Sampled> values;
  std::optional<PreparedSurface> surface;
};

Reference prepare_reference(const Mesh& original, uint32_t samples) {
  Reference r;
  const SurfaceSamples s = sample_surface_area(original, samples, 7);
  const TriangleBvh bvh = TriangleBvh::build(original);
  uint32_t hint = TriangleBvh::kNoHint;
  for (uint32_t i = 0; i < s.area_count; ++i) {
    const ClosestHit hit = bvh.closest(s.points[i], hint);
    hint = hit.triangle;
    r.points.push_back(s.points[i]);
    r.values.push_back(sample_attributes(original, hit.triangle, s.points[i]));
  }
  DistanceOptions o;
  o.samples = 50000;
  auto prepared = PreparedSurface::prepare(original, o);
  if (prepared) r.surface = std::move(*prepared);
  return r;
}

AttributeErrors attribute_errors(const Reference& ref, const Mesh& shown) {
  AttributeErrors e;
  const TriangleBvh bvh = TriangleBvh::build(shown);
  if (bvh.empty()) return e;
  double sn = 0, suv = 0, sc = 0;
  size_t cn = 0, cuv = 0, cc = 0;
  bool shown_n = true, shown_uv = true, shown_c = true;
  uint32_t hint = TriangleBvh::kNoHint;
  for (size_t i = 0; i < ref.points.size(); ++i) {
    const Sampled& a = ref.values[i];
    const ClosestHit hit = bvh.closest(ref.points[i], hint);
    hint = hit.triangle;
    const Sampled b = sample_attributes(shown, hit.triangle, hit.point);
    if (a.has_n) {
      shown_n &= b.has_n;
      const double cosine =
          std::clamp(dot(normalized(a.n), normalized(b.has_n ? b.n : Vec3d{0, 0, 0})), -1.0, 1.0);
      const double deg = std::acos(cosine) * 180 / M_PI;
      sn += deg * deg;
      ++cn;
    }
    if (a.has_uv) {
      shown_uv &= b.has_uv;
      const double du = a.uv[0] - b.uv[0], dv = a.uv[1] - b.uv[1];
      suv += du * du + dv * dv;
      ++cuv;
    }
    if (a.has_c) {
      shown_c &= b.has_c;
      double d2 = 0;
      for (int k = 0; k < 3; ++k) d2 += (a.c[k] - b.c[k]) * (a.c[k] - b.c[k]) * 255 * 255;
      sc += d2;
      ++cc;
    }
  }
  // An attribute the shown mesh lacks is shown grey / unlit: its error is
  // the difference to nothing, marked by the caller as "none" instead.
  if (cn) e.normal_degrees = shown_n ? std::sqrt(sn / cn) : 1e9;
  if (cuv) e.uv = shown_uv ? std::sqrt(suv / cuv) : 1e9;
  if (cc) e.color = shown_c ? std::sqrt(sc / cc) : 1e9;
  return e;
}

Point measure(const Reference& ref, const Mesh& shown, uint64_t bytes) {
  Point p;
  p.bytes = bytes;
  p.faces = uint32_t(shown.triangles.size());
  if (auto prepared = PreparedSurface::prepare(shown, ref.surface->options()))
    p.rel_rms = surface_distance(*ref.surface, *prepared).relative_rms();
  p.att = attribute_errors(ref, shown);
  return p;
}

// A chain level: Draco's points simplified to `fraction` of the triangles
// (meshopt_simplify over the split vertex buffer), unused points removed.
std::unique_ptr<draco::Mesh> simplify_points(const draco::Mesh& dm, double fraction) {
  auto out = draco_only(dm, {});
  if (fraction >= 1) return out;
  const auto* pos = out->GetNamedAttribute(draco::GeometryAttribute::POSITION);
  std::vector<float> xyz(3 * size_t(out->num_points()));
  for (uint32_t p = 0; p < out->num_points(); ++p) {
    const auto v = value_at(pos, draco::PointIndex(p));
    for (int k = 0; k < 3; ++k) xyz[3 * p + k] = v[k];
  }
  std::vector<uint32_t> indices;
  for (uint32_t f = 0; f < out->num_faces(); ++f)
    for (int k = 0; k < 3; ++k) indices.push_back(out->face(draco::FaceIndex(f))[k].value());
  const size_t target = size_t(double(indices.size()) * fraction) / 3 * 3;
  std::vector<uint32_t> lod(indices.size());
  lod.resize(meshopt_simplify(lod.data(), indices.data(), indices.size(), xyz.data(),
                              out->num_points(), 3 * sizeof(float), target, 1.0f, 0, nullptr));
  out->SetNumFaces(lod.size() / 3);
  for (size_t f = 0; f < lod.size() / 3; ++f)
    out->SetFace(draco::FaceIndex(uint32_t(f)),
                 {draco::PointIndex(lod[3 * f]), draco::PointIndex(lod[3 * f + 1]),
                  draco::PointIndex(lod[3 * f + 2])});
  draco::MeshCleanupOptions o;
  o.remove_duplicate_faces = false;
  (void)draco::MeshCleanup::Cleanup(out.get(), o);
  return out;
}

std::string num(double v, const char* fmt) {
  if (v < 0) return "-";
  if (v >= 1e8) return "none";
  char b[32];
  std::snprintf(b, sizeof b, fmt, v);
  return b;
}

std::string cells(const Point& p) {
  return std::to_string(p.bytes) + " | " + std::to_string(p.faces) + " | " +
         num(p.rel_rms * 1e4, "%.2f") + " | " + num(p.att.normal_degrees, "%.2f") + " | " +
         num(p.att.uv < 0 ? -1 : p.att.uv * 1e3, "%.2f") + " | " + num(p.att.color, "%.2f");
}

}  // namespace

int main(int argc, char** argv) {
  // The models folder: the argument, else default_models_dir().
  std::string dir = meshstream::bench::default_models_dir(), out_path, report_dir;
  uint32_t samples = 20000;
  int base_color_bits = EncodeOptions{}.base_color_bits;
  std::string only;  // models whose path holds it; empty: all
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--base-color-bits" && i + 1 < argc)
      base_color_bits = std::atoi(argv[++i]);
    else if (a == "--only" && i + 1 < argc)
      only = argv[++i];
    else if (a == "--out" && i + 1 < argc)
      out_path = argv[++i];
    else if (a == "--report-dir" && i + 1 < argc)  // bench/run's convention
      report_dir = argv[++i];
    else if (a == "--samples" && i + 1 < argc)
      samples = uint32_t(std::stoul(argv[++i]));
    else
      dir = a;
  }
  if (out_path.empty() && !report_dir.empty()) out_path = report_dir + "/attributes_rd.md";
  const std::vector<fs::path> files = meshstream::bench::model_files(dir);
  const std::vector<std::pair<std::string, double>> levels = {
      {"1/64", 1.0 / 64}, {"1/16", 1.0 / 16}, {"1/4", 1.0 / 4}, {"full", 1.0}};
  const std::string header =
      "| model | chain level | chain bytes | faces | pos RMS (1e-4 diag) | normal RMS (deg) | uv "
      "RMS (1e-3) | colour RMS (8-bit) | ours bytes | faces | pos RMS (1e-4 diag) | normal RMS "
      "(deg) | uv RMS (1e-3) | colour RMS (8-bit) |\n"
      "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  std::string table = header, curves =
                                  "| model | bytes | faces | pos RMS (1e-4 diag) | normal "
                                  "RMS (deg) | uv RMS (1e-3) | colour RMS (8-bit) |\n"
                                  "|---|---|---|---|---|---|---|\n";
  for (const fs::path& file : files) {
    const std::string name = fs::relative(file, dir).string();
    if (!only.empty() && name.find(only) == std::string::npos) continue;
    auto read = draco::ReadMeshFromFile(file.string());
    if (!read.ok()) {
      std::printf("%s: Draco cannot read it: %s\n", name.c_str(), read.status().error_msg());
      continue;
    }
    const draco::Mesh& dm = *read.value();
    std::string kinds;
    Mesh mesh = to_mesh(dm, kinds);
    if (auto cleaned = clean_mesh(mesh); !cleaned) {
      std::printf("%s: clean failed: %s\n", name.c_str(), cleaned.error().message.c_str());
      continue;
    }
    const Reference ref = prepare_reference(mesh, samples);
    if (!ref.surface) continue;
    // The chain.
    std::vector<Point> chain;
    uint64_t cumulative = 0;
    for (const auto& [label, fraction] : levels) {
      auto lod = simplify_points(dm, fraction);
      std::vector<uint8_t> bytes;
      cumulative += draco_bytes(*lod, &bytes);
      draco::DecoderBuffer buffer;
      buffer.Init(reinterpret_cast<const char*>(bytes.data()), bytes.size());
      draco::Decoder decoder;
      auto decoded = decoder.DecodeMeshFromBuffer(&buffer);
      if (!decoded.ok()) {
        std::printf("%s: Draco cannot decode its LOD %s\n", name.c_str(), label.c_str());
        break;
      }
      std::string k;
      const Mesh shown = to_mesh(*decoded.value(), k);
      chain.push_back(measure(ref, shown, cumulative));
    }
    // Ours.
    EncodeOptions options;
    options.base_color_bits = base_color_bits;
    auto stream = encode_hcs(mesh, options);
    if (!stream) {
      std::printf("%s: encode failed: %s\n", name.c_str(), stream.error().message.c_str());
      continue;
    }
    auto index = read_stream_index(*stream);
    std::vector<uint64_t> ends;
    for (const RecordEntry& r : index->records) ends.push_back(r.offset + r.size);
    std::vector<uint64_t> prefixes;
    const double first = double(ends.front()), last = double(ends.back());
    for (int i = 0; i < 10; ++i) {
      const double target = first * std::pow(last / first, i / 9.0);
      auto it = std::upper_bound(ends.begin(), ends.end(), uint64_t(target + 0.5));
      prefixes.push_back(it == ends.begin() ? ends.front() : *(it - 1));
    }
    for (const Point& c : chain) {
      auto it = std::upper_bound(ends.begin(), ends.end(), c.bytes);
      prefixes.push_back(it == ends.begin() ? ends.front() : *(it - 1));
    }
    if (ends.size() > 1) prefixes.push_back(ends[1]);
    for (const RecordEntry& r : index->records) {
      const auto p = record_payload(r, std::span<const uint8_t>(*stream).subspan(r.offset, r.size));
      if (p.size() > 1 && p[0] == kRecordAttributes && p[1] == kAttributePartLowBits) {
        prefixes.push_back(r.offset + r.size);
        std::printf("%s: low-bits record ends at %llu bytes\n", name.c_str(),
                    (unsigned long long)(r.offset + r.size));
      }
    }
    std::sort(prefixes.begin(), prefixes.end());
    prefixes.erase(std::unique(prefixes.begin(), prefixes.end()), prefixes.end());
    std::vector<Point> ours;
    IncrementalDecoder decoder;
    uint64_t fed = 0;
    for (uint64_t prefix : prefixes) {
      auto applied = decoder.feed(std::span<const uint8_t>(*stream).subspan(fed, prefix - fed));
      if (!applied) {
        std::printf("%s: prefix %llu: %s\n", name.c_str(), (unsigned long long)prefix,
                    applied.error().message.c_str());
        break;
      }
      fed = prefix;
      ours.push_back(measure(ref, decoder.mesh(), prefix));
      curves += "| " + name + " | " + cells(ours.back()) + " |\n";
    }
    {
      // The client's decoder (every record applied to its mesh, previews
      // and their refreshes included), record by record: median of 3.
      std::vector<double> ms;
      for (int run = 0; run < 3; ++run) {
        const auto t0 = std::chrono::steady_clock::now();
        IncrementalDecoder d;
        for (const RecordEntry& r : index->records) {
          const uint64_t from = r.offset == index->payload_offset ? 0 : r.offset;
          (void)d.feed(std::span<const uint8_t>(*stream).subspan(from, r.offset + r.size - from));
        }
        ms.push_back(
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0)
                .count());
      }
      std::sort(ms.begin(), ms.end());
      std::printf("%s: record-by-record incremental decode %.1f ms (median of 3)\n", name.c_str(),
                  ms[1]);
    }
    for (size_t i = 0; i < chain.size(); ++i) {
      const Point* mine = nullptr;
      for (const Point& p : ours)
        if (p.bytes <= chain[i].bytes) mine = &p;
      const std::string row = "| " + name + " | " + levels[i].first + " | " + cells(chain[i]) +
                              " | " + (mine ? cells(*mine) : "over | | | | |") + " |\n";
      std::printf("%s", row.c_str());
      table += row;
    }
    std::fflush(stdout);
  }
  std::printf("\n%s\n%s", table.c_str(), curves.c_str());
  if (!out_path.empty())
    std::ofstream(out_path)
        << (report_dir.empty()
                ? ""
                : "## Attributes: rate-distortion against an LOD chain (attribute_rd_bench)\n\n")
        << table << "\n"
        << curves;
  return 0;
}
