// Synthetic `.hcs` streams for network tests and load benchmarks: a valid
// container (header, record index, per-record CRC-32) around random
// payloads. The server only reads the index, so these exercise it exactly as
// real encoded streams do, without depending on the encoder. Never served
// as a real model: they decode to nothing.
#pragma once

#include <cstdint>
#include <vector>

namespace meshstream::server {

struct SyntheticStreamOptions {
  uint32_t vertices = 100000;        // of the full "mesh"
  uint32_t base_vertices = 300;      // after record 0
  uint32_t records = 200;            // base mesh included
  uint32_t base_bytes = 8000;        // size of record 0
  uint64_t payload_bytes = 1 << 20;  // all records after the base, about
  uint64_t seed = 1;
};

// Record sizes grow geometrically from small to large (like refinement
// layers of a real stream), with some variation; counts grow to the totals.
// Deterministic for a given seed. O(bytes).
std::vector<uint8_t> make_synthetic_hcs(const SyntheticStreamOptions& options);

}  // namespace meshstream::server
