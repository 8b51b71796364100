// The record table: see record_table.h.
#include "common/codec/record_table.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "common/codec/byte_io.h"
#include "common/codec/container.h"
#include "common/codec/decoder.h"
#include "common/codec/stream_format.h"
#include "common/mesh/adjacency.h"

namespace meshstream {

BoundingSphere bounding_sphere(std::span<const Vec3f> points) {
  BoundingSphere s;
  if (points.empty()) return s;
  auto far_from = [&](Vec3d from) {
    size_t best = 0;
    double best_d = -1;
    for (size_t i = 0; i < points.size(); ++i) {
      const double d = squared_length(to_double(points[i]) - from);
      if (d > best_d) best_d = d, best = i;
    }
    return to_double(points[best]);
  };
  // Ritter (1990): a diameter guess from two far points, then grow the
  // sphere to take in every point outside it.
  const Vec3d a = far_from(to_double(points[0]));
  const Vec3d b = far_from(a);
  Vec3d c = (a + b) * 0.5;
  double r = length(b - a) * 0.5;
  for (const Vec3f& p : points) {
    const Vec3d q = to_double(p);
    const double d = length(q - c);
    if (d > r) {
      const double grown = (r + d) * 0.5;
      c = c + (q - c) * ((grown - r) / d);
      r = grown;
    }
  }
  // Float rounding of the centre must not leave a point outside.
  s.center = to_float(c);
  double worst = 0;
  for (const Vec3f& p : points) worst = std::max(worst, length(to_double(p) - to_double(s.center)));
  s.radius = static_cast<float>(worst * (1 + 1e-6));
  return s;
}

std::vector<uint32_t> needs_closure(const RecordTable& table, std::span<const uint32_t> seeds) {
  const size_t n = table.records.size();
  std::vector<uint8_t> in(n, 0);
  std::vector<uint32_t> stack;
  for (uint32_t s : seeds) {
    if (s < n && !in[s]) in[s] = 1, stack.push_back(s);
  }
  while (!stack.empty()) {
    const uint32_t r = stack.back();
    stack.pop_back();
    for (uint32_t need : table.records[r].needs) {
      if (!in[need]) in[need] = 1, stack.push_back(need);
    }
  }
  std::vector<uint32_t> out;
  for (uint32_t r = 0; r < n; ++r) {
    if (in[r]) out.push_back(r);
  }
  return out;
}

namespace {

Vec3d face_normal(const std::vector<Vec3f>& pos, const Triangle& t) {
  const Vec3d a = to_double(pos[t[0]]), b = to_double(pos[t[1]]), c = to_double(pos[t[2]]);
  return cross(b - a, c - a);  // length = twice the area
}

// Distance from p to triangle (a, b, c) (Ericson, Real-Time Collision
// Detection, 5.1.5).
double point_triangle_distance(Vec3d p, Vec3d a, Vec3d b, Vec3d c) {
  const Vec3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return length(p - a);
  const Vec3d bp = p - b;
  const double d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return length(p - b);
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return length(p - (a + ab * (d1 / (d1 - d3))));
  const Vec3d cp = p - c;
  const double d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return length(p - c);
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return length(p - (a + ac * (d2 / (d2 - d6))));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
    return length(p - (b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)))));
  const double denom = 1.0 / (va + vb + vc);
  return length(p - (a + ab * (vb * denom) + ac * (vc * denom)));
}

NormalCone normal_cone(const std::vector<Vec3f>& pos, const std::vector<Triangle>& faces,
                       std::span<const uint32_t> slots) {
  NormalCone cone;
  Vec3d sum{0, 0, 0};
  for (uint32_t f : slots) sum += face_normal(pos, faces[f]);
  const double len = length(sum);
  if (!(len > 0)) return cone;
  const Vec3d axis = sum / len;
  double worst = 1;
  for (uint32_t f : slots) {
    const Vec3d n = face_normal(pos, faces[f]);
    const double l = length(n);
    if (l > 0) worst = std::min(worst, dot(axis, n) / l);
  }
  cone.axis = to_float(axis);
  // A little slack for the float axis.
  cone.cos_half_angle = static_cast<float>(std::max(-1.0, worst - 1e-6));
  return cone;
}

void add_need(std::vector<uint32_t>& list, uint32_t v) {
  if (v != kNone) list.push_back(v);
}
void sort_unique(std::vector<uint32_t>& list) {
  std::sort(list.begin(), list.end());
  list.erase(std::unique(list.begin(), list.end()), list.end());
}

}  // namespace

Result<RecordTable> build_record_table(std::span<const uint8_t> stream, RecordTrace* trace) {
  auto index = read_stream_index(stream);
  if (!index) return tl::unexpected(index.error());
  if (index->records.empty() || index->total_bytes() > stream.size())
    return make_error(ErrorCode::kTruncated, "record table: the stream is not whole");
  const uint32_t count = static_cast<uint32_t>(index->records.size());
  RecordTable table;
  table.prefix_bytes = index->payload_offset;
  table.total_bytes = index->total_bytes();
  table.records.resize(count);

  IncrementalDecoder decoder(DecodedMeshUpkeep::kEveryRecord);
  if (auto fed = decoder.feed(stream.first(index->payload_offset)); !fed)
    return tl::unexpected(fed.error());

  // The decoder's state as the table follows it.
  std::vector<Vec3f> pos;
  std::vector<Triangle> faces;
  std::vector<std::vector<uint32_t>> vertex_faces;  // slots around each vertex
  std::vector<uint32_t> creator, last_plane;        // per vertex: records
  std::vector<uint32_t> slot_writer;                // per slot: record
  // The same at element level (trace only).
  std::vector<uint32_t> creator_elem, plane_elem, slot_elem;
  const bool elements = trace != nullptr;
  if (trace) *trace = RecordTrace{};

  uint32_t layer = 0;
  std::vector<uint32_t> ring, region_slots, elem_needs;
  std::vector<Vec3f> points;
  std::vector<uint8_t> mark;
  for (uint32_t r = 0; r < count; ++r) {
    const RecordEntry& rec = index->records[r];
    const std::span<const uint8_t> payload =
        record_payload(rec, stream.subspan(rec.offset, rec.size));
    RecordTableEntry& e = table.records[r];
    e.bytes = rec.size;
    const uint32_t old_slots = static_cast<uint32_t>(faces.size());
    auto fed = decoder.feed(stream.subspan(rec.offset, rec.size));
    if (!fed) return tl::unexpected(fed.error());
    if (*fed != 1 || decoder.last_deltas().size() != 1)
      return make_error(ErrorCode::kInternal, "record table: record " + std::to_string(r) +
                                                  " did not decode on its own bytes");
    const RecordDelta& delta = decoder.last_deltas()[0];
    const Mesh& mesh = decoder.mesh();
    const uint8_t flags = payload.empty() ? 0 : payload[0];
    if (r == 0) {
      e.kind = RecordKind::kBase;
    } else if (flags == kRecordPlane) {
      e.kind = RecordKind::kPlane;
    } else if (flags == kRecordAttributes || flags == kRecordTexture) {
      e.kind = RecordKind::kOther;
    } else {
      e.kind = RecordKind::kStructure;
      if (flags & kRecordStartsLayer) ++layer;
      e.layer = layer;
    }

    // Positions before the record (plane errors), then the face writes.
    std::vector<std::pair<uint32_t, Vec3f>> moved_before;
    for (uint32_t v : delta.moved_vertices) moved_before.push_back({v, pos[v]});
    std::vector<FaceWrite> writes;
    if (e.kind == RecordKind::kBase || e.kind == RecordKind::kStructure) {
      for (uint32_t f : delta.touched_faces) {
        FaceWrite w;
        w.slot = f;
        w.after = mesh.triangles[f];
        w.appended = f >= old_slots;
        if (!w.appended) w.before = faces[f];
        writes.push_back(w);
      }
    }
    pos.resize(mesh.positions.size());
    for (uint32_t v : delta.added_vertices) pos[v] = mesh.positions[v];
    for (uint32_t v : delta.moved_vertices) pos[v] = mesh.positions[v];
    const uint32_t nv = static_cast<uint32_t>(pos.size());
    creator.resize(nv, kNone);
    last_plane.resize(nv, kNone);
    vertex_faces.resize(nv);
    if (elements) creator_elem.resize(nv, kNone), plane_elem.resize(nv, kNone);
    mark.resize(nv, 0);

    if (e.kind == RecordKind::kBase || e.kind == RecordKind::kStructure) {
      // Needs: the writers of the slots it rewrites, the creators of the
      // vertices around (ring) and the last plane records of those (its
      // predictions read their positions and shifts).
      for (const FaceWrite& w : writes)
        if (!w.appended) add_need(e.needs, slot_writer[w.slot]);
      for (uint32_t v : delta.added_vertices) mark[v] = 1;
      ring.clear();
      for (const FaceWrite& w : writes)
        for (uint32_t v : w.after)
          if (!mark[v]) ring.push_back(v);
      sort_unique(ring);
      for (uint32_t v : ring) add_need(e.needs, creator[v]), add_need(e.needs, last_plane[v]);
      // Error: each inserted vertex against the faces its patch replaced.
      double error = 0;
      for (uint32_t v : delta.added_vertices) {
        double best = -1;
        for (const FaceWrite& w : writes) {
          if (w.appended || std::find(w.after.begin(), w.after.end(), v) == w.after.end()) continue;
          const double d =
              point_triangle_distance(to_double(pos[v]), to_double(pos[w.before[0]]),
                                      to_double(pos[w.before[1]]), to_double(pos[w.before[2]]));
          if (best < 0 || d < best) best = d;
        }
        error = std::max(error, best);
      }
      // The faces of the patch it replaced, now rewritten: the elements.
      if (elements) {
        const uint32_t first_elem = static_cast<uint32_t>(trace->elements.size());
        if (e.kind == RecordKind::kBase) {
          RecordElement base;
          base.record = 0;
          base.bytes = double(rec.size);
          trace->elements.push_back(base);
          for (uint32_t v : delta.added_vertices) creator_elem[v] = first_elem;
          for (const FaceWrite& w : writes) {
            if (w.slot >= slot_elem.size()) slot_elem.resize(w.slot + 1, kNone);
            slot_elem[w.slot] = first_elem;
          }
        } else {
          const double share =
              double(rec.size) / double(std::max<size_t>(1, delta.added_vertices.size()));
          // Each write belongs to the highest inserted vertex in its face.
          std::vector<uint32_t> owner(writes.size(), kNone);
          for (size_t i = 0; i < writes.size(); ++i)
            for (uint32_t v : writes[i].after)
              if (mark[v] && (owner[i] == kNone || v > owner[i])) owner[i] = v;
          for (uint32_t v : delta.added_vertices) {
            elem_needs.clear();
            for (size_t i = 0; i < writes.size(); ++i) {
              if (owner[i] != v) continue;
              if (!writes[i].appended) add_need(elem_needs, slot_elem[writes[i].slot]);
              for (uint32_t u : writes[i].after) {
                if (u == v) continue;
                if (mark[u]) {
                  if (creator_elem[u] != kNone) add_need(elem_needs, creator_elem[u]);
                } else {
                  add_need(elem_needs, creator_elem[u]);
                  add_need(elem_needs, plane_elem[u]);
                }
              }
            }
            sort_unique(elem_needs);
            RecordElement el;
            el.record = r;
            el.vertex = v;
            el.bytes = share;
            el.needs_begin = static_cast<uint32_t>(trace->element_needs.size());
            trace->element_needs.insert(trace->element_needs.end(), elem_needs.begin(),
                                        elem_needs.end());
            el.needs_end = static_cast<uint32_t>(trace->element_needs.size());
            creator_elem[v] = static_cast<uint32_t>(trace->elements.size());
            trace->elements.push_back(el);
          }
          for (size_t i = 0; i < writes.size(); ++i) {
            if (writes[i].slot >= slot_elem.size()) slot_elem.resize(writes[i].slot + 1, kNone);
            slot_elem[writes[i].slot] = owner[i] == kNone ? kNone : creator_elem[owner[i]];
          }
        }
      }
      for (uint32_t v : delta.added_vertices) mark[v] = 0;
      // Apply the writes to the table's copy.
      faces.resize(mesh.triangles.size());
      slot_writer.resize(faces.size(), kNone);
      for (const FaceWrite& w : writes) {
        if (!w.appended) {
          for (uint32_t v : w.before) {
            auto& list = vertex_faces[v];
            const auto at = std::find(list.begin(), list.end(), w.slot);
            if (at == list.end())
              return make_error(ErrorCode::kInternal,
                                "record table: record " + std::to_string(r) +
                                    " rewrites a face its table copy does not hold");
            list.erase(at);
          }
        }
        for (uint32_t v : w.after) vertex_faces[v].push_back(w.slot);
        faces[w.slot] = w.after;
        slot_writer[w.slot] = r;
      }
      for (uint32_t v : delta.added_vertices) creator[v] = r;
      // Where it acts: the faces it wrote.
      points.clear();
      region_slots.clear();
      for (const FaceWrite& w : writes) {
        region_slots.push_back(w.slot);
        for (uint32_t v : w.after) points.push_back(pos[v]);
      }
      for (uint32_t v : delta.added_vertices) points.push_back(pos[v]);
      e.sphere = bounding_sphere(points);
      e.cone = normal_cone(pos, faces, region_slots);
      e.error = static_cast<float>(error);
    } else if (e.kind == RecordKind::kPlane) {
      size_t at = 1;
      uint32_t first = 0, n = 0;
      if (!get_varint(payload, at, first) || !get_varint(payload, at, n) || first >= nv ||
          n > nv - first)
        return make_error(ErrorCode::kCorrupt, "record table: plane record " + std::to_string(r));
      for (uint32_t v = first; v < first + n; ++v)
        add_need(e.needs, creator[v]), add_need(e.needs, last_plane[v]);
      double error = 0;
      for (const auto& [v, before] : moved_before)
        error = std::max(error, length(to_double(pos[v]) - to_double(before)));
      e.error = static_cast<float>(error);
      if (elements) {
        const double share = double(rec.size) / double(n);
        for (uint32_t v = first; v < first + n; ++v) {
          RecordElement el;
          el.record = r;
          el.vertex = v;
          el.bytes = share;
          el.needs_begin = static_cast<uint32_t>(trace->element_needs.size());
          trace->element_needs.push_back(creator_elem[v]);
          if (plane_elem[v] != kNone) trace->element_needs.push_back(plane_elem[v]);
          el.needs_end = static_cast<uint32_t>(trace->element_needs.size());
          plane_elem[v] = static_cast<uint32_t>(trace->elements.size());
          trace->elements.push_back(el);
        }
      }
      for (uint32_t v = first; v < first + n; ++v) last_plane[v] = r;
      points.clear();
      region_slots.clear();
      for (uint32_t v = first; v < first + n; ++v) points.push_back(pos[v]);
      for (const auto& [v, before] : moved_before) {
        for (uint32_t f : vertex_faces[v]) {
          region_slots.push_back(f);
          for (uint32_t u : faces[f]) points.push_back(pos[u]);
        }
      }
      sort_unique(region_slots);
      e.sphere = bounding_sphere(points);
      e.cone = normal_cone(pos, faces, region_slots);
    } else {
      // Attribute and texture records carry data for the whole mesh.
      for (uint32_t q = 0; q < r; ++q) e.needs.push_back(q);
    }
    sort_unique(e.needs);
    if (trace) trace->writes.push_back(std::move(writes));
  }
  table.model = bounding_sphere(pos);
  table.records[0].error = table.model.radius;
  for (RecordTableEntry& e : table.records) {
    if (e.kind == RecordKind::kOther) e.sphere = table.model;
  }
  if (trace) {
    trace->positions = pos;
    trace->faces = faces;
  }
  return table;
}

}  // namespace meshstream
