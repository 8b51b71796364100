// Base mesh coders: see base_coder.h.
#include "common/codec/base_coder.h"

#include <draco/compression/decode.h>
#include <draco/compression/encode.h>
#include <draco/mesh/mesh.h>

#include <cstring>
#include <optional>
#include <string>

#include "common/codec/byte_io.h"
#include "common/codec/range_coder.h"

namespace meshstream {
namespace {

Status check_ranges(const BaseMesh& base, uint32_t vertex_count, uint32_t face_count,
                    int quant_bits, const char* coder) {
  if (base.positions.size() != vertex_count || base.faces.size() != face_count) {
    return make_error(ErrorCode::kCorrupt,
                      std::string(coder) + " base mesh has " +
                          std::to_string(base.positions.size()) + " vertices and " +
                          std::to_string(base.faces.size()) + " faces, the header says " +
                          std::to_string(vertex_count) + " and " + std::to_string(face_count));
  }
  const int32_t max = (int32_t(1) << quant_bits) - 1;
  for (const Vec3i& p : base.positions)
    for (int a = 0; a < 3; ++a)
      if (p[a] < 0 || p[a] > max)
        return make_error(ErrorCode::kCorrupt,
                          std::string(coder) + " base vertex outside the grid");
  for (const Triangle& t : base.faces)
    for (uint32_t i : t)
      if (i >= vertex_count)
        return make_error(ErrorCode::kCorrupt,
                          std::string(coder) + " base face index out of range");
  return {};
}

struct OwnModels {
  AdaptiveIntModel axis[3];
  AdaptiveIntModel first;
  AdaptiveIntModel other;
};

// Reads the Draco header and the edgebreaker connectivity counts (Draco
// bitstream 2.2: "DRACO", major, minor, encoder type, method, u16 flags, u8
// traversal type, varint vertices, varint faces, u8 attribute data, varint
// symbols, varint split symbols) and refuses a base record whose counts are
// not the index's or that is not what our encoder writes, before Draco sizes
// anything from them (a damaged record once made it reserve 5.7 GB).
Status check_draco_header(std::span<const uint8_t> in, uint32_t vertex_count, uint32_t face_count) {
  auto refuse = [](const std::string& why) {
    return make_error(ErrorCode::kCorrupt, "Draco base record refused before decoding: " + why);
  };
  if (in.size() < 13 || std::memcmp(in.data(), "DRACO", 5) != 0) return refuse("no Draco header");
  if (in[5] != 2 || in[6] != 2) {
    return refuse("bitstream version " + std::to_string(in[5]) + "." + std::to_string(in[6]) +
                  " (2.2 expected)");
  }
  if (in[7] != 1 || in[8] != 1) return refuse("not an edgebreaker-coded triangle mesh");
  if (in[9] != 0 || in[10] != 0) return refuse("header flags set (metadata is never written)");
  if (in[11] > 2) return refuse("unknown edgebreaker traversal " + std::to_string(in[11]));
  size_t pos = 12;
  uint32_t vertices = 0, faces = 0, symbols = 0, splits = 0;
  // Draco's varints are ours (LEB128); counts beyond 32 bits are refused
  // with the rest.
  if (!get_varint(in, pos, vertices) || !get_varint(in, pos, faces)) {
    return refuse("connectivity counts cut short or over 32 bits");
  }
  if (vertices != vertex_count || faces != face_count) {
    return refuse("it declares " + std::to_string(vertices) + " vertices and " +
                  std::to_string(faces) + " faces, the record index " +
                  std::to_string(vertex_count) + " and " + std::to_string(face_count));
  }
  if (pos >= in.size()) return refuse("connectivity counts cut short");
  ++pos;  // attribute data count
  if (!get_varint(in, pos, symbols) || !get_varint(in, pos, splits)) {
    return refuse("symbol counts cut short or over 32 bits");
  }
  if (symbols > faces || splits > symbols) return refuse("more edgebreaker symbols than faces");
  // Even rANS-coded, every face costs some bits: refuse counts far beyond
  // what the record's bytes could describe.
  if (faces > uint64_t(in.size()) * 8 * 64) return refuse("more faces than its bytes can describe");
  return {};
}

}  // namespace

std::vector<uint8_t> encode_base_own(const BaseMesh& base) {
  std::vector<uint8_t> out;
  put_u32(out, static_cast<uint32_t>(base.positions.size()));
  put_u32(out, static_cast<uint32_t>(base.faces.size()));
  RangeEncoder enc;
  OwnModels m;
  Vec3i prev{};
  for (const Vec3i& p : base.positions) {
    for (int a = 0; a < 3; ++a) m.axis[a].encode(enc, p[a] - prev[a]);
    prev = p;
  }
  int64_t prev_first = 0;
  for (const Triangle& t : base.faces) {
    m.first.encode(enc, static_cast<int32_t>(int64_t(t[0]) - prev_first));
    m.other.encode(enc, static_cast<int32_t>(int64_t(t[1]) - t[0]));
    m.other.encode(enc, static_cast<int32_t>(int64_t(t[2]) - t[0]));
    prev_first = t[0];
  }
  std::vector<uint8_t> coded = enc.finish();
  out.insert(out.end(), coded.begin(), coded.end());
  return out;
}

Result<BaseMesh> decode_base_own(std::span<const uint8_t> bytes, uint32_t vertex_count,
                                 uint32_t face_count, int quant_bits) {
  if (bytes.size() < 8) return make_error(ErrorCode::kCorrupt, "base mesh record is too short");
  const uint32_t nv = get_u32(bytes.data()), nf = get_u32(bytes.data() + 4);
  if (nv != vertex_count || nf != face_count) {
    return make_error(ErrorCode::kCorrupt, "base mesh counts do not match the header");
  }
  // Every coded value takes at least one bit's worth of range: refuse counts
  // the record could not hold before allocating.
  if (uint64_t(nv) * 3 + uint64_t(nf) * 3 > uint64_t(bytes.size()) * 8 * 64) {
    return make_error(ErrorCode::kCorrupt, "base mesh counts exceed what its bytes can hold");
  }
  BaseMesh base;
  base.positions.resize(nv);
  base.faces.resize(nf);
  RangeDecoder dec(bytes.subspan(8));
  OwnModels m;
  int64_t prev[3] = {0, 0, 0};
  for (Vec3i& p : base.positions) {
    for (int a = 0; a < 3; ++a) {
      const int64_t v = prev[a] + m.axis[a].decode(dec);
      if (v < 0 || v > (int64_t(1) << quant_bits) - 1)
        return make_error(ErrorCode::kCorrupt, "base vertex outside the grid");
      p[a] = static_cast<int32_t>(v);
      prev[a] = v;
    }
  }
  int64_t prev_first = 0;
  for (Triangle& t : base.faces) {
    const int64_t a = prev_first + m.first.decode(dec);
    const int64_t b = a + m.other.decode(dec);
    const int64_t c = a + m.other.decode(dec);
    for (int64_t i : {a, b, c})
      if (i < 0 || i >= int64_t(nv))
        return make_error(ErrorCode::kCorrupt, "base face index out of range");
    t = {uint32_t(a), uint32_t(b), uint32_t(c)};
    prev_first = a;
  }
  if (dec.exhausted_badly()) return make_error(ErrorCode::kCorrupt, "base mesh data ends early");
  if (auto s = check_ranges(base, vertex_count, face_count, quant_bits, "own-coded"); !s)
    return tl::unexpected(s.error());
  return base;
}

Result<std::vector<uint8_t>> encode_base_draco(const BaseMesh& base) {
  draco::Mesh mesh;
  mesh.set_num_points(static_cast<uint32_t>(base.positions.size()));
  draco::GeometryAttribute ga;
  ga.Init(draco::GeometryAttribute::POSITION, nullptr, 3, draco::DT_INT32, false,
          sizeof(int32_t) * 3, 0);
  const int att = mesh.AddAttribute(ga, true, static_cast<uint32_t>(base.positions.size()));
  draco::PointAttribute* pa = mesh.attribute(att);
  for (uint32_t v = 0; v < base.positions.size(); ++v) {
    const int32_t xyz[3] = {base.positions[v].x, base.positions[v].y, base.positions[v].z};
    pa->SetAttributeValue(draco::AttributeValueIndex(v), xyz);
  }
  mesh.SetNumFaces(base.faces.size());
  for (uint32_t f = 0; f < base.faces.size(); ++f) {
    draco::Mesh::Face face;
    for (int i = 0; i < 3; ++i) face[i] = draco::PointIndex(base.faces[f][i]);
    mesh.SetFace(draco::FaceIndex(f), face);
  }
  draco::Encoder encoder;
  encoder.SetEncodingMethod(draco::MESH_EDGEBREAKER_ENCODING);
  encoder.SetSpeedOptions(0, 0);  // smallest output; the base is tiny
  draco::EncoderBuffer buffer;
  const draco::Status status = encoder.EncodeMeshToBuffer(mesh, &buffer);
  if (!status.ok()) {
    return make_error(ErrorCode::kUnsupported,
                      std::string("Draco refused the base mesh: ") + status.error_msg_string());
  }
  return std::vector<uint8_t>(buffer.data(), buffer.data() + buffer.size());
}

Result<BaseMesh> decode_base_draco(std::span<const uint8_t> bytes, uint32_t vertex_count,
                                   uint32_t face_count, int quant_bits) {
  if (auto st = check_draco_header(bytes, vertex_count, face_count); !st)
    return tl::unexpected(st.error());
  draco::DecoderBuffer buffer;
  buffer.Init(reinterpret_cast<const char*>(bytes.data()), bytes.size());
  draco::Decoder decoder;
  std::optional<draco::StatusOr<std::unique_ptr<draco::Mesh>>> attempt;
  try {
    attempt.emplace(decoder.DecodeMeshFromBuffer(&buffer));
  } catch (const std::exception& e) {
    // Draco sizes vectors from counts in its bitstream (a damaged or hostile
    // base record made it reserve 5.7 GB in tests/fuzz): bad_alloc or
    // length_error is a corrupt record, not a crash of the caller.
    return make_error(ErrorCode::kCorrupt,
                      std::string("Draco could not decode the base mesh: ") + e.what());
  }
  auto& decoded = *attempt;
  if (!decoded.ok()) {
    return make_error(ErrorCode::kCorrupt, std::string("Draco could not decode the base mesh: ") +
                                               decoded.status().error_msg_string());
  }
  const draco::Mesh& mesh = *decoded.value();
  const draco::PointAttribute* pa = mesh.GetNamedAttribute(draco::GeometryAttribute::POSITION);
  if (!pa || pa->num_components() != 3) {
    return make_error(ErrorCode::kCorrupt, "Draco base mesh has no 3-component positions");
  }
  BaseMesh base;
  base.positions.resize(mesh.num_points());
  for (uint32_t p = 0; p < mesh.num_points(); ++p) {
    int32_t xyz[3];
    if (!pa->ConvertValue<int32_t, 3>(pa->mapped_index(draco::PointIndex(p)), xyz)) {
      return make_error(ErrorCode::kCorrupt, "Draco base mesh position unreadable");
    }
    base.positions[p] = {xyz[0], xyz[1], xyz[2]};
  }
  base.faces.resize(mesh.num_faces());
  for (uint32_t f = 0; f < mesh.num_faces(); ++f) {
    const auto& face = mesh.face(draco::FaceIndex(f));
    base.faces[f] = {face[0].value(), face[1].value(), face[2].value()};
  }
  if (auto s = check_ranges(base, vertex_count, face_count, quant_bits, "Draco-coded"); !s)
    return tl::unexpected(s.error());
  return base;
}

bool known_base_coder(uint8_t coder) {
  return coder == kBaseCoderOwn || coder == kBaseCoderDraco || coder == kBaseCoderTraversal;
}

Result<BaseMesh> decode_base(uint8_t coder, std::span<const uint8_t> bytes, uint32_t vertex_count,
                             uint32_t face_count, int quant_bits) {
  switch (coder) {
    case kBaseCoderOwn:
      return decode_base_own(bytes, vertex_count, face_count, quant_bits);
    case kBaseCoderDraco:
      return decode_base_draco(bytes, vertex_count, face_count, quant_bits);
    case kBaseCoderTraversal:
      return decode_base_traversal(bytes, vertex_count, face_count, quant_bits);
  }
  return make_error(ErrorCode::kUnsupported, "unknown base mesh coder " + std::to_string(coder));
}

}  // namespace meshstream
