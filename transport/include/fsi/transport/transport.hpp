#pragma once
// The only code in the project that includes ZeroMQ. Raw bytes in, raw bytes out; the
// typed layer (protocol/) sits on top.
//
// Server: binds one ROUTER socket; each request is [identity, "", payload] so plain REQ
//   and REP peers (e.g. a Python solid using zmq.REP) interoperate with our DEALER client.
// Client: one DEALER socket connected to one server. Every wait has a timeout; a peer
//   whose TCP connection drops while a reply is awaited is reported at once (socket
//   monitor), naming the peer and its endpoint, instead of waiting for the timeout.
// ZeroMQ sets TCP_NODELAY on its TCP sockets (no Nagle delay).
#include <chrono>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace fsi::transport {

class TransportError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};
// No reply within the timeout.
class TimeoutError : public TransportError {
 public:
  using TransportError::TransportError;
};
// The peer's connection dropped (process died, host gone).
class PeerLostError : public TransportError {
 public:
  using TransportError::TransportError;
};

// ZeroMQ CURVE (elliptic-curve encryption and authentication of every connection). Keys
// are Z85 text (40 characters). A folder made by `fsi keys DIR` holds two ZPL certificates
// per side, the format of pyzmq's zmq.auth: server.key / server.key_secret and
// coupler.key / coupler.key_secret.
struct CurveKeys {
  std::string public_key, secret_key;   // this side's pair
  std::string server_public_key;        // a client: the server it may talk to
  std::vector<std::string> authorized;  // a server: the client public keys it accepts
  std::string folder;                   // where they came from (for messages)
  bool enabled() const { return !secret_key.empty(); }
};
// Reads the keys of one side ("server" or "coupler") from a `fsi keys` folder; a server
// accepts the public keys of every *.key certificate in the folder but server.key. Throws TransportError
// naming the file.
CurveKeys load_curve_keys(const std::string& folder, const std::string& side);
// Writes a new server and coupler key pair into `folder` (secret files mode 0600).
void generate_curve_keys(const std::string& folder);

class Client {
 public:
  // `peer_name` names the peer in errors ("solid server"). With `keys`, the connection is
  // encrypted and the server must accept this client's key.
  Client(const std::string& endpoint, std::string peer_name, const CurveKeys& keys = {});
  ~Client();
  Client(const Client&) = delete;
  Client& operator=(const Client&) = delete;

  // Sends one message. Non-blocking up to `timeout` (high-water mark).
  void send(const std::string& payload, std::chrono::milliseconds timeout);
  // Waits for the next message. Throws TimeoutError / PeerLostError.
  std::string receive(std::chrono::milliseconds timeout);
  const std::string& endpoint() const { return endpoint_; }
  const std::string& peer_name() const { return peer_name_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::string endpoint_;
  std::string peer_name_;
};

class Server {
 public:
  // `endpoint` e.g. "tcp://127.0.0.1:*" (a free port is picked) or "tcp://0.0.0.0:5555".
  // With `keys`, only clients whose public key is authorised can connect (ZAP handler).
  explicit Server(const std::string& endpoint, const CurveKeys& keys = {});
  ~Server();
  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;
  // The endpoint actually bound, with the port resolved ("tcp://127.0.0.1:43817").
  std::string endpoint() const;

  // Handler returns the reply bytes; set `stop` to end serving after this reply. `peer`
  // identifies the connection the request came from (opaque bytes, stable while it lasts).
  using Handler = std::function<std::string(const std::string& request, const std::string& peer, bool& stop)>;
  // Serves requests until a handler sets stop, or no request arrives for `idle_timeout`
  // (zero = wait forever), or `should_stop()` returns true (polled every 200 ms).
  // Returns false on idle timeout.
  bool serve(const Handler& handler, std::chrono::milliseconds idle_timeout,
             const std::function<bool()>& should_stop = {});
  // The reply to a message that does not have exactly one frame after its envelope
  // (identity and empty delimiter); without one, such a message is dropped.
  using FrameErrorHandler = std::function<std::string(std::size_t payload_frames)>;
  void set_frame_error_handler(FrameErrorHandler h) { frame_error_ = std::move(h); }
  // Called when the connection of a peer that sent requests closes (its process died or
  // it disconnected), before the next request is handled.
  using DisconnectHandler = std::function<void(const std::string& peer)>;
  void set_disconnect_handler(DisconnectHandler h) { disconnect_ = std::move(h); }

 private:
  void drain_disconnects(std::chrono::milliseconds wait);
  FrameErrorHandler frame_error_;
  DisconnectHandler disconnect_;
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace fsi::transport
