#pragma once
// Typed request/reply over fsi_transport. Sets protocol version and sequence ids, checks
// them on the reply (stale replies are dropped), turns an Error reply into RemoteError.
#include <chrono>
#include <stdexcept>
#include <string>

#include "fsi/transport/transport.hpp"
#include "fsi/v1/coupling.pb.h"

namespace fsi::protocol {

constexpr std::uint32_t kProtocolVersion = fsi::v1::PROTOCOL_VERSION_CURRENT;

// The peer answered with an Error reply, or with something that is not a valid reply.
class RemoteError : public std::runtime_error {
 public:
  RemoteError(fsi::v1::Error::Code code, const std::string& message) : std::runtime_error(message), code_(code) {}
  fsi::v1::Error::Code code() const { return code_; }

 private:
  fsi::v1::Error::Code code_;
};

class ProtocolClient {
 public:
  ProtocolClient(const std::string& endpoint, std::string peer_name,
                 std::chrono::milliseconds timeout = std::chrono::minutes(10), const transport::CurveKeys& keys = {});
  // Sends `request` (version and sequence are filled in) and returns the reply.
  // Throws transport::TransportError (timeout, lost peer) or RemoteError.
  fsi::v1::Reply call(fsi::v1::Request request);
  const std::string& peer_name() const { return peer_name_; }
  const std::string& endpoint() const { return client_.endpoint(); }
  void set_timeout(std::chrono::milliseconds timeout) { timeout_ = timeout; }
  // Wall seconds spent in call() and what the server reported as compute.
  double wall_seconds() const { return wall_seconds_; }
  double server_compute_seconds() const { return compute_seconds_; }
  std::uint64_t calls() const { return sequence_; }
  // How the connection failed, if it did: "" (it did not), "died" (the peer's connection
  // dropped), "timeout" (no reply within the timeout) or "transport" (another error).
  const std::string& failure() const { return failure_; }

 private:
  std::string failure_;
  transport::Client client_;
  std::string peer_name_;
  std::chrono::milliseconds timeout_;
  std::uint64_t sequence_ = 0;
  double wall_seconds_ = 0;
  double compute_seconds_ = 0;
};

// Name of the request body ("solve_step"), for messages.
std::string body_name(const fsi::v1::Request& request);

}  // namespace fsi::protocol
