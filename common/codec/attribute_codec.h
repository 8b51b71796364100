// Attribute records (docs/hcs-format.md, "Attribute records"): normals,
// texture coordinates, colours and face materials, per vertex or per corner
// (with seams), plus extra attributes carried byte for byte.
//
// Seams: an edge (v, b) is a seam at v when the two faces on it give v
// different values (any per-corner attribute, the face material included).
// Both ends of every seam edge are locked against decimation (decimate.h's
// DecimateOptions::locked), so seam edges exist in every prefix mesh and a
// vertex's star is cut by them into the same wedges at every prefix. A
// vertex has one value per wedge; a wedge is named by the seam edge that
// ends it walking around the vertex (kBoundary: the boundary ends it).
// Inserted vertices are never seam vertices: one value each.
//
// Three kinds of records: record 1, right after the base, carries the
// layout (which attributes, their grids, the material table), one seam bit
// per interior edge of each base vertex that has more than one wedge, and
// the base vertices' values. Values records (encoder version 11 on) follow
// geometry records and carry the exact values of every vertex inserted
// since the previous one, coded on the decoder's mesh of that moment with
// models that persist from one values record to the next; they are sized
// like the geometry records (at most 1.5 % of the stream each). From
// version 12 on they leave the normals out; normals records after the last
// geometry record carry them, predicted on the complete mesh; from version
// 13 on record 1 leaves the base's normals to those records too
// (kBaseNormalsLate); from version 14 on it carries the base's texture
// coordinates coarse (kBaseCoarse), and a low-bits record before the first
// values record makes them exact (version 15: colours coarse too, if
// asked). The last
// record carries the exact values of the vertices inserted after the last
// values record (version 10: of every inserted vertex) and the extra
// attributes (zstd). Until its values arrive the decoder shows each
// inserted vertex with a preview (its decoded neighbours' mean; normals: the
// geometric normal of its wedge on the mesh the decoder has),
// so every prefix after record 1 has attributes. Values are predicted in
// exact integers from what the decoder has (parallelograms over the
// connectivity, neighbours; texture coordinates after record 1: from the
// geometry as Draco's predictor; normals: the geometric normal of the wedge's
// faces) and the residuals range-coded with adaptive models.
#pragma once

#include <cstdint>
#include <map>
#include <span>
#include <string>
#include <vector>

#include "common/base/result.h"
#include "common/codec/attribute_quantize.h"
#include "common/codec/editable_mesh.h"
#include "common/codec/range_coder.h"
#include "common/codec/stream_format.h"
#include "common/mesh/mesh.h"

namespace meshstream {

// An attribute record's first payload byte is kRecordAttributes
// (stream_format.h); its second says which part it is.
inline constexpr uint8_t kAttributePartBase = 0;    // record 1
inline constexpr uint8_t kAttributePartFinal = 1;   // the last record
inline constexpr uint8_t kAttributePartValues = 2;  // after geometry records (version 11 on)
// Version 12 on: values records without the normals (which a values record
// would predict from the coarse stars the decoder has then), and normals
// records after the last geometry record with the normals of the vertices
// of those values records, predicted on the complete mesh.
inline constexpr uint8_t kAttributePartValuesLateNormals = 3;
inline constexpr uint8_t kAttributePartNormals = 4;
// Version 14 on: the low bits of the base's values of the channels record 1
// carries coarse (kBaseCoarse), before any values, normals or final record.
inline constexpr uint8_t kAttributePartLowBits = 5;
inline bool is_values_part(uint8_t part) {
  return part == kAttributePartValues || part == kAttributePartValuesLateNormals ||
         part == kAttributePartNormals || part == kAttributePartLowBits;
}
// A values record is closed at about this share of the expected stream
// (the record-size rule: no record beyond the base above 2 % of it).
inline constexpr double kValuesRecordShare = 0.015;
// Wedge key of the wedge the boundary ends; kNone (editable_mesh.h): the
// vertex's only wedge.
inline constexpr uint32_t kBoundaryKey = 0xFFFFFFFEu;

enum class AttributeKind : uint8_t { kNormal = 1, kTexcoord = 2, kColor = 3, kMaterial = 4 };
const char* attribute_kind_name(AttributeKind kind);

// Prediction flags of a channel (the layout's per-channel byte, bit 0 of
// which is "per corner"; version 12 on): record 1 predicts normals from the
// decoded neighbours' normals, texture coordinates from the geometry; the
// records after it predict texture coordinates from the geometry.
inline constexpr uint8_t kPredictBaseAlternative = 2;
inline constexpr uint8_t kPredictLaterFromGeometry = 4;
// A normal channel's flag (version 13 on): record 1 has no section for it;
// the base vertices' normals come after every geometry record with the
// inserted vertices', in the normals records (from vertex 0), predicted on
// the complete mesh. Until then the decoder shows the geometric normal of
// each wedge on the mesh it has. The first display with colours or
// texture then waits for no normal (bench/REPORT.md, "first display").
inline constexpr uint8_t kBaseNormalsLate = 8;
// A texture coordinate channel's flag (version 14 on; a colour channel's
// too from version 15, when the encoder is asked for it): record 1 carries
// the base's values without their low `base_shift` bits (a u8 after the
// bits in the layout), coded on the coarser grid; a low-bits record
// (kAttributePartLowBits) brings them before the first values record (after
// the last geometry record when there is none). The first display shows
// the coarse value at the middle of its range.
inline constexpr uint8_t kBaseCoarse = 16;
// A per-corner texture coordinate (version 16 on) or normal (17 on)
// channel's flag: a wedge
// after the first of its vertex first says whether its value is that of an
// earlier wedge of the vertex (one adaptive bit per distinct earlier value,
// in wedge order; record 1 compares the values it codes, the coarse ones
// where kBaseCoarse), and only a new value is coded. The wedge table is
// shared by every channel, so where normals are per face each corner is
// its own wedge for the UV too (the sphere: 3 840 UV wedges for 729
// values); with this flag a UV shared by several normal wedges is coded
// once. The low-bits record says the same for a wedge whose coarse value
// repeats an earlier wedge's: one bit "same low bits as it". From version
// 17 per-corner normals may carry it too: a normal shared by the wedges
// that the texture coordinates split is coded once (normals are never
// coarse, so only their values and normals records read it).
inline constexpr uint8_t kWedgeRepeat = 32;
// The coarse grid record 1 uses for texture coordinates of more bits (the
// first display shows the small texture level: 1/256 of the UV box).
inline constexpr int kBaseCoarseBits = 8;

struct AttributeChannel {
  AttributeKind kind = AttributeKind::kColor;
  bool per_corner = false;
  uint8_t bits = 8;  // quantization bits (normals: per octahedral coordinate); unused for materials
  TexcoordGrid uv;   // texture coordinates only
  uint8_t flags = 0;       // kPredict* bits (last: the aggregate initializers above it)
  uint8_t base_shift = 0;  // kBaseCoarse: the low bits record 1 leaves out
  uint32_t components() const {
    return kind == AttributeKind::kColor ? 4 : kind == AttributeKind::kMaterial ? 1 : 2;
  }
};

struct AttributeLayout {
  std::vector<AttributeChannel> channels;
  std::vector<Material> materials;  // the material table (texture indices kept as given)
  int32_t max_value(const AttributeChannel& c) const {
    if (c.kind == AttributeKind::kMaterial)
      return materials.empty() ? 0 : int32_t(materials.size()) - 1;
    return (int32_t(1) << c.bits) - 1;
  }
};

// Adaptive models of one channel's residuals: by prediction context
// (parallelogram, neighbours, none, geometric) and component.
struct AttributeChannelModels {
  AdaptiveIntModel residual[4][4];
};

// Integer values in decoder vertex ids. Vertex v has wedges
// [wedge_start[v], wedge_start[v+1]); data[channel] holds components() ints
// per vertex (per-vertex channels) or per wedge (per-corner channels).
struct AttributeValues {
  std::vector<uint32_t> wedge_start{0};
  std::vector<uint32_t> wedge_key;
  std::vector<std::vector<int32_t>> data;
  uint32_t vertices() const { return uint32_t(wedge_start.size() - 1); }
};

// The wedge of corner c (at vertex v = m.vertex(c)) of `m`. O(valence).
uint32_t wedge_of_corner(const EditableMesh& m, const AttributeValues& a, uint32_t c);

struct AttributeOptions {
  int normal_bits = 8;
  int texcoord_bits = 12;
  int color_bits = 8;
  // Record 1's grid for colours (version 15, kBaseCoarse): 0 = colours
  // exact in record 1; kMinAttributeBits .. color_bits - 1 = record 1 codes
  // the base's colours on this many bits per channel and a low-bits record
  // brings the rest; else kInvalidArgument.
  int base_color_bits = 0;
  bool wedge_repeat = true;  // kWedgeRepeat where a value repeats (EncodeOptions)
};

// What the encoder takes from the input before decimation: the layout, the
// quantized values (per input corner or vertex) and the vertices to lock.
struct AttributePlan {
  AttributeLayout layout;
  // Per channel: per input vertex (per-vertex channels) or per input corner.
  std::vector<std::vector<int32_t>> input_values;
  std::vector<uint8_t> locked;  // input vertex ids
  uint32_t locked_count = 0;
  const std::vector<ExtraAttribute>* extras = nullptr;
  int base_color_bits = 0;   // AttributeOptions::base_color_bits
  bool wedge_repeat = true;  // AttributeOptions::wedge_repeat
  bool empty() const { return layout.channels.empty() && (!extras || extras->empty()); }
};

// kInvalidArgument for bits out of 2..16, kInvalidMesh for non-finite values.
Result<AttributePlan> plan_attributes(const Mesh& mesh, const std::vector<Vec3i>& q,
                                      const AttributeOptions& options);

// Bytes of each part of the attribute records ("seams", "normals",
// "texcoords", "colors", "materials", "extra", "layout").
using AttributeParts = std::map<std::string, uint64_t>;

// An attribute record of the rewritten stream: its record number and
// payload bytes.
struct AttributeRecordPlace {
  uint32_t record = 0;
  uint32_t bytes = 0;
};

// Rewrites `stream` (a geometry stream of encode_once, whose decoder vertex
// i is input vertex to_input[i]) with the attribute records added: record
// 1, the values records, the last record. Fills `parts` and `places` (in
// record order) when given. kInternal when the stream disagrees with the plan.
Result<std::vector<uint8_t>> add_attribute_records(const AttributePlan& plan, const Mesh& mesh,
                                                   const std::vector<Vec3i>& q,
                                                   std::span<const uint8_t> stream,
                                                   const std::vector<uint32_t>& to_input,
                                                   AttributeParts* parts,
                                                   std::vector<AttributeRecordPlace>* places);

// The parts of a stream's attribute records' payloads (for `meshstream
// info`; `values_payloads` are the values records', `final_payload` may be
// empty when the file is cut short). kParse when they are not well-formed
// attribute records.
Result<AttributeParts> attribute_record_parts(
    std::span<const uint8_t> base_payload,
    std::span<const std::span<const uint8_t>> values_payloads,
    std::span<const uint8_t> final_payload);

// The decoder's side: see the file comment.
class AttributeDecoder {
 public:
  bool active() const { return active_; }
  bool complete() const { return complete_; }
  // Record 1, on the base mesh (the decoder's state right after record 0).
  Status read_base(std::span<const uint8_t> payload, const EditableMesh& base);
  // Predicted values for the vertices of `m` beyond those known.
  void preview(const EditableMesh& m);
  // The previewed normals of vertices whose exact normals have not come
  // (version 12's values records leave them to the end), recomputed as the
  // geometric normal of their wedge on `m` where their star changed since
  // the last call: the vertices inserted since, and their rings. Display
  // only (nothing is predicted from previews); O(inserted x valence).
  void refresh_normal_previews(const EditableMesh& m);
  // A values record, on the decoder's mesh now: the exact values of every
  // vertex inserted since the previous values (or record 1).
  Status read_values(std::span<const uint8_t> payload, const EditableMesh& m);
  // A normals record (kAttributePartNormals), on the complete mesh: the
  // exact normals of the next vertices whose values came without them.
  Status read_normals(std::span<const uint8_t> payload, const EditableMesh& full);
  // Vertices whose exact values have come (the base's and the values
  // records'; their normals may still be to come: normals_exact_vertices).
  uint32_t exact_vertices() const { return exact_vertices_; }
  uint32_t normals_exact_vertices() const { return normals_exact_; }
  // A low-bits record (kAttributePartLowBits): the base's values exact.
  Status read_low_bits(std::span<const uint8_t> payload);
  // The last record, on the complete mesh.
  Status read_final(std::span<const uint8_t> payload, const EditableMesh& full);
  // Writes every attribute array of `out` for `m` (whose vertices all have
  // values: call preview first).
  void write_mesh(const EditableMesh& m, Mesh& out) const;
  // The material table alone, for the textures `out` holds now (a texture
  // record made more of them valid).
  void write_materials(Mesh& out) const;
  // The material table as the stream has it, texture indices included
  // (write_mesh drops the indices of textures `out` does not hold, so the
  // mesh stays valid until the images arrive).
  const std::vector<Material>& materials() const { return layout_.materials; }
  // The same for the vertices from `first_vertex` on and the faces listed.
  void update_mesh(const EditableMesh& m, uint32_t first_vertex, std::span<const uint32_t> faces,
                   Mesh& out) const;

 private:
  void write_vertex_values(uint32_t first_vertex, Mesh& out) const;
  void write_face(const EditableMesh& m, uint32_t f, Mesh& out) const;
  bool active_ = false, complete_ = false;
  AttributeLayout layout_;
  AttributeValues values_;
  uint32_t base_vertices_ = 0;
  uint32_t exact_vertices_ = 0;
  uint32_t normals_exact_ = 0;      // vertices whose normals are exact (<= exact_vertices_)
  uint32_t normals_refreshed_ = 0;  // refresh_normal_previews saw the vertices below
  bool low_bits_pending_ = false;   // record 1 had coarse channels, their low bits not come
  EditableMesh base_mesh_;          // record 1's mesh, kept while low_bits_pending_
  std::vector<AttributeChannelModels> values_models_;  // the values records', persistent
  std::vector<ExtraAttribute> extras_;
};

}  // namespace meshstream
