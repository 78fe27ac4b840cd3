#include "fsi/protocol/client.hpp"

#include <fmt/format.h>

#include <cmath>

namespace fsi::protocol {

std::string body_name(const fsi::v1::Request& request) {
  const auto* field = request.GetDescriptor()->FindFieldByNumber(request.body_case());
  return field ? field->name() : "empty request";
}

ProtocolClient::ProtocolClient(const std::string& endpoint, std::string peer_name, std::chrono::milliseconds timeout,
                               const transport::CurveKeys& keys)
    : client_(endpoint, peer_name, keys), peer_name_(std::move(peer_name)), timeout_(timeout) {}

fsi::v1::Reply ProtocolClient::call(fsi::v1::Request request) {
  const auto start = std::chrono::steady_clock::now();
  request.set_protocol_version(kProtocolVersion);
  request.set_sequence(++sequence_);
  const std::string what = body_name(request);
  try {
    client_.send(request.SerializeAsString(), timeout_);
  } catch (const transport::TimeoutError&) {
    failure_ = "timeout";
    throw;
  } catch (const transport::PeerLostError&) {
    failure_ = "died";
    throw;
  } catch (const transport::TransportError&) {
    failure_ = "transport";
    throw;
  }
  fsi::v1::Reply reply;
  while (true) {
    const auto left =
        timeout_ - std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::steady_clock::now() - start);
    std::string bytes;
    try {
      bytes = client_.receive(std::max(left, std::chrono::milliseconds(1)));
    } catch (const transport::TimeoutError& e) {
      failure_ = "timeout";
      throw transport::TimeoutError(fmt::format("{} (request '{}', sequence {})", e.what(), what, sequence_));
    } catch (const transport::PeerLostError& e) {
      failure_ = "died";
      throw transport::PeerLostError(fmt::format("{} (request '{}', sequence {})", e.what(), what, sequence_));
    } catch (const transport::TransportError& e) {
      failure_ = "transport";
      throw transport::TransportError(fmt::format("{} (request '{}', sequence {})", e.what(), what, sequence_));
    }
    if (!reply.ParseFromString(bytes))
      throw RemoteError(
          fsi::v1::Error::MALFORMED,
          fmt::format("{} sent a reply that is not a fsi.v1.Reply ({} bytes) to '{}'", peer_name_, bytes.size(), what));
    if (reply.sequence() != 0 && reply.sequence() < sequence_) continue;  // stale reply
    break;
  }
  const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  wall_seconds_ += elapsed;
  if (!(std::isfinite(reply.compute_seconds()) && reply.compute_seconds() >= 0))
    throw RemoteError(fsi::v1::Error::INVALID_ARGUMENT,
                      fmt::format("{} answered '{}' with compute_seconds = {} (must be finite and >= 0)", peer_name_,
                                  what, reply.compute_seconds()));
  compute_seconds_ += reply.compute_seconds();
  if (reply.has_error())
    throw RemoteError(reply.error().code(),
                      fmt::format("{} failed on '{}': {}", peer_name_, what, reply.error().message()));
  if (reply.protocol_version() != kProtocolVersion)
    throw RemoteError(fsi::v1::Error::VERSION_MISMATCH,
                      fmt::format("{} speaks protocol version {}, this coupler speaks {}", peer_name_,
                                  reply.protocol_version(), kProtocolVersion));
  if (reply.sequence() != sequence_)
    throw RemoteError(fsi::v1::Error::BAD_SEQUENCE, fmt::format("{} answered sequence {} to request {} ('{}')",
                                                                peer_name_, reply.sequence(), sequence_, what));
  return reply;
}

}  // namespace fsi::protocol
