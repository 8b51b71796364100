#include "server/synthetic_stream.h"

#include <algorithm>
#include <cmath>
#include <random>

#include "common/codec/container.h"
#include "common/codec/crc32.h"

namespace meshstream::server {

std::vector<uint8_t> make_synthetic_hcs(const SyntheticStreamOptions& o) {
  std::mt19937_64 rng(o.seed);
  const uint32_t n = std::max<uint32_t>(1, o.records);
  // Relative weights 1.02^i, jittered: later records are larger.
  std::vector<double> weights(n > 1 ? n - 1 : 0);
  double sum = 0;
  std::uniform_real_distribution<double> jitter(0.5, 1.5);
  for (size_t i = 0; i < weights.size(); ++i) {
    weights[i] = std::pow(1.02, double(i)) * jitter(rng);
    sum += weights[i];
  }
  std::vector<RecordEntry> records(n);
  records[0].size = std::max<uint32_t>(1, o.base_bytes);
  records[0].vertices = std::min(o.base_vertices, o.vertices);
  for (uint32_t i = 1; i < n; ++i) {
    records[i].size =
        std::max<uint32_t>(1, uint32_t(double(o.payload_bytes) * weights[i - 1] / sum));
    records[i].vertices =
        records[0].vertices + uint32_t(uint64_t(o.vertices - records[0].vertices) * i / (n - 1));
  }
  for (RecordEntry& r : records) r.faces = r.vertices * 2;

  std::vector<std::vector<uint8_t>> payloads(n);
  for (uint32_t i = 0; i < n; ++i) {
    payloads[i].resize(records[i].size);
    uint64_t bits = 0;
    for (size_t k = 0; k < payloads[i].size(); ++k) {
      if (k % 8 == 0) bits = rng();
      payloads[i][k] = uint8_t(bits >> (8 * (k % 8)));
    }
    records[i].crc32 = crc32(0, payloads[i].data(), payloads[i].size());
  }
  StreamHeader header;
  header.vertex_count = records.back().vertices;
  header.face_count = records.back().faces;
  header.base_vertex_count = records[0].vertices;
  header.base_face_count = records[0].faces;
  header.bounds.min = {-1, -1, -1};
  header.bounds.max = {1, 1, 1};
  header.quant_bits = 12;
  header.layer_count = n - 1;
  std::vector<uint8_t> out = write_container_prefix(header, records);
  for (const auto& p : payloads) out.insert(out.end(), p.begin(), p.end());
  return out;
}

}  // namespace meshstream::server
