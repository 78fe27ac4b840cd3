#include "fsi/transport/transport.hpp"

#include <sys/stat.h>

#include <algorithm>
#include <atomic>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <memory>
#include <regex>
#include <thread>
#include <vector>
#include <zmq.hpp>

namespace fsi::transport {
namespace {

zmq::context_t& context() {
  static zmq::context_t ctx(1);
  return ctx;
}

std::atomic<int> monitor_counter{0};

// zmq::poll that treats a signal (EINTR) as "nothing ready": callers loop and re-check
// their deadlines and stop flags.
int poll_items(zmq::pollitem_t* items, std::size_t n, std::chrono::milliseconds timeout) {
  try {
    return zmq::poll(items, n, timeout);
  } catch (const zmq::error_t& e) {
    if (e.num() == EINTR) {
      for (std::size_t i = 0; i < n; ++i) items[i].revents = 0;
      return 0;
    }
    throw;
  }
}

// `public-key = "..."` / `secret-key = "..."` of a ZPL certificate.
std::string cert_value(const std::string& file, const std::string& key) {
  std::ifstream in(file);
  if (!in) throw TransportError("cannot read CURVE certificate '" + file + "' (make the folder with `fsi keys DIR`)");
  const std::regex line("^\\s*" + key + "\\s*=\\s*\"([^\"]{40})\"\\s*$");
  for (std::string l; std::getline(in, l);) {
    std::smatch m;
    if (std::regex_match(l, m, line)) return m[1];
  }
  throw TransportError("CURVE certificate '" + file + "' has no " + key + " (40 Z85 characters)");
}

void write_cert(const std::string& file, const std::string& public_key, const std::string& secret_key) {
  std::ofstream out(file);
  if (!out) throw TransportError("cannot write '" + file + "'");
  out << "#   ZeroMQ CURVE " << (secret_key.empty() ? "Public" : "**Secret**") << " Certificate (fsi keys)\n"
      << "#   "
      << (secret_key.empty() ? "Give this file to the peers that must accept this side."
                             : "Keep this file private: it proves this side's identity.")
      << "\nmetadata\ncurve\n    public-key = \"" << public_key << "\"\n";
  if (!secret_key.empty()) out << "    secret-key = \"" << secret_key << "\"\n";
}

}  // namespace

CurveKeys load_curve_keys(const std::string& folder, const std::string& side) {
  namespace fs = std::filesystem;
  if (!fs::is_directory(folder))
    throw TransportError("--curve-keys '" + folder + "' is not a folder (make one with `fsi keys DIR`)");
  CurveKeys k;
  k.folder = folder;
  const std::string secret = (fs::path(folder) / (side + ".key_secret")).string();
  k.public_key = cert_value(secret, "public-key");
  k.secret_key = cert_value(secret, "secret-key");
  if (side == "server") {
    for (const auto& e : fs::directory_iterator(folder))
      if (e.path().extension() == ".key" && e.path().filename() != "server.key")
        k.authorized.push_back(cert_value(e.path().string(), "public-key"));
    if (k.authorized.empty())
      throw TransportError("--curve-keys '" + folder +
                           "' holds no client certificate (*.key, e.g. coupler.key): no client could connect");
  } else {
    k.server_public_key = cert_value((fs::path(folder) / "server.key").string(), "public-key");
  }
  return k;
}

void generate_curve_keys(const std::string& folder) {
  namespace fs = std::filesystem;
  fs::create_directories(folder);
  for (const std::string side : {"server", "coupler"}) {
    char pub[41], sec[41];
    if (zmq_curve_keypair(pub, sec) != 0)
      throw TransportError("this ZeroMQ cannot make CURVE keys (built without libsodium?)");
    const std::string secret_file = (fs::path(folder) / (side + ".key_secret")).string();
    write_cert((fs::path(folder) / (side + ".key")).string(), pub, "");
    { std::ofstream touch(secret_file); }
    ::chmod(secret_file.c_str(), 0600);
    write_cert(secret_file, pub, sec);
  }
}

struct Client::Impl {
  zmq::socket_t socket{context(), zmq::socket_type::dealer};
  zmq::socket_t monitor;
  bool have_monitor = false;
  bool lost = false;  // the peer disconnected while a reply was awaited
  std::string curve_folder;
};

Client::Client(const std::string& endpoint, std::string peer_name, const CurveKeys& keys)
    : impl_(std::make_unique<Impl>()), endpoint_(endpoint), peer_name_(std::move(peer_name)) {
  try {
    impl_->socket.set(zmq::sockopt::linger, 0);
    if (keys.enabled()) {
      impl_->socket.set(zmq::sockopt::curve_serverkey, keys.server_public_key);
      impl_->socket.set(zmq::sockopt::curve_publickey, keys.public_key);
      impl_->socket.set(zmq::sockopt::curve_secretkey, keys.secret_key);
      impl_->curve_folder = keys.folder;
    }
    const std::string mon = "inproc://fsi-client-monitor-" + std::to_string(monitor_counter++);
    if (zmq_socket_monitor(impl_->socket.handle(), mon.c_str(),
                           ZMQ_EVENT_DISCONNECTED | ZMQ_EVENT_HANDSHAKE_FAILED_AUTH |
                               ZMQ_EVENT_HANDSHAKE_FAILED_PROTOCOL | ZMQ_EVENT_HANDSHAKE_FAILED_NO_DETAIL) == 0) {
      impl_->monitor = zmq::socket_t(context(), zmq::socket_type::pair);
      impl_->monitor.set(zmq::sockopt::linger, 0);
      impl_->monitor.connect(mon);
      impl_->have_monitor = true;
    }
    impl_->socket.connect(endpoint);
  } catch (const zmq::error_t& e) {
    throw TransportError("cannot connect to " + peer_name_ + " at '" + endpoint + "': " + e.what());
  }
}

Client::~Client() {
  if (impl_ && impl_->have_monitor) zmq_socket_monitor(impl_->socket.handle(), nullptr, 0);
}

void Client::send(const std::string& payload, std::chrono::milliseconds timeout) {
  if (impl_->lost) throw PeerLostError(peer_name_ + " at " + endpoint_ + " was lost earlier");
  // Poll until writable or the deadline: a signal (EINTR, e.g. the Ctrl-C that the coupler
  // handles after this step) is not a timeout.
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  zmq::pollitem_t item{impl_->socket.handle(), 0, ZMQ_POLLOUT, 0};
  while (true) {
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    poll_items(&item, 1, std::max(left, std::chrono::milliseconds(0)));
    if ((item.revents & ZMQ_POLLOUT) || left.count() <= 0) break;
  }
  if (!(item.revents & ZMQ_POLLOUT))
    throw TimeoutError("cannot send to " + peer_name_ + " at " + endpoint_ + " within " +
                       std::to_string(timeout.count()) + " ms (not connected?)");
  impl_->socket.send(zmq::message_t(), zmq::send_flags::sndmore);
  impl_->socket.send(zmq::buffer(payload), zmq::send_flags::none);
}

std::string Client::receive(std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (true) {
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0)
      throw TimeoutError("no reply from " + peer_name_ + " at " + endpoint_ + " within " +
                         std::to_string(timeout.count()) + " ms");
    zmq::pollitem_t items[2] = {{impl_->socket.handle(), 0, ZMQ_POLLIN, 0},
                                {impl_->have_monitor ? impl_->monitor.handle() : nullptr, 0, ZMQ_POLLIN, 0}};
    poll_items(items, impl_->have_monitor ? 2 : 1, left);
    if (items[0].revents & ZMQ_POLLIN) {
      std::vector<zmq::message_t> frames;
      while (true) {
        zmq::message_t frame;
        (void)impl_->socket.recv(frame, zmq::recv_flags::none);
        const bool more = frame.more();
        frames.push_back(std::move(frame));
        if (!more) break;
      }
      // [ "", payload ] from ROUTER/REP; tolerate a missing delimiter.
      const auto& last = frames.back();
      return std::string(static_cast<const char*>(last.data()), last.size());
    }
    if (impl_->have_monitor && (items[1].revents & ZMQ_POLLIN)) {
      zmq::message_t event, address;
      (void)impl_->monitor.recv(event, zmq::recv_flags::none);
      if (event.more()) (void)impl_->monitor.recv(address, zmq::recv_flags::none);
      uint16_t id = 0;
      if (event.size() >= sizeof(id)) std::memcpy(&id, event.data(), sizeof(id));
      if (id == ZMQ_EVENT_HANDSHAKE_FAILED_AUTH || id == ZMQ_EVENT_HANDSHAKE_FAILED_PROTOCOL ||
          id == ZMQ_EVENT_HANDSHAKE_FAILED_NO_DETAIL) {
        impl_->lost = true;
        throw TransportError(peer_name_ + " at " + endpoint_ + " refused the connection: " +
                             (impl_->curve_folder.empty()
                                  ? std::string("it requires CURVE authentication (--curve-keys)")
                                  : "CURVE authentication failed with the keys of " + impl_->curve_folder +
                                        " (not the server's keys, or this client's key is not authorised)"));
      }
      if (id == ZMQ_EVENT_DISCONNECTED) {
        // A peer that replies and exits at once (Stop) may disconnect before its reply is
        // delivered to this socket: give the reply a short grace period.
        zmq::pollitem_t last{impl_->socket.handle(), 0, ZMQ_POLLIN, 0};
        if (poll_items(&last, 1, std::chrono::milliseconds(100)) > 0 && (last.revents & ZMQ_POLLIN)) continue;
        impl_->lost = true;
        throw PeerLostError(peer_name_ + " at " + endpoint_ +
                            " closed the connection while a reply was awaited (process died?)");
      }
    }
  }
}

struct Server::Impl {
  // The ZAP handler (ZeroMQ's authentication hook, RFC 27) of a CURVE server: accepts
  // the authorised client keys, refuses every other. Runs on its own thread.
  std::thread zap;
  std::atomic<bool> zap_stop{false};
  zmq::socket_t socket{context(), zmq::socket_type::router};
  zmq::socket_t monitor;
  bool have_monitor = false;
  std::map<int, std::string> peer_of_fd;  // the connection (file descriptor) a peer's requests came on
  ~Impl() {
    zap_stop = true;
    if (zap.joinable()) zap.join();
  }
};

Server::Server(const std::string& endpoint, const CurveKeys& keys) : impl_(std::make_unique<Impl>()) {
  try {
    impl_->socket.set(zmq::sockopt::linger, 1000);
    if (keys.enabled()) {
      auto zap = std::make_shared<zmq::socket_t>(context(), zmq::socket_type::rep);
      zap->set(zmq::sockopt::linger, 0);
      zap->bind("inproc://zeromq.zap.01");
      std::vector<std::string> authorized;
      for (const auto& k : keys.authorized) {
        std::string raw(32, '\0');
        if (zmq_z85_decode(reinterpret_cast<std::uint8_t*>(raw.data()), k.c_str())) authorized.push_back(raw);
      }
      impl_->zap = std::thread([zap, authorized, stop = &impl_->zap_stop] {
        try {
          while (!*stop) {
            zmq::pollitem_t item{zap->handle(), 0, ZMQ_POLLIN, 0};
            if (poll_items(&item, 1, std::chrono::milliseconds(100)) <= 0) continue;
            std::vector<zmq::message_t> f;
            while (true) {
              zmq::message_t m;
              (void)zap->recv(m, zmq::recv_flags::none);
              const bool more = m.more();
              f.push_back(std::move(m));
              if (!more) break;
            }
            auto text = [&](std::size_t i) {
              return i < f.size() ? std::string(static_cast<const char*>(f[i].data()), f[i].size()) : std::string();
            };
            const bool ok = text(5) == "CURVE" && f.size() > 6 &&
                            std::find(authorized.begin(), authorized.end(), text(6)) != authorized.end();
            const std::vector<std::string> reply{
                "1.0", text(1), ok ? "200" : "400", ok ? "OK" : "client key not authorised", "", ""};
            for (std::size_t i = 0; i < reply.size(); ++i)
              zap->send(zmq::buffer(reply[i]), i + 1 < reply.size() ? zmq::send_flags::sndmore : zmq::send_flags::none);
          }
        } catch (const zmq::error_t&) {
          // the context is going away: no more connections to authenticate
        }
      });
      impl_->socket.set(zmq::sockopt::curve_server, 1);
      impl_->socket.set(zmq::sockopt::curve_secretkey, keys.secret_key);
      impl_->socket.set(zmq::sockopt::zap_domain, "fsi");
    }
    const std::string mon = "inproc://fsi-server-monitor-" + std::to_string(monitor_counter++);
    if (zmq_socket_monitor(impl_->socket.handle(), mon.c_str(), ZMQ_EVENT_DISCONNECTED) == 0) {
      impl_->monitor = zmq::socket_t(context(), zmq::socket_type::pair);
      impl_->monitor.set(zmq::sockopt::linger, 0);
      impl_->monitor.connect(mon);
      impl_->have_monitor = true;
    }
    impl_->socket.bind(endpoint);
  } catch (const zmq::error_t& e) {
    throw TransportError("cannot bind '" + endpoint + "': " + e.what());
  }
}

Server::~Server() {
  if (impl_ && impl_->have_monitor) zmq_socket_monitor(impl_->socket.handle(), nullptr, 0);
}

// Reads the monitor's DISCONNECTED events (waiting up to `wait` for the first) and reports
// the peers whose connection closed.
void Server::drain_disconnects(std::chrono::milliseconds wait) {
  if (!impl_->have_monitor) return;
  while (true) {
    zmq::pollitem_t item{impl_->monitor.handle(), 0, ZMQ_POLLIN, 0};
    poll_items(&item, 1, wait);
    if (!(item.revents & ZMQ_POLLIN)) return;
    wait = std::chrono::milliseconds(0);
    zmq::message_t event, address;
    (void)impl_->monitor.recv(event, zmq::recv_flags::none);
    if (event.more()) (void)impl_->monitor.recv(address, zmq::recv_flags::none);
    std::uint16_t id = 0;
    std::uint32_t value = 0;
    if (event.size() >= 6) {
      std::memcpy(&id, event.data(), sizeof(id));
      std::memcpy(&value, static_cast<const char*>(event.data()) + 2, sizeof(value));
    }
    if (id != ZMQ_EVENT_DISCONNECTED) continue;
    const auto it = impl_->peer_of_fd.find(static_cast<int>(value));
    if (it == impl_->peer_of_fd.end()) continue;
    const std::string peer = it->second;
    impl_->peer_of_fd.erase(it);
    if (disconnect_) disconnect_(peer);
  }
}

std::string Server::endpoint() const { return impl_->socket.get(zmq::sockopt::last_endpoint); }

bool Server::serve(const Handler& handler, std::chrono::milliseconds idle_timeout,
                   const std::function<bool()>& should_stop) {
  auto last_activity = std::chrono::steady_clock::now();
  while (true) {
    zmq::pollitem_t item{impl_->socket.handle(), 0, ZMQ_POLLIN, 0};
    poll_items(&item, 1, std::chrono::milliseconds(200));
    if (should_stop && should_stop()) return true;
    drain_disconnects(std::chrono::milliseconds(0));
    if (!(item.revents & ZMQ_POLLIN)) {
      if (idle_timeout.count() > 0 && std::chrono::steady_clock::now() - last_activity > idle_timeout) return false;
      continue;
    }
    std::vector<zmq::message_t> frames;
    while (true) {
      zmq::message_t frame;
      (void)impl_->socket.recv(frame, zmq::recv_flags::none);
      const bool more = frame.more();
      frames.push_back(std::move(frame));
      if (!more) break;
    }
    last_activity = std::chrono::steady_clock::now();
    if (frames.size() < 2) continue;  // no identity: cannot answer
    const std::string peer(static_cast<const char*>(frames[0].data()), frames[0].size());
    // A closed connection whose event is still in flight must be seen before a new peer's
    // request is judged (a restarted coupler after its predecessor died): the first request
    // of a new peer, while others are known, gives the monitor up to 100 ms.
    bool known = false;
    for (const auto& [f, p] : impl_->peer_of_fd) known = known || p == peer;
    drain_disconnects(std::chrono::milliseconds(!known && !impl_->peer_of_fd.empty() ? 100 : 0));
    const int fd = frames.back().get(ZMQ_SRCFD);
    if (fd >= 0) {
      for (auto it = impl_->peer_of_fd.begin(); it != impl_->peer_of_fd.end();)
        it = it->second == peer && it->first != fd ? impl_->peer_of_fd.erase(it) : std::next(it);
      impl_->peer_of_fd[fd] = peer;
    }
    // Envelope = the identity and every frame up to and including the empty delimiter (if
    // there is one); exactly one payload frame must follow.
    std::size_t envelope = 1;
    for (std::size_t i = 1; i < frames.size(); ++i)
      if (frames[i].size() == 0) {
        envelope = i + 1;
        break;
      }
    const std::size_t payload_frames = frames.size() - envelope;
    bool stop = false;
    std::string reply;
    if (payload_frames == 1) {
      const auto& payload = frames[envelope];
      reply = handler(std::string(static_cast<const char*>(payload.data()), payload.size()), peer, stop);
    } else if (frame_error_) {
      reply = frame_error_(payload_frames);
    } else {
      continue;
    }
    for (std::size_t i = 0; i < envelope; ++i)
      impl_->socket.send(zmq::buffer(frames[i].data(), frames[i].size()), zmq::send_flags::sndmore);
    impl_->socket.send(zmq::buffer(reply), zmq::send_flags::none);
    if (stop) return true;
  }
}

}  // namespace fsi::transport
