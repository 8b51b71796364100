// The one way the client includes Boost.Asio. GCC 12 in C++20 mode needs
// <utility> before the Asio headers ("exchange is not a member of std").
#pragma once

// clang-format off: <utility> must stay first (see above).
#include <boost/asio.hpp>
#include <utility>
// clang-format on

namespace meshstream::client {
namespace asio = boost::asio;
using tcp = asio::ip::tcp;
}  // namespace meshstream::client
