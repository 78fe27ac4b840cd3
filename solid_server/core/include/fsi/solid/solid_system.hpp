#pragma once
// The discrete solid: assembly of internal force and tangent on a fixed sparsity pattern,
// constant operators (mass, interface mass, body force), Dirichlet dofs by elimination,
// and a Newton solver for
//     R(d) = M (c_a d + a_hist) + C (c_v d + v_hist) + F_int(d) - F_ext - F_contact(d) + K_s d = 0
// on the free dofs (c_a = c_v = 0 for statics). The time scheme lives in the caller.
//
// Usage:
//   SolidSystem sys(mesh, material, density, fixed);   // fixed: one flag per dof
// One code for 2D (Q4, plane strain) and 3D (Hex8, Tet10): the mesh's cell kind picks the
// element shape, and the 3D constructor takes the 3D material law.
//   sys.set_damping(sys.boundary_mass(edges, gamma));   // optional (Algorithm 2)
//   NewtonReport r = sys.solve(d, f_ext, terms, options);
// The sparsity pattern is analysed once (first solve); each Newton iteration
// refactorises numerically only.
#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <array>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "fsi/solid/contact.hpp"
#include "fsi/solid/elastic_support.hpp"
#include "fsi/solid/element.hpp"
#include "fsi/solid/material.hpp"
#include "fsi/solid/mesh.hpp"

namespace fsi::solid {

using SparseMatrix = Eigen::SparseMatrix<double>;

enum class LinearSolverKind { Cholmod, Umfpack };

// Sparse direct solver with the symbolic analysis done once. CHOLMOD (supernodal LLT)
// for the symmetric positive definite tangent; when a factorisation reports a non-positive
// pivot it switches to UMFPACK (LU) for good.
class SparseDirectSolver {
 public:
  explicit SparseDirectSolver(LinearSolverKind kind = LinearSolverKind::Cholmod);
  ~SparseDirectSolver();
  SparseDirectSolver(SparseDirectSolver&&) noexcept;
  SparseDirectSolver& operator=(SparseDirectSolver&&) noexcept;
  void factorize(const SparseMatrix& A);  // analyses the pattern on the first call
  Eigen::VectorXd solve(const Eigen::VectorXd& b) const;
  LinearSolverKind kind() const { return kind_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  LinearSolverKind kind_;
};

struct TimeTerms {
  double mass_coefficient = 0;           // c_a: a = c_a d + a_hist
  double damping_coefficient = 0;        // c_v: v = c_v d + v_hist
  Eigen::VectorXd acceleration_history;  // a_hist (empty = 0)
  Eigen::VectorXd velocity_history;      // v_hist (empty = 0)
};

struct NewtonOptions {
  int max_iterations = 25;
  double residual_tolerance = 1e-8;    // ||R_k|| <= tol * max(||R_0||, ||F_ext||)
  double increment_tolerance = 1e-10;  // ||dd|| <= tol * ||d||
};

struct NewtonReport {
  int iterations = 0;
  double residual = 0;  // last ||R|| (free dofs)
  double initial_residual = 0;
  bool converged = false;
};

// Thrown by assembly for a non-positive det F (names the element).
struct InvertedElement : std::runtime_error {
  InvertedElement(int element, double det_F);
  int element;
  double det_F;
};

class SolidSystem {
 public:
  // A 2D mesh with a plane strain law.
  SolidSystem(const SolidMesh& mesh, std::shared_ptr<const Material> material, double density,
              std::vector<char> fixed_dofs, LinearSolverKind solver = LinearSolverKind::Cholmod);
  // A 3D mesh with a 3D law.
  SolidSystem(const SolidMesh& mesh, std::shared_ptr<const Material3> material, double density,
              std::vector<char> fixed_dofs, LinearSolverKind solver = LinearSolverKind::Cholmod);

  int dim() const { return mesh_.dim; }
  int num_dofs() const { return mesh_.dim * mesh_.num_nodes(); }
  int num_free() const { return static_cast<int>(free_dofs_.size()); }
  const SolidMesh& mesh() const { return mesh_; }
  const Material& material() const { return *material_; }     // 2D
  const Material3& material3() const { return *material3_; }  // 3D
  const std::vector<char>& fixed() const { return fixed_; }

  const SparseMatrix& mass() const { return mass_; }  // full, consistent
  // Q4 (2D default) or Q4 with enhanced assumed strains, for every cell; Hex8 (default on
  // hexahedra) or Hex8 with enhanced assumed strains; Tet10 on tetrahedra. Throws
  // std::invalid_argument for an element of another cell kind.
  void set_element(ElementKind kind);
  ElementKind element() const { return element_; }
  // weight * int N^T N ds on the given edges (reference configuration), full size (2D).
  SparseMatrix boundary_mass(const std::vector<Facet>& edges, double weight) const;
  void set_damping(SparseMatrix damping);  // C in R(d); pattern must fit the mesh's
  // C from entries (global dofs; duplicates add up). Entries outside the mesh's pattern (an
  // interface mass that couples nodes of different cells) extend the pattern once; the
  // linear solver then analyses the new pattern.
  void set_damping_entries(const std::vector<Eigen::Triplet<double>>& entries);
  const SparseMatrix& damping() const { return damping_; }
  // Rigid obstacles (contact.hpp): their penalty force enters the residual and its tangent
  // the Newton matrix; nothing changes while every gap stays at or above its g_c.
  void set_contact(std::shared_ptr<const ObstacleContact> contact) { contact_ = std::move(contact); }
  const ObstacleContact* contact() const { return contact_.get(); }
  // Elastic supports (elastic_support.hpp): their linear force K_s d enters the residual and
  // K_s the tangent (null: none).
  void set_support(std::shared_ptr<const ElasticSupport> support) { support_ = std::move(support); }
  const ElasticSupport* support() const { return support_.get(); }

  Eigen::VectorXd body_force(const Eigen::VectorXd& force_per_volume) const;  // dim components
  Eigen::VectorXd body_force(const std::function<Eigen::Vector2d(const Eigen::Vector2d&)>& f, int gauss = 3) const;

  // Internal force F_int(d) (full size). Throws InvertedElement.
  Eigen::VectorXd internal_force(const Eigen::VectorXd& d) const;
  // Full residual R(d) (all dofs; on fixed dofs it is the reaction with opposite sign).
  Eigen::VectorXd residual(const Eigen::VectorXd& d, const Eigen::VectorXd& f_ext, const TimeTerms& t) const;
  // Tangent on the free dofs: K(d) + c_a M + c_v C, and the free part of the residual.
  void assemble(const Eigen::VectorXd& d, const Eigen::VectorXd& f_ext, const TimeTerms& t, SparseMatrix& tangent,
                Eigen::VectorXd& residual_free) const;

  // Newton on the free dofs; d holds the prescribed values on fixed dofs and the initial
  // guess elsewhere. Does not throw on non-convergence (see the report); throws
  // InvertedElement.
  NewtonReport solve(Eigen::VectorXd& d, const Eigen::VectorXd& f_ext, const TimeTerms& t,
                     const NewtonOptions& options);
  // Solves M_ff x = b_f on the free dofs (x = 0 on fixed dofs), e.g. initial accelerations.
  Eigen::VectorXd solve_mass(const Eigen::VectorXd& b) const;

  // Linear solver state (for timings and tests).
  SparseDirectSolver& linear_solver() { return solver_; }
  int equation(int dof) const { return equation_[dof]; }

  // A cell's reference coordinates and displacement dofs (Shape: the mesh's, see with_shape).
  template <class Shape = Quad4>
  typename ElementTraits<Shape>::Coords cell_coordinates(int cell) const {
    typename ElementTraits<Shape>::Coords X;
    for (int a = 0; a < Shape::nodes; ++a) X.row(a) = mesh_.nodes.row(mesh_.cells[cell][a]);
    return X;
  }
  template <class Shape = Quad4>
  typename ElementTraits<Shape>::Vector cell_values(int cell, const Eigen::VectorXd& d) const {
    typename ElementTraits<Shape>::Vector u;
    for (int a = 0; a < Shape::nodes; ++a)
      u.template segment<Shape::dim>(Shape::dim * a) = d.segment<Shape::dim>(Shape::dim * mesh_.cells[cell][a]);
    return u;
  }

 private:
  int position(int row, int col) const;       // value index in the full pattern (throws outside it)
  int find_position(int row, int col) const;  // -1 outside the pattern
  // (Re)builds pattern_, the reduced pattern, the value maps and mass_ with the cells' entries
  // plus `extra` (global dof pairs).
  void build_pattern(const std::vector<Eigen::Triplet<double>>& extra);
  SolidMesh mesh_;
  std::shared_ptr<const Material> material_;    // 2D meshes
  std::shared_ptr<const Material3> material3_;  // 3D meshes
  double density_;
  std::vector<char> fixed_;
  std::vector<int> equation_;         // dof -> free equation or -1
  std::vector<int> free_dofs_;        // equation -> dof
  SparseMatrix pattern_;              // full pattern (values zero)
  SparseMatrix mass_, damping_;       // full, on pattern_
  SparseMatrix reduced_pattern_;      // free x free
  std::vector<int> full_to_reduced_;  // value index map, -1 for fixed rows/cols
  std::vector<int> cell_positions_;   // (dofs per cell)^2 per cell: full value index
  SparseDirectSolver solver_;
  std::shared_ptr<const ObstacleContact> contact_;  // null: no obstacles
  std::shared_ptr<const ElasticSupport> support_;   // null: no elastic supports
  ElementKind element_ = ElementKind::Q4;
  template <class Shape>
  ElementStateT<Shape> cell_state(int cell, const Eigen::VectorXd& d, bool with_tangent) const;
  void initialise();  // checks the cells, numbers the free dofs, builds the pattern
};

}  // namespace fsi::solid
