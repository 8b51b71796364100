// `--asa auto`: the display follows the ASA guidance the encoder measured
// and wrote into the stream header (common/codec/asa_guidance.h): per group
// of records, the post-processing (or none) that brought those prefixes
// closest to the original. A stream without guidance, or whose guidance
// does not read, is shown as decoded: the safe default, since no fixed ASA
// setting is never worse than the plain prefix (bench/REPORT.md, fidelity).
#pragma once

#include <optional>
#include <string>

#include "client/decoded_stream.h"
#include "common/codec/asa_guidance.h"

namespace meshstream::client {

class GuidedAsa {
 public:
  // Reads the guidance once the stream's header has arrived (then never
  // again). O(header) once, O(1) after.
  void update(const DecodedStream& decoded);
  // The setting for a prefix of `records` records: nullopt for none (no
  // guidance, guidance refused, or the encoder chose none there).
  std::optional<AsaOptions> options_for(uint32_t records) const;
  // Whether that setting relaxes the decoded positions first (an
  // approximating choice, asa_guidance.h).
  bool approximates_for(uint32_t records) const;
  // "L1 t0.85 crease45", "off", or "none (no guidance)" for events.
  std::string label_for(uint32_t records) const;
  // Why the stream's guidance was refused, once (then ""): the caller warns.
  std::string take_warning();

 private:
  bool read_ = false;
  std::optional<AsaGuidance> guidance_;
  std::string warning_;
};

}  // namespace meshstream::client
