// FlowSolver: the time stepping, nonlinear iterations, global assembly, Nitsche interface,
// linear solves, reactions and checkpoints of both elements; the element parts are
// flow_element_p1p1.cpp and flow_element_p2p1.cpp (flow_element.hpp).
#include "fsi/fluid/flow_solver.hpp"

#include <fmt/format.h>

#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>

#include "flow_element.hpp"
#include "fsi/common/log.hpp"
#include "fsi/common/solver_model.hpp"
#include "fsi/fluid/field_transfer.hpp"
#include "fsi/fluid/linear_solver.hpp"
#include "mpi_ranks.hpp"

#ifdef _OPENMP
#include <omp.h>
#endif

namespace fsi::fluid {
namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

template <int Dim>
struct DirichletCondition {
  std::vector<int> nodes;
  VelocityFunctionT<Dim> velocity;
};

struct SymmetryCondition {
  std::vector<int> nodes;
  int component;  // constrained velocity component (normal to the boundary)
};

// The strong constraints at `time` on the positions X: which unknowns, and their values.
struct StrongConstraints {
  std::vector<char> on;
  Eigen::VectorXd value;
};

// pressure_dof < 0: no pressure reference.
template <int Dim>
StrongConstraints strong_constraints(const detail::DofLayout& dof,
                                     const std::vector<DirichletCondition<Dim>>& dirichlet,
                                     const std::vector<SymmetryCondition>& symmetry, const NodeMatrix<Dim>& X,
                                     double time, int pressure_dof, double pressure_value) {
  StrongConstraints k{std::vector<char>(static_cast<std::size_t>(dof.dofs), 0), Eigen::VectorXd::Zero(dof.dofs)};
  for (const auto& sym : symmetry)
    for (int node : sym.nodes) k.on[static_cast<std::size_t>(dof.velocity(node, sym.component))] = 1;
  for (const auto& dc : dirichlet)
    for (int node : dc.nodes) {
      const Point<Dim> v = dc.velocity(X.row(node).transpose(), time);
      for (int c = 0; c < Dim; ++c) {
        k.on[static_cast<std::size_t>(dof.velocity(node, c))] = 1;
        k.value(dof.velocity(node, c)) = v(c);
      }
    }
  if (pressure_dof >= 0) {
    k.on[static_cast<std::size_t>(pressure_dof)] = 1;
    k.value(pressure_dof) = pressure_value;
  }
  return k;
}

// Strong constraints: the constrained rows of A become identity rows, their rhs the value.
void apply_constraints(Eigen::SparseMatrix<double>& A, Eigen::VectorXd& rhs, const StrongConstraints& k) {
  const int* outer = A.outerIndexPtr();
  const int* inner = A.innerIndexPtr();
  double* av = A.valuePtr();
  for (Eigen::Index col = 0; col < A.cols(); ++col)
    for (int j = outer[col]; j < outer[col + 1]; ++j)
      if (k.on[static_cast<std::size_t>(inner[j])]) av[j] = inner[j] == col ? 1.0 : 0.0;
  for (Eigen::Index d = 0; d < rhs.size(); ++d)
    if (k.on[static_cast<std::size_t>(d)]) rhs(d) = k.value(d);
}

// du/dt ~ (alpha0 u + alpha1 u_n + alpha2 u_{n-1}) / dt; the semi-implicit advection velocity
// u* = (1 + extrap) u_n - extrap u_{n-1}. BDF2 with variable steps (first step BDF1).
struct BdfCoefficients {
  double alpha0 = 0, alpha1 = 0, alpha2 = 0, extrap = 0;
};

BdfCoefficients bdf_coefficients(TimeScheme scheme, int accepted_steps, double dt, double dt_previous) {
  BdfCoefficients c;
  if (scheme == TimeScheme::Steady) return c;
  if (scheme == TimeScheme::BDF2 && accepted_steps >= 1 && dt_previous > 0) {
    const double w = dt / dt_previous;
    c.alpha0 = (1 + 2 * w) / (1 + w);
    c.alpha1 = -(1 + w);
    c.alpha2 = w * w / (1 + w);
    c.extrap = w;
  } else {
    c.alpha0 = 1;
    c.alpha1 = -1;
  }
  return c;
}

// The velocity component a symmetry group constrains: 1 (v) on y = const, 0 (u) on x = const.
int symmetry_component(const FluidMesh& mesh, const std::string& group) {
  const auto& seg = mesh.boundary(group);
  Eigen::Vector2d span = Eigen::Vector2d::Zero();
  for (Eigen::Index e = 0; e < seg.rows(); ++e)
    span += (mesh.nodes.row(seg(e, 1)) - mesh.nodes.row(seg(e, 0))).transpose().cwiseAbs();
  const double tol = 1e-8 * span.norm();
  if (span.y() <= tol) return 1;
  if (span.x() <= tol) return 0;
  throw std::runtime_error("symmetry boundary '" + group + "' is not axis-aligned (only x = const or y = const)");
}

// 3D: the coordinate that is constant over the group's nodes (x, y or z = const).
int symmetry_component(const TetMesh& mesh, const std::string& group) {
  const auto nodes = mesh.boundary_nodes({group});
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = -lo;
  for (int n : nodes) {
    lo = lo.cwiseMin(mesh.nodes.row(n).transpose());
    hi = hi.cwiseMax(mesh.nodes.row(n).transpose());
  }
  const Eigen::Vector3d span = hi - lo;
  for (int c = 0; c < 3; ++c)
    if (span(c) <= 1e-8 * span.norm()) return c;
  throw std::runtime_error("symmetry boundary '" + group +
                           "' is not axis-aligned (only x = const, y = const or z = const)");
}

// ||u_new - u_old|| / ||u_new|| over the velocity unknowns.
template <int Dim>
double relative_velocity_change(const Eigen::VectorXd& u_new, const Eigen::VectorXd& u_old, int nodes,
                                const detail::DofLayout& dof) {
  double diff = 0, norm = 0;
  for (int i = 0; i < nodes; ++i)
    for (int c = 0; c < Dim; ++c) {
      const int k = dof.velocity(i, c);
      diff += std::pow(u_new(k) - u_old(k), 2);
      norm += std::pow(u_new(k), 2);
    }
  return std::sqrt(diff / std::max(norm, 1e-300));
}

template <int Dim>
Eigen::VectorXd flatten(const NodeMatrix<Dim>& m) {
  return Eigen::Map<const Eigen::VectorXd>(m.data(), m.size());
}

template <int Dim>
NodeMatrix<Dim> unflatten(const Eigen::VectorXd& v) {
  return Eigen::Map<const NodeMatrix<Dim>>(v.data(), v.size() / Dim, Dim);
}

std::unique_ptr<detail::FlowElement> make_element(const std::string& name, FluidMesh mesh) {
  if (name == "p1p1") return detail::make_p1p1_element(std::move(mesh));
  if (name == "p2p1") return detail::make_p2p1_element(std::move(mesh));
  throw std::invalid_argument("fluid element must be p1p1 or p2p1, got '" + name + "'");
}

std::unique_ptr<detail::FlowElementT<3>> make_element(const std::string& name, TetMesh mesh) {
  if (name == "p2p1") return detail::make_p2p1_tet_element(std::move(mesh));
  throw std::invalid_argument("3D fluid element must be p2p1 (Taylor-Hood on tetrahedra), got '" + name + "'");
}

// The volume terms' assembly: every cell's unknowns and their positions in the matrix's values
// (the pattern), and the loop over a range of cells (threads: each its own copy of the values,
// summed in thread order).
template <int Dim>
struct CellAssembly {
  const detail::FlowElementT<Dim>* element = nullptr;
  int local = 0;                  // unknowns per cell
  int dofs = 0;                   // unknowns in all
  std::vector<int> element_dofs;  // per cell its `local` unknowns
  std::vector<int> scatter;       // per cell local x local positions in valuePtr (column-major local)
  std::size_t nonzeros = 0;
  std::vector<std::vector<double>> thread_values;

  const int* dofs_of(int e) const {
    return &element_dofs[static_cast<std::size_t>(e) * static_cast<std::size_t>(local)];
  }
  const int* scatter_of(int e) const {
    return &scatter[static_cast<std::size_t>(e) * static_cast<std::size_t>(local * local)];
  }
  // Adds a local system of cell e to the matrix values and the right-hand side.
  void add(int e, const detail::LocalSystem& s, double* values, Eigen::VectorXd& b) const {
    const int* sc = scatter_of(e);
    for (int j = 0; j < local; ++j)
      for (int i = 0; i < local; ++i) values[sc[local * j + i]] += s.matrix(i, j);
    const int* d = dofs_of(e);
    for (int i = 0; i < local; ++i) b(d[i]) += s.rhs(i);
  }

  // Sparsity: per column the sorted rows coupled to it by some cell; returns the CSC structure
  // (values 0) and keeps every cell's positions in it.
  Eigen::SparseMatrix<double> build(const detail::FlowElementT<Dim>& e, int unknowns) {
    element = &e;
    dofs = unknowns;
    const int ndof = dofs, ne = e.mesh().cell_count();
    local = e.local_size();
    element_dofs.resize(static_cast<std::size_t>(ne) * static_cast<std::size_t>(local));
    for (int c = 0; c < ne; ++c) e.element_dofs(c, &element_dofs[static_cast<std::size_t>(c * local)]);
    std::vector<std::vector<int>> rows(static_cast<std::size_t>(ndof));
    for (int c = 0; c < ne; ++c)
      for (int i = 0; i < local; ++i)
        for (int j = 0; j < local; ++j) rows[static_cast<std::size_t>(dofs_of(c)[i])].push_back(dofs_of(c)[j]);
    std::size_t nnz = 0;
    for (auto& list : rows) {
      std::sort(list.begin(), list.end());
      list.erase(std::unique(list.begin(), list.end()), list.end());
      nnz += list.size();
    }
    Eigen::SparseMatrix<double> matrix(ndof, ndof);
    matrix.resizeNonZeros(static_cast<Eigen::Index>(nnz));
    int pos = 0;
    for (int c = 0; c < ndof; ++c) {
      matrix.outerIndexPtr()[c] = pos;
      for (int r : rows[static_cast<std::size_t>(c)]) matrix.innerIndexPtr()[pos++] = r;
    }
    matrix.outerIndexPtr()[ndof] = pos;
    std::fill(matrix.valuePtr(), matrix.valuePtr() + nnz, 0.0);
    nonzeros = nnz;
    scatter.resize(static_cast<std::size_t>(ne) * static_cast<std::size_t>(local * local));
    for (int c = 0; c < ne; ++c) {
      const int* d = dofs_of(c);
      for (int j = 0; j < local; ++j) {
        const auto& list = rows[static_cast<std::size_t>(d[j])];
        for (int i = 0; i < local; ++i) {
          const auto it = std::lower_bound(list.begin(), list.end(), d[i]);
          scatter[static_cast<std::size_t>(c) * static_cast<std::size_t>(local * local) +
                  static_cast<std::size_t>(local * j + i)] =
              matrix.outerIndexPtr()[d[j]] + static_cast<int>(it - list.begin());
        }
      }
    }
    return matrix;
  }

  // The cells [first, last) into `values` (nonzeros) and `b` (dofs), both overwritten. Returns
  // an inverted cell (with its `bad` measure), or -1.
  int assemble(const detail::AssemblyInputT<Dim>& in, int first, int last, int nthreads, double* values,
               Eigen::VectorXd& b, double& bad) {
    thread_values.resize(static_cast<std::size_t>(nthreads));
    std::vector<Eigen::VectorXd> thread_rhs(static_cast<std::size_t>(nthreads), Eigen::VectorXd::Zero(dofs));
    int bad_element = -1;
#pragma omp parallel num_threads(nthreads)
    {
#ifdef _OPENMP
      const int tid = omp_get_thread_num();
#else
      const int tid = 0;
#endif
      auto& mine = thread_values[static_cast<std::size_t>(tid)];
      mine.assign(nonzeros, 0.0);
      auto& rhs = thread_rhs[static_cast<std::size_t>(tid)];
      detail::LocalSystem s;
#pragma omp for schedule(static)
      for (int e = first; e < last; ++e) {
        double measure = 0;
        if (!element->assemble(e, in, s, measure)) {
#pragma omp critical
          {
            bad_element = e;
            bad = measure;
          }
          continue;
        }
        add(e, s, mine.data(), rhs);
      }
    }
    std::copy(thread_values[0].begin(), thread_values[0].end(), values);
    b = thread_rhs[0];
    for (int t = 1; t < nthreads; ++t) {
      const auto& tv = thread_values[static_cast<std::size_t>(t)];
      for (std::size_t k = 0; k < nonzeros; ++k) values[k] += tv[k];
      b += thread_rhs[static_cast<std::size_t>(t)];
    }
    return bad_element;
  }
};

// ---- The distributed assembly (3D, the PETSc engines on several MPI ranks) ----
// Rank r computes the element matrices of the cells [cell_start(r), cell_start(r + 1)) (blocks
// of the mesh's cell order); rank 0 gets their sum (MPI_Reduce) and goes on as on one rank (the
// interface terms, the constraints, the reactions; the solve is distributed by rows). The other
// ranks hold a replica of the mesh and the element, made from rank 0's broadcast.

int cell_start(int cells, int size, int r) { return r * (cells / size) + std::min(r, cells % size); }

// What the element kernels read of FlowParameters, as numbers to broadcast.
std::array<double, 10> kernel_parameters(const FlowParameters& p) {
  const auto& s = p.stabilisation;
  return {p.density,    p.viscosity, double(p.newton),   double(s.supg),          double(s.pspg),
          s.lsic_scale, s.grad_div,  s.viscous_constant, double(s.transient_tau), double(s.viscous_residual)};
}
void set_kernel_parameters(const std::array<double, 10>& a, FlowParameters& p) {
  auto& s = p.stabilisation;
  p.density = a[0], p.viscosity = a[1], p.newton = a[2] != 0, s.supg = a[3] != 0, s.pspg = a[4] != 0;
  s.lsic_scale = a[5], s.grad_div = a[6], s.viscous_constant = a[7], s.transient_tau = a[8] != 0;
  s.viscous_residual = a[9] != 0;
}

// The inputs of one assembly: rank 0's, or a replica's broadcast copies.
struct AssemblyData {
  std::array<double, 12> scalars{};  // alpha0_dt, dt, the kernel parameters
  Eigen::MatrixX3d X, mesh_velocity, body;
  Eigen::VectorXd U_lin, history;
};

// Collective: rank 0's data (sizes first) reach every rank.
void broadcast(AssemblyData& d) {
  std::array<int, 5> sizes{static_cast<int>(d.X.rows()), static_cast<int>(d.mesh_velocity.rows()),
                           static_cast<int>(d.body.rows()), static_cast<int>(d.U_lin.size()),
                           static_cast<int>(d.history.size())};
  ranks::broadcast(sizes.data(), sizes.size());
  d.X.resize(sizes[0], 3), d.mesh_velocity.resize(sizes[1], 3), d.body.resize(sizes[2], 3);
  d.U_lin.resize(sizes[3]), d.history.resize(sizes[4]);
  ranks::broadcast(d.scalars.data(), d.scalars.size());
  for (auto* m : {&d.X, &d.mesh_velocity, &d.body}) ranks::broadcast(m->data(), static_cast<std::size_t>(m->size()));
  for (auto* v : {&d.U_lin, &d.history}) ranks::broadcast(v->data(), static_cast<std::size_t>(v->size()));
}

// Collective: every rank's part summed into rank 0's values and rhs; rank 0 learns an inverted
// cell of any rank (the first rank's that has one).
int reduce_parts(double* values, std::size_t nonzeros, Eigen::VectorXd& rhs, int bad_element, double& bad) {
  ranks::sum_to_root(values, nonzeros);
  ranks::sum_to_root(rhs.data(), static_cast<std::size_t>(rhs.size()));
  const double mine[2] = {static_cast<double>(bad_element), bad};
  std::vector<double> all(2 * static_cast<std::size_t>(ranks::size()));
  ranks::gather_to_root(mine, 2, all.data());
  if (ranks::rank() != 0) return -1;
  for (std::size_t r = 0; r < all.size(); r += 2)
    if (all[r] >= 0) {
      bad = all[r + 1];
      return static_cast<int>(all[r]);
    }
  return -1;
}

// A rank's replica of rank 0's solver: the mesh, the element and the pattern.
struct Replica {
  std::unique_ptr<detail::FlowElementT<3>> element;
  CellAssembly<3> cells;
  FlowParameters params;
  int threads = 1;
  std::vector<double> values;
  Eigen::VectorXd rhs;
};

std::map<int, Replica>& replicas() {
  static std::map<int, Replica> all;
  return all;
}

// Collective: the mesh (the element's, 10-node), the element's name and the threads.
void broadcast_mesh(TetMesh& mesh, std::string& element, int& threads) {
  std::array<int, 4> sizes{mesh.node_count(), mesh.cell_count(), mesh.vertex_count, threads};
  ranks::broadcast(sizes.data(), sizes.size());
  ranks::broadcast(element);
  mesh.nodes.resize(sizes[0], 3);
  mesh.tets.resize(sizes[1], 4);
  mesh.edge_nodes.resize(sizes[1], 6);
  mesh.vertex_count = sizes[2];
  threads = sizes[3];
  ranks::broadcast(mesh.nodes.data(), static_cast<std::size_t>(mesh.nodes.size()));
  ranks::broadcast(mesh.tets.data(), static_cast<std::size_t>(mesh.tets.size()));
  ranks::broadcast(mesh.edge_nodes.data(), static_cast<std::size_t>(mesh.edge_nodes.size()));
}

// ---- The partitioned assembly: each rank keeps only its block of cells ----

// A rank's cells [first, last) as a mesh of their own: local node numbers (the cells' vertices
// first, then their midpoints), the element on it, its pattern (CSC on its own unknowns), and the
// map of its nodes and unknowns to the whole mesh's. Its matrices go straight into the rows of
// the distributed matrix (ranks::fill_system).
struct Part {
  int first = 0, last = 0;
  int unknowns = 0;  // of the whole system
  int threads = 1;
  std::unique_ptr<detail::FlowElementT<3>> element;
  CellAssembly<3> cells;
  Eigen::SparseMatrix<double> volume;
  Eigen::VectorXd rhs;
  std::vector<int> node;  // local node -> the mesh's
  std::vector<int> dof;   // local unknown -> the system's
  FlowParameters params;
  Eigen::MatrixX3d X, mesh_velocity, body;  // the inputs at the local nodes and unknowns
  Eigen::VectorXd U_lin, history;

  ranks::Part view() const {
    ranks::Part v;
    v.unknowns = unknowns;
    v.columns = static_cast<int>(dof.size());
    v.colptr = volume.outerIndexPtr();
    v.rowind = volume.innerIndexPtr();
    v.values = volume.valuePtr();
    v.global = dof.data();
    v.rhs = rhs.data();
    return v;
  }
};

// The layout of the whole system as numbers to broadcast.
std::array<int, 4> layout_numbers(const detail::DofLayout& d) {
  return {d.dofs, d.velocity_stride, d.pressure_offset, d.pressure_stride};
}

std::unique_ptr<Part> make_part(const TetMesh& mesh, const std::string& element, const std::array<int, 4>& whole,
                                int first, int last, int threads) {
  auto part = std::make_unique<Part>();
  part->first = first, part->last = last, part->threads = threads, part->unknowns = whole[0];
  if (first >= last) return part;
  std::vector<int> local(static_cast<std::size_t>(mesh.node_count()), -1);
  auto number = [&](int n) {
    auto& l = local[static_cast<std::size_t>(n)];
    if (l < 0) {
      l = static_cast<int>(part->node.size());
      part->node.push_back(n);
    }
    return l;
  };
  TetMesh sub;
  sub.tets.resize(last - first, 4);
  sub.edge_nodes.resize(last - first, 6);
  for (int e = first; e < last; ++e)
    for (int k = 0; k < 4; ++k) sub.tets(e - first, k) = number(mesh.tets(e, k));
  sub.vertex_count = static_cast<int>(part->node.size());
  for (int e = first; e < last; ++e)
    for (int k = 0; k < 6; ++k) sub.edge_nodes(e - first, k) = number(mesh.edge_nodes(e, k));
  sub.nodes.resize(static_cast<Eigen::Index>(part->node.size()), 3);
  for (std::size_t i = 0; i < part->node.size(); ++i)
    sub.nodes.row(static_cast<Eigen::Index>(i)) = mesh.nodes.row(part->node[i]);
  part->element = make_element(element, std::move(sub));
  const auto mine = part->element->layout();
  const detail::DofLayout all{whole[0], whole[1], whole[2], whole[3]};
  part->dof.assign(static_cast<std::size_t>(mine.dofs), -1);
  for (std::size_t i = 0; i < part->node.size(); ++i)
    for (int c = 0; c < 3; ++c)
      part->dof[static_cast<std::size_t>(mine.velocity(static_cast<int>(i), c))] = all.velocity(part->node[i], c);
  for (int v = 0; v < part->element->mesh().vertices(); ++v)
    part->dof[static_cast<std::size_t>(mine.pressure(v))] = all.pressure(part->node[static_cast<std::size_t>(v)]);
  part->volume = part->cells.build(*part->element, mine.dofs);
  return part;
}

// The part's element matrices for rank 0's inputs; returns an inverted cell (the mesh's number).
int assemble_part(Part& p, const AssemblyData& d, double& bad) {
  if (!p.element) {
    p.rhs = Eigen::VectorXd::Zero(0);
    return -1;
  }
  std::array<double, 10> kernel{};
  std::copy(d.scalars.begin() + 2, d.scalars.end(), kernel.begin());
  set_kernel_parameters(kernel, p.params);
  const auto n = static_cast<Eigen::Index>(p.node.size());
  auto rows = [&](const Eigen::MatrixX3d& all, Eigen::MatrixX3d& mine) {
    mine.setZero(n, 3);
    if (all.rows() == 0) return;
    for (Eigen::Index i = 0; i < n; ++i) mine.row(i) = all.row(p.node[static_cast<std::size_t>(i)]);
  };
  rows(d.X, p.X), rows(d.mesh_velocity, p.mesh_velocity), rows(d.body, p.body);
  auto entries = [&](const Eigen::VectorXd& all, Eigen::VectorXd& mine) {
    mine.setZero(static_cast<Eigen::Index>(p.dof.size()));
    if (all.size() == 0) return;
    for (std::size_t i = 0; i < p.dof.size(); ++i) mine(static_cast<Eigen::Index>(i)) = all(p.dof[i]);
  };
  entries(d.U_lin, p.U_lin), entries(d.history, p.history);
  const detail::AssemblyInputT<3> in{p.X,       p.mesh_velocity, p.body,       p.U_lin,
                                     p.history, p.params,        d.scalars[0], d.scalars[1]};
  p.element->prepare(in);
  const int e = p.cells.assemble(in, 0, p.last - p.first, p.threads, p.volume.valuePtr(), p.rhs, bad);
  return e < 0 ? -1 : p.first + e;
}

// The part's share of the reactions K_vol U - F_vol, added into `reaction` (every unknown).
void add_part_reaction(const Part& p, const Eigen::VectorXd& U, Eigen::VectorXd& reaction) {
  if (!p.element) return;
  Eigen::VectorXd mine(static_cast<Eigen::Index>(p.dof.size()));
  for (std::size_t i = 0; i < p.dof.size(); ++i) mine(static_cast<Eigen::Index>(i)) = U(p.dof[i]);
  const Eigen::VectorXd r = p.volume * mine - p.rhs;
  for (std::size_t i = 0; i < p.dof.size(); ++i) reaction(p.dof[i]) += r(static_cast<Eigen::Index>(i));
}

// Collective: every rank learns whether some rank found an inverted cell; rank 0 also which
// (the first rank's that has one) and its measure. Returns that cell on rank 0, -1 elsewhere.
int agree_on_inverted(int bad_element, double& bad, bool& any) {
  const double mine[2] = {static_cast<double>(bad_element), bad};
  std::vector<double> all(2 * static_cast<std::size_t>(ranks::size()));
  ranks::gather_to_root(mine, 2, all.data());
  double verdict[2] = {-1, 0};
  if (ranks::rank() == 0)
    for (std::size_t r = 0; r < all.size(); r += 2)
      if (all[r] >= 0) {
        verdict[0] = all[r], verdict[1] = all[r + 1];
        break;
      }
  ranks::broadcast(verdict, 2);
  any = verdict[0] >= 0;
  bad = verdict[1];
  return ranks::rank() == 0 ? static_cast<int>(verdict[0]) : -1;
}

// Ranks > 0: their parts, by rank 0's id, with the linear system they fill.
struct ServedPart {
  std::unique_ptr<Part> part;
  int system = -1;
};
std::map<int, ServedPart>& parts() {
  static std::map<int, ServedPart> all;
  return all;
}

// Ranks > 0: rank 0's commands of the distributed assembly.
void serve_assembly(int command, int id) {
  if (command == ranks::kAssemblyDestroy) {
    replicas().erase(id);
    parts().erase(id);
    return;
  }
  if (command == ranks::kAssemblyCreate) {
    TetMesh mesh;
    std::string element;
    int threads = 1;
    broadcast_mesh(mesh, element, threads);
    std::array<int, 6> info{};  // partitioned, the system's id, its layout
    ranks::broadcast(info.data(), info.size());
    if (info[0]) {
      const int cells = mesh.cell_count();
      parts()[id] = ServedPart{make_part(mesh, element, {info[2], info[3], info[4], info[5]},
                                         cell_start(cells, ranks::size(), ranks::rank()),
                                         cell_start(cells, ranks::size(), ranks::rank() + 1), threads),
                               info[1]};
      return;  // the whole mesh goes: this rank keeps its cells only
    }
    Replica r;
    r.element = make_element(element, std::move(mesh));
    r.threads = threads;
    const auto layout = r.element->layout();
    (void)r.cells.build(*r.element, layout.dofs);
    r.values.resize(r.cells.nonzeros);
    replicas()[id] = std::move(r);
    return;
  }
  if (const auto it = parts().find(id); it != parts().end()) {
    Part& part = *it->second.part;
    if (command == ranks::kAssemblyReaction) {
      Eigen::VectorXd U(part.unknowns), reaction = Eigen::VectorXd::Zero(part.unknowns);
      ranks::broadcast(U.data(), static_cast<std::size_t>(U.size()));
      add_part_reaction(part, U, reaction);
      ranks::sum_to_root(reaction.data(), static_cast<std::size_t>(reaction.size()));
      return;
    }
    AssemblyData d;
    broadcast(d);
    double bad = 0;
    bool any = false;
    agree_on_inverted(assemble_part(part, d, bad), bad, any);
    if (any) return;
    try {
      ranks::fill_system(it->second.system, part.view(), {}, {});
    } catch (const std::runtime_error&) {  // rank 0 reports it
    }
    return;
  }
  // kAssemble
  Replica& r = replicas().at(id);
  AssemblyData d;
  broadcast(d);
  std::array<double, 10> kernel{};
  std::copy(d.scalars.begin() + 2, d.scalars.end(), kernel.begin());
  set_kernel_parameters(kernel, r.params);
  const detail::AssemblyInputT<3> in{d.X,       d.mesh_velocity, d.body,       d.U_lin,
                                     d.history, r.params,        d.scalars[0], d.scalars[1]};
  r.element->prepare(in);
  const int cells = r.element->mesh().cell_count();
  double bad = 0;
  const int e =
      r.cells.assemble(in, cell_start(cells, ranks::size(), ranks::rank()),
                       cell_start(cells, ranks::size(), ranks::rank() + 1), r.threads, r.values.data(), r.rhs, bad);
  reduce_parts(r.values.data(), r.cells.nonzeros, r.rhs, e, bad);
}

const bool assembly_served = ranks::on_command(ranks::kAssemblyCreate, serve_assembly) &&
                             ranks::on_command(ranks::kAssemble, serve_assembly) &&
                             ranks::on_command(ranks::kAssemblyDestroy, serve_assembly) &&
                             ranks::on_command(ranks::kAssemblyReaction, serve_assembly);

}  // namespace

template <int Dim>
struct BasicFlowSolver<Dim>::Impl {
  std::unique_ptr<detail::FlowElementT<Dim>> element;
  detail::DofLayout dof;
  CellAssembly<Dim> cells;                     // the pattern and the volume loop
  Eigen::SparseMatrix<double> matrix, volume;  // the system (constraints applied); the volume terms (reactions)
  Eigen::VectorXd rhs, rhs_volume;
  std::unique_ptr<LinearSolver> lu;
  std::vector<DirichletCondition<Dim>> dirichlet;
  std::vector<SymmetryCondition> symmetry;
  std::vector<detail::InterfaceEdge> edges;
  struct PressureCondition {
    std::vector<detail::InterfaceEdge> traces;
    std::function<double(double)> pressure;
  };
  std::vector<PressureCondition> pressures;  // normal tractions -p n (add_pressure)
  std::vector<detail::InterfaceEdge> open;   // traction-free faces (add_open_boundary)
  // The backflow stabilisation's faces: every pressure boundary's, then the open ones; `active`:
  // whether each is traction-free at `time` (a pressure boundary while its pressure is 0).
  std::vector<const detail::InterfaceEdge*> backflow_faces(double time = 0, std::vector<char>* active = nullptr) const {
    std::vector<const detail::InterfaceEdge*> faces;
    for (const auto& c : pressures) {
      const bool free = active && c.pressure(time) == 0;
      for (const auto& t : c.traces) {
        faces.push_back(&t);
        if (active) active->push_back(free);
      }
    }
    for (const auto& t : open) {
      faces.push_back(&t);
      if (active) active->push_back(1);
    }
    return faces;
  }
  std::vector<Eigen::MatrixXd> backflow_blocks;  // partitioned: the last fill's, per face (reactions)
  int pressure_vertex = -1;
  std::function<double(double)> pressure_value;
  Velocity body_force;

  const Mesh& mesh() const { return element->mesh(); }
  std::vector<detail::InterfaceEdge> traces(const std::vector<std::string>& groups, const std::map<int, int>& index,
                                            std::vector<std::array<int, 2>>& segments,
                                            std::vector<std::array<int, 6>>& faces) const;
  const int* dofs_of(int e) const { return cells.dofs_of(e); }
  void add(int e, const detail::LocalSystem& s, double* values, Eigen::VectorXd& b) const {
    cells.add(e, s, values, b);
  }
  void build_pattern() {
    matrix = cells.build(*element, dof.dofs);
    volume = matrix;
  }
  // The distributed assembly's id (-1: this rank assembles every cell).
  int distributed = -1;
  // The partitioned assembly (3D): rank 0's own block of cells, and the linear system every rank
  // fills (-1: the whole matrix is assembled here, by this rank or summed from the others').
  std::unique_ptr<Part> part;
  int system = -1;
  struct Extras {  // rank 0's own entries of the system (fill_partitioned)
    std::vector<int> rows, cols, rhs_rows;
    std::vector<double> values, rhs_values;
  } extras;
  bool partitioned() const { return system >= 0; }
  // The interface mass's row sums at positions X (the Robin condition's lumped areas).
  Eigen::VectorXd lumped_interface_mass(const NodeMatrix<Dim>& X, std::size_t nodes) const {
    std::vector<Eigen::Triplet<double>> t;
    for (const auto& edge : edges) element->interface_mass(edge, X, t);
    Eigen::VectorXd lumped = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(nodes));
    for (const auto& e : t) lumped(e.row()) += e.value();
    return lumped;
  }
  // A cell's unknowns in the system (the pattern's, or the element's in the partitioned mode).
  const int* unknowns_of(int e, std::vector<int>& scratch) const {
    if (!partitioned()) return cells.dofs_of(e);
    scratch.resize(static_cast<std::size_t>(element->local_size()));
    element->element_dofs(e, scratch.data());
    return scratch.data();
  }
  ~Impl() {
    if (distributed >= 0) ranks::command(ranks::kAssemblyDestroy, distributed);
  }
  // 3D with the PETSc engines on several ranks (and fluid.mpi.assembly distributed): the other
  // ranks make their replicas.
  void distribute(const FlowParameters& params) {
    if constexpr (Dim == 3) {
      if (params.engine == LinearEngine::Umfpack || !params.distributed_assembly || ranks::size() <= 1) return;
      static int next_id = 0;
      const int id = next_id++;
      if (!ranks::command(ranks::kAssemblyCreate, id)) return;
      TetMesh copy = mesh();
      std::string name = element->name();
      int threads = std::max(1, params.threads);
      broadcast_mesh(copy, name, threads);
      const int target = params.partitioned_assembly ? lu->partition_id() : -1;
      const auto whole = layout_numbers(dof);
      std::array<int, 6> info{target >= 0, target, whole[0], whole[1], whole[2], whole[3]};
      ranks::broadcast(info.data(), info.size());
      if (target >= 0) {
        part = make_part(mesh(), name, whole, 0, cell_start(mesh().cell_count(), ranks::size(), 1), threads);
        system = target;
      }
      distributed = id;
      fsi::logger("fluid")->info("assembly: {} cells over {} MPI ranks ({} to {} cells each){}", mesh().cell_count(),
                                 ranks::size(), mesh().cell_count() / ranks::size(),
                                 cell_start(mesh().cell_count(), ranks::size(), 1),
                                 partitioned() ? "; partitioned: each rank keeps its cells and fills its rows" : "");
    } else {
      (void)params;
    }
  }
  // The volume terms into `volume` and `rhs_volume`. Returns an inverted cell, or -1.
  int assemble_volume(const detail::AssemblyInputT<Dim>& in, int nthreads, double& bad) {
    const int all = mesh().cell_count();
    if (distributed < 0) return cells.assemble(in, 0, all, nthreads, volume.valuePtr(), rhs_volume, bad);
    if constexpr (Dim == 3) {
      ranks::command(ranks::kAssemble, distributed);
      AssemblyData d;
      d.X = in.X, d.mesh_velocity = in.mesh_velocity, d.body = in.body, d.U_lin = in.U_lin, d.history = in.history;
      d.scalars[0] = in.alpha0_dt, d.scalars[1] = in.dt;
      const auto kernel = kernel_parameters(in.params);
      std::copy(kernel.begin(), kernel.end(), d.scalars.begin() + 2);
      broadcast(d);
      if (partitioned()) {
        // rhs_volume keeps rank 0's loads only (the pressure boundaries): the reactions' share
        rhs_volume = Eigen::VectorXd::Zero(dof.dofs);
        bool any = false;
        return agree_on_inverted(assemble_part(*part, d, bad), bad, any);
      }
      const int e =
          cells.assemble(in, 0, cell_start(all, ranks::size(), 1), nthreads, volume.valuePtr(), rhs_volume, bad);
      return reduce_parts(volume.valuePtr(), cells.nonzeros, rhs_volume, e, bad);
    }
    return -1;
  }
};

// Everything a solve of one time level fixes before its iterations.
template <int Dim>
struct BasicFlowSolver<Dim>::Step {
  double time = 0, dt = 0;  // dt: 0 if steady
  double alpha0_dt = 0;     // alpha0 / dt (0 if steady)
  Nodes mesh_velocity, body;
  Eigen::VectorXd U_lin;    // linearisation velocity of the first iteration
  Eigen::VectorXd history;  // (alpha1 u_n + alpha2 u_{n-1}) / dt
  StrongConstraints constraints;
  bool retrial = false;                   // a repeated solve of the time level: start from its last solution
  const RobinCondition* robin = nullptr;  // a Robin interface condition instead of Nitsche's terms
};

template <int Dim>
BasicFlowSolver<Dim>::BasicFlowSolver(Mesh mesh, FlowParameters params, const std::string& element)
    : params_(params), impl_(std::make_unique<Impl>()) {
  auto& im = *impl_;
  im.element = make_element(element, std::move(mesh));
  im.dof = im.element->layout();
  std::vector<char> pressure(static_cast<std::size_t>(im.dof.dofs), 0);
  for (int v = 0; v < im.mesh().vertices(); ++v) pressure[static_cast<std::size_t>(im.dof.pressure(v))] = 1;
  im.lu = make_linear_solver(params_, Dim, std::move(pressure));
  im.distribute(params_);  // first: the other ranks build their patterns while this one builds its own
  if (!im.partitioned()) im.build_pattern();
  U_ = U_n_ = U_nm1_ = reaction_ = Eigen::VectorXd::Zero(im.dof.dofs);
  X_ = X_n_ = X_nm1_ = im.mesh().nodes;
  interface_segments_.resize(0, 2);
}

template <int Dim>
BasicFlowSolver<Dim>::~BasicFlowSolver() = default;
template <int Dim>
BasicFlowSolver<Dim>::BasicFlowSolver(BasicFlowSolver&&) noexcept = default;
template <int Dim>
BasicFlowSolver<Dim>& BasicFlowSolver<Dim>::operator=(BasicFlowSolver&&) noexcept = default;

template <int Dim>
const typename BasicFlowSolver<Dim>::Mesh& BasicFlowSolver<Dim>::mesh() const {
  return impl_->mesh();
}
template <int Dim>
int BasicFlowSolver<Dim>::dofs() const {
  return impl_->dof.dofs;
}
template <int Dim>
const Eigen::SparseMatrix<double>& BasicFlowSolver<Dim>::last_matrix() const {
  return impl_->matrix;
}
template <int Dim>
const Eigen::VectorXd& BasicFlowSolver<Dim>::last_rhs() const {
  return impl_->rhs;
}

template <int Dim>
void BasicFlowSolver<Dim>::add_dirichlet(const std::string& group, Velocity velocity) {
  impl_->dirichlet.push_back({mesh().boundary_nodes({group}), std::move(velocity)});
}

template <int Dim>
void BasicFlowSolver<Dim>::add_symmetry(const std::string& group) {
  impl_->symmetry.push_back({mesh().boundary_nodes({group}), symmetry_component(mesh(), group)});
}

// The element traces (edges in 2D, faces in 3D) of the boundary groups, with the nodes indexed
// by `index`; their interface segments (2D) or faces (3D) appended to `segments` / `faces`.
template <int Dim>
std::vector<detail::InterfaceEdge> BasicFlowSolver<Dim>::Impl::traces(const std::vector<std::string>& groups,
                                                                      const std::map<int, int>& index,
                                                                      std::vector<std::array<int, 2>>& segments,
                                                                      std::vector<std::array<int, 6>>& faces) const {
  const auto& m = mesh();
  std::vector<detail::InterfaceEdge> out;
  if constexpr (Dim == 3) {
    (void)segments;
    std::map<std::array<int, 3>, std::pair<int, int>> face_owner;  // sorted vertex triple -> (tetrahedron, opposite)
    for (int e = 0; e < m.cell_count(); ++e)
      for (int o = 0; o < 4; ++o) {
        std::array<int, 3> f{};
        for (int k = 0, j = 0; k < 4; ++k)
          if (k != o) f[static_cast<std::size_t>(j++)] = m.tets(e, k);
        std::sort(f.begin(), f.end());
        face_owner[f] = {e, o};
      }
    for (const auto& name : groups) {
      const auto& group = m.boundary(name);
      for (Eigen::Index s = 0; s < group.rows(); ++s) {
        const std::array<int, 3> abc{group(s, 0), group(s, 1), group(s, 2)};
        auto key = abc;
        std::sort(key.begin(), key.end());
        const auto it = face_owner.find(key);
        if (it == face_owner.end())
          throw std::runtime_error(fmt::format("boundary group '{}': face ({}, {}, {}) is not a tetrahedron's face",
                                               name, abc[0], abc[1], abc[2]));
        out.push_back(element->interface_face(it->second.first, it->second.second, abc, index, faces));
      }
    }
  } else {
    (void)faces;
    std::map<std::pair<int, int>, std::pair<int, int>> edge_owner;  // vertex pair -> (triangle, edge)
    for (int e = 0; e < m.triangle_count(); ++e)
      for (int k = 0; k < 3; ++k) {
        const int a = m.triangles(e, k), b = m.triangles(e, (k + 1) % 3);
        edge_owner[{std::min(a, b), std::max(a, b)}] = {e, k};
      }
    for (const auto& name : groups) {
      const auto& seg = m.boundary(name);
      for (Eigen::Index s = 0; s < seg.rows(); ++s) {
        const int a = seg(s, 0), b = seg(s, 1);
        const auto it = edge_owner.find({std::min(a, b), std::max(a, b)});
        if (it == edge_owner.end())
          throw std::runtime_error(
              fmt::format("interface group '{}': segment ({}, {}) is not a triangle edge", name, a, b));
        out.push_back(element->interface_edge(it->second.first, it->second.second, a, b, index, segments));
      }
    }
  }
  return out;
}

template <int Dim>
void BasicFlowSolver<Dim>::set_interface(const std::vector<std::string>& groups) {
  interface_nodes_ = mesh().boundary_nodes(groups);
  std::map<int, int> local;
  for (std::size_t i = 0; i < interface_nodes_.size(); ++i) local[interface_nodes_[i]] = static_cast<int>(i);
  std::vector<std::array<int, 2>> segs;
  interface_faces_.clear();
  impl_->edges = impl_->traces(groups, local, segs, interface_faces_);
  if constexpr (Dim == 2) {
    interface_segments_.resize(static_cast<Eigen::Index>(segs.size()), 2);
    for (std::size_t s = 0; s < segs.size(); ++s)
      interface_segments_.row(static_cast<Eigen::Index>(s)) << segs[s][0], segs[s][1];
  }
  interface_velocity_ = Eigen::VectorXd::Zero(Dim * static_cast<Eigen::Index>(interface_nodes_.size()));
}

template <int Dim>
void BasicFlowSolver<Dim>::add_pressure(const std::string& group, std::function<double(double)> pressure) {
  std::map<int, int> index;
  for (int node : mesh().boundary_nodes({group})) index[node] = static_cast<int>(index.size());
  std::vector<std::array<int, 2>> segs;
  std::vector<std::array<int, 6>> faces;
  impl_->pressures.push_back({impl_->traces({group}, index, segs, faces), std::move(pressure)});
}

template <int Dim>
void BasicFlowSolver<Dim>::add_open_boundary(const std::string& group) {
  std::map<int, int> index;
  for (int node : mesh().boundary_nodes({group})) index[node] = static_cast<int>(index.size());
  std::vector<std::array<int, 2>> segs;
  std::vector<std::array<int, 6>> faces;
  const auto traces = impl_->traces({group}, index, segs, faces);
  impl_->open.insert(impl_->open.end(), traces.begin(), traces.end());
}

template <int Dim>
void BasicFlowSolver<Dim>::set_pressure_reference(const PointD& point, std::function<double(double)> value) {
  Eigen::Index best = 0;
  (mesh().nodes.topRows(mesh().vertices()).rowwise() - point.transpose()).rowwise().squaredNorm().minCoeff(&best);
  impl_->pressure_vertex = static_cast<int>(best);
  impl_->pressure_value = std::move(value);
}

template <int Dim>
void BasicFlowSolver<Dim>::set_body_force(Velocity force) {
  impl_->body_force = std::move(force);
}

template <int Dim>
void BasicFlowSolver<Dim>::set_initial_velocity(const Nodes& velocity) {
  for (int i = 0; i < mesh().node_count(); ++i)
    for (int c = 0; c < Dim; ++c) {
      const int k = impl_->dof.velocity(i, c);
      U_n_(k) = U_nm1_(k) = U_(k) = velocity(i, c);
    }
}

template <int Dim>
typename BasicFlowSolver<Dim>::Step BasicFlowSolver<Dim>::begin_step(double time, double dt, const Nodes& positions,
                                                                     const Eigen::VectorXd& interface_velocity) {
  const auto& im = *impl_;
  const int n = mesh().node_count();
  if (positions.rows() != n) throw std::invalid_argument("FlowSolver::solve: positions has the wrong size");
  X_ = positions;
  dt_trial_ = dt;
  if (interface_velocity.size() == 0)
    interface_velocity_.setZero();
  else if (interface_velocity.size() != Dim * static_cast<Eigen::Index>(interface_nodes_.size()))
    throw std::invalid_argument(fmt::format("interface velocity has {} entries, expected {}", interface_velocity.size(),
                                            Dim * interface_nodes_.size()));
  else
    interface_velocity_ = interface_velocity;

  Step s;
  s.time = time;
  // Time discretisation, and the mesh velocity BDF-consistent with it.
  const bool steady = params_.scheme == TimeScheme::Steady;
  const auto [alpha0, alpha1, alpha2, extrap] = bdf_coefficients(params_.scheme, accepted_, dt, dt_n_);
  s.dt = steady ? 0.0 : dt;
  s.alpha0_dt = steady ? 0.0 : alpha0 / dt;
  s.mesh_velocity = Nodes::Zero(n, Dim);
  if (!steady) s.mesh_velocity = (alpha0 * X_ + alpha1 * X_n_ + alpha2 * X_nm1_) / dt;
  if (params_.mesh_velocity_scale != 1.0) s.mesh_velocity *= params_.mesh_velocity_scale;
  s.U_lin = steady ? U_n_ : Eigen::VectorXd((1 + extrap) * U_n_ - extrap * U_nm1_);
  // A later coupling iteration of the step starts its linear solve from the last iterate's
  // solution (closer than the extrapolation; the system solved is the same).
  s.retrial = trial_solves_ > 0 && U_.size() == s.U_lin.size();
  if (params_.relinearise && trial_solves_ > 0) s.U_lin = U_;  // a coupling iteration: about the last iterate
  ++trial_solves_;
  s.history = Eigen::VectorXd::Zero(im.dof.dofs);
  if (!steady) s.history = (alpha1 * U_n_ + alpha2 * U_nm1_) / dt;

  // Constraints at t_{n+1} on the current positions.
  s.constraints = strong_constraints(im.dof, im.dirichlet, im.symmetry, X_, time,
                                     im.pressure_vertex >= 0 ? im.dof.pressure(im.pressure_vertex) : -1,
                                     im.pressure_value ? im.pressure_value(time) : 0.0);
  s.body = Nodes::Zero(n, Dim);
  if (im.body_force)
    for (int i = 0; i < n; ++i) s.body.row(i) = im.body_force(X_.row(i).transpose(), time).transpose();
  return s;
}

// The system of one iteration about U_lin: volume terms, Nitsche terms, strong constraints.
template <int Dim>
void BasicFlowSolver<Dim>::assemble(const Step& step, const Eigen::VectorXd& U_lin, StepReport& report) {
  auto& im = *impl_;
  const auto t_assembly = Clock::now();
  const detail::AssemblyInputT<Dim> in{X_,      step.mesh_velocity, step.body, U_lin, step.history,
                                       params_, step.alpha0_dt,     step.dt};
  im.element->prepare(in);
  double bad = 0;
  if (const int e = im.assemble_volume(in, std::max(1, params_.threads), bad); e >= 0) {
    const auto& m = mesh();
    if constexpr (Dim == 2) {
      const Eigen::RowVector2d centre =
          (X_.row(m.triangles(e, 0)) + X_.row(m.triangles(e, 1)) + X_.row(m.triangles(e, 2))) / 3.0;
      throw MeshTangled(
          fmt::format("fluid step at t = {:.6g}: {} {} near ({:.5g}, {:.5g}) is {}; the mesh motion "
                      "tangled the mesh",
                      step.time, im.element->cell_name(), e, centre(0), centre(1), im.element->inverted(bad)));
    } else {
      Eigen::RowVector3d centre = Eigen::RowVector3d::Zero();
      for (int k = 0; k < 4; ++k) centre += X_.row(m.tets(e, k)) / 4.0;
      throw MeshTangled(fmt::format("fluid step at t = {:.6g}: {} {} near ({:.5g}, {:.5g}, {:.5g}) is {}", step.time,
                                    im.element->cell_name(), e, centre(0), centre(1), centre(2),
                                    im.element->inverted(bad)));
    }
  }
  // Prescribed normal tractions -p n: loads of the volume residual (the reactions of nodes shared
  // with the interface or a wall then hold only their own boundary's traction).
  for (const auto& c : im.pressures) {
    const double p = c.pressure(step.time);
    if (p == 0) continue;
    Eigen::VectorXd load;
    for (const auto& t : c.traces) {
      im.element->pressure_load(t, X_, p, load);
      std::vector<int> scratch;
      const int* d = im.unknowns_of(t.element, scratch);
      for (Eigen::Index i = 0; i < load.size(); ++i) im.rhs_volume(d[i]) += load(i);
    }
  }
  // The backflow stabilisation of the traction-free boundaries (outlets; pressure boundaries while
  // their pressure is 0): part of the volume residual, as their loads (the reactions of nodes
  // shared with the interface keep the interface's traction only).
  if (params_.backflow_beta > 0) {
    detail::LocalSystem s;
    std::vector<char> active;
    const auto faces = im.backflow_faces(step.time, &active);
    im.backflow_blocks.resize(faces.size());
    for (std::size_t f = 0; f < faces.size(); ++f) {
      if (!active[f]) {
        im.backflow_blocks[f].setZero(im.element->local_size(), im.element->local_size());
        continue;
      }
      im.element->backflow(*faces[f], X_, U_lin, step.mesh_velocity, params_.backflow_beta * params_.density, s);
      if (im.partitioned())
        im.backflow_blocks[f] = s.matrix;
      else
        im.add(faces[f]->element, s, im.volume.valuePtr(), im.rhs_volume);
    }
  }
  if (im.partitioned()) {
    fill_partitioned(step);
    report.assembly_seconds += seconds_since(t_assembly);
    return;
  }
  std::copy(im.volume.valuePtr(), im.volume.valuePtr() + im.volume.nonZeros(), im.matrix.valuePtr());
  im.rhs = im.rhs_volume;
  if (step.robin) {
    // The Robin condition, lumped: A_j (v_j - v*_j) - f*_j on node j's momentum rows, A_j =
    // coefficient_j int N_j (the interface mass's row sum on the current interface).
    const RobinCondition& r = *step.robin;
    const Eigen::VectorXd lumped = im.lumped_interface_mass(X_, interface_nodes_.size());
    for (Eigen::Index j = 0; j < lumped.size(); ++j) {
      const double a = r.coefficient(j) * lumped(j);
      for (int c = 0; c < Dim; ++c) {
        const int k = im.dof.velocity(interface_nodes_[static_cast<std::size_t>(j)], c);
        im.matrix.coeffRef(k, k) += a;
        im.rhs(k) += a * r.velocity(Dim * j + c) + r.traction(Dim * j + c);
      }
    }
  } else {
    // Nitsche terms on the interface.
    const detail::NitscheInputT<Dim> nitsche{X_, penalty_positions(), interface_velocity_, params_};
    detail::LocalSystem s;
    for (const auto& edge : im.edges) {
      im.element->nitsche(edge, nitsche, s);
      im.add(edge.element, s, im.matrix.valuePtr(), im.rhs);
    }
  }
  apply_constraints(im.matrix, im.rhs, step.constraints);
  report.assembly_seconds += seconds_since(t_assembly);
}

// The partitioned assembly's system: every rank's cells, and from this rank the loads, the
// interface terms and the constraints. The interface entries' pattern is every interface face's
// cell block and the interface velocities' diagonal (Nitsche or Robin: one pattern for both).
template <int Dim>
void BasicFlowSolver<Dim>::fill_partitioned(const Step& step) {
  auto& im = *impl_;
  auto& x = im.extras;
  const int local = im.element->local_size();
  const auto blocks = static_cast<std::size_t>(local) * static_cast<std::size_t>(local);
  if (x.rows.empty()) {
    std::vector<int> d(static_cast<std::size_t>(local));
    std::vector<int> cells;
    for (const auto& edge : im.edges) cells.push_back(edge.element);
    if (params_.backflow_beta > 0)
      for (const auto* face : im.backflow_faces()) cells.push_back(face->element);
    for (int cell : cells) {
      im.element->element_dofs(cell, d.data());
      for (int j = 0; j < local; ++j)
        for (int i = 0; i < local; ++i)
          x.rows.push_back(d[static_cast<std::size_t>(i)]), x.cols.push_back(d[static_cast<std::size_t>(j)]);
    }
    for (int node : interface_nodes_)
      for (int c = 0; c < Dim; ++c) x.rows.push_back(im.dof.velocity(node, c)), x.cols.push_back(x.rows.back());
    x.values.assign(x.rows.size(), 0.0);
  }
  std::fill(x.values.begin(), x.values.end(), 0.0);
  x.rhs_rows.clear(), x.rhs_values.clear();
  for (Eigen::Index i = 0; i < im.rhs_volume.size(); ++i)
    if (im.rhs_volume(i) != 0) x.rhs_rows.push_back(static_cast<int>(i)), x.rhs_values.push_back(im.rhs_volume(i));
  if (step.robin) {
    const RobinCondition& r = *step.robin;
    const Eigen::VectorXd lumped = im.lumped_interface_mass(X_, interface_nodes_.size());
    const std::size_t diagonal = (im.edges.size() + im.backflow_blocks.size()) * blocks;
    for (Eigen::Index j = 0; j < lumped.size(); ++j) {
      const double a = r.coefficient(j) * lumped(j);
      for (int c = 0; c < Dim; ++c) {
        x.values[diagonal + static_cast<std::size_t>(Dim * j + c)] = a;
        x.rhs_rows.push_back(im.dof.velocity(interface_nodes_[static_cast<std::size_t>(j)], c));
        x.rhs_values.push_back(a * r.velocity(Dim * j + c) + r.traction(Dim * j + c));
      }
    }
  } else {
    const detail::NitscheInputT<Dim> nitsche{X_, penalty_positions(), interface_velocity_, params_};
    detail::LocalSystem s;
    std::vector<int> d(static_cast<std::size_t>(local));
    for (std::size_t f = 0; f < im.edges.size(); ++f) {
      im.element->nitsche(im.edges[f], nitsche, s);
      std::copy(s.matrix.data(), s.matrix.data() + blocks, x.values.begin() + static_cast<long>(f * blocks));
      im.element->element_dofs(im.edges[f].element, d.data());
      for (int i = 0; i < local; ++i)
        x.rhs_rows.push_back(d[static_cast<std::size_t>(i)]), x.rhs_values.push_back(s.rhs(i));
    }
  }
  for (std::size_t f = 0; f < im.backflow_blocks.size(); ++f)
    std::copy(im.backflow_blocks[f].data(), im.backflow_blocks[f].data() + blocks,
              x.values.begin() + static_cast<long>((im.edges.size() + f) * blocks));
  auto part = im.part->view();
  part.extra_count = static_cast<int>(x.rows.size());
  part.extra_rows = x.rows.data(), part.extra_cols = x.cols.data(), part.extra_values = x.values.data();
  part.extra_rhs_count = static_cast<int>(x.rhs_rows.size());
  part.extra_rhs_rows = x.rhs_rows.data(), part.extra_rhs_values = x.rhs_values.data();
  std::vector<int> rows;
  std::vector<double> values;
  for (std::size_t i = 0; i < step.constraints.on.size(); ++i)
    if (step.constraints.on[i])
      rows.push_back(static_cast<int>(i)), values.push_back(step.constraints.value(static_cast<Eigen::Index>(i)));
  try {
    ranks::fill_system(im.system, part, rows, values);
  } catch (const std::runtime_error& e) {
    throw SolverError(
        fmt::format("fluid step at t = {:.6g}: filling the distributed matrix failed: {}", step.time, e.what()));
  }
}

// The reactions K_vol U - F_vol of the partitioned assembly: every rank's cells' share, summed here.
template <int Dim>
Eigen::VectorXd BasicFlowSolver<Dim>::partitioned_reaction() {
  auto& im = *impl_;
  ranks::command(ranks::kAssemblyReaction, im.distributed);
  Eigen::VectorXd U = U_, reaction = Eigen::VectorXd::Zero(im.dof.dofs);
  ranks::broadcast(U.data(), static_cast<std::size_t>(U.size()));
  if constexpr (Dim == 3) add_part_reaction(*im.part, U, reaction);
  ranks::sum_to_root(reaction.data(), static_cast<std::size_t>(reaction.size()));
  // The backflow terms are part of the volume residual (assemble): their share, from this rank.
  const auto faces = im.backflow_faces();
  std::vector<int> d(static_cast<std::size_t>(im.element->local_size()));
  for (std::size_t f = 0; f < im.backflow_blocks.size(); ++f) {
    im.element->element_dofs(faces[f]->element, d.data());
    Eigen::VectorXd u(static_cast<Eigen::Index>(d.size()));
    for (std::size_t i = 0; i < d.size(); ++i) u(static_cast<Eigen::Index>(i)) = U(d[i]);
    const Eigen::VectorXd r = im.backflow_blocks[f] * u;
    for (std::size_t i = 0; i < d.size(); ++i) reaction(d[i]) += r(static_cast<Eigen::Index>(i));
  }
  return reaction - im.rhs_volume;
}

template <int Dim>
StepReport BasicFlowSolver<Dim>::solve(double time, double dt, const Nodes& positions,
                                       const Eigen::VectorXd& interface_velocity) {
  Step step = begin_step(time, dt, positions, interface_velocity);
  return solve(step);
}

template <int Dim>
StepReport BasicFlowSolver<Dim>::solve_robin(double time, double dt, const Nodes& positions,
                                             const RobinCondition& robin) {
  const auto n = static_cast<Eigen::Index>(interface_nodes_.size());
  if (robin.coefficient.size() != n || robin.velocity.size() != Dim * n || robin.traction.size() != Dim * n)
    throw std::invalid_argument(fmt::format(
        "Robin condition: {} coefficients, {} velocities and {} tractions for {} interface nodes (expected {}, {}, {})",
        robin.coefficient.size(), robin.velocity.size(), robin.traction.size(), n, n, Dim * n, Dim * n));
  Step step = begin_step(time, dt, positions, robin.velocity);
  step.robin = &robin;
  return solve(step);
}

template <int Dim>
StepReport BasicFlowSolver<Dim>::solve(Step& step) {
  StepReport report;
  auto& im = *impl_;
  const double time = step.time;
  robin_ = step.robin != nullptr;
  Eigen::VectorXd& U_lin = step.U_lin;
  double previous_change = std::numeric_limits<double>::infinity();
  for (int iteration = 1; iteration <= std::max(1, params_.max_iterations); ++iteration) {
    assemble(step, U_lin, report);
    const auto where = fmt::format("fluid step at t = {:.6g}, iteration {}", time, iteration);
    const Eigen::VectorXd& guess = step.retrial ? U_ : U_lin;
    Eigen::VectorXd U_new = im.partitioned() ? im.lu->solve_filled(im.dof.dofs, guess, report, where, step.alpha0_dt)
                                             : im.lu->solve(im.matrix, im.rhs, guess, report, where, step.alpha0_dt);
    double change = relative_velocity_change<Dim>(U_new, U_lin, mesh().node_count(), im.dof);
    // Damped Newton (P2/P1): an update that grows the change is halved (iterations 3 on, so
    // the first Oseen/Stokes solve and the first Newton correction are always taken whole).
    if (im.element->damped_newton() && params_.newton && iteration >= 3 && change > previous_change) {
      U_new = U_lin + 0.5 * (U_new - U_lin);
      change *= 0.5;
    }
    previous_change = change;
    report.change = change;
    report.iterations = iteration;
    U_ = U_new;
    U_lin = U_new;
    reaction_ = im.partitioned() ? partitioned_reaction() : Eigen::VectorXd(im.volume * U_ - im.rhs_volume);
    if (observer_) observer_(iteration, change);
    if (report.change < params_.tolerance) break;
  }
  return report;
}

template <int Dim>
int BasicFlowSolver<Dim>::assembly_ranks() const {
  return impl_->distributed >= 0 ? ranks::size() : 1;
}

template <int Dim>
void BasicFlowSolver<Dim>::accept() {
  U_nm1_ = U_n_;
  U_n_ = U_;
  X_nm1_ = X_n_;
  X_n_ = X_;
  dt_n_ = dt_trial_;
  ++accepted_;
  trial_solves_ = 0;
}

// Entries under `prefix`: element (text), u, u_n, u_nm1, reaction (every unknown), x, x_n,
// x_nm1 (every node, column-major: all x then all y), dt_n, dt_trial, accepted_steps,
// trial_solves, interface_velocity (2 per interface node); the linear solver's under "lu.".
template <int Dim>
void BasicFlowSolver<Dim>::save_state(StateArchive& state, const std::string& prefix) {
  state.put(prefix + "element", std::string(impl_->element->name()));
  state.put(prefix + "u", U_);
  state.put(prefix + "u_n", U_n_);
  state.put(prefix + "u_nm1", U_nm1_);
  state.put(prefix + "reaction", reaction_);
  state.put(prefix + "x", flatten<Dim>(X_));
  state.put(prefix + "x_n", flatten<Dim>(X_n_));
  state.put(prefix + "x_nm1", flatten<Dim>(X_nm1_));
  state.put(prefix + "dt_n", dt_n_);
  state.put(prefix + "dt_trial", dt_trial_);
  state.put(prefix + "accepted_steps", static_cast<std::int64_t>(accepted_));
  state.put(prefix + "trial_solves", static_cast<std::int64_t>(trial_solves_));
  state.put(prefix + "interface_velocity", interface_velocity_);
  impl_->lu->save_state(state, prefix + "lu.");
  impl_->lu->discard_factors();  // the next solve refactorises, as in a solver restored from this state
}

// Reads every entry of the flow state before changing anything: a state that does not fit
// (another element, mesh or interface) throws fsi::StateError naming the entry and leaves the
// solver as it was; then the linear solver's entries.
template <int Dim>
void BasicFlowSolver<Dim>::load_state(const StateArchive& state, const std::string& prefix) {
  const std::string element = impl_->element->name(), saved = state.text(prefix + "element");
  if (saved != element)
    throw StateError(
        fmt::format("entry '{}element' is '{}', this configuration uses fluid.element {}", prefix, saved, element));
  const Eigen::Index ndof = U_.size(), npos = X_.size();
  Eigen::VectorXd U = state.vector(prefix + "u", ndof), U_n = state.vector(prefix + "u_n", ndof),
                  U_nm1 = state.vector(prefix + "u_nm1", ndof), reaction = state.vector(prefix + "reaction", ndof);
  const Eigen::VectorXd X = state.vector(prefix + "x", npos), X_n = state.vector(prefix + "x_n", npos),
                        X_nm1 = state.vector(prefix + "x_nm1", npos);
  Eigen::VectorXd iface = state.vector(prefix + "interface_velocity", interface_velocity_.size());
  const double dt_n = state.real(prefix + "dt_n"), dt_trial = state.real(prefix + "dt_trial");
  const auto accepted = state.integer(prefix + "accepted_steps"), trial = state.integer(prefix + "trial_solves");
  if (accepted < 0 || trial < 0)
    throw StateError(fmt::format("entries '{}accepted_steps' / '{}trial_solves' are negative", prefix, prefix));
  U_ = std::move(U);
  U_n_ = std::move(U_n);
  U_nm1_ = std::move(U_nm1);
  reaction_ = std::move(reaction);
  X_ = unflatten<Dim>(X);
  X_n_ = unflatten<Dim>(X_n);
  X_nm1_ = unflatten<Dim>(X_nm1);
  interface_velocity_ = std::move(iface);
  dt_n_ = dt_n;
  dt_trial_ = dt_trial;
  accepted_ = static_cast<int>(accepted);
  trial_solves_ = static_cast<int>(trial);
  impl_->lu->load_state(state, prefix + "lu.");
}

template <int Dim>
TransferReport BasicFlowSolver<Dim>::transfer_state(const BasicFlowSolver& old, const std::vector<int>& old_node) {
  if constexpr (Dim == 3) {
    (void)old;
    (void)old_node;
    throw std::invalid_argument("the 3D fluid cannot transfer a state between meshes yet");
  } else {
    const auto& om = old.mesh();
    const auto& nm = mesh();
    const auto& od = old.impl_->dof;
    const auto& nd = impl_->dof;
    if (old_node.size() != static_cast<std::size_t>(nm.node_count()))
      throw std::invalid_argument("FlowSolver::transfer_state: old_node has the wrong size");
    // Old nodal fields: u_n, u_{n-1} (2 + 2 columns) and x_n - x_{n-1} (2) per node; p_n, p_{n-1} per vertex.
    const int on = om.node_count(), ov = om.vertices();
    Eigen::MatrixXd nodal(on, 6), vertex(ov, 2);
    for (int i = 0; i < on; ++i)
      for (int c = 0; c < 2; ++c) {
        nodal(i, c) = old.U_n_(od.velocity(i, c));
        nodal(i, 2 + c) = old.U_nm1_(od.velocity(i, c));
        nodal(i, 4 + c) = old.X_n_(i, c) - old.X_nm1_(i, c);
      }
    for (int v = 0; v < ov; ++v) vertex(v, 0) = old.U_n_(od.pressure(v)), vertex(v, 1) = old.U_nm1_(od.pressure(v));
    const MeshLocator locator(om, old.X_n_);
    TransferReport report;
    Eigen::MatrixXd at_nodes = interpolate_field(locator, om, nodal, nm.nodes, &report);
    Eigen::MatrixXd at_vertices = interpolate_field(locator, om, vertex, nm.nodes.topRows(nm.vertices()));
    // Kept nodes: their own values, not an interpolation.
    for (int i = 0; i < nm.node_count(); ++i)
      if (const int o = old_node[static_cast<std::size_t>(i)]; o >= 0) {
        at_nodes.row(i) = nodal.row(o);
        if (i < nm.vertices()) {
          if (o >= ov) throw std::invalid_argument("FlowSolver::transfer_state: a vertex kept as a midpoint");
          at_vertices.row(i) = vertex.row(o);
        }
      }
    U_n_ = U_nm1_ = Eigen::VectorXd::Zero(nd.dofs);
    for (int i = 0; i < nm.node_count(); ++i)
      for (int c = 0; c < 2; ++c) {
        U_n_(nd.velocity(i, c)) = at_nodes(i, c);
        U_nm1_(nd.velocity(i, c)) = at_nodes(i, 2 + c);
      }
    for (int v = 0; v < nm.vertices(); ++v)
      U_n_(nd.pressure(v)) = at_vertices(v, 0), U_nm1_(nd.pressure(v)) = at_vertices(v, 1);
    U_ = U_n_;
    reaction_ = Eigen::VectorXd::Zero(nd.dofs);
    X_ = X_n_ = nm.nodes;
    X_nm1_ = nm.nodes - at_nodes.rightCols<2>();
    dt_n_ = old.dt_n_;
    dt_trial_ = old.dt_trial_;
    accepted_ = old.accepted_;
    trial_solves_ = 0;
    if (interface_velocity_.size() == old.interface_velocity_.size()) interface_velocity_ = old.interface_velocity_;
    return report;
  }
}

template <int Dim>
void BasicFlowSolver<Dim>::restart_history() {
  U_nm1_ = U_ = U_n_;
  X_nm1_ = X_ = X_n_;
  dt_n_ = dt_trial_ = 0;
  accepted_ = trial_solves_ = 0;
  interface_velocity_.setZero();
}

template <int Dim>
typename BasicFlowSolver<Dim>::History BasicFlowSolver<Dim>::history() const {
  return History{U_,     U_n_,  U_nm1_,    reaction_, interface_velocity_, X_,    X_n_,
                 X_nm1_, dt_n_, dt_trial_, accepted_, trial_solves_,       robin_};
}

template <int Dim>
void BasicFlowSolver<Dim>::set_history(const History& h) {
  U_ = h.U, U_n_ = h.U_n, U_nm1_ = h.U_nm1, reaction_ = h.reaction, interface_velocity_ = h.interface_velocity;
  X_ = h.X, X_n_ = h.X_n, X_nm1_ = h.X_nm1;
  dt_n_ = h.dt_n, dt_trial_ = h.dt_trial;
  accepted_ = h.accepted, trial_solves_ = h.trial_solves;
  robin_ = h.robin;
}

template <int Dim>
void BasicFlowSolver<Dim>::hold_penalty_interface(bool hold) {
  if (hold && !hold_penalty_) X_penalty_ = X_n_;
  if (!hold) X_penalty_ = Nodes();
  hold_penalty_ = hold;
}

template <int Dim>
typename BasicFlowSolver<Dim>::Nodes BasicFlowSolver<Dim>::velocity() const {
  Nodes v(mesh().node_count(), Dim);
  for (int i = 0; i < mesh().node_count(); ++i)
    for (int c = 0; c < Dim; ++c) v(i, c) = U_(impl_->dof.velocity(i, c));
  return v;
}

template <int Dim>
Eigen::VectorXd BasicFlowSolver<Dim>::pressure() const {
  return impl_->element->nodal_pressure(U_);
}

template <int Dim>
typename BasicFlowSolver<Dim>::PointD BasicFlowSolver<Dim>::force(const std::vector<std::string>& groups) const {
  PointD f = PointD::Zero();
  for (int node : mesh().boundary_nodes(groups)) f -= reaction_.template segment<Dim>(impl_->dof.velocity(node, 0));
  return f;
}

template <int Dim>
Eigen::SparseMatrix<double> BasicFlowSolver<Dim>::interface_mass() const {
  const auto n = static_cast<Eigen::Index>(interface_nodes_.size());
  std::vector<Eigen::Triplet<double>> t;
  t.reserve(9 * impl_->edges.size());
  const Nodes& X = params_.penalty_on_step_start ? penalty_positions() : X_;
  for (const auto& edge : impl_->edges) impl_->element->interface_mass(edge, X, t);
  Eigen::SparseMatrix<double> m(n, n);
  m.setFromTriplets(t.begin(), t.end());
  return m;
}

template <int Dim>
Eigen::VectorXd BasicFlowSolver<Dim>::interface_velocity_integral() const {
  Eigen::VectorXd vf(Dim * static_cast<Eigen::Index>(interface_nodes_.size()));
  for (std::size_t i = 0; i < interface_nodes_.size(); ++i)
    vf.template segment<Dim>(Dim * static_cast<Eigen::Index>(i)) =
        U_.template segment<Dim>(impl_->dof.velocity(interface_nodes_[i], 0));
  return apply_nodal(interface_mass(), vf);  // f_v = M_f v_f, the penalty term's own operator
}

template <int Dim>
Eigen::VectorXd BasicFlowSolver<Dim>::interface_traction() const {
  const Eigen::Index ni = static_cast<Eigen::Index>(interface_nodes_.size());
  Eigen::VectorXd f(Dim * ni);
  for (Eigen::Index i = 0; i < ni; ++i)
    f.template segment<Dim>(Dim * i) =
        reaction_.template segment<Dim>(impl_->dof.velocity(interface_nodes_[static_cast<std::size_t>(i)], 0));
  if (robin_) return f;
  // + gamma_N1 int N^T (v_f - v_s) = gamma_N1 (f_v - M_f v_s)
  return f +
         params_.nitsche_penalty * (interface_velocity_integral() - apply_nodal(interface_mass(), interface_velocity_));
}

// The vertex triangle holding `point` (at the positions of the last solve), with barycentric
// coordinates; false when the point is outside (by more than round-off).
template <int Dim>
bool BasicFlowSolver<Dim>::locate(const PointD& point, int& element, Eigen::Matrix<double, Dim + 1, 1>& bary) const {
  const auto& m = mesh();
  double best = -std::numeric_limits<double>::infinity();
  for (int e = 0; e < m.cell_count(); ++e) {
    Eigen::Matrix<double, Dim + 1, 1> l;
    if constexpr (Dim == 2) {
      const Eigen::Vector2d a = X_.row(m.triangles(e, 0)), b = X_.row(m.triangles(e, 1)), c = X_.row(m.triangles(e, 2));
      Eigen::Matrix2d J;
      J << b - a, c - a;
      const Eigen::Vector2d s = J.inverse() * (point - a);
      l << 1 - s(0) - s(1), s(0), s(1);
    } else {
      const Eigen::Vector3d a = X_.row(m.tets(e, 0));
      Eigen::Matrix3d J;
      for (int k = 0; k < 3; ++k) J.col(k) = X_.row(m.tets(e, k + 1)).transpose() - a;
      const Eigen::Vector3d s = J.inverse() * (point - a);
      l << 1 - s.sum(), s(0), s(1), s(2);
    }
    const double worst = l.minCoeff();
    if (worst > best) {
      best = worst;
      element = e;
      bary = l;
      if (worst >= 0) return true;
    }
  }
  return best > -1e-9;
}

template <int Dim>
double BasicFlowSolver<Dim>::pressure_at(const PointD& point) const {
  int e = 0;
  Eigen::Matrix<double, Dim + 1, 1> l;
  if (!locate(point, e, l)) return std::numeric_limits<double>::quiet_NaN();
  double p = 0;
  for (int k = 0; k < Dim + 1; ++k) {
    if constexpr (Dim == 2)
      p += l(k) * U_(impl_->dof.pressure(mesh().triangles(e, k)));
    else
      p += l(k) * U_(impl_->dof.pressure(mesh().tets(e, k)));
  }
  return p;
}

template <int Dim>
typename BasicFlowSolver<Dim>::PointD BasicFlowSolver<Dim>::velocity_at(const PointD& point) const {
  int e = 0;
  Eigen::Matrix<double, Dim + 1, 1> l;
  if (!locate(point, e, l)) return PointD::Constant(std::numeric_limits<double>::quiet_NaN());
  return impl_->element->velocity_at(e, l, U_);
}

template class BasicFlowSolver<2>;
template class BasicFlowSolver<3>;

}  // namespace fsi::fluid
