#pragma once
// Client side: a SolidModel / FluidModel whose work is done by a server process. The
// coupler drives these exactly like in-process models.
#include <memory>

#include "fsi/common/solver_model.hpp"
#include "fsi/protocol/client.hpp"

namespace fsi::protocol {

struct RemoteTimes {
  double wall = 0;     // seconds inside calls
  double compute = 0;  // seconds the server reported computing
  double messaging() const { return wall > compute ? wall - compute : 0.0; }
};

class RemoteSolid : public SolidModel {
 public:
  explicit RemoteSolid(std::unique_ptr<ProtocolClient> client);
  std::string name() const override { return server_name_; }
  bool supports_interface_damping() const override { return supports_damping_; }
  bool supports_interface_mass() const override { return supports_interface_mass_; }
  void set_interface_mass(const NodalMatrix& m) override { interface_mass_ = m, send_interface_mass_ = true; }
  void configure(const ConfigSection& section, const SolidSetup& setup) override;
  InterfaceMeshData interface() const override { return interface_; }
  SolidStepResult solve_step(const StepInfo& info, const Eigen::VectorXd& interface_force) override;
  bool supports_substeps() const override { return supports_substeps_; }
  SolidStepResult solve_window(const StepInfo& info, const Waveform& force, int substeps) override;
  std::map<std::string, double> accept_step(const StepInfo& info) override;
  std::vector<std::string> write_output(const StepInfo& info) override;
  std::map<std::string, double> timings() const override { return timings_; }
  std::map<std::string, double> diagnostics() const override { return diagnostics_; }
  bool supports_checkpoint() const override { return supports_checkpoint_; }
  bool supports_output() const override { return supports_output_; }
  std::string save_checkpoint(int step, double time) override;
  void load_checkpoint(int step, double time, const std::string& bytes) override;
  void stop(const std::string& reason);
  RemoteTimes times() const { return {client_->wall_seconds(), client_->server_compute_seconds()}; }
  ProtocolClient& client() { return *client_; }

 private:
  std::map<std::string, double> timings_;
  std::map<std::string, double> diagnostics_;
  std::unique_ptr<ProtocolClient> client_;
  std::string server_name_ = "solid server";
  bool supports_damping_ = false;
  bool supports_interface_mass_ = false;
  NodalMatrix interface_mass_;
  bool send_interface_mass_ = false;  // a new M_G goes with the next SolveStep
  bool supports_substeps_ = false;
  bool supports_checkpoint_ = false;
  bool supports_output_ = false;
  InterfaceMeshData interface_;
};

class RemoteFluid : public FluidModel {
 public:
  explicit RemoteFluid(std::unique_ptr<ProtocolClient> client);
  std::string name() const override { return server_name_; }
  void configure(const ConfigSection& section, const FluidSetup& setup) override;
  InterfaceMeshData interface() const override { return interface_; }
  FluidLoads initial_loads(const Eigen::VectorXd& d, const Eigen::VectorXd& v) override;
  FluidLoads solve_step(const StepInfo& info, const Eigen::VectorXd& d, const Eigen::VectorXd& v) override;
  bool supports_robin() const override { return supports_robin_; }
  FluidLoads solve_robin(const StepInfo& info, const Eigen::VectorXd& d, const RobinCondition& robin) override;
  bool supports_substeps() const override { return supports_substeps_; }
  FluidLoads solve_window(const StepInfo& info, const Waveform& d, const Waveform& v, int substeps) override;
  std::map<std::string, double> accept_step(const StepInfo& info) override;
  std::vector<std::string> write_output(const StepInfo& info) override;
  std::map<std::string, double> timings() const override { return timings_; }
  std::map<std::string, double> diagnostics() const override { return diagnostics_; }
  bool supports_checkpoint() const override { return supports_checkpoint_; }
  bool supports_output() const override { return supports_output_; }
  std::string save_checkpoint(int step, double time) override;
  void load_checkpoint(int step, double time, const std::string& bytes) override;
  void stop(const std::string& reason);
  RemoteTimes times() const { return {client_->wall_seconds(), client_->server_compute_seconds()}; }
  ProtocolClient& client() { return *client_; }

 private:
  std::map<std::string, double> timings_;
  std::map<std::string, double> diagnostics_;
  std::unique_ptr<ProtocolClient> client_;
  std::string server_name_ = "fluid server";
  bool supports_checkpoint_ = false;
  bool supports_output_ = false;
  bool supports_robin_ = false;
  bool supports_substeps_ = false;
  InterfaceMeshData interface_;
};

// Conversions between Eigen vectors and repeated double fields.
Eigen::VectorXd to_eigen(const google::protobuf::RepeatedField<double>& field);
void from_eigen(const Eigen::VectorXd& v, google::protobuf::RepeatedField<double>* field);
// NodalMatrix <-> fsi.v1.NodalMatrix (coordinate format). nodal_from_proto checks the size
// (n nodes), the indices and finiteness; std::invalid_argument names `what` and the entry.
void nodal_to_proto(const NodalMatrix& m, fsi::v1::NodalMatrix* out);
NodalMatrix nodal_from_proto(const fsi::v1::NodalMatrix& m, std::size_t n, const std::string& what);
InterfaceMeshData interface_from_proto(const fsi::v1::InterfaceMesh& mesh);
void interface_to_proto(const InterfaceMeshData& data, fsi::v1::InterfaceMesh* mesh);

}  // namespace fsi::protocol
