// Rewriting the checksums of an .hcs stream so they match its bytes: for
// fuzzing and hostile-stream tests, whose damaged streams must get past the
// CRC checks to reach the record decoders (a damaged file whose CRCs still
// match, or a hostile server). Every container version (1-3).
#pragma once

#include <cstdint>
#include <vector>

namespace meshstream {

// Recomputes the header CRC, every record CRC the index can locate inside
// `stream` (versions 1-2: in the index; version 3: each record's trailer),
// and the index CRC, as far as the bytes hold them; leaves anything it
// cannot parse as it is. Never reads or writes out of bounds.
// O(stream size).
void reseal_checksums(std::vector<uint8_t>& stream);

}  // namespace meshstream
