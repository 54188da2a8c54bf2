#include "tcp_endpoint.h"

#include <boost/asio/ip/address.hpp>

namespace scenewatch::service {
namespace asio = boost::asio;
using tcp = asio::ip::tcp;

std::string format_endpoint(const tcp::endpoint& endpoint) {
  const std::string address = endpoint.address().to_string();
  return (endpoint.address().is_v6() ? "[" + address + "]" : address) + ":" + std::to_string(endpoint.port());
}

std::uint16_t bound_port(const tcp::acceptor& acceptor) {
  boost::system::error_code ec;
  const auto endpoint = acceptor.local_endpoint(ec);
  return ec ? 0 : endpoint.port();
}

std::string bound_endpoint(const tcp::acceptor& acceptor) {
  boost::system::error_code ec;
  const auto endpoint = acceptor.local_endpoint(ec);
  return ec ? std::string() : format_endpoint(endpoint);
}

Status listen_on(tcp::acceptor& acceptor, const std::string& address, std::uint16_t port,
                 const std::string& address_key, const std::string& what) {
  boost::system::error_code ec;
  const auto ip = asio::ip::make_address(address, ec);
  if (ec) return invalid_argument(address_key + ": '" + address + "' is not an IP address");
  const tcp::endpoint endpoint(ip, port);
  acceptor.open(endpoint.protocol(), ec);
  if (!ec) acceptor.set_option(tcp::acceptor::reuse_address(true), ec);
  if (!ec) acceptor.bind(endpoint, ec);
  if (!ec) acceptor.listen(asio::socket_base::max_listen_connections, ec);
  if (ec) {
    boost::system::error_code ignored;
    acceptor.close(ignored);
    return io_error("cannot listen " + what + "on " + format_endpoint(endpoint) + ": " + ec.message());
  }
  return {};
}

}  // namespace scenewatch::service
