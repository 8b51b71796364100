// Fuzz target: the `.hcs` stream decoder, the part of the client that reads
// bytes straight off the network. The input is one stream; libFuzzer's
// FuzzedDataProvider takes the split points from the END of the input (its
// integers come from the back), so a real stream seed stays a real stream
// prefix and the fuzzer also explores where network reads end.
//
// Checked: read_stream_index and decode_hcs on the whole input, and
// IncrementalDecoder fed piece by piece never crash, never read out of
// bounds (ASan) and never hit undefined behaviour (UBSan); once the decoder
// reports an error it stays in error and keeps its last good (valid) mesh, its
// attribute arrays included (check_attribute_counts); a resume
// at the decoder's own resume offset is accepted.
//
// The container's CRC-32s would stop almost every mutation at the index or
// at a record's checksum, so the payload decoders (base mesh, refinement
// records) would never see malformed bytes. But a CRC is no defence against
// a hostile server: for half the inputs (a flag from the back) the target
// first rewrites the header, index and record checksums to match the
// mutated bytes, so the fuzzer reaches the record decoders themselves.
#include <fuzzer/FuzzedDataProvider.h>

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "common/codec/container.h"
#include "common/codec/container_reseal.h"
#include "common/codec/decoder.h"
#include "common/mesh/mesh.h"

namespace {
void check(bool ok) {
  if (!ok) __builtin_trap();  // a broken invariant is a finding, like a crash
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace meshstream;
  std::vector<uint8_t> fixed;
  if (size > 0 && (data[size - 1] & 1)) {  // the flag: checksums made valid
    fixed.assign(data, data + size - 1);
    reseal_checksums(fixed);  // every container version (v3: index CRC and record trailers)
    data = fixed.data();
    size = fixed.size();
  }
  const std::span<const uint8_t> all(data, size);

  if (auto index = read_stream_index(all)) {
    check(index->payload_offset <= index->total_bytes());
    uint64_t at = index->payload_offset;
    for (const RecordEntry& r : index->records) {  // contiguous, as promised
      check(r.offset == at);
      at += r.size;
    }
  }
  if (size < 4096) (void)decode_hcs(all);  // whole-buffer path (small inputs: speed)

  FuzzedDataProvider provider(data, size);
  IncrementalDecoder decoder;
  bool failed = false;
  uint32_t pieces = 0;
  while (provider.remaining_bytes() > 0 && pieces < 64) {
    const size_t n = provider.ConsumeIntegralInRange<size_t>(1, 1 + provider.remaining_bytes());
    std::vector<uint8_t> piece = provider.ConsumeBytes<uint8_t>(n);
    ++pieces;
    const uint32_t before = decoder.records_decoded();
    const size_t faces_before = decoder.mesh().triangles.size();
    auto fed = decoder.feed(piece);
    if (!fed) {
      failed = true;
      // Records completed before the bad one in this piece stay applied;
      // the mesh is the last good state (valid) and later feeds keep failing.
      check(decoder.records_decoded() >= before);
      check(decoder.records_decoded() > before || decoder.mesh().triangles.size() == faces_before);
      check(validate_arrays(decoder.mesh()).has_value());
      check(check_attribute_counts(decoder.mesh()).has_value());  // attribute arrays too
      check(!decoder.feed(piece).has_value());
      break;
    }
    check(decoder.records_decoded() == before + *fed);
  }
  if (!failed && decoder.records_decoded() > 0) {
    // A reconnect resumes at the last applied record boundary.
    const uint64_t resume = decoder.resume_offset();
    check(decoder.resume_at(resume).has_value());
    check(decoder.resume_offset() == resume);
    const Mesh& mesh = decoder.mesh();
    check(validate_arrays(mesh).has_value());  // every index names a vertex
    // Attribute arrays as long as the vertex and corner arrays, indices in range.
    check(check_attribute_counts(mesh).has_value());
  }
  return 0;
}
