// Draco as the single-rate peer of the codec benchmark: our Mesh in, a
// Draco edgebreaker file out, and back. Positions only (what .hcs codes).
// Header-only so each bench executable can include it.
#pragma once

#include <draco/compression/decode.h>
#include <draco/compression/expert_encode.h>
#include <draco/mesh/mesh.h>

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "common/base/result.h"
#include "common/mesh/mesh.h"

namespace meshstream::bench {

// A Draco mesh with one POSITION attribute mapped 1:1 to our vertices.
inline std::unique_ptr<draco::Mesh> to_draco_mesh(const Mesh& mesh) {
  auto out = std::make_unique<draco::Mesh>();
  out->set_num_points(mesh.vertex_count());
  draco::GeometryAttribute position;
  position.Init(draco::GeometryAttribute::POSITION, nullptr, 3, draco::DT_FLOAT32, false,
                sizeof(float) * 3, 0);
  const int id = out->AddAttribute(position, true, mesh.vertex_count());
  draco::PointAttribute* attribute = out->attribute(id);
  for (uint32_t v = 0; v < mesh.vertex_count(); ++v) {
    const float xyz[3] = {mesh.positions[v].x, mesh.positions[v].y, mesh.positions[v].z};
    attribute->SetAttributeValue(draco::AttributeValueIndex(v), xyz);
  }
  out->SetNumFaces(mesh.face_count());
  for (uint32_t f = 0; f < mesh.face_count(); ++f) {
    const Triangle& t = mesh.triangles[f];
    out->SetFace(draco::FaceIndex(f),
                 {draco::PointIndex(t[0]), draco::PointIndex(t[1]), draco::PointIndex(t[2])});
  }
  return out;
}

// Encodes like `draco_encoder -qp quant_bits -cl level`: edgebreaker, speed
// 10 - level for encoding and decoding.
inline Result<std::vector<uint8_t>> draco_encode(const Mesh& mesh, int quant_bits, int level) {
  const auto dm = to_draco_mesh(mesh);
  draco::ExpertEncoder encoder(*dm);
  encoder.SetEncodingMethod(draco::MESH_EDGEBREAKER_ENCODING);
  encoder.SetSpeedOptions(10 - level, 10 - level);
  encoder.SetAttributeQuantization(0, quant_bits);
  draco::EncoderBuffer buffer;
  const draco::Status status = encoder.EncodeToBuffer(&buffer);
  if (!status.ok()) {
    return make_error(ErrorCode::kInvalidArgument, "draco encode: " + status.error_msg_string());
  }
  return std::vector<uint8_t>(buffer.data(), buffer.data() + buffer.size());
}

// Decodes a Draco mesh file back into our Mesh (positions and triangles).
inline Result<Mesh> draco_decode(std::span<const uint8_t> bytes) {
  draco::DecoderBuffer buffer;
  buffer.Init(reinterpret_cast<const char*>(bytes.data()), bytes.size());
  draco::Decoder decoder;
  auto decoded = decoder.DecodeMeshFromBuffer(&buffer);
  if (!decoded.ok()) {
    return make_error(ErrorCode::kParse, "draco decode: " + decoded.status().error_msg_string());
  }
  const draco::Mesh& dm = *decoded.value();
  const draco::PointAttribute* position = dm.GetNamedAttribute(draco::GeometryAttribute::POSITION);
  if (position == nullptr) return make_error(ErrorCode::kParse, "draco decode: no positions");
  Mesh out;
  out.positions.resize(dm.num_points());
  for (uint32_t p = 0; p < dm.num_points(); ++p) {
    float xyz[3];
    position->GetMappedValue(draco::PointIndex(p), xyz);
    out.positions[p] = {xyz[0], xyz[1], xyz[2]};
  }
  out.triangles.resize(dm.num_faces());
  for (uint32_t f = 0; f < dm.num_faces(); ++f) {
    const draco::Mesh::Face& face = dm.face(draco::FaceIndex(f));
    out.triangles[f] = {face[0].value(), face[1].value(), face[2].value()};
  }
  return out;
}

// Decodes only, keeping Draco's own mesh: what "Draco's decode throughput"
// measures (no conversion to our arrays). Returns the point count, 0 on error.
inline uint32_t draco_decode_only(std::span<const uint8_t> bytes) {
  draco::DecoderBuffer buffer;
  buffer.Init(reinterpret_cast<const char*>(bytes.data()), bytes.size());
  draco::Decoder decoder;
  auto decoded = decoder.DecodeMeshFromBuffer(&buffer);
  return decoded.ok() ? decoded.value()->num_points() : 0;
}

}  // namespace meshstream::bench
