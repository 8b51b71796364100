// The one way the client includes Boost.Asio. GCC 12 in C++20 mode needs
// <utility> before the Asio headers ("exchange is not a member of std").
#pragma once

// <utility> must stay first, so clang-format must not sort this block.
// clang-format off
#include <utility>

#include <boost/asio.hpp>
// clang-format on

namespace meshstream::client {
namespace asio = boost::asio;
using tcp = asio::ip::tcp;
}  // namespace meshstream::client
