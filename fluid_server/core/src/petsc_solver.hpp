#pragma once
// The PETSc engines (linear_solver.hpp); built only with PETSc (FSI_HAVE_PETSC).
#include <memory>
#include <string>
#include <vector>

#include "fsi/fluid/linear_solver.hpp"

namespace fsi::fluid {

class PetscSolver final : public LinearSolver {
 public:
  // Initialises PETSc (and MPI) at the first call. std::invalid_argument for options PETSc
  // cannot parse.
  PetscSolver(const FlowParameters& params, std::vector<char> pressure);
  ~PetscSolver() override;
  Eigen::VectorXd solve(const Eigen::SparseMatrix<double>& A, const Eigen::VectorXd& b, const Eigen::VectorXd& guess,
                        StepReport& report, const std::string& where, double time_coefficient) override;
  int partition_id() const override;
  Eigen::VectorXd solve_filled(int unknowns, const Eigen::VectorXd& guess, StepReport& report, const std::string& where,
                               double time_coefficient) override;
  void discard_factors() override;
  void save_state(StateArchive& state, const std::string& prefix) const override;
  void load_state(const StateArchive& state, const std::string& prefix) override;

 private:
  Eigen::VectorXd run(Eigen::Index unknowns, Eigen::Index nonzeros,
                      const Eigen::SparseMatrix<double, Eigen::RowMajor>* rows, const Eigen::VectorXd* b,
                      const Eigen::VectorXd& guess, StepReport& report, const std::string& where,
                      double time_coefficient);
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

std::string petsc_default_options(LinearEngine engine);
int petsc_start_mpi_ranks();

}  // namespace fsi::fluid
