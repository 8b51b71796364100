#include "server/server_metrics.h"

#include <algorithm>
#include <cctype>

namespace meshstream::server {
namespace {

class Exposition {
 public:
  void family(const char* name, const char* type, const char* help) {
    name_ = name;
    text_ += std::string("# HELP ") + name + " " + help + "\n";
    text_ += std::string("# TYPE ") + name + " " + type + "\n";
  }
  void sample(uint64_t value) { text_ += name_ + " " + std::to_string(value) + "\n"; }
  void sample(const char* label, const std::string& value, uint64_t n) {
    text_ += name_ + "{" + label + "=\"" + value + "\"} " + std::to_string(n) + "\n";
  }
  std::string take() { return std::move(text_); }

 private:
  std::string name_;
  std::string text_;
};

uint64_t load(const std::atomic<uint64_t>& a) { return a.load(std::memory_order_relaxed); }

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

}  // namespace

std::string render_prometheus(const ServerMetrics& m, int64_t open_sessions,
                              const ModelCounts& models) {
  Exposition out;
  out.family("meshstream_sessions_open", "gauge", "Client connections being served now.");
  out.sample(static_cast<uint64_t>(std::max<int64_t>(0, open_sessions)));
  out.family("meshstream_sessions_total", "counter",
             "Client connections served since start (rejected ones not included).");
  out.sample(load(m.sessions_total));
  out.family("meshstream_bytes_sent_total", "counter", "Stream bytes sent in chunks.");
  out.sample(load(m.bytes_sent));
  out.family("meshstream_streams_total", "counter",
             "Streams ended, by outcome (interrupted: the connection closed while it ran).");
  const char* outcomes[kStreamOutcomes] = {"complete", "budget", "cancelled", "interrupted"};
  for (size_t i = 0; i < kStreamOutcomes; ++i)
    out.sample("outcome", outcomes[i], load(m.streams[i]));
  out.family("meshstream_errors_total", "counter", "Error frames sent to clients, by code.");
  for (int code = 1; code < v1::Error::Code_ARRAYSIZE; ++code) {
    if (!v1::Error::Code_IsValid(code)) continue;
    out.sample("code", lower(v1::Error::Code_Name(static_cast<v1::Error::Code>(code))),
               load(m.errors[static_cast<size_t>(code)]));
  }
  out.family("meshstream_models", "gauge", "Models in the catalog, by state.");
  out.sample("state", "queued", models.queued);
  out.sample("state", "encoding", models.encoding);
  out.sample("state", "ready", models.ready);
  out.sample("state", "failed", models.failed);
  out.family("meshstream_encode_queue_length", "gauge",
             "Models waiting for the encoder (queued, not yet encoding).");
  out.sample(models.queued);
  return out.take();
}

}  // namespace meshstream::server
