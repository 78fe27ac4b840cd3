#include "fsi/solid/solid_system.hpp"

#include <Eigen/CholmodSupport>
#include <Eigen/SparseCholesky>
#include <Eigen/UmfPackSupport>
#include <algorithm>
#include <cmath>
#include <string>

#include "fsi/common/log.hpp"
#include "fsi/common/solver_model.hpp"
#include "fsi/solid/element.hpp"

namespace fsi::solid {

// ---------------------------------------------------------------- linear solver
struct SparseDirectSolver::Impl {
  Eigen::CholmodSupernodalLLT<SparseMatrix, Eigen::Lower> cholmod;
  Eigen::UmfPackLU<SparseMatrix> umfpack;
  bool analysed = false;
};

SparseDirectSolver::SparseDirectSolver(LinearSolverKind kind) : impl_(std::make_unique<Impl>()), kind_(kind) {
  // Inside Newton the iterative refinement of UMFPACK is not worth its cost.
  impl_->umfpack.umfpackControl()(UMFPACK_IRSTEP) = 0;
}
SparseDirectSolver::~SparseDirectSolver() = default;
SparseDirectSolver::SparseDirectSolver(SparseDirectSolver&&) noexcept = default;
SparseDirectSolver& SparseDirectSolver::operator=(SparseDirectSolver&&) noexcept = default;

void SparseDirectSolver::factorize(const SparseMatrix& A) {
  if (kind_ == LinearSolverKind::Cholmod) {
    if (!impl_->analysed) impl_->cholmod.analyzePattern(A), impl_->analysed = true;
    impl_->cholmod.factorize(A);
    if (impl_->cholmod.info() == Eigen::Success) return;
    fsi::logger("solid")->warn("CHOLMOD: tangent not positive definite; switching to UMFPACK");
    kind_ = LinearSolverKind::Umfpack;
    impl_->analysed = false;
  }
  if (!impl_->analysed) impl_->umfpack.analyzePattern(A), impl_->analysed = true;
  impl_->umfpack.factorize(A);
  if (impl_->umfpack.info() != Eigen::Success) throw fsi::SolverError("UMFPACK: singular tangent matrix");
}

Eigen::VectorXd SparseDirectSolver::solve(const Eigen::VectorXd& b) const {
  if (kind_ == LinearSolverKind::Cholmod) return impl_->cholmod.solve(b);
  return impl_->umfpack.solve(b);
}

// ---------------------------------------------------------------- system

InvertedElement::InvertedElement(int e, double det)
    : std::runtime_error("element " + std::to_string(e) + ": det F = " + std::to_string(det) + " <= 0"),
      element(e),
      det_F(det) {}

SolidSystem::SolidSystem(const SolidMesh& mesh, std::shared_ptr<const Material> material, double density,
                         std::vector<char> fixed_dofs, LinearSolverKind solver)
    : mesh_(mesh), material_(std::move(material)), density_(density), fixed_(std::move(fixed_dofs)), solver_(solver) {
  if (mesh_.dim != 2) throw std::invalid_argument("SolidSystem: a 2D material law needs a 2D mesh");
  initialise();
}

SolidSystem::SolidSystem(const SolidMesh& mesh, std::shared_ptr<const Material3> material, double density,
                         std::vector<char> fixed_dofs, LinearSolverKind solver)
    : mesh_(mesh), material3_(std::move(material)), density_(density), fixed_(std::move(fixed_dofs)), solver_(solver) {
  if (mesh_.dim != 3) throw std::invalid_argument("SolidSystem: a 3D material law needs a 3D mesh");
  if (mesh_.cell == CellKind::Quad4)
    throw std::invalid_argument("SolidSystem: a 3D mesh needs Hex8 or Tet10 cells (SolidMesh::cell)");
  element_ = mesh_.cell == CellKind::Tet10 ? ElementKind::Tet10 : ElementKind::Hex8;
  initialise();
}

void SolidSystem::set_element(ElementKind kind) {
  const CellKind cell = kind == ElementKind::Tet10                                  ? CellKind::Tet10
                        : kind == ElementKind::Hex8 || kind == ElementKind::Hex8Eas ? CellKind::Hex8
                                                                                    : CellKind::Quad4;
  if (cell != mesh_.cell)
    throw std::invalid_argument(std::string("SolidSystem: a ") + cell_kind_name(cell) + " element on a mesh of " +
                                cell_kind_name(mesh_.cell) + " cells");
  element_ = kind;
}

void SolidSystem::initialise() {
  const int n = num_dofs();
  if ((mesh_.dim == 2) != (mesh_.cell == CellKind::Quad4))
    throw std::invalid_argument(std::string("SolidSystem: a ") + std::to_string(mesh_.dim) + "D mesh of " +
                                cell_kind_name(mesh_.cell) + " cells");
  if (mesh_.nodes.cols() != mesh_.dim)
    throw std::invalid_argument("SolidSystem: the mesh's nodes need " + std::to_string(mesh_.dim) + " coordinates");
  if (static_cast<int>(fixed_.size()) != n)
    throw std::invalid_argument("SolidSystem: fixed flags must have one entry per dof");
  equation_.assign(n, -1);
  for (int i = 0; i < n; ++i)
    if (!fixed_[i]) equation_[i] = static_cast<int>(free_dofs_.size()), free_dofs_.push_back(i);

  for (int c = 0; c < mesh_.num_cells(); ++c) {
    if (static_cast<int>(mesh_.cells[c].size()) != mesh_.nodes_per_cell())
      throw std::invalid_argument("cell " + std::to_string(c) + " has " + std::to_string(mesh_.cells[c].size()) +
                                  " nodes, expected " + std::to_string(mesh_.nodes_per_cell()));
    for (int node : mesh_.cells[c])
      if (node < 0 || node >= mesh_.num_nodes())
        throw std::invalid_argument("cell " + std::to_string(c) + " names node " + std::to_string(node) +
                                    " of a mesh of " + std::to_string(mesh_.num_nodes()));
    if (mesh_.dim == 2) {
      const auto X = cell_coordinates(c);
      double area2 = 0;
      for (int a = 0; a < 4; ++a) area2 += X(a, 0) * X((a + 1) % 4, 1) - X((a + 1) % 4, 0) * X(a, 1);
      if (!(area2 > 0))
        throw std::invalid_argument("cell " + std::to_string(c) + " is not counter-clockwise or is degenerate");
    } else {
      with_shape(mesh_.cell, [&](auto shape) {
        using Shape = decltype(shape);
        const auto X = cell_coordinates<Shape>(c);
        for (const auto& [xi, w] : Shape::gauss())
          if (!((X.transpose() * Shape::derivatives(xi)).determinant() > 0))
            throw std::invalid_argument("cell " + std::to_string(c) + " is inverted or degenerate (node order)");
      });
    }
  }

  build_pattern({});
}

void SolidSystem::build_pattern(const std::vector<Eigen::Triplet<double>>& extra) {
  const int n = num_dofs(), dim = mesh_.dim, nd = dim * mesh_.nodes_per_cell(), nd2 = nd * nd;
  // Full pattern from the cell connectivity (and the extra entries).
  std::vector<Eigen::Triplet<double>> trip;
  trip.reserve(nd2 * mesh_.cells.size() + extra.size());
  for (const auto& cell : mesh_.cells)
    for (int a = 0; a < nd; ++a)
      for (int b = 0; b < nd; ++b) trip.emplace_back(dim * cell[a / dim] + a % dim, dim * cell[b / dim] + b % dim, 0.0);
  for (const auto& e : extra) trip.emplace_back(e.row(), e.col(), 0.0);
  pattern_.resize(n, n);
  pattern_.setFromTriplets(trip.begin(), trip.end());
  pattern_.makeCompressed();

  cell_positions_.resize(nd2 * mesh_.cells.size());
  for (std::size_t c = 0; c < mesh_.cells.size(); ++c) {
    const auto& cell = mesh_.cells[c];
    for (int a = 0; a < nd; ++a)
      for (int b = 0; b < nd; ++b)
        cell_positions_[nd2 * c + nd * a + b] = position(dim * cell[a / dim] + a % dim, dim * cell[b / dim] + b % dim);
  }

  // Reduced pattern and the value map.
  std::vector<Eigen::Triplet<double>> rtrip;
  for (int col = 0; col < n; ++col)
    for (SparseMatrix::InnerIterator it(pattern_, col); it; ++it)
      if (equation_[it.row()] >= 0 && equation_[col] >= 0) rtrip.emplace_back(equation_[it.row()], equation_[col], 0.0);
  reduced_pattern_.resize(num_free(), num_free());
  reduced_pattern_.setFromTriplets(rtrip.begin(), rtrip.end());
  reduced_pattern_.makeCompressed();
  full_to_reduced_.assign(pattern_.nonZeros(), -1);
  for (int col = 0; col < n; ++col)
    for (SparseMatrix::InnerIterator it(pattern_, col); it; ++it) {
      const int r = equation_[it.row()], c = equation_[col];
      if (r < 0 || c < 0) continue;
      const int* begin = reduced_pattern_.innerIndexPtr() + reduced_pattern_.outerIndexPtr()[c];
      const int* end = reduced_pattern_.innerIndexPtr() + reduced_pattern_.outerIndexPtr()[c + 1];
      full_to_reduced_[&it.valueRef() - pattern_.valuePtr()] =
          static_cast<int>(std::lower_bound(begin, end, r) - reduced_pattern_.innerIndexPtr());
    }

  mass_ = pattern_;
  with_shape(mesh_.cell, [&](auto shape) {
    using Shape = decltype(shape);
    for (int c = 0; c < mesh_.num_cells(); ++c) {
      const auto Me = element_mass<Shape>(cell_coordinates<Shape>(c), density_);
      for (int k = 0; k < nd2; ++k) mass_.valuePtr()[cell_positions_[nd2 * c + k]] += Me(k / nd, k % nd);
    }
  });
  damping_ = pattern_;
  solver_ = SparseDirectSolver(solver_.kind());  // a new pattern: analysed again on the next solve
}

int SolidSystem::find_position(int row, int col) const {
  const int* begin = pattern_.innerIndexPtr() + pattern_.outerIndexPtr()[col];
  const int* end = pattern_.innerIndexPtr() + pattern_.outerIndexPtr()[col + 1];
  const int* it = std::lower_bound(begin, end, row);
  if (it == end || *it != row) return -1;
  return static_cast<int>(it - pattern_.innerIndexPtr());
}

void SolidSystem::set_damping_entries(const std::vector<Eigen::Triplet<double>>& entries) {
  for (const auto& e : entries)
    if (e.row() < 0 || e.row() >= num_dofs() || e.col() < 0 || e.col() >= num_dofs())
      throw std::invalid_argument("set_damping_entries: entry outside the system's dofs");
  bool inside = true;
  for (const auto& e : entries)
    if (find_position(e.row(), e.col()) < 0) {
      inside = false;
      break;
    }
  if (!inside) build_pattern(entries);
  SparseMatrix C = pattern_;
  for (const auto& e : entries) C.valuePtr()[position(e.row(), e.col())] += e.value();
  damping_ = std::move(C);
}

int SolidSystem::position(int row, int col) const {
  const int* begin = pattern_.innerIndexPtr() + pattern_.outerIndexPtr()[col];
  const int* end = pattern_.innerIndexPtr() + pattern_.outerIndexPtr()[col + 1];
  const int* it = std::lower_bound(begin, end, row);
  if (it == end || *it != row) throw std::invalid_argument("entry outside the mesh's sparsity pattern");
  return static_cast<int>(it - pattern_.innerIndexPtr());
}

SparseMatrix SolidSystem::boundary_mass(const std::vector<Facet>& edges, double weight) const {
  if (mesh_.dim != 2) throw std::invalid_argument("boundary_mass: 2D meshes only");
  SparseMatrix C = pattern_;
  for (const auto& e : edges) {
    const Eigen::Matrix4d Me = edge_mass(mesh_.nodes.row(e[0]).transpose(), mesh_.nodes.row(e[1]).transpose(), weight);
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b) C.valuePtr()[position(2 * e[a / 2] + a % 2, 2 * e[b / 2] + b % 2)] += Me(a, b);
  }
  return C;
}

void SolidSystem::set_damping(SparseMatrix damping) {
  if (damping.rows() != num_dofs() || damping.nonZeros() != pattern_.nonZeros())
    throw std::invalid_argument("set_damping: matrix must be built on the system's pattern (boundary_mass)");
  damping_ = std::move(damping);
}

Eigen::VectorXd SolidSystem::body_force(const Eigen::VectorXd& b) const {
  if (b.size() != mesh_.dim) throw std::invalid_argument("body_force: one component per dimension");
  Eigen::VectorXd f = Eigen::VectorXd::Zero(num_dofs());
  with_shape(mesh_.cell, [&](auto shape) {
    using Shape = decltype(shape);
    constexpr int dim = Shape::dim;
    const Eigen::Matrix<double, dim, 1> bd = b;
    for (int c = 0; c < mesh_.num_cells(); ++c) {
      const auto fe = element_body_force<Shape>(cell_coordinates<Shape>(c), bd);
      for (int a = 0; a < Shape::nodes; ++a)
        f.segment<dim>(dim * mesh_.cells[c][a]) += fe.template segment<dim>(dim * a);
    }
  });
  return f;
}

Eigen::VectorXd SolidSystem::body_force(const std::function<Eigen::Vector2d(const Eigen::Vector2d&)>& b,
                                        int gauss) const {
  if (mesh_.dim != 2) throw std::invalid_argument("body_force(function): 2D meshes only");
  Eigen::VectorXd f = Eigen::VectorXd::Zero(num_dofs());
  const auto rule = gauss_rule_2d(gauss);
  for (int c = 0; c < mesh_.num_cells(); ++c) {
    const auto X = cell_coordinates(c);
    for (const auto& [xi, eta, w] : rule) {
      const Eigen::Vector4d N = q4_shape(xi, eta);
      const double dV = w * (X.transpose() * q4_shape_derivatives(xi, eta)).determinant();
      const Eigen::Vector2d bx = b(X.transpose() * N);
      for (int a = 0; a < 4; ++a) f.segment<2>(2 * mesh_.cells[c][a]) += dV * N(a) * bx;
    }
  }
  return f;
}

template <class Shape>
ElementStateT<Shape> SolidSystem::cell_state(int c, const Eigen::VectorXd& d, bool with_tangent) const {
  const auto& law = [this]() -> const MaterialLaw<Shape::dim>& {
    if constexpr (Shape::dim == 2)
      return *material_;
    else
      return *material3_;
  }();
  if constexpr (Shape::eas_modes > 0)
    if (is_enhanced(element_))
      return eas_internal_force<Shape>(cell_coordinates<Shape>(c), cell_values<Shape>(c, d), law, with_tangent);
  return solid::internal_force<Shape>(cell_coordinates<Shape>(c), cell_values<Shape>(c, d), law, with_tangent);
}

Eigen::VectorXd SolidSystem::internal_force(const Eigen::VectorXd& d) const {
  Eigen::VectorXd f = Eigen::VectorXd::Zero(num_dofs());
  with_shape(mesh_.cell, [&](auto shape) {
    using Shape = decltype(shape);
    constexpr int dim = Shape::dim;
    for (int c = 0; c < mesh_.num_cells(); ++c) {
      const ElementStateT<Shape> s = cell_state<Shape>(c, d, false);
      if (!(s.min_det_F > 0)) throw InvertedElement(c, s.min_det_F);
      for (int a = 0; a < Shape::nodes; ++a)
        f.segment<dim>(dim * mesh_.cells[c][a]) += s.internal_force.template segment<dim>(dim * a);
    }
  });
  return f;
}

namespace {
Eigen::VectorXd time_vector(double coef, const Eigen::VectorXd& d, const Eigen::VectorXd& hist) {
  Eigen::VectorXd v = coef * d;
  if (hist.size()) v += hist;
  return v;
}
}  // namespace

Eigen::VectorXd SolidSystem::residual(const Eigen::VectorXd& d, const Eigen::VectorXd& f_ext,
                                      const TimeTerms& t) const {
  Eigen::VectorXd r = internal_force(d) - f_ext;
  if (t.mass_coefficient != 0 || t.acceleration_history.size())
    r += mass_ * time_vector(t.mass_coefficient, d, t.acceleration_history);
  if (damping_.nonZeros() && (t.damping_coefficient != 0 || t.velocity_history.size()))
    r += damping_ * time_vector(t.damping_coefficient, d, t.velocity_history);
  if (contact_) contact_->add_to_residual(d, r);
  if (support_) support_->add_to_residual(d, r);
  return r;
}

void SolidSystem::assemble(const Eigen::VectorXd& d, const Eigen::VectorXd& f_ext, const TimeTerms& t, SparseMatrix& K,
                           Eigen::VectorXd& r_free) const {
  if (K.nonZeros() != reduced_pattern_.nonZeros()) K = reduced_pattern_;
  std::fill(K.valuePtr(), K.valuePtr() + K.nonZeros(), 0.0);
  Eigen::VectorXd r = -f_ext;
  double* values = K.valuePtr();
  with_shape(mesh_.cell, [&](auto shape) {
    using Shape = decltype(shape);
    constexpr int dim = Shape::dim, nd = ElementTraits<Shape>::dofs;
    for (int c = 0; c < mesh_.num_cells(); ++c) {
      const ElementStateT<Shape> s = cell_state<Shape>(c, d, true);
      if (!(s.min_det_F > 0)) throw InvertedElement(c, s.min_det_F);
      for (int a = 0; a < Shape::nodes; ++a)
        r.segment<dim>(dim * mesh_.cells[c][a]) += s.internal_force.template segment<dim>(dim * a);
      const int* pos = &cell_positions_[nd * nd * c];
      for (int k = 0; k < nd * nd; ++k) {
        const int red = full_to_reduced_[pos[k]];
        if (red >= 0) values[red] += s.tangent(k / nd, k % nd);
      }
    }
  });
  auto add_scaled = [&](const SparseMatrix& A, double coef) {
    if (coef == 0) return;
    for (Eigen::Index i = 0; i < A.nonZeros(); ++i)
      if (full_to_reduced_[i] >= 0) values[full_to_reduced_[i]] += coef * A.valuePtr()[i];
  };
  add_scaled(mass_, t.mass_coefficient);
  add_scaled(damping_, t.damping_coefficient);
  if (t.mass_coefficient != 0 || t.acceleration_history.size())
    r += mass_ * time_vector(t.mass_coefficient, d, t.acceleration_history);
  if (t.damping_coefficient != 0 || t.velocity_history.size())
    r += damping_ * time_vector(t.damping_coefficient, d, t.velocity_history);
  if (contact_) {
    contact_->add_to_residual(d, r);
    contact_->add_to_tangent(d, [&](int row, int col, double value) {
      if (equation_[row] >= 0 && equation_[col] >= 0) values[full_to_reduced_[position(row, col)]] += value;
    });
  }
  if (support_) {
    support_->add_to_residual(d, r);
    support_->add_to_tangent([&](int row, int col, double value) {
      if (equation_[row] >= 0 && equation_[col] >= 0) values[full_to_reduced_[position(row, col)]] += value;
    });
  }
  r_free.resize(num_free());
  for (int i = 0; i < num_free(); ++i) r_free(i) = r(free_dofs_[i]);
}

NewtonReport SolidSystem::solve(Eigen::VectorXd& d, const Eigen::VectorXd& f_ext, const TimeTerms& t,
                                const NewtonOptions& options) {
  NewtonReport rep;
  SparseMatrix K;
  Eigen::VectorXd r;
  // stableNorm: a load of 1e155 must not overflow to inf in the squares (and then pass
  // any relative test); a non-finite load or residual never counts as converged.
  Eigen::VectorXd f_free(num_free());
  for (int i = 0; i < num_free(); ++i) f_free(i) = f_ext(free_dofs_[i]);
  const double f_norm = f_free.stableNorm();
  for (int it = 0; it <= options.max_iterations; ++it) {
    assemble(d, f_ext, t, K, r);
    rep.residual = r.stableNorm();
    if (it == 0) rep.initial_residual = rep.residual;
    const double ref = std::max(rep.initial_residual, f_norm);
    if (!std::isfinite(rep.residual) || !std::isfinite(ref)) return rep;  // not converged
    if (rep.residual <= options.residual_tolerance * ref || rep.residual == 0) {
      rep.converged = true;
      return rep;
    }
    if (it == options.max_iterations) break;
    solver_.factorize(K);
    const Eigen::VectorXd dd = solver_.solve(-r);
    if (!dd.allFinite()) break;
    double d_norm = 0;
    for (int i = 0; i < num_free(); ++i) {
      d(free_dofs_[i]) += dd(i);
      d_norm += d(free_dofs_[i]) * d(free_dofs_[i]);
    }
    rep.iterations = it + 1;
    if (dd.norm() <= options.increment_tolerance * std::sqrt(d_norm)) {
      // Increment negligible: accept after one more residual evaluation.
      assemble(d, f_ext, t, K, r);
      rep.residual = r.stableNorm();
      rep.converged = std::isfinite(rep.residual) && d.allFinite() &&
                      rep.residual <= std::sqrt(options.residual_tolerance) * std::max(rep.initial_residual, f_norm);
      return rep;
    }
  }
  return rep;
}

Eigen::VectorXd SolidSystem::solve_mass(const Eigen::VectorXd& b) const {
  SparseMatrix Mff = reduced_pattern_;
  for (Eigen::Index i = 0; i < mass_.nonZeros(); ++i)
    if (full_to_reduced_[i] >= 0) Mff.valuePtr()[full_to_reduced_[i]] += mass_.valuePtr()[i];
  Eigen::SimplicialLDLT<SparseMatrix> ldlt(Mff);
  if (ldlt.info() != Eigen::Success) throw fsi::SolverError("mass matrix factorisation failed");
  Eigen::VectorXd bf(num_free());
  for (int i = 0; i < num_free(); ++i) bf(i) = b(free_dofs_[i]);
  const Eigen::VectorXd xf = ldlt.solve(bf);
  Eigen::VectorXd x = Eigen::VectorXd::Zero(num_dofs());
  for (int i = 0; i < num_free(); ++i) x(free_dofs_[i]) = xf(i);
  return x;
}

}  // namespace fsi::solid
