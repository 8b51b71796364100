#include "common/codec/asa_guidance.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>

#include "common/asa/settings_check.h"
#include "common/base/parallel_blocks.h"
#include "common/codec/byte_io.h"
#include "common/codec/crc32.h"
#include "common/codec/decoder.h"
#include "common/metrics/surface_quadrature.h"
#include "common/metrics/surface_sampling.h"

namespace meshstream {
namespace {

constexpr float kFlatness[4] = {0.85f, 0.90f, 0.95f, 0.75f};
constexpr float kCrease[5] = {0, 40, 45, 60, 75};
// The refinement format's own header bytes come first (extra[0], extra[1]).
constexpr size_t kExtensionsAt = 2;

Error corrupt(const std::string& what) {
  return Error{ErrorCode::kCorrupt, ".hcs ASA guidance: " + what};
}

uint8_t make_choice(int levels, int flatness_index, int crease_index, bool projection) {
  return static_cast<uint8_t>(levels | flatness_index << 2 | crease_index << 4 |
                              (projection ? 0x80 : 0));
}

// Where the guidance block sits in `extra`: [begin, end) of the whole
// block (tag, length, payload) and the payload; nullopt when absent.
struct BlockSpan {
  size_t begin = 0, payload = 0, end = 0;
};
Result<std::optional<BlockSpan>> find_block(const std::vector<uint8_t>& extra) {
  size_t pos = kExtensionsAt;
  while (pos < extra.size()) {
    BlockSpan span;
    span.begin = pos;
    const uint8_t tag = extra[pos++];
    uint32_t length = 0;
    if (!get_varint(extra, pos, length) || length > extra.size() - pos)
      return tl::unexpected(
          corrupt("header extension block " + std::to_string(tag) + " runs past the header"));
    span.payload = pos;
    span.end = pos + length;
    if (tag == kAsaGuidanceTag) return std::optional<BlockSpan>(span);
    pos = span.end;  // a block this build does not know
  }
  return std::optional<BlockSpan>();
}

}  // namespace

std::vector<uint8_t> AsaGuidanceOptions::default_candidates() {
  // L1 t0.85 (the old fixed default), with creases at 60 degrees, and t0.95
  // with creases at 45. Two levels (t0.85, crease 45) and L1 t0.85 crease 45
  // were tried too and never chosen on the 12 real meshes (bench/REPORT.md,
  // fidelity): each candidate costs a measurement per group.
  return {make_choice(1, 0, 0, false), make_choice(1, 0, 3, false), make_choice(1, 2, 2, false)};
}

bool asa_choice_approximates(uint8_t choice) {
  return (choice & 3) == 0 && (choice & 0x80) && asa_choice_options(choice).has_value();
}

std::optional<uint8_t> approximating_choice(uint8_t choice) {
  if ((choice & 3) != 1 || (choice & 0x80)) return std::nullopt;
  const uint8_t a = static_cast<uint8_t>((choice & 0x7c) | 0x80);
  if (!asa_choice_options(a)) return std::nullopt;
  return a;
}

RelaxOptions asa_choice_relax(const AsaOptions& asa_step) {
  RelaxOptions r;
  if (asa_step.crease_degrees > 0) r.sharp_degrees = asa_step.crease_degrees;
  return r;
}

Result<Mesh> apply_asa_choice(const Mesh& prefix, uint8_t choice,
                              std::vector<uint32_t>* source_face) {
  auto o = asa_choice_options(choice);
  if (!o) return tl::unexpected(o.error());
  if (!*o) {
    if (source_face) {
      source_face->resize(prefix.face_count());
      for (uint32_t f = 0; f < prefix.face_count(); ++f) (*source_face)[f] = f;
    }
    return prefix;
  }
  AsaOptions options = **o;
  options.track_source_faces = source_face != nullptr;
  Mesh relaxed;
  if (asa_choice_approximates(choice)) {
    relaxed = prefix;
    if (auto s = relax_toward_smooth(relaxed, asa_choice_relax(options)); !s)
      return tl::unexpected(s.error());
  }
  auto r = subdivide(asa_choice_approximates(choice) ? relaxed : prefix, options);
  if (!r) return tl::unexpected(r.error());
  if (source_face) *source_face = std::move(r->source_face);
  return std::move(r->mesh);
}

Result<std::optional<AsaOptions>> asa_choice_options(uint8_t choice) {
  if (choice == kAsaChoiceOff) return std::optional<AsaOptions>();
  char hex[8];
  std::snprintf(hex, sizeof hex, "0x%02x", choice);
  if ((choice & 3) == 0 && (choice & 0x80)) {
    // Approximating: one Zorin level with these flatness and crease bits.
    auto step = asa_choice_options(static_cast<uint8_t>((choice & 0x7c) | 1));
    if (!step)
      return tl::unexpected(corrupt(std::string("approximating choice ") + hex +
                                    " has no such crease angle, or one below acos(t)"));
    return step;
  }
  const int levels = choice & 3;
  const int flatness = (choice >> 2) & 3;
  const int crease = (choice >> 4) & 7;
  if (levels == 0) return tl::unexpected(corrupt(std::string("choice ") + hex + " has no levels"));
  if (crease >= int(std::size(kCrease)))
    return tl::unexpected(corrupt(std::string("choice ") + hex + " has no such crease angle"));
  AsaOptions o;
  o.levels = levels;
  o.flatness = kFlatness[flatness];
  o.crease_degrees = kCrease[crease];
  o.rule = (choice & 0x80) ? ButterflyRule::kProjection : ButterflyRule::kZorin;
  if (!asa_settings_problem(o, "crease", "flatness").empty())
    return tl::unexpected(
        corrupt(std::string("choice ") + hex + " has a crease angle below acos(t)"));
  return std::optional<AsaOptions>(o);
}

std::optional<uint8_t> asa_choice_of(const AsaOptions& o) {
  if (o.levels < 1 || o.levels > 3 || o.uniform || o.tension != 0 || o.view.enabled)
    return std::nullopt;
  const auto f = std::find(std::begin(kFlatness), std::end(kFlatness), o.flatness);
  const auto c = std::find(std::begin(kCrease), std::end(kCrease), o.crease_degrees);
  if (f == std::end(kFlatness) || c == std::end(kCrease)) return std::nullopt;
  const uint8_t choice =
      make_choice(o.levels, int(f - std::begin(kFlatness)), int(c - std::begin(kCrease)),
                  o.rule == ButterflyRule::kProjection);
  if (!asa_choice_options(choice)) return std::nullopt;
  return choice;
}

std::string asa_choice_label(uint8_t choice) {
  auto o = asa_choice_options(choice);
  if (!o) return "invalid";
  if (!*o) return "off";
  char text[80];
  std::snprintf(text, sizeof text, "L%d t%.2f", (*o)->levels, double((*o)->flatness));
  std::string label = text;
  if ((*o)->crease_degrees > 0) label += " crease" + std::to_string(int((*o)->crease_degrees));
  if (asa_choice_approximates(choice))
    label += " approximate";
  else if ((*o)->rule == ButterflyRule::kProjection)
    label += " projection";
  return label;
}

uint8_t AsaGuidance::choice_for(uint32_t records_decoded) const {
  const uint32_t last = records_decoded > 0 ? records_decoded - 1 : 0;
  uint8_t choice = groups.front().choice;
  for (const AsaGuidanceGroup& g : groups) {
    if (g.first_record > last) break;
    choice = g.choice;
  }
  return choice;
}

void append_asa_guidance(std::vector<uint8_t>& extra, const AsaGuidance& guidance) {
  std::vector<uint8_t> payload;
  put_varint(payload, static_cast<uint32_t>(guidance.groups.size()));
  uint32_t previous = 0;
  for (const AsaGuidanceGroup& g : guidance.groups) {
    put_varint(payload, g.first_record - previous);
    payload.push_back(g.choice);
    previous = g.first_record;
  }
  extra.push_back(kAsaGuidanceTag);
  put_varint(extra, static_cast<uint32_t>(payload.size()));
  extra.insert(extra.end(), payload.begin(), payload.end());
}

Result<std::optional<AsaGuidance>> read_asa_guidance(const StreamHeader& header,
                                                     uint32_t record_count) {
  auto span = find_block(header.extra);
  if (!span) return tl::unexpected(span.error());
  if (!*span) return std::optional<AsaGuidance>();
  const std::span<const uint8_t> payload(header.extra.data() + (*span)->payload,
                                         (*span)->end - (*span)->payload);
  size_t pos = 0;
  uint32_t n = 0;
  if (!get_varint(payload, pos, n) || n == 0 || n > record_count)
    return tl::unexpected(corrupt("implausible group count"));
  AsaGuidance g;
  uint32_t record = 0;
  for (uint32_t i = 0; i < n; ++i) {
    uint32_t delta = 0;
    if (!get_varint(payload, pos, delta) || pos >= payload.size())
      return tl::unexpected(corrupt("group " + std::to_string(i) + " is cut short"));
    if (i == 0 ? delta != 0 : delta == 0)
      return tl::unexpected(
          corrupt(i == 0 ? "the first group does not start at record 0"
                         : "group " + std::to_string(i) + " does not start after the one before"));
    if (delta >= record_count - record)
      return tl::unexpected(corrupt("group " + std::to_string(i) + " starts past the last record"));
    record += delta;
    const uint8_t choice = payload[pos++];
    if (auto o = asa_choice_options(choice); !o) return tl::unexpected(o.error());
    g.groups.push_back({record, choice});
  }
  if (pos != payload.size()) return tl::unexpected(corrupt("bytes after the last group"));
  return std::optional<AsaGuidance>(std::move(g));
}

namespace {

constexpr size_t kBlock = 4096;

// A well-spread subset of a prefix's faces, about one in `stride`: a
// multiplicative hash of the face index, so the subset follows no pattern
// of the decoder's face order.
bool is_probe(uint32_t face, uint32_t stride) {
  return stride <= 1 || (face * 2654435761u) % stride == 0;
}

// The normals a picture is shaded with, as the client's renderer makes
// them (client/viewer/crease_normals.h, its default 60-degree angle): per
// corner, the area-weighted normal of the vertex's faces whose normals are
// within the angle of the corner's own face (the renderer groups faces by
// edge-connected runs; for the few vertices where that differs, this is a
// close stand-in). Face normals alone judge a subdivided mesh by facets the
// picture never shows (issue 20: casting at ratio 10 lost 0.40 dB with
// 0.92x the RMS of the plain prefix). O(sum of squared valences).
constexpr float kShadingCreaseCos = 0.5f;  // cos(60 degrees)

std::vector<Vec3f> shading_corner_normals(const Mesh& mesh) {
  const uint32_t faces = mesh.face_count();
  std::vector<Vec3f> area_normal(faces), unit(faces);
  std::vector<uint32_t> start(mesh.vertex_count() + 1, 0);
  for (uint32_t f = 0; f < faces; ++f) {
    const Triangle& t = mesh.triangles[f];
    area_normal[f] = cross(mesh.positions[t[1]] - mesh.positions[t[0]],
                           mesh.positions[t[2]] - mesh.positions[t[0]]);
    unit[f] = normalized(area_normal[f]);
    for (uint32_t v : t) ++start[v + 1];
  }
  for (size_t v = 1; v < start.size(); ++v) start[v] += start[v - 1];
  std::vector<uint32_t> fill(start.begin(), start.end() - 1), around(start.back());
  for (uint32_t f = 0; f < faces; ++f)
    for (uint32_t v : mesh.triangles[f]) around[fill[v]++] = f;
  std::vector<Vec3f> corner(3 * size_t(faces));
  for (uint32_t f = 0; f < faces; ++f) {
    for (int k = 0; k < 3; ++k) {
      const uint32_t v = mesh.triangles[f][k];
      Vec3f sum{};
      for (uint32_t i = start[v]; i < start[v + 1]; ++i)
        if (dot(unit[around[i]], unit[f]) >= kShadingCreaseCos) sum = sum + area_normal[around[i]];
      corner[3 * size_t(f) + k] = normalized(sum);
    }
  }
  return corner;
}

// The shading normal at `point` on face f: its corners' normals blended by
// the point's barycentric coordinates (the renderer's interpolation).
Vec3d shading_normal_at(const Mesh& mesh, const std::vector<Vec3f>& corner, uint32_t f,
                        const Vec3d& point) {
  const Triangle& t = mesh.triangles[f];
  auto at = [&](int k) {
    const Vec3f& p = mesh.positions[t[k]];
    return Vec3d{p.x, p.y, p.z};
  };
  const Vec3d a = at(0), e1 = at(1) - a, e2 = at(2) - a, q = point - a;
  const double d11 = dot(e1, e1), d12 = dot(e1, e2), d22 = dot(e2, e2);
  const double q1 = dot(q, e1), q2 = dot(q, e2), det = d11 * d22 - d12 * d12;
  double u = 1.0 / 3, w = 1.0 / 3;  // a degenerate face: its corners' mean
  if (det > 1e-30 * (d11 * d22 + 1e-300)) {
    u = std::clamp((d22 * q1 - d12 * q2) / det, 0.0, 1.0);
    w = std::clamp((d11 * q2 - d12 * q1) / det, 0.0, 1.0 - u);
  }
  auto n = [&](int k) {
    const Vec3f& c = corner[3 * size_t(f) + k];
    return Vec3d{c.x, c.y, c.z};
  };
  return normalized(n(0) * (1 - u - w) + n(1) * u + n(2) * w);
}

// The distances the guidance judges a shown mesh by, against the original.
struct Distances {
  double rms = 0;     // symmetric RMS surface distance over the diagonal
  double normal = 0;  // mean 1 - cos of the angle between the original's
                      // and the shown surface's shading normals at the
                      // original's samples (what shading shows and
                      // distance does not)
};

// Where one prefix and its candidates are measured: a fixed, well-spread
// subset of the prefix's faces (the probes), their neighbours (faces
// sharing a vertex: where a probe's nearby surface may move to), and the
// original's samples whose closest point on the plain prefix's probe region
// lies on a probe. The same for every candidate of the prefix, so a
// triangle a candidate leaves alone weighs the same in the plain and the
// candidate's measurement, and the cost is bounded by the probes, not the
// mesh (a large prefix's subdivision is never measured, nor held in a
// hierarchy, whole).
struct Probes {
  enum : uint8_t { kOutside = 0, kNeighbour = 1, kProbe = 2 };
  std::vector<uint8_t> kind;   // per prefix face
  std::vector<uint32_t> kept;  // indices of the original's samples measured
  bool whole = true;           // every face a probe (a small prefix)
};

// The original, prepared once for every prefix and candidate: area samples
// with their face normals, a hierarchy, and the sampling density.
class GuidanceMeasure {
 public:
  GuidanceMeasure(const Mesh& original, uint32_t samples, uint32_t probe_faces, unsigned threads,
                  const TriangleBvh* hierarchy)
      : threads_(threads), probe_faces_(std::max<uint32_t>(probe_faces, 1)) {
    samples = std::max<uint32_t>(samples, 1);
    const SurfaceSamples area = sample_surface_area(original, samples, 1);
    cell_area_ = area.area / samples;
    points_.assign(area.points.begin(), area.points.begin() + area.area_count);
    if (hierarchy && !hierarchy->empty()) {
      bvh_ = hierarchy;
    } else {
      own_bvh_ = TriangleBvh::build(original, threads_);
      bvh_ = &own_bvh_;
    }
    diagonal_ = bounding_box(original).diagonal();
    normals_.resize(points_.size());
    const std::vector<Vec3f> corner = shading_corner_normals(original);
    for_each_block((points_.size() + kBlock - 1) / kBlock, threads_, [&](size_t b) {
      for (size_t i = b * kBlock; i < std::min(points_.size(), (b + 1) * kBlock); ++i) {
        const ClosestHit hit = bvh_->closest(points_[i]);
        normals_[i] = shading_normal_at(original, corner, hit.triangle, hit.point);
      }
    });
  }

  Probes probes(const Mesh& prefix) const {
    Probes p;
    const uint32_t faces = prefix.face_count();
    const uint32_t stride = faces / probe_faces_;
    p.whole = stride <= 1;
    p.kind.assign(faces, Probes::kProbe);
    if (p.whole) {
      p.kept.resize(points_.size());
      for (uint32_t i = 0; i < p.kept.size(); ++i) p.kept[i] = i;
      return p;
    }
    std::vector<uint8_t> near(prefix.vertex_count(), 0);
    for (uint32_t f = 0; f < faces; ++f) {
      p.kind[f] = is_probe(f, stride) ? Probes::kProbe : Probes::kOutside;
      if (p.kind[f] == Probes::kProbe)
        for (uint32_t v : prefix.triangles[f]) near[v] = 1;
    }
    for (uint32_t f = 0; f < faces; ++f) {
      const Triangle& t = prefix.triangles[f];
      if (p.kind[f] == Probes::kOutside && (near[t[0]] || near[t[1]] || near[t[2]]))
        p.kind[f] = Probes::kNeighbour;
    }
    const Mesh region = region_of(prefix, p, nullptr);
    const TriangleBvh bvh = TriangleBvh::build(region, threads_);
    std::vector<uint8_t> on_probe(points_.size(), 0);
    for_each_block((points_.size() + kBlock - 1) / kBlock, threads_, [&](size_t b) {
      uint32_t hint = TriangleBvh::kNoHint;
      for (size_t i = b * kBlock; i < std::min(points_.size(), (b + 1) * kBlock); ++i) {
        const ClosestHit hit = bvh.closest(points_[i], hint);
        hint = hit.triangle;
        on_probe[i] = region_kind_[hit.triangle] == Probes::kProbe;
      }
    });
    for (uint32_t i = 0; i < on_probe.size(); ++i)
      if (on_probe[i]) p.kept.push_back(i);
    return p;
  }

  // The distances of `shown` (the prefix, or a candidate's subdivision of
  // it with its source faces) to the original, at `probes` of the prefix.
  // When the shown-to-original direction alone already reaches
  // `give_up_at` (relative), the candidate cannot win: the other direction
  // is not measured and rms is that lower bound (normal is then 0).
  Distances measure(const Mesh& shown, const Probes& probes,
                    const std::vector<uint32_t>* source_face,
                    double give_up_at = std::numeric_limits<double>::infinity()) const {
    auto kind_of = [&](uint32_t f) { return probes.kind[source_face ? (*source_face)[f] : f]; };
    std::vector<uint32_t> probed;
    for (uint32_t f = 0; f < shown.triangles.size(); ++f)
      if (kind_of(f) == Probes::kProbe) probed.push_back(f);
    const WeightedSamples from_shown = quadrature_samples(shown, cell_area_, probed);
    std::vector<uint32_t>().swap(probed);  // freed (`= {}` would keep the capacity)
    const double to_original = weighted_rms_distance(from_shown, *bvh_, threads_);
    if (diagonal_ > 0 && to_original / diagonal_ >= give_up_at) return {to_original / diagonal_, 0};

    const Mesh region = probes.whole ? Mesh{} : region_of(shown, probes, source_face);
    const Mesh& target = probes.whole ? shown : region;
    const TriangleBvh shown_bvh = TriangleBvh::build(target, threads_);
    const std::vector<Vec3f> corner = shading_corner_normals(target);
    const std::vector<uint32_t>& kept = probes.kept;
    const size_t blocks = (kept.size() + kBlock - 1) / kBlock;
    std::vector<double> squared(blocks, 0.0), normal(blocks, 0.0);
    for_each_block(blocks, threads_, [&](size_t b) {
      uint32_t hint = TriangleBvh::kNoHint;
      for (size_t j = b * kBlock; j < std::min(kept.size(), (b + 1) * kBlock); ++j) {
        const uint32_t i = kept[j];
        const ClosestHit hit = shown_bvh.closest(points_[i], hint);
        hint = hit.triangle;
        squared[b] += hit.squared_distance;
        const Vec3d n = shading_normal_at(target, corner, hit.triangle, hit.point);
        const Vec3d& o = normals_[i];
        normal[b] +=
            1.0 - std::clamp(double(n.x) * o.x + double(n.y) * o.y + double(n.z) * o.z, -1.0, 1.0);
      }
    });
    double sum_squared = 0, sum_normal = 0;
    for (size_t b = 0; b < blocks; ++b) {
      sum_squared += squared[b];
      sum_normal += normal[b];
    }
    const double count = double(std::max<size_t>(kept.size(), 1));
    const double to_shown = std::sqrt(sum_squared / count);
    Distances d;
    d.rms = diagonal_ > 0 ? std::max(to_shown, to_original) / diagonal_ : 0;
    d.normal = sum_normal / count;
    return d;
  }

 private:
  // The faces of `shown` in the probe region (probes and neighbours), with
  // their kinds in region_kind_ (for probes(): the plain prefix).
  Mesh region_of(const Mesh& shown, const Probes& probes,
                 const std::vector<uint32_t>* source_face) const {
    Mesh region;
    region.positions = shown.positions;
    region_kind_.clear();
    for (uint32_t f = 0; f < shown.triangles.size(); ++f) {
      const uint8_t k = probes.kind[source_face ? (*source_face)[f] : f];
      if (k == Probes::kOutside) continue;
      region.triangles.push_back(shown.triangles[f]);
      region_kind_.push_back(k);
    }
    return region;
  }

  unsigned threads_ = 1;
  uint32_t probe_faces_ = 1;
  double cell_area_ = 0, diagonal_ = 0;
  std::vector<Vec3d> points_;
  std::vector<Vec3d> normals_;        // shading normals of the original at points_
  const TriangleBvh* bvh_ = nullptr;  // own_bvh_ or the caller's
  TriangleBvh own_bvh_;
  mutable std::vector<uint8_t> region_kind_;
};

// The decision rule (issue 20, "never worse"): a candidate qualifies when
// it is closer than the plain prefix by the margin in RMS distance and, but
// for a negative shading_margin, in shading deviation too; among the
// qualifying ones the lowest RMS wins. Both margins cover the measurement's
// sampling noise (16 000 samples: well under 1 %).
bool qualifies(const Distances& plain, const Distances& d, const AsaGuidanceOptions& o) {
  if (!(d.rms < (1 - o.margin) * plain.rms)) return false;
  if (o.shading_margin < 0) return true;
  return d.normal < (1 - o.shading_margin) * plain.normal;
}

// Runs `choice` (not off) on `prefix` into `out`, source faces tracked; an
// approximating choice relaxes a copy of the prefix first (same faces, so
// the prefix's probes and source faces still hold).
Status subdivide_choice_into(const Mesh& prefix, uint8_t choice, AsaWorkspace& workspace,
                             AsaResult& out) {
  AsaOptions step = **asa_choice_options(choice);
  step.track_source_faces = true;
  if (!asa_choice_approximates(choice)) return subdivide_into(prefix, step, workspace, out);
  Mesh relaxed = prefix;
  if (auto s = relax_toward_smooth(relaxed, asa_choice_relax(step)); !s) return s;
  return subdivide_into(relaxed, step, workspace, out);
}

}  // namespace

Result<AsaGuidance> measure_asa_guidance(const Mesh& original, std::span<const uint8_t> stream,
                                         const AsaGuidanceOptions& options,
                                         AsaGuidanceReport* report) {
  const auto start = std::chrono::steady_clock::now();
  auto index = read_stream_index(stream);
  if (!index) return tl::unexpected(index.error());
  const std::vector<RecordEntry>& records = index->records;
  const uint32_t n = static_cast<uint32_t>(records.size());
  if (n == 0) return make_error(ErrorCode::kInvalidArgument, "ASA guidance: stream has no records");
  if (original.triangles.empty())
    return make_error(ErrorCode::kInvalidArgument, "ASA guidance: the original has no triangles");
  const double total = double(index->total_bytes());
  const int per_octave = std::max(1, options.groups_per_octave);
  const int coarsest = int(std::floor(std::log2(std::max(options.max_ratio, 1.0)) * per_octave));
  auto bin_of = [&](uint32_t i) {
    const double ratio = total / double(records[i].offset + records[i].size);
    return std::clamp(int(std::floor(std::log2(ratio) * per_octave)), 0, coarsest);
  };
  auto ratio_of = [&](uint32_t i) { return total / double(records[i].offset + records[i].size); };

  // Groups: runs of records in one bin, the complete stream on its own.
  struct Planned {
    uint32_t first, measured, last;
  };
  std::vector<Planned> planned;
  for (uint32_t i = 0; i + 1 < n;) {
    const int bin = bin_of(i);
    const double middle = std::pow(2.0, (bin + 0.5) / per_octave);
    uint32_t j = i, best = i;
    for (; j + 1 < n && bin_of(j) == bin; ++j) {
      if (std::abs(std::log(ratio_of(j) / middle)) < std::abs(std::log(ratio_of(best) / middle)))
        best = j;
    }
    planned.push_back({i, best, j - 1});
    i = j;
  }

  std::vector<AsaOptions> candidate_options;
  for (uint8_t c : options.candidates) {
    auto o = asa_choice_options(c);
    if (!o || !*o)
      return make_error(
          ErrorCode::kInvalidArgument,
          "ASA guidance: candidate " + asa_choice_label(c) + " is not an ASA setting");
    candidate_options.push_back(**o);
    candidate_options.back().track_source_faces = true;
  }
  const GuidanceMeasure measure(original, options.samples, options.probe_faces, options.threads,
                                options.original_hierarchy);
  // Progress by the bytes decoded and the measured prefixes' sizes (the
  // finer a prefix, the more its measurement costs).
  double planned_work = 0, work_done = 0;
  for (const Planned& p : planned)
    planned_work += double(records[p.measured].offset + records[p.measured].size);

  AsaGuidance guidance;
  IncrementalDecoder decoder;
  AsaWorkspace workspace;
  AsaResult out;
  uint64_t fed = 0;
  double report_last_ratio = 0;  // of the last group measured
  for (const Planned& p : planned) {
    // ASA's gain shrinks as the prefix fills in: once a group as fine as
    // stop_below_ratio chose none, the finer ones are not measured (none
    // of the bench's meshes chose ASA finer than such a group, and the
    // finest groups cost the most).
    if (!guidance.groups.empty() && guidance.groups.back().choice == kAsaChoiceOff &&
        report_last_ratio > 0 && report_last_ratio < options.stop_below_ratio)
      break;
    const auto group_start = std::chrono::steady_clock::now();
    const uint64_t end = records[p.measured].offset + records[p.measured].size;
    // Reserved for this prefix, not the stream: the finer ones may go unmeasured.
    decoder.expect_prefix(end);
    auto applied = decoder.feed(stream.subspan(fed, end - fed));
    if (!applied) return tl::unexpected(applied.error());
    fed = end;
    const Mesh& prefix = decoder.mesh();
    if (prefix.triangles.empty())
      return make_error(ErrorCode::kInvalidMesh, "ASA guidance: a decoded prefix has no triangles");
    const uint32_t prefix_faces = prefix.face_count();
    AsaGuidanceReport::Group row;
    row.first_record = p.first;
    row.measured_record = p.measured;
    row.ratio = ratio_of(p.measured);
    const Probes probes = measure.probes(prefix);
    const Distances plain = measure.measure(prefix, probes, nullptr);
    row.rms.push_back(plain.rms);
    row.normal.push_back(plain.normal);
    double best_rms = (1 - options.margin) * plain.rms;  // to beat
    uint8_t choice = kAsaChoiceOff;
    for (size_t k = 0; k < candidate_options.size(); ++k) {
      if (auto s = subdivide_into(prefix, candidate_options[k], workspace, out); !s)
        return tl::unexpected(s.error());
      // A candidate whose RMS reaches the best qualifying one's cannot be
      // chosen: measure it only that far.
      const Distances d = out.mesh.face_count() == prefix_faces
                              ? plain
                              : measure.measure(out.mesh, probes, &out.source_face, best_rms);
      row.rms.push_back(d.rms);
      row.normal.push_back(d.normal);
      if (d.rms < best_rms && qualifies(plain, d, options)) {
        best_rms = d.rms;
        choice = options.candidates[k];
      }
    }
    // The approximating step refines the winning interpolating setting:
    // measured only where one won (its cost stays off the groups that
    // choose none, the finest and dearest ones).
    // It must beat that setting by the margin too: it is the less proven
    // step, and a smaller difference is within the measurement's noise.
    const bool coarse = row.ratio >= options.approximate_above_ratio;
    if (auto a = options.approximate && coarse ? approximating_choice(choice) : std::nullopt) {
      if (auto s = subdivide_choice_into(prefix, *a, workspace, out); !s)
        return tl::unexpected(s.error());
      const double to_beat = (1 - options.margin) * best_rms;
      const Distances d = measure.measure(out.mesh, probes, &out.source_face, to_beat);
      row.approximate_rms = d.rms;
      row.approximate_normal = d.normal;
      if (d.rms < to_beat && qualifies(plain, d, options)) choice = *a;
    }
    if (choice != kAsaChoiceOff && options.check_finest_end && p.last > p.measured) {
      const uint64_t last_end = records[p.last].offset + records[p.last].size;
      auto more = decoder.feed(stream.subspan(fed, last_end - fed));
      if (!more) return tl::unexpected(more.error());
      fed = last_end;
      const Mesh& finest = decoder.mesh();
      const Probes finest_probes = measure.probes(finest);
      const Distances finest_plain = measure.measure(finest, finest_probes, nullptr);
      if (auto s = subdivide_choice_into(finest, choice, workspace, out); !s)
        return tl::unexpected(s.error());
      const Distances d = out.mesh.face_count() == finest.face_count()
                              ? finest_plain
                              : measure.measure(out.mesh, finest_probes, &out.source_face,
                                                (1 - options.margin) * finest_plain.rms);
      row.finest_ratio = ratio_of(p.last);
      row.finest_rms_ratio = finest_plain.rms > 0 ? d.rms / finest_plain.rms : 0;
      row.finest_normal_ratio = finest_plain.normal > 0 ? d.normal / finest_plain.normal : 0;
      if (!qualifies(finest_plain, d, options)) choice = kAsaChoiceOff;
    }
    row.choice = choice;
    row.prefix_faces = prefix_faces;
    row.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - group_start).count();
    report_last_ratio = row.ratio;
    if (guidance.groups.empty() || guidance.groups.back().choice != choice)
      guidance.groups.push_back({p.first, choice});
    if (report) report->groups.push_back(std::move(row));
    work_done += double(end);
    if (options.progress) options.progress(work_done / planned_work);
  }
  // Nothing is missing from the complete stream: show it as decoded.
  if (guidance.groups.empty())
    guidance.groups.push_back({0, kAsaChoiceOff});
  else if (guidance.groups.back().choice != kAsaChoiceOff)
    guidance.groups.push_back({n - 1, kAsaChoiceOff});
  if (options.progress) options.progress(1.0);
  if (report)
    report->seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return guidance;
}

Result<std::vector<uint8_t>> with_asa_guidance(std::span<const uint8_t> stream,
                                               const AsaGuidance& guidance) {
  auto index = read_stream_index(stream);
  if (!index) return tl::unexpected(index.error());
  StreamHeader header = index->header;
  if (header.extra.size() < kExtensionsAt)
    return make_error(ErrorCode::kInvalidArgument,
                      "ASA guidance: the stream's header has no refinement format bytes");
  auto span = find_block(header.extra);
  if (!span) return tl::unexpected(span.error());
  if (*span)
    header.extra.erase(header.extra.begin() + std::ptrdiff_t((*span)->begin),
                       header.extra.begin() + std::ptrdiff_t((*span)->end));
  append_asa_guidance(header.extra, guidance);
  const std::vector<uint8_t> head = encode_stream_header(header);
  const uint32_t old_size = get_u32(stream.data() + 8);
  std::vector<uint8_t> out(stream.begin(), stream.begin() + 8);  // magic, version, flags
  put_u32(out, static_cast<uint32_t>(head.size()));
  out.insert(out.end(), head.begin(), head.end());
  put_u32(out, crc32(0, head.data(), head.size()));
  out.insert(out.end(), stream.begin() + 12 + old_size + 4, stream.end());
  return out;
}

}  // namespace meshstream
