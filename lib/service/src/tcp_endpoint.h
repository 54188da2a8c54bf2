#pragma once
// The TCP listening both servers share (the API's Server and the live view's HttpServer): opening
// an acceptor on an address and port, and naming endpoints in messages and logs.
#include <boost/asio/ip/tcp.hpp>

#include <cstdint>
#include <string>

#include "scenewatch/core/result.h"

namespace scenewatch::service {

/// "1.2.3.4:5678", or "[::1]:5678" for IPv6.
std::string format_endpoint(const boost::asio::ip::tcp::endpoint& endpoint);
/// The port an acceptor is bound to (0 when it is not), and its endpoint formatted ("" when not).
std::uint16_t bound_port(const boost::asio::ip::tcp::acceptor& acceptor);
std::string bound_endpoint(const boost::asio::ip::tcp::acceptor& acceptor);

/// Opens `acceptor` on `address`:`port` (0: a free port) with SO_REUSEADDR and starts listening.
/// An address that is not an IP address is kInvalidArgument naming `address_key` (the config key
/// it came from); a failure to bind or listen is kIoError "cannot listen `what`on ENDPOINT: why",
/// and leaves the acceptor closed.
Status listen_on(boost::asio::ip::tcp::acceptor& acceptor, const std::string& address, std::uint16_t port,
                 const std::string& address_key, const std::string& what);

}  // namespace scenewatch::service
