// A cross-process lock on one cache entry, so that N meshstream-server
// processes sharing one --cache folder encode each model once: the first
// takes `<entry>.lock` (flock, exclusive) and encodes; the others wait on
// it, then find the entry written and map it. The lock file stays (removing
// it would race with a process that has just opened it); it is empty.
// flock locks are released by the kernel when the process dies, so a
// server killed mid-encode never leaves the entry locked.
#pragma once

#include <string>

#include "common/base/result.h"

namespace meshstream::server {

class CacheEntryLock {
 public:
  // Blocks until this process holds the lock on `entry` (the path of the
  // cached file; the lock is `entry` + ".lock"). kIo (naming the lock file)
  // when it cannot be created or locked, e.g. a read-only cache folder; the
  // caller then encodes without the lock (temp + rename still keeps the
  // entry whole).
  static Result<CacheEntryLock> acquire(const std::string& entry);

  CacheEntryLock(CacheEntryLock&& other) noexcept : fd_(other.fd_) { other.fd_ = -1; }
  CacheEntryLock& operator=(CacheEntryLock&& other) noexcept;
  CacheEntryLock(const CacheEntryLock&) = delete;
  CacheEntryLock& operator=(const CacheEntryLock&) = delete;
  ~CacheEntryLock();  // releases it

 private:
  explicit CacheEntryLock(int fd) : fd_(fd) {}
  int fd_ = -1;
};

}  // namespace meshstream::server
