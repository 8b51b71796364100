// See attribute_codec.h and docs/hcs-format.md ("Attribute records").
#include "common/codec/attribute_codec.h"

#include <zstd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <unordered_map>
#include <utility>

#include "common/codec/byte_io.h"
#include "common/codec/container.h"
#include "common/codec/decoder.h"
#include "common/codec/range_coder.h"
#include "common/codec/refinement_state.h"
#include "common/codec/stream_format.h"
#include "common/codec/structure_record_reader.h"

namespace meshstream {

const char* attribute_kind_name(AttributeKind kind) {
  switch (kind) {
    case AttributeKind::kNormal:
      return "normals";
    case AttributeKind::kTexcoord:
      return "texcoords";
    case AttributeKind::kColor:
      return "colors";
    case AttributeKind::kMaterial:
      return "materials";
  }
  return "unknown";
}

uint32_t wedge_of_corner(const EditableMesh& m, const AttributeValues& a, uint32_t c) {
  const uint32_t v = m.vertex(c);
  const uint32_t first = a.wedge_start[v], count = a.wedge_start[v + 1] - first;
  if (count <= 1) return first;
  // Walk across the edges (v, b) until one ends the wedge.
  uint32_t cur = c;
  for (uint32_t guard = 0; guard < 4 * kMaxPatchValence * 64; ++guard) {
    const uint32_t b = m.vertex(EditableMesh::prev(cur));
    const uint32_t o = m.opposite(EditableMesh::next(cur));
    const uint32_t key = o == kNone ? kBoundaryKey : b;
    for (uint32_t w = first; w < first + count; ++w)
      if (a.wedge_key[w] == key) return w;
    if (o == kNone) break;
    cur = EditableMesh::next(o);
    if (cur == c) break;
  }
  return first;  // only a hostile stream gets here (read_base checked the wedges)
}

namespace {

constexpr int kContexts = 4;  // parallelogram, neighbours, none, geometric
using ChannelModels = AttributeChannelModels;
static_assert(sizeof(ChannelModels::residual) / sizeof(ChannelModels::residual[0]) == kContexts);

// Values of channel `ch` at corner c.
const int32_t* corner_value(const EditableMesh& m, const AttributeValues& a,
                            const AttributeChannel& channel, size_t ch, uint32_t c) {
  const uint32_t idx = channel.per_corner ? wedge_of_corner(m, a, c) : m.vertex(c);
  return &a.data[ch][size_t(idx) * channel.components()];
}

// How a value is predicted: from the neighbours' values in the channel's
// own integers (parallelograms, means), from the geometry (normals: the
// geometric normal of the wedge), or (normals, record 1 from version 12 on
// when it codes smaller) from the mean of the decoded neighbours' unit
// normals at the wedge's faces.
// kNeighbourMean (previews only, never coded against): the mean of the
// decoded neighbours' values, no parallelogram; an inserted vertex's value
// interpolated, not extrapolated from the coarse faces around it (its UV
// error at SheenCloth's prefixes 24-30 -> 16-17 x 1e-3 before the values
// records come, bench/REPORT.md).
enum class Prediction { kValues, kGeometric, kNeighbourNormals, kNeighbourMean, kGeometricUv };

// The mean direction of the decoded (lower id) neighbours' normals at the
// corners of wedge w of v; false when none is decoded.
bool neighbour_normal_mean(const EditableMesh& m, const AttributeValues& a,
                           const AttributeChannel& channel, size_t ch, uint32_t v, uint32_t w,
                           const std::vector<uint32_t>& corners, double* d) {
  d[0] = d[1] = d[2] = 0;
  int count = 0;
  for (uint32_t c : corners) {
    if (channel.per_corner && a.wedge_start[v + 1] - a.wedge_start[v] > 1 &&
        wedge_of_corner(m, a, c) != w)
      continue;
    for (uint32_t nc : {EditableMesh::next(c), EditableMesh::prev(c)}) {
      if (m.vertex(nc) >= v) continue;
      const int32_t* u = corner_value(m, a, channel, ch, nc);
      const Vec3f n = dequantize_normal({u[0], u[1]}, channel.bits);
      d[0] += n.x;
      d[1] += n.y;
      d[2] += n.z;
      ++count;
    }
  }
  return count > 0 && (d[0] != 0 || d[1] != 0 || d[2] != 0);
}

// Texture coordinates of v in face (v, a, b) from the geometry (as Draco's
// texture-coordinate predictor): v's position projected on the edge (a, b)
// gives a ratio along it and a distance from it (relative to its length);
// the same in UV from A and B, on the side of the edge away from X (the
// third corner of the face across (a, b)). False when the edge is
// degenerate in space or UV, or X lies on it.
bool texcoord_from_geometry(const Vec3i& pv, const Vec3i& pa, const Vec3i& pb, const int32_t* A,
                            const int32_t* B, const int32_t* X, int32_t* out) {
  const double ex = double(pb.x) - pa.x, ey = double(pb.y) - pa.y, ez = double(pb.z) - pa.z;
  const double dx = double(pv.x) - pa.x, dy = double(pv.y) - pa.y, dz = double(pv.z) - pa.z;
  const double len2 = ex * ex + ey * ey + ez * ez;
  if (!(len2 > 0)) return false;
  const double t = (dx * ex + dy * ey + dz * ez) / len2;
  const double px = dx - t * ex, py = dy - t * ey, pz = dz - t * ez;
  const double h = std::sqrt((px * px + py * py + pz * pz) / len2);
  const double Eu = double(B[0]) - A[0], Ev = double(B[1]) - A[1];
  if (Eu == 0 && Ev == 0) return false;
  const double fu = A[0] + t * Eu, fv = A[1] + t * Ev;
  // Normal of the UV edge, and X's side of it.
  const double nu = -Ev, nv = Eu;
  const double side = (X[0] - A[0]) * nu + (X[1] - A[1]) * nv;
  if (side == 0) return false;
  const double s = side > 0 ? -h : h;
  out[0] = int32_t(std::lround(fu + s * nu));
  out[1] = int32_t(std::lround(fv + s * nv));
  return true;
}

// The prediction of vertex v's value (wedge w of a per-corner channel) from
// vertices below v; returns its context.
int predict(const EditableMesh& m, const AttributeValues& a, const AttributeLayout& layout,
            size_t ch, uint32_t v, uint32_t w, Prediction how, int32_t* out,
            std::vector<uint32_t>& ring, std::vector<uint32_t>& corners) {
  const bool geometric = how == Prediction::kGeometric || how == Prediction::kNeighbourNormals;
  const AttributeChannel& channel = layout.channels[ch];
  const uint32_t n = channel.components();
  const int32_t max = layout.max_value(channel);
  m.star(v, ring, corners);
  int64_t para[4] = {0, 0, 0, 0}, near[4] = {0, 0, 0, 0};
  int64_t para_count = 0, near_count = 0;
  double normal[3] = {0, 0, 0};
  for (uint32_t c : corners) {
    if (channel.per_corner && a.wedge_start[v + 1] - a.wedge_start[v] > 1 &&
        wedge_of_corner(m, a, c) != w)
      continue;
    const uint32_t na = EditableMesh::next(c), pb = EditableMesh::prev(c);
    const uint32_t va = m.vertex(na), vb = m.vertex(pb);
    if (geometric) {
      const Vec3i& p = m.positions()[v];
      const Vec3i& pa = m.positions()[va];
      const Vec3i& pbv = m.positions()[vb];
      const int64_t ax = pa.x - p.x, ay = pa.y - p.y, az = pa.z - p.z;
      const int64_t bx = pbv.x - p.x, by = pbv.y - p.y, bz = pbv.z - p.z;
      normal[0] += double(ay * bz - az * by);
      normal[1] += double(az * bx - ax * bz);
      normal[2] += double(ax * by - ay * bx);
      continue;
    }
    const bool a_known = va < v, b_known = vb < v;
    if (a_known && b_known && how != Prediction::kNeighbourMean) {
      const uint32_t o = m.opposite(c);
      if (o != kNone && m.vertex(o) < v) {
        const int32_t* A = corner_value(m, a, channel, ch, na);
        const int32_t* B = corner_value(m, a, channel, ch, pb);
        const int32_t* X = corner_value(m, a, channel, ch, o);
        int32_t uv[2];
        if (how == Prediction::kGeometricUv &&
            texcoord_from_geometry(m.positions()[v], m.positions()[va], m.positions()[vb], A, B, X,
                                   uv)) {
          para[0] += uv[0];
          para[1] += uv[1];
          ++para_count;
          continue;
        }
        for (uint32_t i = 0; i < n; ++i) para[i] += int64_t(A[i]) + B[i] - X[i];
        ++para_count;
        continue;
      }
    }
    if (a_known) {
      const int32_t* A = corner_value(m, a, channel, ch, na);
      for (uint32_t i = 0; i < n; ++i) near[i] += A[i];
      ++near_count;
    }
    if (b_known) {
      const int32_t* B = corner_value(m, a, channel, ch, pb);
      for (uint32_t i = 0; i < n; ++i) near[i] += B[i];
      ++near_count;
    }
  }
  if (how == Prediction::kNeighbourNormals) {
    double d[3];
    if (neighbour_normal_mean(m, a, channel, ch, v, w, corners, d)) {
      const auto q = quantize_direction(d[0], d[1], d[2], channel.bits);
      out[0] = q[0];
      out[1] = q[1];
      return 3;
    }
  }
  if (geometric && (normal[0] != 0 || normal[1] != 0 || normal[2] != 0)) {
    const auto q = quantize_direction(normal[0], normal[1], normal[2], channel.bits);
    out[0] = q[0];
    out[1] = q[1];
    return 3;
  }
  if (geometric) return predict(m, a, layout, ch, v, w, Prediction::kValues, out, ring, corners);
  int context = 2;
  for (uint32_t i = 0; i < n; ++i) out[i] = 0;
  if (para_count > 0) {
    context = 0;
    for (uint32_t i = 0; i < n; ++i) out[i] = int32_t(para[i] / para_count);
  } else if (near_count > 0) {
    context = 1;
    for (uint32_t i = 0; i < n; ++i) out[i] = int32_t(near[i] / near_count);
  } else if (v > 0 || w > 0) {
    // The previous value of this channel.
    const size_t idx = channel.per_corner ? (w > 0 ? w - 1 : 0) : v - 1;
    for (uint32_t i = 0; i < n; ++i) out[i] = a.data[ch][idx * n + i];
  }
  for (uint32_t i = 0; i < n; ++i) out[i] = std::clamp(out[i], 0, max);
  return context;
}

// Residual of value against prediction: normals wrap around the octahedral
// grid (both ends are one fold apart), the others are plain differences.
int32_t residual_of(const AttributeChannel& c, int32_t max, int32_t value, int32_t pred) {
  int32_t r = value - pred;
  if (c.kind == AttributeKind::kNormal) {
    const int32_t span = max + 1;
    if (r > span / 2)
      r -= span;
    else if (r < -((span - 1) / 2))
      r += span;
  }
  return r;
}

// The value a residual gives; false when it leaves the grid.
bool value_of(const AttributeChannel& c, int32_t max, int32_t pred, int64_t r, int32_t& value) {
  int64_t v = int64_t(pred) + r;
  if (c.kind == AttributeKind::kNormal) {
    const int64_t span = int64_t(max) + 1;
    if (r < -span || r > span) return false;
    v = ((v % span) + span) % span;
  }
  if (v < 0 || v > max) return false;
  value = int32_t(v);
  return true;
}

// How channel c is predicted in record 1 (`base_record`) or in the later
// records, as its layout flags say. Normals: the geometric normal (in the
// last and normals records from the exact positions, in record 1 from the
// base's coarse ones: what the decoder has), or in record 1 the
// neighbours' normals. Texture coordinates: parallelograms, or the
// geometry-based prediction. The encoder sets the flags where they code
// smaller (record 1) or always (later records: version 12).
Prediction prediction_of(const AttributeChannel& c, bool base_record) {
  const bool alternative =
      (c.flags & (base_record ? kPredictBaseAlternative : kPredictLaterFromGeometry)) != 0;
  if (c.kind == AttributeKind::kNormal)
    return base_record && alternative ? Prediction::kNeighbourNormals : Prediction::kGeometric;
  if (c.kind == AttributeKind::kTexcoord && alternative) return Prediction::kGeometricUv;
  return Prediction::kValues;
}

// The wedges of every vertex of `m` from per-corner values (all corner
// channels, each corner's ints concatenated): seam sets per vertex.
std::vector<std::vector<uint32_t>> seams_of(const EditableMesh& m,
                                            const std::vector<std::vector<int32_t>>& values,
                                            const AttributeLayout& layout,
                                            const std::vector<uint32_t>* corner_map) {
  std::vector<std::vector<uint32_t>> seams(m.vertex_count());
  auto same = [&](uint32_t c1, uint32_t c2) {
    const uint32_t i1 = corner_map ? (*corner_map)[c1] : c1;
    const uint32_t i2 = corner_map ? (*corner_map)[c2] : c2;
    for (size_t ch = 0; ch < layout.channels.size(); ++ch) {
      const AttributeChannel& channel = layout.channels[ch];
      if (!channel.per_corner) continue;
      const uint32_t n = channel.components();
      for (uint32_t i = 0; i < n; ++i)
        if (values[ch][size_t(i1) * n + i] != values[ch][size_t(i2) * n + i]) return false;
    }
    return true;
  };
  for (uint32_t c = 0; c < 3 * m.face_slot_count(); ++c) {
    if (m.face_dead(c / 3)) continue;
    const uint32_t o = m.opposite(EditableMesh::next(c));
    if (o == kNone) continue;
    const uint32_t c2 = EditableMesh::next(o);
    if (!same(c, c2)) seams[m.vertex(c)].push_back(m.vertex(EditableMesh::prev(c)));
  }
  return seams;
}

bool any_corner_channel(const AttributeLayout& l) {
  return std::any_of(l.channels.begin(), l.channels.end(),
                     [](const AttributeChannel& c) { return c.per_corner; });
}

// Whether a values-kind record of this part has a section for channel c.
bool carried_in(uint8_t part, const AttributeChannel& c) {
  const bool normal = c.kind == AttributeKind::kNormal;
  if (part == kAttributePartNormals) return normal;
  if (part == kAttributePartLowBits) return (c.flags & kBaseCoarse) != 0;
  if (part == kAttributePartValuesLateNormals) return !normal;
  return true;
}

// Whether record 1 has a section for channel c (version 13's normals have
// none: kBaseNormalsLate).
bool in_base_record(const AttributeChannel& c) {
  return !(c.kind == AttributeKind::kNormal && (c.flags & kBaseNormalsLate));
}

// The layout record 1's values are coded with: coarse channels
// (kBaseCoarse) on their grid of bits - base_shift.
AttributeLayout coarse_layout(const AttributeLayout& l) {
  AttributeLayout out = l;
  for (AttributeChannel& c : out.channels)
    if (c.flags & kBaseCoarse) c.bits = uint8_t(c.bits - c.base_shift);
  return out;
}

// ---- layout bytes ----

void put_f64(std::vector<uint8_t>& out, double d) {
  uint64_t b;
  std::memcpy(&b, &d, 8);
  put_u32(out, uint32_t(b));
  put_u32(out, uint32_t(b >> 32));
}

void put_string(std::vector<uint8_t>& out, const std::string& s) {
  put_varint(out, uint32_t(s.size()));
  out.insert(out.end(), s.begin(), s.end());
}

std::vector<uint8_t> write_layout(const AttributeLayout& l) {
  std::vector<uint8_t> out;
  out.push_back(uint8_t(l.channels.size()));
  for (const AttributeChannel& c : l.channels) {
    out.push_back(uint8_t(c.kind));
    out.push_back(uint8_t((c.per_corner ? 1 : 0) | c.flags));
    out.push_back(c.bits);
    if (c.flags & kBaseCoarse) out.push_back(c.base_shift);
    if (c.kind == AttributeKind::kTexcoord) {
      put_f32(out, c.uv.min.x);
      put_f32(out, c.uv.min.y);
      put_f64(out, c.uv.step);
    }
  }
  put_varint(out, uint32_t(l.materials.size()));
  for (const Material& m : l.materials) {
    put_string(out, m.name);
    for (float f :
         {m.base_color.x, m.base_color.y, m.base_color.z, m.base_color.w, m.metallic, m.roughness})
      put_f32(out, f);
    for (int32_t t : {m.base_color_texture, m.normal_texture, m.metallic_roughness_texture,
                      m.occlusion_texture, m.emissive_texture})
      put_u32(out, uint32_t(t));
    put_varint(out, m.base_color_texcoord_set);
    out.push_back(m.double_sided ? 1 : 0);
  }
  return out;
}

struct Reader {
  std::span<const uint8_t> in;
  size_t pos = 0;
  bool ok = true;
  bool need(size_t n) {
    if (in.size() - pos < n) ok = false;
    return ok;
  }
  uint8_t u8() { return need(1) ? in[pos++] : 0; }
  uint32_t u32() {
    if (!need(4)) return 0;
    const uint32_t v = get_u32(in.data() + pos);
    pos += 4;
    return v;
  }
  float f32() {
    if (!need(4)) return 0;
    const float f = get_f32(in.data() + pos);
    pos += 4;
    return f;
  }
  double f64() {
    const uint64_t lo = u32(), hi = u32();
    const uint64_t b = lo | (hi << 32);
    double d;
    std::memcpy(&d, &b, 8);
    return d;
  }
  uint32_t varint() {
    uint32_t v = 0;
    if (ok && !get_varint(in, pos, v)) ok = false;
    return ok ? v : 0;
  }
  std::string string(size_t limit) {
    const uint32_t n = varint();
    if (!ok || n > limit || !need(n)) {
      ok = false;
      return {};
    }
    std::string s(reinterpret_cast<const char*>(in.data() + pos), n);
    pos += n;
    return s;
  }
  std::span<const uint8_t> section() {
    const uint32_t n = varint();
    if (!ok || !need(n)) return {};
    auto s = in.subspan(pos, n);
    pos += n;
    return s;
  }
};

Error parse_error(const std::string& what) {
  return Error{ErrorCode::kParse, "attribute record: " + what};
}

Result<AttributeLayout> read_layout(std::span<const uint8_t> bytes) {
  Reader r{bytes};
  AttributeLayout l;
  const uint32_t count = r.u8();
  if (count > 8) return tl::unexpected(parse_error("more than 8 attributes"));
  for (uint32_t i = 0; i < count && r.ok; ++i) {
    AttributeChannel c;
    const uint8_t kind = r.u8();
    if (kind < 1 || kind > 4) return tl::unexpected(parse_error("unknown attribute kind"));
    c.kind = AttributeKind(kind);
    const uint8_t flags = r.u8();
    c.per_corner = (flags & 1) != 0;
    c.flags = uint8_t(flags & ~1);
    c.bits = r.u8();
    for (const AttributeChannel& other : l.channels)
      if (other.kind == c.kind) return tl::unexpected(parse_error("an attribute kind repeats"));
    if (c.kind != AttributeKind::kMaterial &&
        (c.bits < kMinAttributeBits || c.bits > kMaxAttributeBits))
      return tl::unexpected(parse_error("quantization bits out of 2..16"));
    if (c.flags & kBaseCoarse) {
      c.base_shift = r.u8();
      if (c.base_shift < 1 || c.base_shift + kMinAttributeBits > c.bits)
        return tl::unexpected(parse_error("coarse base shift out of range"));
    }
    const uint8_t allowed =
        c.kind == AttributeKind::kTexcoord
            ? kPredictBaseAlternative | kPredictLaterFromGeometry | kBaseCoarse | kWedgeRepeat
        : c.kind == AttributeKind::kNormal
            ? kPredictBaseAlternative | kBaseNormalsLate | kWedgeRepeat
        : c.kind == AttributeKind::kColor ? kBaseCoarse
                                          : 0;
    if (c.flags & ~allowed) return tl::unexpected(parse_error("unknown prediction flags"));
    if (c.kind == AttributeKind::kMaterial && !c.per_corner)
      return tl::unexpected(parse_error("face materials must be per corner"));
    if (c.kind == AttributeKind::kTexcoord) {
      c.uv.bits = c.bits;
      c.uv.min.x = r.f32();
      c.uv.min.y = r.f32();
      c.uv.step = r.f64();
      if (!std::isfinite(c.uv.min.x) || !std::isfinite(c.uv.min.y) || !std::isfinite(c.uv.step) ||
          !(c.uv.step > 0))
        return tl::unexpected(parse_error("texture coordinate grid is not finite"));
    }
    l.channels.push_back(c);
  }
  const uint32_t materials = r.varint();
  if (materials > 65536) return tl::unexpected(parse_error("more than 65536 materials"));
  for (uint32_t i = 0; i < materials && r.ok; ++i) {
    Material m;
    m.name = r.string(4096);
    m.base_color = {r.f32(), r.f32(), r.f32(), r.f32()};
    m.metallic = r.f32();
    m.roughness = r.f32();
    m.base_color_texture = int32_t(r.u32());
    m.normal_texture = int32_t(r.u32());
    m.metallic_roughness_texture = int32_t(r.u32());
    m.occlusion_texture = int32_t(r.u32());
    m.emissive_texture = int32_t(r.u32());
    m.base_color_texcoord_set = r.varint();
    m.double_sided = r.u8() != 0;
    l.materials.push_back(std::move(m));
  }
  if (!r.ok || r.pos != bytes.size())
    return tl::unexpected(parse_error("layout section is truncated or too long"));
  for (const AttributeChannel& c : l.channels)
    if (c.kind == AttributeKind::kMaterial && l.materials.empty())
      return tl::unexpected(parse_error("face materials without a material table"));
  return l;
}

void put_section(std::vector<uint8_t>& out, const std::vector<uint8_t>& bytes) {
  put_varint(out, uint32_t(bytes.size()));
  out.insert(out.end(), bytes.begin(), bytes.end());
}

// The slots of vertex v's values in channel c: its wedges [begin, end) in
// a per-corner channel, else v alone.
struct WedgeRange {
  uint32_t begin, end;
};
WedgeRange wedges_of(const AttributeChannel& c, const AttributeValues& a, uint32_t v) {
  return c.per_corner ? WedgeRange{a.wedge_start[v], a.wedge_start[v + 1]} : WedgeRange{v, v + 1};
}

// kWedgeRepeat: the earlier wedges of [w0, w) whose values (n ints each,
// compared after >> shift) appear first there, in order.
void distinct_before(const std::vector<int32_t>& d, uint32_t n, uint32_t w0, uint32_t w, int shift,
                     std::vector<uint32_t>& out) {
  auto same = [&](uint32_t a, uint32_t b) {
    for (uint32_t i = 0; i < n; ++i)
      if ((d[a * n + i] >> shift) != (d[b * n + i] >> shift)) return false;
    return true;
  };
  out.clear();
  for (uint32_t u = w0; u < w; ++u)
    if (std::none_of(out.begin(), out.end(), [&](uint32_t k) { return same(k, u); }))
      out.push_back(u);
}

// Codes (decodes) whether wedge w repeats one of `earlier` (the index, or
// earlier.size() for a new value): one bit per candidate, in order.
struct RepeatModels {
  BitModel same[3];
  BitModel& at(size_t k) { return same[std::min<size_t>(k, 2)]; }
  void encode(RangeEncoder& enc, size_t pick, size_t count) {
    for (size_t k = 0; k < count; ++k) {
      enc.encode_bit(at(k), k == pick ? 1 : 0);
      if (k == pick) return;
    }
  }
  size_t decode(RangeDecoder& dec, size_t count) {
    for (size_t k = 0; k < count; ++k)
      if (dec.decode_bit(at(k))) return k;
    return count;
  }
};

// Vertex v's normals (channel ch) shown as the geometric normal of each of
// its wedges on `m`, until their exact values come.
void show_geometric_normals(const EditableMesh& m, AttributeValues& a, const AttributeLayout& l,
                            size_t ch, uint32_t v, std::vector<uint32_t>& ring,
                            std::vector<uint32_t>& corners) {
  int32_t pred[4];
  const auto [w0, w1] = wedges_of(l.channels[ch], a, v);
  for (uint32_t w = w0; w < w1; ++w) {
    predict(m, a, l, ch, v, w, Prediction::kGeometric, pred, ring, corners);
    a.data[ch][2 * size_t(w)] = pred[0];
    a.data[ch][2 * size_t(w) + 1] = pred[1];
  }
}

// Codes (or decodes) the values of vertices [first, last) of channel ch, in
// id order, wedges in order. Encoder: `truth` holds them. `persistent`:
// the models to continue (values records), else fresh ones.
struct ValueCoder {
  const AttributeLayout& layout;
  bool base_record = false;  // record 1 (its prediction flags)
  // Scratch reused across vertices (initialised empty: aggregate
  // initialisation names only the two fields above).
  std::vector<uint32_t> ring = {}, corners = {}, earlier = {};

  bool repeats(const AttributeChannel& c) const {
    return c.per_corner && (c.flags & kWedgeRepeat) != 0;
  }

  std::vector<uint8_t> encode(const EditableMesh& m, const AttributeValues& truth, size_t ch,
                              uint32_t first, uint32_t last, ChannelModels* persistent = nullptr) {
    const AttributeChannel& c = layout.channels[ch];
    const uint32_t n = c.components();
    const int32_t max = layout.max_value(c);
    ChannelModels fresh;
    ChannelModels& models = persistent ? *persistent : fresh;
    RepeatModels repeat;
    RangeEncoder enc;
    int32_t pred[4];
    for (uint32_t v = first; v < last; ++v) {
      const auto [w0, w1] = wedges_of(c, truth, v);
      for (uint32_t w = w0; w < w1; ++w) {
        if (repeats(c) && w > w0) {
          distinct_before(truth.data[ch], n, w0, w, 0, earlier);
          size_t pick = 0;
          while (pick < earlier.size() &&
                 !std::equal(&truth.data[ch][w * n], &truth.data[ch][w * n] + n,
                             &truth.data[ch][earlier[pick] * n]))
            ++pick;
          repeat.encode(enc, pick, earlier.size());
          if (pick < earlier.size()) continue;
        }
        const int ctx =
            predict(m, truth, layout, ch, v, w, prediction_of(c, base_record), pred, ring, corners);
        for (uint32_t i = 0; i < n; ++i)
          models.residual[ctx][i].encode(enc,
                                         residual_of(c, max, truth.data[ch][w * n + i], pred[i]));
      }
    }
    return enc.finish();
  }

  Status decode(const EditableMesh& m, AttributeValues& a, size_t ch, uint32_t first, uint32_t last,
                std::span<const uint8_t> bytes, ChannelModels* persistent = nullptr) {
    const AttributeChannel& c = layout.channels[ch];
    const uint32_t n = c.components();
    const int32_t max = layout.max_value(c);
    ChannelModels fresh;
    ChannelModels& models = persistent ? *persistent : fresh;
    RepeatModels repeat;
    RangeDecoder dec(bytes);
    int32_t pred[4];
    for (uint32_t v = first; v < last; ++v) {
      const auto [w0, w1] = wedges_of(c, a, v);
      for (uint32_t w = w0; w < w1; ++w) {
        if (repeats(c) && w > w0) {
          distinct_before(a.data[ch], n, w0, w, 0, earlier);
          const size_t pick = repeat.decode(dec, earlier.size());
          if (pick < earlier.size()) {
            std::copy_n(&a.data[ch][earlier[pick] * n], n, &a.data[ch][w * n]);
            continue;
          }
        }
        const int ctx =
            predict(m, a, layout, ch, v, w, prediction_of(c, base_record), pred, ring, corners);
        for (uint32_t i = 0; i < n; ++i) {
          const int64_t r = models.residual[ctx][i].decode(dec);
          if (!value_of(c, max, pred[i], r, a.data[ch][w * n + i]))
            return tl::unexpected(parse_error(std::string(attribute_kind_name(c.kind)) +
                                              " value of vertex " + std::to_string(v) +
                                              " off the grid"));
        }
      }
      if (dec.exhausted_badly())
        return tl::unexpected(
            parse_error(std::string(attribute_kind_name(c.kind)) + " data runs out"));
    }
    return {};
  }
};

// The low bits of a coarse channel's base values (low-bits record, version
// 14), vertex by vertex, wedges and components in order, on record 1's mesh.
// Each value's high bits are known (record 1); its record-1 prediction, now
// at full precision from the exact values before it, says where in the
// range [lo, lo + 2^shift) it should be: below the range (context 0: code
// value - lo), above it (context 1: hi - value) or inside (context 2:
// value - prediction mod 2^shift). Each context's symbol goes through a
// binary tree of adaptive bits per component: about `shift` bits where the
// prediction says nothing, fewer where it is good.
struct LowBitCoder {
  const AttributeLayout& layout;
  size_t ch;
  int shift;
  std::vector<BitModel> tree;
  std::vector<uint32_t> ring, corners, earlier;
  BitModel same;  // kWedgeRepeat: same low bits as the earlier wedge of equal coarse value
  // kWedgeRepeat: the first earlier wedge of [w0, w) whose coarse value is
  // wedge w's, or w.
  uint32_t coarse_twin(const std::vector<int32_t>& d, uint32_t n, uint32_t w0, uint32_t w) {
    if (!(layout.channels[ch].per_corner && (layout.channels[ch].flags & kWedgeRepeat))) return w;
    distinct_before(d, n, w0, w, shift, earlier);
    for (uint32_t u : earlier)
      if (std::equal(&d[u * n], &d[u * n] + n, &d[w * n],
                     [&](int32_t x, int32_t y) { return (x >> shift) == (y >> shift); }))
        return u;
    return w;
  }
  LowBitCoder(const AttributeLayout& l, size_t channel)
      : layout(l),
        ch(channel),
        shift(l.channels[channel].base_shift),
        tree((size_t(4) * 3) << shift) {}
  BitModel* models(uint32_t component, int context) {
    return &tree[(size_t(component) * 3 + context) << shift];
  }
  // Where `pred` lies against the range [lo, lo + 2^shift): below (0),
  // above (1) or inside (2). It depends on the prediction alone, so the
  // decoder knows it before the symbol.
  int context_of(int32_t pred, int32_t lo) const {
    return pred < lo ? 0 : pred > lo + (int32_t(1) << shift) - 1 ? 1 : 2;
  }
  // Context and symbol of `value` in [lo, lo + 2^shift) against `pred`.
  std::pair<int, int32_t> symbol(int32_t pred, int32_t lo, int32_t value) const {
    const int context = context_of(pred, lo);
    if (context == 0) return {0, value - lo};
    if (context == 1) return {1, lo + (int32_t(1) << shift) - 1 - value};
    return {2, (value - pred) & ((int32_t(1) << shift) - 1)};
  }
  int32_t value_of(int context, int32_t pred, int32_t lo, int32_t sym) const {
    const int32_t mask = (int32_t(1) << shift) - 1;
    if (context == 0) return lo + sym;
    if (context == 1) return lo + mask - sym;
    return lo + ((pred - lo + sym) & mask);
  }

  std::vector<uint8_t> encode(const EditableMesh& base, const AttributeValues& truth,
                              uint32_t base_n) {
    const AttributeChannel& c = layout.channels[ch];
    const uint32_t n = c.components();
    RangeEncoder enc;
    int32_t pred[4];
    for (uint32_t v = 0; v < base_n; ++v) {
      const auto [w0, w1] = wedges_of(c, truth, v);
      for (uint32_t w = w0; w < w1; ++w) {
        if (const uint32_t u = coarse_twin(truth.data[ch], n, w0, w); u != w) {
          const bool equal = std::equal(&truth.data[ch][u * n], &truth.data[ch][u * n] + n,
                                        &truth.data[ch][w * n]);
          enc.encode_bit(same, equal ? 1 : 0);
          if (equal) continue;
        }
        predict(base, truth, layout, ch, v, w, prediction_of(c, true), pred, ring, corners);
        for (uint32_t i = 0; i < n; ++i) {
          const int32_t value = truth.data[ch][w * n + i];
          const auto [context, sym] = symbol(pred[i], (value >> shift) << shift, value);
          BitModel* m = models(i, context);
          uint32_t node = 1;
          for (int b = shift - 1; b >= 0; --b) {
            const int bit = (sym >> b) & 1;
            enc.encode_bit(m[node], bit);
            node = 2 * node + uint32_t(bit);
          }
        }
      }
    }
    return enc.finish();
  }

  Status decode(const EditableMesh& base, AttributeValues& a, uint32_t base_n,
                std::span<const uint8_t> bytes) {
    const AttributeChannel& c = layout.channels[ch];
    const uint32_t n = c.components();
    RangeDecoder dec(bytes);
    int32_t pred[4];
    for (uint32_t v = 0; v < base_n; ++v) {
      const auto [w0, w1] = wedges_of(c, a, v);
      for (uint32_t w = w0; w < w1; ++w) {
        if (const uint32_t u = coarse_twin(a.data[ch], n, w0, w); u != w && dec.decode_bit(same)) {
          std::copy_n(&a.data[ch][u * n], n, &a.data[ch][w * n]);
          continue;
        }
        predict(base, a, layout, ch, v, w, prediction_of(c, true), pred, ring, corners);
        for (uint32_t i = 0; i < n; ++i) {
          int32_t& value = a.data[ch][w * n + i];
          const int32_t lo = (value >> shift) << shift;
          const int context = context_of(pred[i], lo);
          BitModel* m = models(i, context);
          uint32_t node = 1;
          for (int b = shift - 1; b >= 0; --b) node = 2 * node + uint32_t(dec.decode_bit(m[node]));
          value = value_of(context, pred[i], lo, int32_t(node - (uint32_t(1) << shift)));
        }
      }
      if (dec.exhausted_badly()) return tl::unexpected(parse_error("low-bits data runs out"));
    }
    return {};
  }
};

// Seam bits of the base: per vertex one bit "more than one wedge", then one
// bit per interior edge of its star (is it a seam at the vertex).
struct SeamModels {
  BitModel split[2];    // by boundary
  BitModel edge[2][2];  // by boundary, previous edge bit
};

// The wedge keys of base vertex v from its seam edges (in star order).
void keys_from_star(const EditableMesh& base, uint32_t v, const std::vector<uint8_t>& bits,
                    const std::vector<uint32_t>& corners, std::vector<uint32_t>& keys) {
  keys.clear();
  size_t k = 0;
  for (uint32_t c : corners) {
    if (base.opposite(EditableMesh::next(c)) == kNone) continue;
    if (bits[k++]) keys.push_back(base.vertex(EditableMesh::prev(c)));
  }
  if (!keys.empty() && base.is_boundary(v)) keys.push_back(kBoundaryKey);
}

}  // namespace

// ---------------- encoder ----------------

Result<AttributePlan> plan_attributes(const Mesh& mesh, const std::vector<Vec3i>& q,
                                      const AttributeOptions& options) {
  for (int b : {options.normal_bits, options.texcoord_bits, options.color_bits})
    if (b < kMinAttributeBits || b > kMaxAttributeBits)
      return make_error(ErrorCode::kInvalidArgument,
                        "attribute quantization bits " + std::to_string(b) + " out of 2..16");
  if (options.base_color_bits != 0 && (options.base_color_bits < kMinAttributeBits ||
                                       options.base_color_bits >= options.color_bits))
    return make_error(ErrorCode::kInvalidArgument,
                      "base colour bits " + std::to_string(options.base_color_bits) +
                          " out of 2.." + std::to_string(options.color_bits - 1) + " (0: exact)");
  if (auto s = check_attribute_counts(mesh); !s) return tl::unexpected(s.error());
  AttributePlan plan;
  plan.extras = &mesh.extra_attributes;
  plan.base_color_bits = options.base_color_bits;
  plan.wedge_repeat = options.wedge_repeat;
  const size_t corners = 3 * mesh.triangles.size();
  auto finite2 = [](Vec2f v) { return std::isfinite(v.x) && std::isfinite(v.y); };
  auto finite3 = [](Vec3f v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
  };
  // Normals.
  auto add_normals = [&](const Vec3f* values, size_t count, const uint32_t* index, size_t n,
                         bool per_corner) -> Status {
    AttributeChannel c{AttributeKind::kNormal, per_corner, uint8_t(options.normal_bits), {}};
    std::vector<int32_t> out(2 * n);
    for (size_t i = 0; i < n; ++i) {
      const Vec3f& v = values[index ? index[i] : i];
      if (!finite3(v)) return make_error(ErrorCode::kInvalidMesh, "a normal is not finite");
      const auto qn = quantize_normal(v, c.bits);
      out[2 * i] = qn[0];
      out[2 * i + 1] = qn[1];
    }
    (void)count;
    plan.layout.channels.push_back(c);
    plan.input_values.push_back(std::move(out));
    return {};
  };
  if (!mesh.normals.empty()) {
    if (auto s = add_normals(mesh.normals.data(), mesh.normals.size(), nullptr, mesh.normals.size(),
                             false);
        !s)
      return tl::unexpected(s.error());
  } else if (!mesh.corner_normals.empty()) {
    if (auto s = add_normals(mesh.corner_normals.values.data(), mesh.corner_normals.values.size(),
                             mesh.corner_normals.corners.data(), corners, true);
        !s)
      return tl::unexpected(s.error());
  }
  // Texture coordinates.
  auto add_uv = [&](const std::vector<Vec2f>& values, const uint32_t* index, size_t n,
                    bool per_corner) -> Status {
    for (const Vec2f& v : values)
      if (!finite2(v))
        return make_error(ErrorCode::kInvalidMesh, "a texture coordinate is not finite");
    AttributeChannel c{AttributeKind::kTexcoord, per_corner, uint8_t(options.texcoord_bits), {}};
    c.uv = make_texcoord_grid(values.data(), values.size(), c.bits);
    std::vector<int32_t> out(2 * n);
    for (size_t i = 0; i < n; ++i) {
      const auto qt = quantize_texcoord(c.uv, values[index ? index[i] : i]);
      out[2 * i] = qt[0];
      out[2 * i + 1] = qt[1];
    }
    plan.layout.channels.push_back(c);
    plan.input_values.push_back(std::move(out));
    return {};
  };
  if (!mesh.texcoords.empty()) {
    if (auto s = add_uv(mesh.texcoords, nullptr, mesh.texcoords.size(), false); !s)
      return tl::unexpected(s.error());
  } else if (!mesh.corner_texcoords.empty()) {
    if (auto s = add_uv(mesh.corner_texcoords.values, mesh.corner_texcoords.corners.data(), corners,
                        true);
        !s)
      return tl::unexpected(s.error());
  }
  // Colours.
  auto add_colors = [&](const std::vector<Vec4f>& values, const uint32_t* index, size_t n,
                        bool per_corner) {
    AttributeChannel c{AttributeKind::kColor, per_corner, uint8_t(options.color_bits), {}};
    std::vector<int32_t> out(4 * n);
    for (size_t i = 0; i < n; ++i) {
      const Vec4f& v = values[index ? index[i] : i];
      const float ch[4] = {v.x, v.y, v.z, v.w};
      for (int k = 0; k < 4; ++k) out[4 * i + k] = quantize_color_channel(ch[k], c.bits);
    }
    plan.layout.channels.push_back(c);
    plan.input_values.push_back(std::move(out));
  };
  if (!mesh.colors.empty()) {
    add_colors(mesh.colors, nullptr, mesh.colors.size(), false);
  } else if (!mesh.corner_colors.empty()) {
    add_colors(mesh.corner_colors.values, mesh.corner_colors.corners.data(), corners, true);
  }
  plan.layout.materials = mesh.materials;
  if (!mesh.face_materials.empty()) {
    AttributeChannel c{AttributeKind::kMaterial, true, 0, {}};
    std::vector<int32_t> out(corners);
    for (size_t f = 0; f < mesh.triangles.size(); ++f)
      for (int k = 0; k < 3; ++k) out[3 * f + k] = int32_t(mesh.face_materials[f]);
    plan.layout.channels.push_back(c);
    plan.input_values.push_back(std::move(out));
  }
  // Locks: both ends of every seam edge.
  if (any_corner_channel(plan.layout)) {
    auto m = EditableMesh::build(q, mesh.triangles);
    if (!m) return tl::unexpected(m.error());
    const auto seams = seams_of(*m, plan.input_values, plan.layout, nullptr);
    plan.locked.assign(mesh.vertex_count(), 0);
    for (uint32_t v = 0; v < seams.size(); ++v) {
      if (seams[v].empty()) continue;
      plan.locked[v] = 1;
      for (uint32_t b : seams[v]) plan.locked[b] = 1;
    }
    plan.locked_count = uint32_t(std::count(plan.locked.begin(), plan.locked.end(), 1));
  }
  return plan;
}

Result<std::vector<uint8_t>> add_attribute_records(const AttributePlan& plan, const Mesh& mesh,
                                                   const std::vector<Vec3i>& q,
                                                   std::span<const uint8_t> stream,
                                                   const std::vector<uint32_t>& to_input,
                                                   AttributeParts* parts,
                                                   std::vector<AttributeRecordPlace>* places) {
  auto internal = [](const std::string& what) {
    return tl::unexpected(Error{ErrorCode::kInternal, "encoder attributes: " + what});
  };
  auto index = read_stream_index(stream);
  if (!index) return tl::unexpected(index.error());
  const StreamIndex& idx = *index;
  const uint32_t n = mesh.vertex_count();
  if (to_input.size() != n) return internal("vertex map size");
  const uint32_t base_n = idx.records[0].vertices;
  // The decoder's base and final meshes, as it will hold them.
  IncrementalDecoder base_decoder;
  const uint64_t base_end = idx.records[0].offset + idx.records[0].size;
  base_decoder.expect_prefix(base_end);
  if (auto f = base_decoder.feed(stream.subspan(0, base_end)); !f) return tl::unexpected(f.error());
  // The base as the decoder's state holds it after record 0: coarse
  // positions q >> b at the middle of their unknown low bits.
  const int quant_bits = idx.header.quant_bits;
  const auto format = idx.header.extra.empty()
                          ? std::nullopt
                          : RefinementFormatInfo::from_header_byte(idx.header.extra[0]);
  const int base_shift =
      format && format->embedded && idx.header.extra.size() > 1 ? idx.header.extra[1] : 0;
  std::vector<Vec3i> coarse(base_n);
  for (uint32_t v = 0; v < base_n; ++v)
    for (int a = 0; a < 3; ++a) coarse[v][a] = q[to_input[v]][a] >> base_shift;
  auto base_state = RefinementState::from_coarse_base(coarse, base_decoder.mesh().triangles,
                                                      quant_bits, base_shift);
  if (!base_state) return tl::unexpected(base_state.error());
  const EditableMesh* base = &base_state->mesh;
  auto decoded = decode_hcs(stream);
  if (!decoded) return tl::unexpected(decoded.error());
  std::vector<Vec3i> positions(n);
  for (uint32_t v = 0; v < n; ++v) positions[v] = q[to_input[v]];
  auto full = EditableMesh::build(positions, decoded->triangles);
  if (!full) return tl::unexpected(full.error());

  // Decoded corner -> input corner.
  auto key_of = [](uint32_t a, uint32_t b, uint32_t c) {
    // Rotate so the smallest id leads: a rotation-invariant key of an oriented face.
    if (b < a && b < c) return std::tuple{b, c, a};
    if (c < a && c < b) return std::tuple{c, a, b};
    return std::tuple{a, b, c};
  };
  auto hash = [](std::tuple<uint32_t, uint32_t, uint32_t> t) {
    const auto [a, b, c] = t;
    return (uint64_t(a) * 0x9E3779B97F4A7C15ull) ^ (uint64_t(b) << 21) ^
           (uint64_t(c) * 0xC2B2AE3D27D4EB4Full);
  };
  std::unordered_multimap<uint64_t, uint32_t> faces_by_key;
  faces_by_key.reserve(mesh.triangles.size());
  for (uint32_t f = 0; f < mesh.triangles.size(); ++f) {
    const Triangle& t = mesh.triangles[f];
    faces_by_key.emplace(hash(key_of(t[0], t[1], t[2])), f);
  }
  std::vector<uint32_t> corner_map(3 * decoded->triangles.size());
  for (uint32_t f = 0; f < decoded->triangles.size(); ++f) {
    const Triangle& d = decoded->triangles[f];
    const uint32_t a = to_input[d[0]], b = to_input[d[1]], c = to_input[d[2]];
    const auto k = key_of(a, b, c);
    bool found = false;
    auto range = faces_by_key.equal_range(hash(k));
    for (auto it = range.first; it != range.second && !found; ++it) {
      const Triangle& t = mesh.triangles[it->second];
      if (key_of(t[0], t[1], t[2]) != k) continue;
      for (int r = 0; r < 3; ++r) {
        if (t[r] == a) {
          corner_map[3 * f] = 3 * it->second + r;
          corner_map[3 * f + 1] = 3 * it->second + (r + 1) % 3;
          corner_map[3 * f + 2] = 3 * it->second + (r + 2) % 3;
          found = true;
        }
      }
    }
    if (!found) return internal("decoded face " + std::to_string(f) + " is not an input face");
  }

  // The values in decoder terms: wedges from the full mesh, named as the
  // base's stars give them.
  // The layout as coded: texture coordinates after record 1 predicted from
  // the geometry (version 12; the positions are exact or nearly there);
  // record 1's choices are made below.
  AttributeLayout layout = plan.layout;
  for (AttributeChannel& c : layout.channels)
    if (c.kind == AttributeKind::kTexcoord) c.flags |= kPredictLaterFromGeometry;
  AttributeValues truth;
  truth.data.resize(layout.channels.size());
  const auto seams = seams_of(*full, plan.input_values, layout, &corner_map);
  std::vector<uint32_t> ring, corners, keys;
  std::vector<std::vector<uint8_t>> seam_bits(base_n);
  truth.wedge_start.assign(1, 0);
  for (uint32_t v = 0; v < n; ++v) {
    keys.clear();
    if (!seams[v].empty()) {
      if (v >= base_n) return internal("seam vertex " + std::to_string(v) + " was decimated");
      base->star(v, ring, corners);
      std::vector<uint8_t>& bits = seam_bits[v];
      for (uint32_t c : corners) {
        if (base->opposite(EditableMesh::next(c)) == kNone) continue;
        const uint32_t b = base->vertex(EditableMesh::prev(c));
        bits.push_back(std::find(seams[v].begin(), seams[v].end(), b) != seams[v].end());
      }
      keys_from_star(*base, v, bits, corners, keys);
      const size_t expected = seams[v].size() + (base->is_boundary(v) ? 1 : 0);
      if (keys.size() != expected) return internal("seam edges of a base vertex left the base");
    } else if (v < base_n && !base->is_isolated(v)) {
      base->star(v, ring, corners);
      uint32_t interior = 0;
      for (uint32_t c : corners) interior += base->opposite(EditableMesh::next(c)) != kNone;
      seam_bits[v].assign(interior, 0);
    }
    if (keys.empty()) keys.push_back(kNone);
    for (uint32_t k : keys) truth.wedge_key.push_back(k);
    truth.wedge_start.push_back(uint32_t(truth.wedge_key.size()));
  }
  const uint32_t wedges = uint32_t(truth.wedge_key.size());
  for (size_t ch = 0; ch < layout.channels.size(); ++ch) {
    const AttributeChannel& c = layout.channels[ch];
    const uint32_t nc = c.components();
    auto& data = truth.data[ch];
    if (!c.per_corner) {
      data.resize(size_t(n) * nc);
      for (uint32_t v = 0; v < n; ++v)
        for (uint32_t i = 0; i < nc; ++i)
          data[size_t(v) * nc + i] = plan.input_values[ch][size_t(to_input[v]) * nc + i];
      continue;
    }
    data.assign(size_t(wedges) * nc, 0);
    for (uint32_t dc = 0; dc < corner_map.size(); ++dc) {
      const uint32_t w = wedge_of_corner(*full, truth, dc);
      for (uint32_t i = 0; i < nc; ++i)
        data[size_t(w) * nc + i] = plan.input_values[ch][size_t(corner_map[dc]) * nc + i];
    }
  }
  // Check: every corner's value is its wedge's (the seam rule holds).
  for (size_t ch = 0; ch < layout.channels.size(); ++ch) {
    const AttributeChannel& c = layout.channels[ch];
    if (!c.per_corner) continue;
    const uint32_t nc = c.components();
    for (uint32_t dc = 0; dc < corner_map.size(); ++dc) {
      const uint32_t w = wedge_of_corner(*full, truth, dc);
      for (uint32_t i = 0; i < nc; ++i)
        if (truth.data[ch][size_t(w) * nc + i] !=
            plan.input_values[ch][size_t(corner_map[dc]) * nc + i])
          return internal("a wedge holds two values");
    }
  }

  // Record 1: layout, seams, base values (the layout last: its flags say
  // which prediction record 1's values took).
  AttributeParts local_parts;
  std::vector<uint8_t> first{kRecordAttributes, kAttributePartBase};
  std::vector<uint8_t> after_layout;
  if (any_corner_channel(layout)) {
    RangeEncoder enc;
    SeamModels models;
    for (uint32_t v = 0; v < base_n; ++v) {
      if (base->is_isolated(v)) continue;
      const bool boundary = base->is_boundary(v);
      const bool split = truth.wedge_start[v + 1] - truth.wedge_start[v] > 1;
      enc.encode_bit(models.split[boundary], split);
      if (!split) continue;
      uint32_t prev = 0;
      for (uint8_t bit : seam_bits[v]) {
        enc.encode_bit(models.edge[boundary][prev], bit);
        prev = bit;
      }
    }
    const std::vector<uint8_t> bytes = enc.finish();
    put_section(after_layout, bytes);
    local_parts["seams"] += bytes.size();
  }
  // Record 1's normals and texture coordinates: each both ways (the
  // geometric normal of the coarse base or the neighbours' normals;
  // parallelograms or the geometry-based UV prediction), the smaller kept
  // and named by the layout flag kPredictBaseAlternative. The base's
  // positions miss their low bits, which spoils the geometry-based guesses
  // where the base is as fine as the mesh (every vertex locked: Draco's
  // textured sphere); on a coarse base of exact-enough positions they win.
  //
  // Normals stay out of record 1 (version 13, kBaseNormalsLate): the base's
  // come in the normals records with the inserted vertices', predicted on
  // the complete mesh, and the first display with colours or texture
  // waits for none of them (CesiumMilkTruck: 3 034 of record 1's 8 457
  // bytes were the base's normals, bench/REPORT.md).
  for (AttributeChannel& c : layout.channels)
    if (c.kind == AttributeKind::kNormal) c.flags |= kBaseNormalsLate;
  // Texture coordinates of more than kBaseCoarseBits bits go coarse into
  // record 1 (version 14, kBaseCoarse): their low bits follow in a low-bits
  // record before the first values record (truck: record 1's UV 4 515 ->
  // about 2 400 bytes; the first display shows the small texture level).
  for (AttributeChannel& c : layout.channels)
    if (c.kind == AttributeKind::kTexcoord && c.bits > kBaseCoarseBits) {
      c.flags |= kBaseCoarse;
      c.base_shift = uint8_t(c.bits - kBaseCoarseBits);
    }
  // A texture coordinate shared by several wedges of a vertex (split by
  // the normals) is coded once (version 16, kWedgeRepeat), and so is a
  // normal shared by the wedges the texture coordinates split (version 17);
  // where no value repeats (usb's UV: 573 wedges, none), the flag's bits
  // would only cost (8 B).
  for (size_t ch = 0; ch < layout.channels.size(); ++ch) {
    AttributeChannel& c = layout.channels[ch];
    const bool may_repeat = c.kind == AttributeKind::kTexcoord || c.kind == AttributeKind::kNormal;
    if (!may_repeat || !c.per_corner || !plan.wedge_repeat) continue;
    std::vector<uint32_t> earlier;
    bool any = false;
    for (uint32_t v = 0; v < n && !any; ++v)
      for (uint32_t w = truth.wedge_start[v] + 1; w < truth.wedge_start[v + 1] && !any; ++w) {
        distinct_before(truth.data[ch], c.components(), truth.wedge_start[v], w + 1, 0, earlier);
        any = earlier.size() < w + 1 - truth.wedge_start[v];
      }
    if (any) c.flags |= kWedgeRepeat;
  }
  // Colours go coarse only when asked (version 15, base_color_bits):
  // bench/REPORT.md measures what it costs and saves.
  for (AttributeChannel& c : layout.channels)
    if (c.kind == AttributeKind::kColor && plan.base_color_bits > 0 &&
        c.bits > plan.base_color_bits) {
      c.flags |= kBaseCoarse;
      c.base_shift = uint8_t(c.bits - plan.base_color_bits);
    }
  // Record 1 codes on the coarse grids (the flags it sets below are the
  // layout's too).
  AttributeLayout record1_layout = coarse_layout(layout);
  ValueCoder base_coder{record1_layout, true};
  for (size_t ch = 0; ch < layout.channels.size(); ++ch) {
    if (!in_base_record(layout.channels[ch])) continue;
    // The base's values predicted over the base mesh (the decoder's state
    // after record 0); the wedge tables of base vertices are the same.
    AttributeValues base_truth;
    base_truth.wedge_start.assign(truth.wedge_start.begin(),
                                  truth.wedge_start.begin() + base_n + 1);
    base_truth.wedge_key.assign(truth.wedge_key.begin(),
                                truth.wedge_key.begin() + base_truth.wedge_start.back());
    base_truth.data.resize(layout.channels.size());
    const AttributeChannel& c = layout.channels[ch];
    const size_t count =
        size_t(c.per_corner ? base_truth.wedge_start.back() : base_n) * c.components();
    base_truth.data[ch].assign(truth.data[ch].begin(), truth.data[ch].begin() + count);
    if (c.flags & kBaseCoarse)
      for (int32_t& x : base_truth.data[ch]) x >>= c.base_shift;
    std::vector<uint8_t> bytes = base_coder.encode(*base, base_truth, ch, 0, base_n);
    if (c.kind == AttributeKind::kNormal || c.kind == AttributeKind::kTexcoord) {
      record1_layout.channels[ch].flags |= kPredictBaseAlternative;
      std::vector<uint8_t> other = base_coder.encode(*base, base_truth, ch, 0, base_n);
      if (other.size() < bytes.size()) {
        bytes = std::move(other);
        layout.channels[ch].flags |= kPredictBaseAlternative;
      } else {
        record1_layout.channels[ch].flags &= uint8_t(~kPredictBaseAlternative);
      }
    }
    put_section(after_layout, bytes);
    local_parts[attribute_kind_name(c.kind)] += bytes.size();
  }
  const std::vector<uint8_t> layout_bytes = write_layout(layout);
  put_section(first, layout_bytes);
  first.insert(first.end(), after_layout.begin(), after_layout.end());
  local_parts["layout"] += layout_bytes.size();

  // The low-bits record (version 14): per coarse channel the base's exact
  // values, in record 1's order and with its predictions on its mesh, now
  // at full precision from the exact values before them, each prediction
  // clamped into the range its coarse value leaves (so a residual costs at
  // most about the missing bits, and less where the prediction is good).
  std::vector<uint8_t> low_bits;
  if (std::any_of(layout.channels.begin(), layout.channels.end(),
                  [](const AttributeChannel& c) { return (c.flags & kBaseCoarse) != 0; })) {
    low_bits = {kRecordAttributes, kAttributePartLowBits};
    put_varint(low_bits, base_n);
    for (size_t ch = 0; ch < layout.channels.size(); ++ch) {
      if (!(layout.channels[ch].flags & kBaseCoarse)) continue;
      LowBitCoder low_coder(layout, ch);
      const std::vector<uint8_t> bytes = low_coder.encode(*base, truth, base_n);
      put_section(low_bits, bytes);
      local_parts[attribute_kind_name(layout.channels[ch].kind)] += bytes.size();
    }
  }

  // Values records: the geometry stream replayed as the decoder reads it,
  // and after a geometry record, once the vertices inserted since the last
  // values are worth about kValuesRecordShare of the stream, their exact
  // values coded on the mesh the decoder holds then. Their size per vertex
  // is estimated from coding them all on the full mesh (version 10's last
  // record).
  //
  // Normals go late (version 12): their prediction is the geometric normal
  // of the vertex's wedge, which on the coarse stars of a values record's
  // moment missed by far more than on the complete mesh (SheenCloth: 45 240
  // normal bytes against 27 952 on the complete mesh's stars with the same
  // positions; the positions were already exact there). So values records
  // leave them out (part 3) and normals records after the last geometry
  // record carry them, coded on the complete mesh, in records of the same
  // size rule; until then the decoder previews a vertex's normal with the
  // geometric normal of its wedge on the mesh it has.
  const uint32_t inserted = n - base_n;
  const bool late_normals =
      std::any_of(layout.channels.begin(), layout.channels.end(),
                  [](const AttributeChannel& c) { return c.kind == AttributeKind::kNormal; });
  auto deferred = [&](size_t ch) {
    return late_normals && layout.channels[ch].kind == AttributeKind::kNormal;
  };
  // The normals records start at vertex 0: the base's normals too.
  const uint32_t normals_from = 0;
  uint64_t all_inserted_bytes = 0, values_inserted_bytes = 0, normal_bytes = 0;
  {
    ValueCoder estimate{layout};
    for (size_t ch = 0; ch < layout.channels.size(); ++ch) {
      if (deferred(ch)) {
        normal_bytes += estimate.encode(*full, truth, ch, normals_from, n).size();
        continue;
      }
      const uint64_t b = estimate.encode(*full, truth, ch, base_n, n).size();
      all_inserted_bytes += b;
      values_inserted_bytes += b;
    }
    all_inserted_bytes += normal_bytes;
  }
  uint64_t fixed_bytes = stream.size() + first.size();
  for (const ExtraAttribute& e : *plan.extras) fixed_bytes += e.bytes.size() / 4;  // a guess
  const double per_vertex = inserted ? double(values_inserted_bytes) / inserted : 0;
  const double target = kValuesRecordShare * double(fixed_bytes + all_inserted_bytes);
  std::vector<std::vector<uint8_t>> values_after(idx.records.size());
  uint32_t done = base_n;
  if (inserted > 0 && idx.records.size() > 2) {
    auto replay = RefinementState::from_coarse_base(coarse, base_decoder.mesh().triangles,
                                                    quant_bits, base_shift);
    if (!replay) return tl::unexpected(replay.error());
    if (format) replay->format = *format;
    std::vector<ChannelModels> models(layout.channels.size());
    ValueCoder values_coder{layout};
    // The last geometry record's vertices go into the last record.
    for (size_t i = 1; i + 1 < idx.records.size(); ++i) {
      const RecordEntry& r = idx.records[i];
      AppliedRecord applied;
      applied.record_changes = false;
      if (auto s =
              apply_refinement_record(*replay, record_payload(r, stream.subspan(r.offset, r.size)),
                                      r.vertices, r.faces, applied);
          !s)
        return internal("replaying record " + std::to_string(i) + ": " + s.error().message);
      const uint32_t now = replay->mesh.vertex_count();
      if (now <= done || double(now - done) * per_vertex < target) continue;
      std::vector<uint8_t> payload{
          kRecordAttributes, late_normals ? kAttributePartValuesLateNormals : kAttributePartValues};
      put_varint(payload, now - done);
      for (size_t ch = 0; ch < layout.channels.size(); ++ch) {
        if (deferred(ch)) continue;
        const std::vector<uint8_t> bytes =
            values_coder.encode(replay->mesh, truth, ch, done, now, &models[ch]);
        put_section(payload, bytes);
        local_parts[attribute_kind_name(layout.channels[ch].kind)] += bytes.size();
      }
      values_after[i] = std::move(payload);
      done = now;
    }
  }

  // Normals records: the normals the values records left out, on the
  // complete mesh, each about kValuesRecordShare of the stream.
  std::vector<std::vector<uint8_t>> normals_records;
  if (late_normals && done > normals_from) {
    const double per_normal = double(normal_bytes) / (n - normals_from);
    const uint32_t chunk =
        std::max<uint32_t>(1, per_normal > 0 ? uint32_t(target / per_normal) : done - normals_from);
    std::vector<ChannelModels> models(layout.channels.size());
    ValueCoder normals_coder{layout};
    for (uint32_t from = normals_from; from < done;) {
      const uint32_t to = std::min(done, from + chunk);
      std::vector<uint8_t> payload{kRecordAttributes, kAttributePartNormals};
      put_varint(payload, to - from);
      for (size_t ch = 0; ch < layout.channels.size(); ++ch) {
        if (!deferred(ch)) continue;
        const std::vector<uint8_t> bytes =
            normals_coder.encode(*full, truth, ch, from, to, &models[ch]);
        put_section(payload, bytes);
        local_parts[attribute_kind_name(layout.channels[ch].kind)] += bytes.size();
      }
      normals_records.push_back(std::move(payload));
      from = to;
    }
  }

  // The last record: the values of the vertices inserted since the last
  // values record, then the extra attributes.
  std::vector<uint8_t> last{kRecordAttributes, kAttributePartFinal};
  ValueCoder final_coder{layout};
  for (size_t ch = 0; ch < layout.channels.size(); ++ch) {
    const std::vector<uint8_t> bytes = final_coder.encode(*full, truth, ch, done, n);
    put_section(last, bytes);
    local_parts[attribute_kind_name(layout.channels[ch].kind)] += bytes.size();
  }
  const auto& extras = *plan.extras;
  put_varint(last, uint32_t(extras.size()));
  for (const ExtraAttribute& e : extras) {
    const size_t before = last.size();
    put_string(last, e.name);
    last.push_back(uint8_t(e.component_type));
    last.push_back(e.components);
    last.push_back(e.normalized ? 1 : 0);
    const uint32_t es = element_size(e);
    std::vector<uint8_t> raw(corner_map.size() * es);
    for (size_t dc = 0; dc < corner_map.size(); ++dc)
      std::memcpy(raw.data() + dc * es, e.bytes.data() + size_t(corner_map[dc]) * es, es);
    std::vector<uint8_t> packed(ZSTD_compressBound(raw.size()));
    const size_t z = ZSTD_compress(packed.data(), packed.size(), raw.data(), raw.size(), 19);
    if (ZSTD_isError(z)) return internal(std::string("zstd: ") + ZSTD_getErrorName(z));
    packed.resize(z);
    put_varint(last, uint32_t(raw.size()));
    put_section(last, packed);
    local_parts["extra"] += last.size() - before;
  }

  // The stream again with the attribute records.
  std::vector<std::vector<uint8_t>> payloads;
  std::vector<RecordCounts> counts;
  std::vector<AttributeRecordPlace> local_places;
  auto add_attributes = [&](std::vector<uint8_t> payload) {
    local_places.push_back({uint32_t(payloads.size()), uint32_t(payload.size())});
    counts.push_back(counts.back());
    payloads.push_back(std::move(payload));
  };
  // The low-bits record goes just before the first values record (the
  // values are predicted from the base's exact values), else after the
  // last geometry record. Right after record 1 (measured for version 15,
  // not kept) makes a base of every vertex exact sooner (Draco's textured
  // sphere 4 887 -> 3 566 bytes) but delays every geometry record by its
  // size, and there the coarse positions, not the 8-bit grid, are what the
  // display misses (sphere UV RMS 19.2 against 1.2-14.9 x 1e-3 at equal
  // bytes; bench/REPORT.md).
  for (size_t i = 0; i < idx.records.size(); ++i) {
    const RecordEntry& r = idx.records[i];
    const auto bytes = record_payload(r, stream.subspan(r.offset, r.size));
    payloads.emplace_back(bytes.begin(), bytes.end());
    counts.push_back({r.vertices, r.faces});
    if (i == 0) add_attributes(std::move(first));
    if (!values_after[i].empty()) {
      if (!low_bits.empty()) add_attributes(std::exchange(low_bits, {}));
      add_attributes(std::move(values_after[i]));
    }
  }
  if (!low_bits.empty()) add_attributes(std::exchange(low_bits, {}));
  for (std::vector<uint8_t>& r : normals_records) add_attributes(std::move(r));
  add_attributes(std::move(last));
  auto written = write_container(idx.header, payloads, counts);
  if (!written) return tl::unexpected(written.error());
  if (parts) *parts = std::move(local_parts);
  if (places) *places = std::move(local_places);
  return std::move(written->bytes);
}

Result<AttributeParts> attribute_record_parts(
    std::span<const uint8_t> base_payload,
    std::span<const std::span<const uint8_t>> values_payloads,
    std::span<const uint8_t> final_payload) {
  AttributeParts parts;
  if (base_payload.size() < 2 || base_payload[0] != kRecordAttributes ||
      base_payload[1] != kAttributePartBase)
    return tl::unexpected(parse_error("record 1 is not the base attribute record"));
  Reader r{base_payload, 2};
  auto layout_bytes = r.section();
  if (!r.ok) return tl::unexpected(parse_error("truncated"));
  auto layout = read_layout(layout_bytes);
  if (!layout) return tl::unexpected(layout.error());
  parts["layout"] += layout_bytes.size();
  if (any_corner_channel(*layout)) parts["seams"] += r.section().size();
  for (const AttributeChannel& c : layout->channels)
    if (in_base_record(c)) parts[attribute_kind_name(c.kind)] += r.section().size();
  if (!r.ok) return tl::unexpected(parse_error("base attribute record truncated"));
  for (std::span<const uint8_t> values : values_payloads) {
    if (values.size() < 2 || values[0] != kRecordAttributes || !is_values_part(values[1]))
      return tl::unexpected(parse_error("not a values record"));
    Reader v{values, 2};
    v.varint();
    for (const AttributeChannel& c : layout->channels)
      if (carried_in(values[1], c)) parts[attribute_kind_name(c.kind)] += v.section().size();
    if (!v.ok) return tl::unexpected(parse_error("values record truncated"));
  }
  if (final_payload.empty()) return parts;
  if (final_payload.size() < 2 || final_payload[0] != kRecordAttributes ||
      final_payload[1] != kAttributePartFinal)
    return tl::unexpected(parse_error("the last record is not the final attribute record"));
  Reader f{final_payload, 2};
  for (const AttributeChannel& c : layout->channels)
    parts[attribute_kind_name(c.kind)] += f.section().size();
  const uint32_t extras = f.varint();
  for (uint32_t i = 0; i < extras && f.ok && i < 64; ++i) {
    const size_t before = f.pos;
    f.string(4096);
    f.u8();
    f.u8();
    f.u8();
    f.varint();
    f.section();
    parts["extra"] += f.pos - before;
  }
  if (!f.ok) return tl::unexpected(parse_error("final attribute record truncated"));
  return parts;
}

// ---------------- decoder ----------------

Status AttributeDecoder::read_base(std::span<const uint8_t> payload, const EditableMesh& base) {
  if (active_) return tl::unexpected(parse_error("a second base attribute record"));
  if (payload.size() < 2 || payload[1] != kAttributePartBase)
    return tl::unexpected(parse_error("the first attribute record is not the base part"));
  Reader r{payload, 2};
  auto layout_bytes = r.section();
  if (!r.ok) return tl::unexpected(parse_error("layout section truncated"));
  auto layout = read_layout(layout_bytes);
  if (!layout) return tl::unexpected(layout.error());
  layout_ = std::move(*layout);
  const uint32_t n = base.vertex_count();
  base_vertices_ = n;
  values_ = AttributeValues{};
  values_.data.resize(layout_.channels.size());
  std::vector<uint32_t> ring, corners, keys;
  std::vector<uint8_t> bits;
  if (any_corner_channel(layout_)) {
    auto seam_bytes = r.section();
    if (!r.ok) return tl::unexpected(parse_error("seam section truncated"));
    RangeDecoder dec(seam_bytes);
    SeamModels models;
    for (uint32_t v = 0; v < n; ++v) {
      keys.clear();
      if (!base.is_isolated(v)) {
        const bool boundary = base.is_boundary(v);
        if (dec.decode_bit(models.split[boundary])) {
          base.star(v, ring, corners);
          bits.clear();
          uint32_t prev = 0;
          for (uint32_t c : corners) {
            if (base.opposite(EditableMesh::next(c)) == kNone) continue;
            prev = dec.decode_bit(models.edge[boundary][prev]);
            bits.push_back(uint8_t(prev));
          }
          keys_from_star(base, v, bits, corners, keys);
          if (keys.size() < 2)
            return tl::unexpected(parse_error("base vertex " + std::to_string(v) +
                                              " is split by fewer than two seams"));
        }
      }
      if (keys.empty()) keys.push_back(kNone);
      for (uint32_t k : keys) values_.wedge_key.push_back(k);
      values_.wedge_start.push_back(uint32_t(values_.wedge_key.size()));
      if (dec.exhausted_badly()) return tl::unexpected(parse_error("seam data runs out"));
    }
  } else {
    for (uint32_t v = 0; v < n; ++v) {
      values_.wedge_key.push_back(kNone);
      values_.wedge_start.push_back(v + 1);
    }
  }
  // Coarse channels (version 14) decode on their coarse grids.
  const AttributeLayout record1_layout = coarse_layout(layout_);
  ValueCoder coder{record1_layout, true};
  bool normals_late = false;
  for (size_t ch = 0; ch < layout_.channels.size(); ++ch) {
    const AttributeChannel& c = layout_.channels[ch];
    values_.data[ch].assign(size_t(c.per_corner ? values_.wedge_key.size() : n) * c.components(),
                            0);
    if (!in_base_record(c)) {
      // Version 13: the base's normals come later; each wedge shows its
      // geometric normal on the base meanwhile.
      normals_late = true;
      for (uint32_t v = 0; v < n; ++v)
        show_geometric_normals(base, values_, layout_, ch, v, ring, corners);
      continue;
    }
    auto bytes = r.section();
    if (!r.ok) return tl::unexpected(parse_error("value section truncated"));
    if (auto s = coder.decode(base, values_, ch, 0, n, bytes); !s) return s;
    if (c.flags & kBaseCoarse) {
      // Shown at the middle of the low bits' range until they come.
      for (int32_t& x : values_.data[ch]) x = (x << c.base_shift) | (1 << (c.base_shift - 1));
      low_bits_pending_ = true;
      base_mesh_ = base;
    }
  }
  if (r.pos != payload.size()) return tl::unexpected(parse_error("bytes after the base part"));
  exact_vertices_ = n;
  normals_exact_ = normals_late ? 0 : n;
  normals_refreshed_ = n;
  values_models_.assign(layout_.channels.size(), ChannelModels{});
  active_ = true;
  return {};
}

Status AttributeDecoder::read_values(std::span<const uint8_t> payload, const EditableMesh& m) {
  if (!active_)
    return tl::unexpected(parse_error("values record before the base attribute record"));
  if (complete_) return tl::unexpected(parse_error("values record after the final one"));
  const uint8_t part = payload.size() > 1 ? payload[1] : 0xFF;
  if (part != kAttributePartValues && part != kAttributePartValuesLateNormals)
    return tl::unexpected(parse_error("not a values record"));
  if (part == kAttributePartValues && normals_exact_ != exact_vertices_)
    return tl::unexpected(parse_error("values record with normals after one without"));
  if (low_bits_pending_)
    return tl::unexpected(parse_error("values record before the base's low bits"));
  Reader r{payload, 2};
  const uint32_t count = r.varint();
  if (!r.ok) return tl::unexpected(parse_error("values record truncated"));
  const uint32_t now = m.vertex_count();
  if (count == 0 || uint64_t(exact_vertices_) + count != now)
    return tl::unexpected(parse_error(
        "values record for " + std::to_string(count) + " vertices where " +
        std::to_string(now - std::min(now, exact_vertices_)) + " were inserted since the last"));
  // Room for the vertices not previewed (a decoder that keeps no output
  // mesh previews none); every one of them is decoded below.
  for (uint32_t v = values_.vertices(); v < now; ++v) {
    values_.wedge_key.push_back(kNone);
    values_.wedge_start.push_back(uint32_t(values_.wedge_key.size()));
    for (size_t ch = 0; ch < layout_.channels.size(); ++ch)
      values_.data[ch].resize(values_.data[ch].size() + layout_.channels[ch].components());
  }
  ValueCoder coder{layout_};
  for (size_t ch = 0; ch < layout_.channels.size(); ++ch) {
    if (!carried_in(part, layout_.channels[ch])) continue;
    auto bytes = r.section();
    if (!r.ok) return tl::unexpected(parse_error("value section truncated"));
    if (auto s = coder.decode(m, values_, ch, exact_vertices_, now, bytes, &values_models_[ch]); !s)
      return s;
  }
  if (r.pos != payload.size()) return tl::unexpected(parse_error("bytes after a values record"));
  if (part == kAttributePartValues) normals_exact_ = now;
  exact_vertices_ = now;
  return {};
}

Status AttributeDecoder::read_normals(std::span<const uint8_t> payload, const EditableMesh& full) {
  if (!active_)
    return tl::unexpected(parse_error("normals record before the base attribute record"));
  if (complete_) return tl::unexpected(parse_error("normals record after the final one"));
  if (low_bits_pending_)
    return tl::unexpected(parse_error("normals record before the base's low bits"));
  Reader r{payload, 2};
  const uint32_t count = r.varint();
  if (!r.ok) return tl::unexpected(parse_error("normals record truncated"));
  if (count == 0 || uint64_t(normals_exact_) + count > exact_vertices_)
    return tl::unexpected(
        parse_error("normals record for " + std::to_string(count) + " vertices where " +
                    std::to_string(exact_vertices_ - normals_exact_) + " wait for their normals"));
  ValueCoder coder{layout_};
  for (size_t ch = 0; ch < layout_.channels.size(); ++ch) {
    if (!carried_in(kAttributePartNormals, layout_.channels[ch])) continue;
    auto bytes = r.section();
    if (!r.ok) return tl::unexpected(parse_error("normal section truncated"));
    if (auto s = coder.decode(full, values_, ch, normals_exact_, normals_exact_ + count, bytes,
                              &values_models_[ch]);
        !s)
      return s;
  }
  if (r.pos != payload.size()) return tl::unexpected(parse_error("bytes after a normals record"));
  normals_exact_ += count;
  return {};
}

void AttributeDecoder::preview(const EditableMesh& m) {
  if (!active_) return;
  std::vector<uint32_t> ring, corners;
  int32_t pred[4];
  for (uint32_t v = values_.vertices(); v < m.vertex_count(); ++v) {
    const uint32_t w = uint32_t(values_.wedge_key.size());
    values_.wedge_key.push_back(kNone);
    values_.wedge_start.push_back(w + 1);
    for (size_t ch = 0; ch < layout_.channels.size(); ++ch) {
      const AttributeChannel& c = layout_.channels[ch];
      const uint32_t nc = c.components();
      values_.data[ch].resize(values_.data[ch].size() + nc);
      // Normals: the geometric normal of the mesh now (version 12's values
      // records leave them to the end; refresh_normal_previews updates it);
      // the others: the mean of the decoded neighbours' values.
      predict(
          m, values_, layout_, ch, v, w,
          c.kind == AttributeKind::kNormal ? Prediction::kGeometric : Prediction::kNeighbourMean,
          pred, ring, corners);
      std::copy(pred, pred + nc, values_.data[ch].end() - nc);
    }
  }
}

void AttributeDecoder::refresh_normal_previews(const EditableMesh& m) {
  if (!active_ || complete_) return;
  const uint32_t now = std::min(m.vertex_count(), values_.vertices());
  if (normals_exact_ >= now) {
    normals_refreshed_ = std::max(normals_refreshed_, now);
    return;
  }
  std::vector<uint32_t> ring, corners, stale;
  // A star changes when a neighbour is inserted: the vertices inserted since
  // the last refresh, and their rings.
  for (uint32_t u = std::max(normals_refreshed_, normals_exact_); u < now; ++u) {
    stale.push_back(u);
    m.star(u, ring, corners);
    for (uint32_t v : ring)
      if (v >= normals_exact_ && v < now) stale.push_back(v);
  }
  std::sort(stale.begin(), stale.end());
  stale.erase(std::unique(stale.begin(), stale.end()), stale.end());
  for (size_t ch = 0; ch < layout_.channels.size(); ++ch) {
    if (layout_.channels[ch].kind != AttributeKind::kNormal) continue;
    // Inserted vertices have one wedge, base vertices (version 13's
    // normals wait for them too) one or more.
    for (uint32_t v : stale) show_geometric_normals(m, values_, layout_, ch, v, ring, corners);
  }
  normals_refreshed_ = now;
}

Status AttributeDecoder::read_low_bits(std::span<const uint8_t> payload) {
  if (!active_)
    return tl::unexpected(parse_error("low-bits record before the base attribute record"));
  if (!low_bits_pending_)
    return tl::unexpected(parse_error("low-bits record without coarse base values to refine"));
  Reader r{payload, 2};
  const uint32_t count = r.varint();
  if (!r.ok || count != base_vertices_)
    return tl::unexpected(parse_error("low-bits record for " + std::to_string(count) +
                                      " vertices where the base has " +
                                      std::to_string(base_vertices_)));
  for (size_t ch = 0; ch < layout_.channels.size(); ++ch) {
    const AttributeChannel& c = layout_.channels[ch];
    if (!(c.flags & kBaseCoarse)) continue;
    auto bytes = r.section();
    if (!r.ok) return tl::unexpected(parse_error("low-bits section truncated"));
    LowBitCoder coder(layout_, ch);
    if (auto s = coder.decode(base_mesh_, values_, base_vertices_, bytes); !s) return s;
  }
  if (r.pos != payload.size()) return tl::unexpected(parse_error("bytes after a low-bits record"));
  low_bits_pending_ = false;
  base_mesh_ = EditableMesh{};
  return {};
}

Status AttributeDecoder::read_final(std::span<const uint8_t> payload, const EditableMesh& full) {
  if (!active_) return tl::unexpected(parse_error("final attribute record before the base one"));
  if (complete_) return tl::unexpected(parse_error("a second final attribute record"));
  if (payload.size() < 2 || payload[1] != kAttributePartFinal)
    return tl::unexpected(parse_error("unknown attribute record part"));
  if (low_bits_pending_)
    return tl::unexpected(parse_error("final attribute record before the base's low bits"));
  Reader r{payload, 2};
  const uint32_t n = full.vertex_count();
  // Back to the exact values (the base's and the values records'); every
  // vertex inserted after them decoded exactly.
  values_.wedge_start.resize(exact_vertices_ + 1);
  values_.wedge_key.resize(values_.wedge_start.back());
  for (uint32_t v = exact_vertices_; v < n; ++v) {
    values_.wedge_key.push_back(kNone);
    values_.wedge_start.push_back(uint32_t(values_.wedge_key.size()));
  }
  ValueCoder coder{layout_};
  for (size_t ch = 0; ch < layout_.channels.size(); ++ch) {
    const AttributeChannel& c = layout_.channels[ch];
    values_.data[ch].resize(size_t(c.per_corner ? values_.wedge_key.size() : n) * c.components());
    auto bytes = r.section();
    if (!r.ok) return tl::unexpected(parse_error("value section truncated"));
    // Normals from the first vertex whose normal has not come (version 12's
    // values records leave them to normals records and this one).
    const uint32_t from = c.kind == AttributeKind::kNormal ? normals_exact_ : exact_vertices_;
    if (auto s = coder.decode(full, values_, ch, from, n, bytes); !s) return s;
  }
  const uint32_t extra_count = r.varint();
  if (!r.ok || extra_count > 64) return tl::unexpected(parse_error("bad extra attribute count"));
  const size_t corners = 3 * size_t(full.face_slot_count());
  extras_.clear();
  for (uint32_t i = 0; i < extra_count; ++i) {
    ExtraAttribute e;
    e.name = r.string(4096);
    const uint8_t type = r.u8();
    e.components = r.u8();
    e.normalized = r.u8() != 0;
    const uint32_t raw = r.varint();
    auto packed = r.section();
    if (!r.ok) return tl::unexpected(parse_error("extra attribute truncated"));
    if (type > uint8_t(ExtraAttribute::ComponentType::kFloat32) || e.components < 1 ||
        e.components > 4)
      return tl::unexpected(parse_error("extra attribute '" + e.name + "' has a bad type"));
    e.component_type = ExtraAttribute::ComponentType(type);
    if (raw != corners * element_size(e))
      return tl::unexpected(
          parse_error("extra attribute '" + e.name + "' size differs from the corners'"));
    const unsigned long long frame = ZSTD_getFrameContentSize(packed.data(), packed.size());
    if (frame != raw)
      return tl::unexpected(
          parse_error("extra attribute '" + e.name + "' is not a zstd frame of its size"));
    e.bytes.resize(raw);
    const size_t got = ZSTD_decompress(e.bytes.data(), raw, packed.data(), packed.size());
    if (ZSTD_isError(got) || got != raw)
      return tl::unexpected(parse_error("extra attribute '" + e.name + "' does not decompress"));
    extras_.push_back(std::move(e));
  }
  if (r.pos != payload.size()) return tl::unexpected(parse_error("bytes after the final part"));
  exact_vertices_ = n;
  normals_exact_ = n;
  complete_ = true;
  return {};
}

void AttributeDecoder::write_vertex_values(uint32_t first_vertex, Mesh& out) const {
  const uint32_t n = values_.vertices();
  for (size_t ch = 0; ch < layout_.channels.size(); ++ch) {
    const AttributeChannel& c = layout_.channels[ch];
    const auto& d = values_.data[ch];
    if (c.kind == AttributeKind::kMaterial) continue;
    const uint32_t w0 =
        c.per_corner ? values_.wedge_start[std::min(first_vertex, n)] : first_vertex;
    const uint32_t w1 = c.per_corner ? uint32_t(values_.wedge_key.size()) : n;
    auto normal = [&](uint32_t w) { return dequantize_normal({d[2 * w], d[2 * w + 1]}, c.bits); };
    auto uv = [&](uint32_t w) { return dequantize_texcoord(c.uv, {d[2 * w], d[2 * w + 1]}); };
    auto color = [&](uint32_t w) {
      return Vec4f{dequantize_color_channel(d[4 * w], c.bits),
                   dequantize_color_channel(d[4 * w + 1], c.bits),
                   dequantize_color_channel(d[4 * w + 2], c.bits),
                   dequantize_color_channel(d[4 * w + 3], c.bits)};
    };
    switch (c.kind) {
      case AttributeKind::kNormal: {
        auto& target = c.per_corner ? out.corner_normals.values : out.normals;
        target.resize(w1);
        for (uint32_t w = w0; w < w1; ++w) target[w] = normal(w);
        break;
      }
      case AttributeKind::kTexcoord: {
        auto& target = c.per_corner ? out.corner_texcoords.values : out.texcoords;
        target.resize(w1);
        for (uint32_t w = w0; w < w1; ++w) target[w] = uv(w);
        break;
      }
      case AttributeKind::kColor: {
        auto& target = c.per_corner ? out.corner_colors.values : out.colors;
        target.resize(w1);
        for (uint32_t w = w0; w < w1; ++w) target[w] = color(w);
        break;
      }
      case AttributeKind::kMaterial:
        break;
    }
  }
}

void AttributeDecoder::write_face(const EditableMesh& m, uint32_t f, Mesh& out) const {
  for (size_t ch = 0; ch < layout_.channels.size(); ++ch) {
    const AttributeChannel& c = layout_.channels[ch];
    if (!c.per_corner) continue;
    if (c.kind == AttributeKind::kMaterial) {
      const uint32_t w = wedge_of_corner(m, values_, 3 * f);
      out.face_materials[f] = uint32_t(values_.data[ch][w]);
      continue;
    }
    auto& corners = c.kind == AttributeKind::kNormal     ? out.corner_normals.corners
                    : c.kind == AttributeKind::kTexcoord ? out.corner_texcoords.corners
                                                         : out.corner_colors.corners;
    for (uint32_t k = 0; k < 3; ++k) corners[3 * f + k] = wedge_of_corner(m, values_, 3 * f + k);
  }
}

void AttributeDecoder::write_materials(Mesh& out) const {
  if (!active_) return;
  out.materials = layout_.materials;
  const int32_t textures = int32_t(out.textures.size());
  for (Material& m : out.materials) {
    for (int32_t* t : {&m.base_color_texture, &m.normal_texture, &m.metallic_roughness_texture,
                       &m.occlusion_texture, &m.emissive_texture})
      if (*t >= textures || *t < -1) *t = -1;
  }
}

void AttributeDecoder::write_mesh(const EditableMesh& m, Mesh& out) const {
  if (!active_) return;
  write_materials(out);
  write_vertex_values(0, out);
  const uint32_t faces = m.face_slot_count();
  for (const AttributeChannel& c : layout_.channels) {
    if (!c.per_corner) continue;
    if (c.kind == AttributeKind::kMaterial) out.face_materials.assign(faces, 0);
    if (c.kind == AttributeKind::kNormal) out.corner_normals.corners.assign(3 * size_t(faces), 0);
    if (c.kind == AttributeKind::kTexcoord)
      out.corner_texcoords.corners.assign(3 * size_t(faces), 0);
    if (c.kind == AttributeKind::kColor) out.corner_colors.corners.assign(3 * size_t(faces), 0);
  }
  for (uint32_t f = 0; f < faces; ++f) write_face(m, f, out);
  if (complete_) out.extra_attributes = extras_;
}

void AttributeDecoder::update_mesh(const EditableMesh& m, uint32_t first_vertex,
                                   std::span<const uint32_t> faces, Mesh& out) const {
  if (!active_) return;
  write_vertex_values(first_vertex, out);
  const size_t count = m.face_slot_count();
  for (const AttributeChannel& c : layout_.channels) {
    if (!c.per_corner) continue;
    if (c.kind == AttributeKind::kMaterial) out.face_materials.resize(count);
    if (c.kind == AttributeKind::kNormal) out.corner_normals.corners.resize(3 * count);
    if (c.kind == AttributeKind::kTexcoord) out.corner_texcoords.corners.resize(3 * count);
    if (c.kind == AttributeKind::kColor) out.corner_colors.corners.resize(3 * count);
  }
  for (uint32_t f : faces) write_face(m, f, out);
}

}  // namespace meshstream
