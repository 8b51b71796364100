// "Did you mean": the catalog names close to a name a client asked for,
// for the UNKNOWN_MODEL error frame and the server log.
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace meshstream::server {

// Edit distance with adjacent transpositions (optimal string alignment):
// insertions, deletions, substitutions and swaps of two neighbours cost 1.
// O(|a| * |b|) time, O(|b|) memory.
size_t edit_distance(std::string_view a, std::string_view b);

// The names (in `names`) close to `requested`, closest first, at most
// `limit`: within an edit distance of a third of the request's length (at
// least 1, at most 3), or equal to the request without its extension
// ("bunny.ply" -> "bunny"). None for an empty request or one over 128 bytes
// (a name that long is not a typo).
std::vector<std::string> closest_names(std::string_view requested,
                                       const std::vector<std::string>& names, size_t limit = 3);

// `text` with control characters as \xNN, so a client's bytes cannot forge
// lines in the log; at most `max_bytes` of it, "..." marking a cut.
std::string printable(std::string_view text, size_t max_bytes = 128);

// "unknown model 'bunnny': did you mean 'bunny'? (see --list)", or without
// the question when `suggestions` is empty.
std::string unknown_model_message(std::string_view requested,
                                  const std::vector<std::string>& suggestions);

}  // namespace meshstream::server
