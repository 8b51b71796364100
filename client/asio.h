// The one way the client includes Boost.Asio. GCC 12 in C++20 mode needs
// <utility> before the Asio headers ("exchange is not a member of std").
#pragma once

// <utility> must stay first (see above); clang-format 14 only honours a bare
// "clang-format off" comment, so the reason sits on its own lines.
// clang-format off
#include <utility>
#include <boost/asio.hpp>
// clang-format on

namespace meshstream::client {
namespace asio = boost::asio;
using tcp = asio::ip::tcp;
}  // namespace meshstream::client
