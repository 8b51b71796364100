#include "client/guided_asa.h"

namespace meshstream::client {

void GuidedAsa::update(const DecodedStream& decoded) {
  if (read_) return;
  const auto header = decoded.stream_header();
  const auto summary = decoded.index_summary();
  if (!header || !summary) return;
  read_ = true;
  auto guidance = read_asa_guidance(*header, summary->second);
  if (!guidance) {
    warning_ = guidance.error().message + "; showing the decoded mesh without ASA";
    return;
  }
  guidance_ = std::move(*guidance);
}

std::optional<AsaOptions> GuidedAsa::options_for(uint32_t records) const {
  if (!guidance_) return std::nullopt;
  auto options = asa_choice_options(guidance_->choice_for(records));
  if (!options) return std::nullopt;  // read_asa_guidance checked every choice
  return *options;
}

bool GuidedAsa::approximates_for(uint32_t records) const {
  return guidance_ && asa_choice_approximates(guidance_->choice_for(records));
}

std::string GuidedAsa::label_for(uint32_t records) const {
  if (!guidance_) return "off (no guidance)";
  return asa_choice_label(guidance_->choice_for(records));
}

std::string GuidedAsa::take_warning() { return std::exchange(warning_, std::string()); }

}  // namespace meshstream::client
