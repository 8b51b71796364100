// The one way meshstream includes Boost.Asio (client, server, their tests,
// tools and benchmarks): include only this header. GCC 12 in C++20 mode needs
// <utility> before <boost/asio/awaitable.hpp> ("exchange is not a member of
// std"), and clang-format's include sorting would move it after boost/.
#pragma once

// <utility> must stay first, so clang-format must not sort this block.
// clang-format off
#include <utility>

#include <boost/asio.hpp>
#include <boost/asio/awaitable.hpp>
#include <boost/asio/co_spawn.hpp>
#include <boost/asio/detached.hpp>
#include <boost/asio/redirect_error.hpp>
#include <boost/asio/use_awaitable.hpp>
// clang-format on

namespace meshstream::net {
namespace asio = boost::asio;
using tcp = asio::ip::tcp;
}  // namespace meshstream::net
