// The client's transport seam: where stream bytes come from. Everything
// after it (DecodedStream, the display pipeline, events, budgets, --out,
// snapshots, the viewer) is the same for every source. Two sources exist:
// a meshstream server over its TCP protocol (StreamClient) and a plain web
// server over HTTP/1.1 range requests (HttpStreamClient).
#pragma once

#include <functional>
#include <memory>

#include "client/decoded_stream.h"
#include "client/stream_facts.h"
#include "common/base/result.h"
#include "proto/framing.h"

namespace meshstream::client {

struct ClientOptions;

class StreamSource {
 public:
  virtual ~StreamSource() = default;
  // Streams into `decoded` until the end, the budget, a fatal error or
  // stop(); always calls decoded.finish(). `on_header` runs once, on this
  // thread, when the stream's facts are known. Blocking.
  virtual void run(DecodedStream& decoded,
                   const std::function<void(const StreamFacts&)>& on_header) = 0;
  // Checked once, before any record is streamed; an error ends the run.
  virtual void check_header(std::function<Status(const StreamFacts&)> check) = 0;
  // Called on the network thread before each retry (for logs).
  virtual void on_retry(std::function<void(const Error&, int attempt)> f) = 0;
  // --wait: called on the network thread each time the server says the
  // model is not ready yet (a meshstream server only; a web server's file
  // is there or not).
  virtual void on_waiting(std::function<void(const v1::ModelInfo&)> f) = 0;
  virtual void stop() = 0;
  virtual void pause() = 0;
  virtual void resume() = 0;
  virtual bool paused() const = 0;
  virtual double rate_bytes_per_s() const = 0;
  virtual int reconnects() const = 0;
};

// A source class with those members (StreamClient, HttpStreamClient) as a
// StreamSource, so neither needs to know about this seam.
template <class Client>
class SourceOf final : public StreamSource {
 public:
  template <class... Args>
  explicit SourceOf(Args&&... args) : client_(std::forward<Args>(args)...) {}
  void run(DecodedStream& d, const std::function<void(const StreamFacts&)>& h) override {
    client_.run(d, h);
  }
  void check_header(std::function<Status(const StreamFacts&)> c) override {
    client_.check_header(std::move(c));
  }
  void on_retry(std::function<void(const Error&, int)> f) override {
    client_.on_retry(std::move(f));
  }
  void on_waiting(std::function<void(const v1::ModelInfo&)> f) override {
    if constexpr (requires { client_.on_waiting(std::move(f)); }) client_.on_waiting(std::move(f));
  }
  void stop() override { client_.stop(); }
  void pause() override { client_.pause(); }
  void resume() override { client_.resume(); }
  bool paused() const override { return client_.paused(); }
  double rate_bytes_per_s() const override { return client_.rate_bytes_per_s(); }
  int reconnects() const override { return client_.reconnects(); }

 private:
  Client client_;
};

// The source `options` name: an http:// URL or a meshstream server.
std::unique_ptr<StreamSource> make_stream_source(const ClientOptions& options);

}  // namespace meshstream::client
