#include "server/model_registry.h"

namespace meshstream::server {

const char* state_name(ModelState state) {
  switch (state) {
    case ModelState::kQueued:
      return "queued";
    case ModelState::kEncoding:
      return "encoding";
    case ModelState::kReady:
      return "ready";
    case ModelState::kFailed:
      return "failed";
  }
  return "?";
}

ModelRegistry::ModelRegistry() : current_(std::make_shared<const ModelSnapshot>()) {}

std::shared_ptr<const ModelSnapshot> ModelRegistry::snapshot() const {
  std::lock_guard lock(mutex_);
  return current_;
}

uint64_t ModelRegistry::put(ModelStatus status) {
  std::lock_guard lock(mutex_);
  status.generation = next_generation_++;
  const uint64_t generation = status.generation;
  auto next = std::make_shared<ModelSnapshot>(*current_);
  std::string name = status.name;
  (*next)[std::move(name)] = std::move(status);
  current_ = std::move(next);
  return generation;
}

bool ModelRegistry::update(std::string_view name, uint64_t generation,
                           const std::function<void(ModelStatus&)>& change) {
  std::lock_guard lock(mutex_);
  auto found = current_->find(name);
  if (found == current_->end() || found->second.generation != generation) return false;
  auto next = std::make_shared<ModelSnapshot>(*current_);
  change(next->find(name)->second);
  current_ = std::move(next);
  return true;
}

bool ModelRegistry::remove(std::string_view name) {
  std::lock_guard lock(mutex_);
  if (current_->find(name) == current_->end()) return false;
  auto next = std::make_shared<ModelSnapshot>(*current_);
  next->erase(next->find(name));
  current_ = std::move(next);
  return true;
}

StateCounts count_states(const ModelSnapshot& snapshot) {
  StateCounts counts;
  for (const auto& [name, status] : snapshot) {
    switch (status.state) {
      case ModelState::kQueued:
        ++counts.queued;
        break;
      case ModelState::kEncoding:
        ++counts.encoding;
        break;
      case ModelState::kReady:
        ++counts.ready;
        break;
      case ModelState::kFailed:
        ++counts.failed;
        break;
    }
  }
  return counts;
}

StateCounts ModelRegistry::counts() const { return count_states(*snapshot()); }

v1::ModelInfo model_info(const ModelStatus& status) {
  v1::ModelInfo info;
  info.set_name(status.name);
  info.set_source(status.source);
  if (status.model) {
    const StreamIndex& index = status.model->index;
    info.set_vertices(index.header.vertex_count);
    info.set_faces(index.header.face_count);
    info.set_stream_bytes(index.total_bytes());
    info.set_records(static_cast<uint32_t>(index.records.size()));
  }
  switch (status.state) {
    case ModelState::kQueued:
      info.set_state(v1::ModelInfo::QUEUED);
      break;
    case ModelState::kEncoding:
      info.set_state(v1::ModelInfo::ENCODING);
      info.set_percent(status.percent);
      info.set_stage(status.stage);
      break;
    case ModelState::kReady:
      info.set_state(v1::ModelInfo::READY);
      break;
    case ModelState::kFailed:
      info.set_state(v1::ModelInfo::FAILED);
      info.set_reason(status.reason);
      break;
  }
  return info;
}

std::vector<uint8_t> model_list_frame(const ModelSnapshot& snapshot) {
  v1::ServerMessage out;
  v1::ModelList* list = out.mutable_model_list();
  for (const auto& [name, status] : snapshot) *list->add_models() = model_info(status);
  return proto::encode_frame(out);
}

}  // namespace meshstream::server
