// The record table of an `.hcs` stream (issue 17, view-dependent
// streaming): per record where it acts (bounding sphere, normal cone), how
// far it moves the surface (geometric error) and which earlier records it
// needs — the records that wrote the faces it rewrites, inserted the
// vertices it reads and last sharpened their positions. Any set of records
// closed under "needs" names a conforming mesh (tests/codec/record_table_test:
// its face edits replay to a manifold mesh, in any order that respects the
// needs), which is what a view-ordered client would fetch.
//
// The needs are the records' *data* dependencies, as a record coded with
// encoder-fixed ids would have them (docs/view-dependent-records.md). Today's
// records also depend on everything before them through their coding (the
// layer's walk over the order list and entropy models carried across
// records); the table does not list that, and today's decoder still needs the
// stream in order.
//
// Built by decoding the stream once, record by record (the encoder's own
// output; the table is what the encoder would write beside the index). The
// stream must be whole and intact.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "common/base/result.h"
#include "common/mesh/mesh.h"

namespace meshstream {

enum class RecordKind : uint8_t {
  kBase = 0,
  kStructure = 1,  // inserts vertices (a run of one layer's walk)
  kPlane = 2,      // sharpens positions by one bit plane
  kOther = 3,      // attribute or texture record: treated as needing everything before it
};

struct BoundingSphere {
  Vec3f center;
  float radius = 0;
};

// Every changed face's normal lies within the cone: dot(axis, n) >=
// cos_half_angle. cos_half_angle = -1: any direction (no face with area, or
// normals all around).
struct NormalCone {
  Vec3f axis{0, 0, 1};
  float cos_half_angle = -1;
};

struct RecordTableEntry {
  RecordKind kind = RecordKind::kBase;
  uint32_t layer = 0;  // structure records: the layer restored, 1 = the first after the base
  uint64_t bytes = 0;  // the record's size in the stream (payload and trailer)
  // Contains every vertex of every face the record writes or moves (after
  // the record), and the vertices it inserts or sharpens.
  BoundingSphere sphere;
  NormalCone cone;
  // How far the record moves the surface, in the stream's units (the
  // decoded positions'): a structure record the largest distance of an
  // inserted vertex from the faces its patch replaces; a plane record the
  // largest move of a vertex. The base: the model's bounding radius.
  float error = 0;
  // Earlier records this one needs, ascending, each < its own index.
  std::vector<uint32_t> needs;
};

struct RecordTable {
  std::vector<RecordTableEntry> records;
  BoundingSphere model;       // of the full mesh
  uint64_t prefix_bytes = 0;  // magic, header and index: sent before any record
  uint64_t total_bytes = 0;   // the whole stream
};

// One face slot a record wrote: `before` is kNoFace for a slot it appended.
struct FaceWrite {
  uint32_t slot = 0;
  Triangle before{};
  Triangle after{};
  bool appended = false;
};

// One unit below the record: an inserted vertex (structure record), one
// vertex's plane step (plane record), or the base; with the elements it
// needs. The finest dependency graph the stream has (bench/record_graph_bench:
// how local records could be at best, and records regrouped by cell).
struct RecordElement {
  uint32_t record = 0;
  uint32_t vertex = 0;                      // decoder id; the base element: 0
  double bytes = 0;                         // its share of its record's bytes
  uint32_t needs_begin = 0, needs_end = 0;  // into RecordTrace::element_needs
};

// What build_record_table can also report (tests, benchmarks).
struct RecordTrace {
  std::vector<std::vector<FaceWrite>> writes;  // per record, in the decoder's order
  std::vector<Vec3f> positions;                // the full decode's
  std::vector<Triangle> faces;                 // the full decode's, by slot
  std::vector<RecordElement> elements;         // element 0 is the base
  std::vector<uint32_t> element_needs;         // element ids, each below its element's
};

// The table of the whole, intact stream `stream` (kTruncated / the decoder's
// error otherwise). O(stream) time; O(vertices + faces) memory, more with
// a trace (O(elements) and the face writes).
Result<RecordTable> build_record_table(std::span<const uint8_t> stream,
                                       RecordTrace* trace = nullptr);

// The smallest set holding `seeds` closed under needs, ascending. Seeds
// out of range are ignored.
std::vector<uint32_t> needs_closure(const RecordTable& table, std::span<const uint32_t> seeds);

// The smallest-enclosing-sphere approximation (Ritter) of `points`; it
// contains each of them. Radius 0 for one point; empty: radius 0 at 0.
BoundingSphere bounding_sphere(std::span<const Vec3f> points);

}  // namespace meshstream
