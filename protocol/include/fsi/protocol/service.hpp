#pragma once
// Server side: turns wire requests into calls on a SolidModel / FluidModel, and every
// outcome (including exceptions) into exactly one Reply. A request that does not parse,
// has the wrong version or arrives out of order gets an Error reply; the server stays up.
#include <functional>
#include <memory>
#include <string>

#include "fsi/common/solver_model.hpp"
#include "fsi/common/standalone.hpp"
#include "fsi/transport/transport.hpp"
#include "fsi/v1/coupling.pb.h"

namespace fsi::protocol {

// Handles raw request bytes -> raw reply bytes; sets `stop` after a Stop request.
class Service {
 public:
  virtual ~Service() = default;
  // `peer` identifies the client's connection (transport); "" = the only client.
  std::string handle_bytes(const std::string& request_bytes, bool& stop, const std::string& peer = "");
  fsi::v1::Reply handle(const fsi::v1::Request& request, bool& stop, const std::string& peer = "");
  // The connection of `peer` closed: its session, if it holds one, ends and the server
  // forgets its configuration (the next coupler configures it again).
  void peer_gone(const std::string& peer);
  bool in_session() const { return session_open_; }

 protected:
  virtual void dispatch(const fsi::v1::Request& request, fsi::v1::Reply& reply, bool& stop) = 0;
  // "'solve_step' before 'configure'", naming the last Configure's failure if there was one.
  std::string before_configure(const std::string& request) const;
  std::string configure_failure_;
  // Called when a session ends without Stop: drop the model.
  virtual void reset() = 0;

 private:
  bool session_open_ = false;
  std::string session_peer_, session_id_, session_client_, session_since_;
};

using fsi::FluidFactory;
using fsi::SolidFactory;

class SolidService : public Service {
 public:
  SolidService(SolidFactory factory, std::string server_name);

 protected:
  void dispatch(const fsi::v1::Request& request, fsi::v1::Reply& reply, bool& stop) override;
  void reset() override { model_.reset(); }

 private:
  SolidFactory factory_;
  std::string server_name_;
  std::unique_ptr<SolidModel> model_;
  std::size_t interface_nodes_ = 0;
  int dimension_ = 2;  // of the model's interface
  double dt_ = 0;
};

class FluidService : public Service {
 public:
  FluidService(FluidFactory factory, std::string server_name);

 protected:
  void dispatch(const fsi::v1::Request& request, fsi::v1::Reply& reply, bool& stop) override;
  void reset() override { model_.reset(); }

 private:
  FluidFactory factory_;
  std::string server_name_;
  std::unique_ptr<FluidModel> model_;
  std::size_t interface_nodes_ = 0;
  int dimension_ = 2;  // of the model's interface
};

// Binds `endpoint`, writes the bound endpoint to `port_file` (if non-empty, atomically),
// and serves until Stop, idle timeout, or SIGINT/SIGTERM. Returns the process exit code.
// With CURVE `keys`, only authorised clients can connect.
int run_server(Service& service, const std::string& endpoint, const std::string& port_file, double idle_timeout_seconds,
               const std::string& log_name, const transport::CurveKeys& keys = {});

}  // namespace fsi::protocol
