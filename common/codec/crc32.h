// CRC-32 (IEEE 802.3 polynomial, as zlib and PNG use), for per-record checksums.
#pragma once

#include <cstddef>
#include <cstdint>

namespace meshstream {

// Continues a running CRC: crc32(crc32(0, a), b) == crc32 of a followed by b.
uint32_t crc32(uint32_t crc, const uint8_t* data, size_t size);

}  // namespace meshstream
