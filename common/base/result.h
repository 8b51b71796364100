// The error convention used everywhere in meshstream.
//
// Every function that reads untrusted input (files, streams, frames) returns
// `Result<T>`: either the value or an `Error` whose code is stable (the wire
// protocol mirrors it) and whose message names the input and the problem.
// Nothing aborts on bad data; exceptions are reserved for programming errors
// and allocation failure.
#pragma once

#include <string>
#include <tl/expected.hpp>
#include <utility>

namespace meshstream {

enum class ErrorCode {
  kInvalidArgument = 1,  // the caller asked for something impossible
  kIo = 2,               // a file or socket could not be read or written
  kParse = 3,            // bytes are not in the expected format
  kInvalidMesh = 4,      // the mesh breaks a rule (NaN, bad index, empty, ...)
  kNonManifold = 5,      // topology the codec and ASA cannot work on
  kCorrupt = 6,          // a checksum or consistency check failed
  kTruncated = 7,        // the input ended before a unit was complete
  kUnsupported = 8,      // a valid input using a feature or version we lack
  kLimit = 9,            // a size or count limit was exceeded
  // Our own bug, not the input's: an invariant the code keeps did not hold
  // (the encoder's and decoder's views of a record disagree, say).
  kInternal = 10,
};

const char* to_string(ErrorCode code);

struct Error {
  ErrorCode code;
  std::string message;

  // Prefixes the message with context, e.g. the file name:
  // "bunny.obj: vertex 12 has a NaN coordinate".
  Error&& with_context(const std::string& context) && {
    message = context + ": " + message;
    return std::move(*this);
  }
};

template <class T>
using Result = tl::expected<T, Error>;

using Status = tl::expected<void, Error>;

inline tl::unexpected<Error> make_error(ErrorCode code, std::string message) {
  return tl::unexpected<Error>(Error{code, std::move(message)});
}

inline const char* to_string(ErrorCode code) {
  switch (code) {
    case ErrorCode::kInvalidArgument:
      return "invalid argument";
    case ErrorCode::kIo:
      return "i/o error";
    case ErrorCode::kParse:
      return "parse error";
    case ErrorCode::kInvalidMesh:
      return "invalid mesh";
    case ErrorCode::kNonManifold:
      return "non-manifold mesh";
    case ErrorCode::kCorrupt:
      return "corrupt data";
    case ErrorCode::kTruncated:
      return "truncated data";
    case ErrorCode::kUnsupported:
      return "unsupported";
    case ErrorCode::kLimit:
      return "limit exceeded";
    case ErrorCode::kInternal:
      return "internal error";
  }
  return "unknown error";
}

}  // namespace meshstream
