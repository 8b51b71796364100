// How far an encode has got, for a progress bar (`meshstream encode` on a
// terminal) or a server log line. The encoder calls the callback from the
// thread that called encode_hcs, at stage changes and often enough within a
// long stage (a few hundred calls per encode at most), never concurrently.
#pragma once

#include <functional>
#include <string_view>

namespace meshstream {

struct EncodeProgress {
  // "decimating", "coding records", "measuring" (the automatic record
  // ordering's choice), "coding the winner" (when the choice fell on a
  // candidate not coded whole yet), "measuring ASA guidance" (the
  // encoder-guided ASA's choices, asa_guidance.h; unless
  // EncodeOptions::asa_guidance is off), "done"
  std::string_view stage;
  double fraction = 0;  // of the whole encode, 0..1, never decreasing
};

using EncodeProgressCallback = std::function<void(const EncodeProgress&)>;

}  // namespace meshstream
