#include "fsi/solid/fem_solid.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <set>

#include "fsi/common/interface_geometry.hpp"
#include "fsi/common/log.hpp"
#include "fsi/common/scene_reader.hpp"
#include "fsi/solid/element.hpp"

#ifdef FSI_HAVE_GMSH_READER
#include "fsi/common/gmsh_mesher.hpp"
#include "fsi/common/gmsh_reader.hpp"
#endif

namespace fsi::solid {

namespace {

// A vector key of the mesh's dimension ([x, y] or [x, y, z], checked by the reader); absent: zero.
Eigen::VectorXd vec(const schema::Reader& s, const std::string& key, int dim) {
  if (!s.has(key)) return Eigen::VectorXd::Zero(dim);
  const std::vector<double> v = s.vector(key, dim);
  return Eigen::Map<const Eigen::VectorXd>(v.data(), dim);
}

SolidMesh build_mesh(const schema::Reader& m) {
  const auto type = m.get<std::string>("type");
  if (type == "box") {
    const Eigen::Vector3d origin = vec(m, "origin", 3);
    const Eigen::Vector3d size = vec(m, "size", 3);
    const auto n = m.get<std::vector<int>>("divisions");
    if (n.size() != 3 || n[0] < 1 || n[1] < 1 || n[2] < 1)
      m.fail("divisions", "must be [nx, ny, nz] with nx, ny, nz >= 1");
    if (!(size.minCoeff() > 0)) m.fail("size", "must be positive");
    return box_mesh(origin, size, n[0], n[1], n[2]);
  }
  if (type == "tube") {
    const Eigen::Vector3d origin = vec(m, "origin", 3);
    const auto n = m.get<std::vector<int>>("divisions");
    if (n[0] < 3 || n[1] < 1 || n[2] < 1)
      m.fail("divisions", "must be [n_theta, n_r, n_z] with n_theta >= 3, n_r, n_z >= 1");
    const double ri = m.get<double>("inner_radius"), ro = m.get<double>("outer_radius");
    if (!(ro > ri)) m.fail("outer_radius", fmt::format("must be larger than inner_radius ({})", ri));
    return tube_mesh(origin, ri, ro, m.get<double>("length"), n[0], n[1], n[2]);
  }
  if (type == "rectangle") {
    const Eigen::Vector2d origin = vec(m, "origin", 2);
    const Eigen::Vector2d size = vec(m, "size", 2);
    const auto n = m.get<std::vector<int>>("elements");
    if (n.size() != 2 || n[0] < 1 || n[1] < 1) m.fail("elements", "must be [nx, ny] with nx, ny >= 1");
    if (!(size(0) > 0 && size(1) > 0)) m.fail("size", "must be positive");
    return rectangle_mesh(origin(0), origin(1), size(0), size(1), n[0], n[1]);
  }
  if (type == "gmsh") {
    const auto domain = m.get_or<std::string>("domain", "");
#ifdef FSI_HAVE_GMSH_READER
    const std::string source = m.has("geo") ? "geo" : "file";
    std::filesystem::path file;
    if (source == "file") {
      file = m.path("file");
    } else {
      std::map<std::string, double> parameters;
      (void)m.declared("parameters");
      if (auto extra = m.section().optional_child("parameters"))
        for (const auto& k : extra->keys()) parameters[k] = extra->get<double>(k);
      const auto cache =
          m.has("cache_dir") ? std::filesystem::path(m.get<std::string>("cache_dir")) : fsi::default_mesh_cache();
      try {
        file = fsi::mesh_geo(m.path("geo"), parameters, cache, m.get<int>("order"), 3, "solid");
      } catch (const std::runtime_error& e) {
        m.fail("geo", e.what());
      }
    }
    try {
      return mesh_from_gmsh(fsi::read_gmsh(file), domain);
    } catch (const std::invalid_argument& e) {
      m.fail(source, source == "geo" ? fmt::format("gmsh meshed it into {}, but {}", file.string(), e.what())
                                     : std::string(e.what()));
    }
#else
    const auto file = m.path(m.has("geo") ? "geo" : "file");
    m.fail("type", "gmsh meshes need fsi::read_gmsh, not built into fsi_common yet ('" + file.string() + "')");
#endif
  }
  m.fail("type", "must be 'rectangle', 'box' or 'gmsh', got '" + type + "'");
}

}  // namespace

void FemSolid::configure(const ConfigSection& section, const SolidSetup& setup) {
  const schema::Reader s(section, fem_solid_keys());
  auto log = fsi::logger("solid");
  setup_ = setup;

  // 1. Mesh; its dimension is the solid's.
  mesh_ = build_mesh(s.child("mesh"));
  const int dim = mesh_.dim;

  // 2. Material.
  const auto mat = s.child("material");
  const auto law = mat.get<std::string>("law");
  const double nu = mat.get<double>("poisson_ratio");
  ElasticConstants constants;
  const bool has_E = mat.has("youngs_modulus"), has_mu = mat.has("shear_modulus");
  if (has_E == has_mu)
    mat.fail(has_E ? "youngs_modulus" : "law", "give exactly one of youngs_modulus or shear_modulus");
  if (has_E) {
    const double E = mat.get_or<double>("youngs_modulus", 0.0);
    constants = ElasticConstants::from_youngs(E, nu);
  } else {
    const double mu = mat.get_or<double>("shear_modulus", 0.0);
    constants = ElasticConstants::from_shear(mu, nu);
  }
  std::shared_ptr<const Material> material;
  std::shared_ptr<const Material3> material3;
  try {
    if (dim == 2)
      material = make_material<2>(law, constants);
    else
      material3 = make_material<3>(law, constants);
  } catch (const std::invalid_argument& e) {
    mat.fail("law", e.what());
  }
  const double density = s.get<double>("density");

  // 3. Analysis type and scheme.
  const auto analysis = s.get<std::string>("analysis");
  const auto scheme = s.get<std::string>("time_scheme");
  if (analysis == "static") {
    scheme_ = TimeScheme::Static;
  } else if (analysis == "dynamic") {
    if (scheme == "bdf1")
      scheme_ = TimeScheme::Bdf1;
    else if (scheme == "bdf2")
      scheme_ = TimeScheme::Bdf2;
    else if (scheme == "newmark")
      scheme_ = TimeScheme::Newmark;
    else
      s.fail("time_scheme", "must be 'bdf1', 'bdf2' or 'newmark', got '" + scheme + "'");
  } else {
    s.fail("analysis", "must be 'static' or 'dynamic', got '" + analysis + "'");
  }
  load_steps_ = s.get<int>("load_steps");

  // 4. Newton and the linear solver.
  {
    const auto n = s.child_or_defaults("newton");
    newton_.max_iterations = n.get<int>("max_iterations");
    newton_.residual_tolerance = n.get<double>("residual_tolerance");
    newton_.increment_tolerance = n.get<double>("increment_tolerance");
  }
  const auto solver_name = s.get<std::string>("linear_solver");
  LinearSolverKind solver_kind = LinearSolverKind::Cholmod;
  if (solver_name == "umfpack")
    solver_kind = LinearSolverKind::Umfpack;
  else if (solver_name != "cholmod")
    s.fail("linear_solver", "must be 'cholmod' or 'umfpack'");

  // 5. Clamps (homogeneous Dirichlet on named facets, every component) and supports (some
  // components only, e.g. u_z = 0 on the side faces of an extruded 2D problem).
  const auto clamp = s.names("clamp");
  std::vector<char> fixed(static_cast<std::size_t>(dim * mesh_.num_nodes()), 0);
  try {
    for (int n : mesh_.facet_nodes(clamp))
      for (int c = 0; c < dim; ++c) fixed[static_cast<std::size_t>(dim * n + c)] = 1;
  } catch (const std::invalid_argument& e) {
    s.fail("clamp", e.what());
  }
  for (const auto& support : s.list("supports")) {
    std::vector<int> nodes;
    try {
      nodes = mesh_.facet_nodes(support.names("boundary"));
    } catch (const std::invalid_argument& e) {
      support.fail("boundary", e.what());
    }
    const std::string axes = dim == 2 ? "xy" : "xyz";
    for (const auto& component : support.names("fixed")) {
      const auto c = axes.find(component);
      if (component.size() != 1 || c == std::string::npos)
        support.fail("fixed", fmt::format("'{}' is not a component of a {}D mesh (give some of {})", component, dim,
                                          dim == 2 ? "x, y" : "x, y, z"));
      for (int n : nodes) fixed[static_cast<std::size_t>(dim * n) + c] = 1;
    }
  }
  system_ = dim == 2 ? std::make_unique<SolidSystem>(mesh_, material, density, fixed, solver_kind)
                     : std::make_unique<SolidSystem>(mesh_, material3, density, fixed, solver_kind);
  // The elements of the mesh's cells; the first is the default.
  const std::vector<std::pair<std::string, ElementKind>> elements =
      mesh_.cell == CellKind::Quad4
          ? std::vector<std::pair<std::string, ElementKind>>{{"q4", ElementKind::Q4}, {"q4_eas", ElementKind::Q4Eas}}
      : mesh_.cell == CellKind::Hex8
          ? std::vector<std::pair<std::string, ElementKind>>{{"hex8", ElementKind::Hex8},
                                                             {"h8_eas", ElementKind::Hex8Eas}}
          : std::vector<std::pair<std::string, ElementKind>>{{"tet10", ElementKind::Tet10}};
  const auto element = s.get_or<std::string>("element", elements.front().first);
  const auto chosen = std::find_if(elements.begin(), elements.end(), [&](const auto& e) { return e.first == element; });
  if (chosen == elements.end()) {
    std::string names;
    for (const auto& e : elements) names += (names.empty() ? "" : " or ") + e.first;
    s.fail("element", fmt::format("'{}' is not an element of a {}D mesh of {} cells (give {})", element, dim,
                                  cell_kind_name(mesh_.cell), names));
  }
  system_->set_element(chosen->second);

  // 6. Loads: gravity (force per reference volume rho_s g), dead facet tractions, point loads.
  const Eigen::VectorXd gravity = vec(s, "gravity", dim);
  dead_load_ = system_->body_force(Eigen::VectorXd(density * gravity));
  for (const auto& t : s.list("tractions")) {
    const auto boundary = t.names("boundary");
    const Eigen::VectorXd traction = vec(t, "traction", dim);  // force per reference length (2D) or area (3D)
    std::vector<Facet> facets;
    try {
      facets = mesh_.facets(boundary);
    } catch (const std::invalid_argument& e) {
      t.fail("boundary", e.what());
    }
    for (const auto& e : facets) {
      if (dim == 2) {
        const double L = (mesh_.nodes.row(e[0]) - mesh_.nodes.row(e[1])).norm();
        for (int n : e) dead_load_.segment<2>(2 * n) += 0.5 * L * traction;
      } else {  // int N_a dA, consistent (0 at the vertices of a flat 6-node triangle)
        Eigen::MatrixXd X(e.size(), 3);
        for (std::size_t a = 0; a < e.size(); ++a) X.row(static_cast<Eigen::Index>(a)) = mesh_.nodes.row(e[a]);
        const Eigen::VectorXd w = face_weights(X);
        for (std::size_t a = 0; a < e.size(); ++a)
          dead_load_.segment<3>(3 * e[a]) += w(static_cast<Eigen::Index>(a)) * traction;
      }
    }
  }

  // Dead pressures: -p int N n0 dA with n0 the outward normal of the reference configuration,
  // oriented away from the cell that holds the facet (whatever the facet's node order).
  for (const auto& p : s.list("pressures")) {
    const double pressure = p.get<double>("pressure");
    std::vector<Facet> facets;
    std::vector<Eigen::MatrixXd> area;
    try {
      facets = mesh_.facets(p.names("boundary"));
      area = outward_area_vectors(mesh_, facets);
    } catch (const std::invalid_argument& e) {
      p.fail("boundary", e.what());
    }
    for (std::size_t i = 0; i < facets.size(); ++i)
      for (std::size_t k = 0; k < facets[i].size(); ++k)
        dead_load_.segment(dim * facets[i][k], dim) -= pressure * area[i].row(static_cast<Eigen::Index>(k)).transpose();
  }

  for (const auto& p : s.list("point_loads")) {  // force at the node nearest to a point
    const Eigen::VectorXd point = vec(p, "point", dim);
    const Eigen::VectorXd force = vec(p, "force", dim);
    Eigen::Index nearest = 0;
    (mesh_.nodes.rowwise() - point.transpose()).rowwise().squaredNorm().minCoeff(&nearest);
    dead_load_.segment(dim * nearest, dim) += force;
  }

  // 7. Interface: named edges -> InterfaceMeshData; Algorithm 2 damping on them.
  const auto iface = s.names("interface");
  std::vector<Facet> iface_edges;
  try {
    iface_edges = mesh_.facets(iface);
    interface_nodes_ = mesh_.facet_nodes(iface);
  } catch (const std::invalid_argument& e) {
    s.fail("interface", e.what());
  }
  std::map<int, int> local;
  for (std::size_t i = 0; i < interface_nodes_.size(); ++i) local[interface_nodes_[i]] = static_cast<int>(i);
  interface_ = {};
  interface_.dimension = dim;
  interface_.coordinates.resize(static_cast<Eigen::Index>(interface_nodes_.size()), dim);
  interface_.lumped_measure = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(interface_nodes_.size()));
  for (std::size_t i = 0; i < interface_nodes_.size(); ++i) {
    interface_.node_ids.push_back(interface_nodes_[i]);
    interface_.coordinates.row(static_cast<Eigen::Index>(i)) = mesh_.nodes.row(interface_nodes_[i]);
  }
  if (dim == 2) {
    for (const auto& e : iface_edges) {
      const int a = local[e[0]], b = local[e[1]];
      interface_.segments.push_back({a, b});
      const double L = (mesh_.nodes.row(e[0]) - mesh_.nodes.row(e[1])).norm();
      interface_.lumped_measure(a) += 0.5 * L;
      interface_.lumped_measure(b) += 0.5 * L;
    }
  } else {  // the boundary faces of the named sets (bilinear quadrilaterals, or 6-node triangles)
    for (const auto& f : iface_edges) {
      InterfaceFace face;
      for (int v : f) face.nodes.push_back(local[v]);
      interface_.faces.push_back(face);
    }
    // The row sums of int N^T N (the nodal areas of bilinear faces); those of a 6-node
    // triangle vanish at its vertices, and the protocol wants every node's measure > 0: the
    // HRZ shares there (lumped_facet_measure, the same total area).
    const bool quadratic =
        std::any_of(iface_edges.begin(), iface_edges.end(), [](const Facet& f) { return f.size() == 6; });
    if (quadratic) {
      const Eigen::VectorXd measure = lumped_facet_measure(mesh_, unique_facets(iface_edges));
      for (std::size_t i = 0; i < interface_nodes_.size(); ++i)
        interface_.lumped_measure(static_cast<Eigen::Index>(i)) = measure(interface_nodes_[i]);
    } else if (!interface_.faces.empty()) {
      interface_.lumped_measure = lumped_interface_measure(interface_);
    }
  }
  // The solid's mass over its interface measure (the automatic Robin parameter's m_s / |Gamma|):
  // the consistent mass matrix sums to dim rho |Omega_s| (one per component).
  if (interface_.lumped_measure.sum() > 0)
    interface_.mass_per_area = Eigen::VectorXd(system_->mass() * Eigen::VectorXd::Ones(system_->mass().cols())).sum() /
                               dim / interface_.lumped_measure.sum();
  if (setup.interface_damping < 0) throw ConfigError("interface damping gamma_N1 must be >= 0");
  if (setup.interface_damping > 0) {
    if (iface_edges.empty()) s.fail("interface", "is required when the coupler asks for interface damping");
    if (dim == 2)
      system_->set_damping(system_->boundary_mass(iface_edges, setup.interface_damping));
    else  // int N^T N on the faces (the coupler's M_G replaces it when it sends one)
      set_interface_mass(nodal_interface_mass(interface_, Eigen::VectorXd()));
  }

  // 8. Rigid obstacles (contact) and elastic supports.
  configure_obstacles(s, constants);
  configure_supports(s);

  // 9. Probes: displacement of named points, interpolated in the cell that holds them.
  probes_.clear();
  for (const auto& p : s.list("probes")) {
    Probe probe;
    probe.name = p.get<std::string>("name");
    probe.point = vec(p, "point", dim);
    double best = 1e300;  // the cell whose natural coordinates are the most inside (Shape::extent)
    with_shape(mesh_.cell, [&](auto shape) {
      using Shape = decltype(shape);
      for (int c = 0; c < mesh_.num_cells(); ++c) {
        typename Shape::Point xi;
        if (!inverse_map<Shape>(system_->cell_coordinates<Shape>(c), probe.point, xi)) continue;
        const double outside = Shape::extent(xi);
        if (outside < best) best = outside, probe.cell = c, probe.xi = xi;
      }
    });
    if (best > 1 + 1e-6) probe.cell = -1;
    if (probe.cell < 0) p.fail("point", "is not inside the solid mesh");
    probes_.push_back(probe);
  }

  // VTK goes to the run's output folder when the driver/coupler asks (time.output_every) and
  // the step is a multiple of solid.output_every (default 1; 0 = the solid writes nothing).
  output_every_ = s.get<int>("output_every");
  series_.reset();
  if (!setup.output_dir.empty() && output_every_ > 0) series_.emplace(setup.output_dir, "solid", setup.vtk_format);

  // 10. Initial state: at rest, undeformed; Newmark needs a consistent a_0 = M^-1 (F - F_int).
  const int n = system_->num_dofs();
  d_n_ = v_n_ = a_n_ = f_n_ = Eigen::VectorXd::Zero(n);
  if (scheme_ == TimeScheme::Newmark) a_n_ = system_->solve_mass(dead_load_);
  d_ = d_n_, v_ = v_n_, a_ = a_n_, f_ = f_n_;
  d_nm1_ = d_n_, v_nm1_ = v_n_;
  accepted_steps_ = 0;
  solved_ = false;
  contact_stats_ = {};
  log->info("fem solid: {}D, {} nodes, {} {} cells, {} free dofs, law {}, mu {:.6g}, lambda {:.6g}, {} analysis{}{}",
            dim, mesh_.num_nodes(), mesh_.num_cells(), element, system_->num_free(),
            dim == 2 ? material->name() : material3->name(), constants.mu, constants.lambda, analysis,
            scheme_ == TimeScheme::Static ? "" : ", scheme " + scheme,
            setup.interface_damping > 0 ? fmt::format(", interface damping {:.4g}", setup.interface_damping) : "");
}

void FemSolid::configure_obstacles(const schema::Reader& s, const ElasticConstants& constants) {
  const int dim = mesh_.dim;
  const double youngs = constants.mu * (3 * constants.lambda + 2 * constants.mu) / (constants.lambda + constants.mu);
  std::vector<Obstacle> obstacles;
  std::vector<std::vector<Facet>> per_obstacle;  // each facet once (a facet in two sets counts once)
  const auto list = s.list("obstacles");
  for (const auto& o : list) {
    Obstacle obstacle;
    obstacle.point = vec(o, "point", dim);
    obstacle.normal = vec(o, "normal", dim);
    if (!(obstacle.normal.norm() > 0)) o.fail("normal", "must not be zero");
    obstacle.contact_gap = o.get<double>("contact_gap");
    std::vector<Facet> mine;
    try {
      mine = mesh_.facets(o.has("boundary") ? o.names("boundary") : mesh_.facet_set_names());
    } catch (const std::invalid_argument& e) {
      o.fail("boundary", e.what());
    }
    const std::vector<Facet> unique = unique_facets(mine);
    double h = 1e300;
    for (const auto& f : unique) {
      for (std::size_t a = 0; a < f.size(); ++a)
        h = std::min(h, (mesh_.nodes.row(f[a]) - mesh_.nodes.row(f[(a + 1) % f.size()])).norm());
    }
    if (unique.empty()) o.fail("boundary", "names no facets");
    obstacle.stiffness = o.has("stiffness") ? o.get<double>("stiffness") : youngs / h;
    obstacles.push_back(obstacle);
    per_obstacle.push_back(std::move(unique));
  }
  if (obstacles.empty()) {
    system_->set_contact(nullptr);
    return;
  }
  std::shared_ptr<ObstacleContact> contact;
  try {
    contact = std::make_shared<ObstacleContact>(mesh_, obstacles, per_obstacle, system_->fixed());
  } catch (const ObstacleError& e) {
    list[static_cast<std::size_t>(e.obstacle)].fail("point", e.what());
  }
  for (std::size_t i = 0; i < obstacles.size(); ++i)
    fsi::logger("solid")->info(
        "obstacle {}: contact gap {:.4g}, stiffness {:.4g}, {} contact nodes ({} start within the gap and are left "
        "out)",
        i, obstacles[i].contact_gap, obstacles[i].stiffness, contact->candidates(static_cast<int>(i)),
        contact->excluded(static_cast<int>(i)));
  system_->set_contact(std::move(contact));
}

void FemSolid::configure_supports(const schema::Reader& s) {
  std::vector<SupportSpec> specs;
  const auto list = s.list("elastic_supports");
  for (const auto& e : list) {
    SupportSpec spec;
    try {
      spec.facets = unique_facets(mesh_.facets(e.names("boundary")));
    } catch (const std::invalid_argument& err) {
      e.fail("boundary", err.what());
    }
    if (spec.facets.empty()) e.fail("boundary", "names no facets");
    spec.stiffness = e.get<double>("stiffness");
    spec.normal_only = e.get<std::string>("direction") == "normal";
    specs.push_back(std::move(spec));
  }
  if (specs.empty()) {
    system_->set_support(nullptr);
    return;
  }
  auto support = std::make_shared<ElasticSupport>(mesh_, specs);
  fsi::logger("solid")->info("elastic supports: {} boundary nodes", support->nodes());
  system_->set_support(std::move(support));
}

void FemSolid::set_interface_mass(const NodalMatrix& m) {
  if (!system_) throw SolverError("solid: set_interface_mass before configure");
  const auto n = static_cast<Eigen::Index>(interface_nodes_.size());
  if (m.rows() != n || m.cols() != n)
    throw std::invalid_argument(
        fmt::format("solid: interface mass is {} x {}, expected {} x {} (interface nodes)", m.rows(), m.cols(), n, n));
  if (!(setup_.interface_damping > 0)) return;  // no damping (Algorithm 1 or gamma_N1 = 0)
  std::vector<Eigen::Triplet<double>> t;
  const int dim = mesh_.dim;
  t.reserve(static_cast<std::size_t>(dim * m.nonZeros()));
  for (int col = 0; col < m.outerSize(); ++col)
    for (NodalMatrix::InnerIterator it(m, col); it; ++it)
      for (int c = 0; c < dim; ++c)
        t.emplace_back(dim * interface_nodes_[static_cast<std::size_t>(it.row())] + c,
                       dim * interface_nodes_[static_cast<std::size_t>(it.col())] + c,
                       setup_.interface_damping * it.value());
  system_->set_damping_entries(t);
}

Eigen::VectorXd FemSolid::external_force(const Eigen::VectorXd& interface_force) const {
  Eigen::VectorXd f = dead_load_;
  const auto n = static_cast<Eigen::Index>(interface_nodes_.size());
  if (interface_force.size() == 0) return f;
  const int dim = mesh_.dim;
  if (interface_force.size() != dim * n)
    throw SolverError(fmt::format("solid: interface force has {} entries, expected {} ({} per interface node)",
                                  interface_force.size(), dim * n, dim));
  for (Eigen::Index i = 0; i < n; ++i)
    f.segment(dim * interface_nodes_[i], dim) += interface_force.segment(dim * i, dim);
  return f;
}

void FemSolid::newton(Eigen::VectorXd& d, const Eigen::VectorXd& f, const TimeTerms& t, const StepInfo& info) {
  NewtonReport rep;
  try {
    rep = system_->solve(d, f, t, newton_);
  } catch (const InvertedElement& e) {
    throw SolverError(fmt::format("solid step {} (t = {:.6g}): element {} inverted (det F = {:.3g})", info.step,
                                  info.time, e.element, e.det_F));
  }
  last_iterations_ += rep.iterations;
  fsi::logger("solid")->debug("step {} k {}: Newton {} iterations, |R| {:.3e} -> {:.3e}", info.step, info.iteration,
                              rep.iterations, rep.initial_residual, rep.residual);
  if (!rep.converged)
    throw SolverError(
        fmt::format("solid step {} (t = {:.6g}): Newton did not converge in {} iterations (|R| {:.3e}, "
                    "initial {:.3e})",
                    info.step, info.time, rep.iterations, rep.residual, rep.initial_residual));
}

void FemSolid::set_history(const History& h) {
  d_n_ = h.d_n, v_n_ = h.v_n, a_n_ = h.a_n, f_n_ = h.f_n, d_nm1_ = h.d_nm1, v_nm1_ = h.v_nm1;
  accepted_steps_ = h.accepted_steps;
  dt_n_ = h.dt_n;
}

SolidStepResult FemSolid::solve_window(const StepInfo& info, const Waveform& force, int substeps) {
  if (!system_) throw SolverError("solid: solve_step before configure");
  Waveform w = force;
  w.degree = scheme_ == TimeScheme::Bdf1 ? 1 : 2;
  const History start = history();
  const double h = info.dt / substeps, t0 = info.time - info.dt;
  SolidStepResult out;
  int iterations = 0;
  try {
    for (int j = 1; j <= substeps; ++j) {
      if (j > 1) {  // the last substep becomes the history of the next
        d_nm1_ = d_n_, v_nm1_ = v_n_;
        d_n_ = d_, v_n_ = v_, a_n_ = a_, f_n_ = f_;
        dt_n_ = dt_solved_;
        ++accepted_steps_;
      }
      const StepInfo sub{substep_time(t0, info.dt, j, substeps), h, info.step, info.iteration};
      const SolidStepResult r = solve_step(sub, w.at(sub.time));
      iterations += r.newton_iterations;
      const Eigen::Index m = r.interface_displacement.size();
      if (j == 1) out.displacement_samples.resize(m * substeps), out.velocity_samples.resize(m * substeps);
      out.displacement_samples.segment((j - 1) * m, m) = r.interface_displacement;
      out.velocity_samples.segment((j - 1) * m, m) = r.interface_velocity;
      if (j == substeps)
        out.interface_displacement = r.interface_displacement, out.interface_velocity = r.interface_velocity;
    }
  } catch (...) {
    set_history(start);
    throw;
  }
  window_end_ = history();
  set_history(start);
  out.newton_iterations = last_iterations_ = iterations;
  return out;
}

SolidStepResult FemSolid::solve_step(const StepInfo& info, const Eigen::VectorXd& interface_force) {
  if (!system_) throw SolverError("solid: solve_step before configure");
  window_end_.reset();
  f_ = external_force(interface_force);
  last_iterations_ = 0;
  const double dt = info.dt > 0 ? info.dt : setup_.dt;
  if (scheme_ != TimeScheme::Static && !(dt > 0)) throw SolverError("solid: dynamic analysis needs dt > 0");
  if (scheme_ == TimeScheme::Static) {
    d_ = d_n_;
    for (int s = 1; s <= load_steps_; ++s) {
      const Eigen::VectorXd f = f_n_ + (double(s) / load_steps_) * (f_ - f_n_);
      newton(d_, f, TimeTerms{}, info);
    }
    v_.setZero();
    a_.setZero();
  } else if (scheme_ == TimeScheme::Bdf2 && accepted_steps_ >= 1) {
    TimeTerms t;
    const double w = dt_n_ > 0 ? dt / dt_n_ : 1.0;  // this step over the last one
    if (w == 1.0) {
      // v = (3 d - 4 d_n + d_nm1) / (2 dt), a = (3 v - 4 v_n + v_nm1) / (2 dt)
      t.damping_coefficient = 1.5 / dt;
      t.velocity_history = (-4.0 * d_n_ + d_nm1_) / (2.0 * dt);
      t.mass_coefficient = 1.5 / dt * t.damping_coefficient;
      t.acceleration_history = 1.5 / dt * t.velocity_history - (4.0 * v_n_ - v_nm1_) / (2.0 * dt);
    } else {
      // Variable steps (w = dt / dt_n): v = (a0 d + a1 d_n + a2 d_nm1) / dt, a alike from v,
      // a0 = (1 + 2w) / (1 + w), a1 = -(1 + w), a2 = w^2 / (1 + w) (w = 1: the line above).
      const double a0 = (1 + 2 * w) / (1 + w), a1 = -(1 + w), a2 = w * w / (1 + w);
      t.damping_coefficient = a0 / dt;
      t.velocity_history = (a1 * d_n_ + a2 * d_nm1_) / dt;
      t.mass_coefficient = a0 / dt * t.damping_coefficient;
      t.acceleration_history = a0 / dt * t.velocity_history + (a1 * v_n_ + a2 * v_nm1_) / dt;
    }
    d_ = d_n_ + dt * v_n_;
    newton(d_, f_, t, info);
    v_ = t.damping_coefficient * d_ + t.velocity_history;
    a_ = t.mass_coefficient * d_ + t.acceleration_history;
  } else if (scheme_ == TimeScheme::Bdf1 || scheme_ == TimeScheme::Bdf2) {
    TimeTerms t;
    t.mass_coefficient = 1.0 / (dt * dt);
    t.acceleration_history = -d_n_ / (dt * dt) - v_n_ / dt;
    t.damping_coefficient = 1.0 / dt;
    t.velocity_history = -d_n_ / dt;
    d_ = d_n_ + dt * v_n_;
    newton(d_, f_, t, info);
    v_ = (d_ - d_n_) / dt;
    a_ = (v_ - v_n_) / dt;
  } else {
    const double newmark_beta = 0.25, newmark_gamma = 0.5;
    TimeTerms t;
    t.mass_coefficient = 1.0 / (newmark_beta * dt * dt);
    t.acceleration_history = -(d_n_ + dt * v_n_) / (newmark_beta * dt * dt) - (0.5 / newmark_beta - 1.0) * a_n_;
    t.damping_coefficient = newmark_gamma * dt * t.mass_coefficient;
    t.velocity_history = v_n_ + dt * (1 - newmark_gamma) * a_n_ + newmark_gamma * dt * t.acceleration_history;
    d_ = d_n_ + dt * v_n_;
    newton(d_, f_, t, info);
    a_ = t.mass_coefficient * d_ + t.acceleration_history;
    v_ = t.damping_coefficient * d_ + t.velocity_history;
  }
  solved_ = true;
  dt_solved_ = scheme_ == TimeScheme::Static ? 0.0 : dt;
  SolidStepResult r;
  const auto n = static_cast<Eigen::Index>(interface_nodes_.size());
  const int dim = mesh_.dim;
  r.interface_displacement.resize(dim * n);
  r.interface_velocity.resize(dim * n);
  for (Eigen::Index i = 0; i < n; ++i) {
    r.interface_displacement.segment(dim * i, dim) = d_.segment(dim * interface_nodes_[i], dim);
    r.interface_velocity.segment(dim * i, dim) = v_.segment(dim * interface_nodes_[i], dim);
  }
  r.newton_iterations = last_iterations_;
  return r;
}

Eigen::VectorXd FemSolid::probe_displacement(const Probe& p, const Eigen::VectorXd& d) const {
  return with_shape(mesh_.cell, [&](auto shape) -> Eigen::VectorXd {
    using Shape = decltype(shape);
    constexpr int dim = Shape::dim;
    const auto N = Shape::shape(p.xi);
    const auto u = system_->cell_values<Shape>(p.cell, d);
    Eigen::Matrix<double, dim, 1> out = Eigen::Matrix<double, dim, 1>::Zero();
    for (int a = 0; a < Shape::nodes; ++a) out += N(a) * u.template segment<dim>(dim * a);
    return out;
  });
}

std::map<std::string, double> FemSolid::accept_step(const StepInfo& info) {
  if (!solved_) throw SolverError(fmt::format("solid: accept_step {} without a solve_step", info.step));
  if (window_end_) set_history(*window_end_), window_end_.reset();
  d_nm1_ = d_n_, v_nm1_ = v_n_;
  d_n_ = d_, v_n_ = v_, a_n_ = a_, f_n_ = f_;
  dt_n_ = dt_solved_;
  ++accepted_steps_;
  solved_ = false;
  std::map<std::string, double> probes;
  for (const auto& p : probes_) {
    const Eigen::VectorXd u = probe_displacement(p, d_n_);
    probes[p.name + "_x"] = u(0);
    probes[p.name + "_y"] = u(1);
    if (u.size() == 3) probes[p.name + "_z"] = u(2);
  }
  probes["newton_iterations"] = last_iterations_;
  if (const ObstacleContact* contact = system_->contact()) {
    const ContactState state = contact->measure(d_n_);
    const bool was_active = contact_stats_.active;
    contact_stats_.add(state, info.time, info.dt > 0 ? info.dt : setup_.dt);
    if (contact_stats_.active != was_active)
      fsi::logger("solid")->info(
          "step {} (t = {:.6g}): contact {}: {} nodes below the contact gap, smallest gap {:.4g}, force {:.4g}",
          info.step, info.time, contact_stats_.active ? "begins" : "ends", state.active_nodes, state.min_gap,
          state.force.norm());
  }
  return probes;
}

void ContactStatistics::add(const ContactState& s, double time, double dt) {
  active = s.active_nodes > 0;
  if (s.min_gap < min_gap) min_gap = s.min_gap, min_gap_time = time, min_gap_point = s.min_gap_point;
  if (!active) return;
  ++active_steps;
  active_time += dt;
  if (first_time < 0) first_time = time;
  last_time = time;
  if (s.force.norm() > max_force) max_force = s.force.norm(), max_force_time = time;
  if (lower.size() == 0)
    lower = s.lower, upper = s.upper;
  else
    lower = lower.cwiseMin(s.lower), upper = upper.cwiseMax(s.upper);
}

std::map<std::string, double> ContactStatistics::report() const {
  std::map<std::string, double> r;
  const char* axes = "xyz";
  r["contact_active_steps"] = active_steps;
  r["contact_active_time"] = active_time;
  if (min_gap_time >= 0) {
    r["contact_min_gap"] = min_gap;
    r["contact_min_gap_time"] = min_gap_time;
    for (Eigen::Index c = 0; c < min_gap_point.size(); ++c)
      r[std::string("contact_min_gap_") + axes[c]] = min_gap_point(c);
  }
  if (active_steps == 0) return r;
  r["contact_first_time"] = first_time;
  r["contact_last_time"] = last_time;
  r["contact_max_force"] = max_force;
  r["contact_max_force_time"] = max_force_time;
  for (Eigen::Index c = 0; c < lower.size(); ++c) {
    r[std::string("contact_region_") + axes[c] + "_min"] = lower(c);
    r[std::string("contact_region_") + axes[c] + "_max"] = upper(c);
  }
  return r;
}

void ContactStatistics::save(StateArchive& state) const {
  // [steps, time, first, last, min gap, its time, max force, its time, active], then the points.
  state.put("solid.contact.scalars",
            std::vector<double>{static_cast<double>(active_steps), active_time, first_time, last_time, min_gap,
                                min_gap_time, max_force, max_force_time, active ? 1.0 : 0.0});
  state.put("solid.contact.min_gap_point", min_gap_point);
  state.put("solid.contact.lower", lower);
  state.put("solid.contact.upper", upper);
}

void ContactStatistics::load(const StateArchive& state, int dim) {
  const Eigen::VectorXd v = state.vector("solid.contact.scalars", 9);
  active_steps = static_cast<int>(v(0));
  active_time = v(1), first_time = v(2), last_time = v(3), min_gap = v(4), min_gap_time = v(5);
  max_force = v(6), max_force_time = v(7), active = v(8) != 0;
  min_gap_point = state.vector("solid.contact.min_gap_point");
  lower = state.vector("solid.contact.lower");
  upper = state.vector("solid.contact.upper");
  for (const auto* p : {&min_gap_point, &lower, &upper})
    if (p->size() != 0 && p->size() != dim)
      throw StateError(fmt::format("solid checkpoint: a contact point has {} components, the mesh {}", p->size(), dim));
}

std::map<std::string, double> FemSolid::diagnostics() const {
  if (!system_ || !system_->contact()) return {};
  return contact_stats_.report();
}

void FemSolid::save_state(StateArchive& state) {
  state.put("solid.scheme", static_cast<std::int64_t>(scheme_));
  state.put("solid.accepted_steps", static_cast<std::int64_t>(accepted_steps_));
  state.put("solid.d_n", d_n_);
  state.put("solid.v_n", v_n_);
  state.put("solid.a_n", a_n_);
  state.put("solid.f_n", f_n_);
  state.put("solid.d_nm1", d_nm1_);
  state.put("solid.v_nm1", v_nm1_);
  state.put("solid.dt_n", dt_n_);
  if (system_->contact()) contact_stats_.save(state);
}

void FemSolid::load_state(const StateArchive& state) {
  if (!system_) throw SolverError("solid: load_state before configure");
  if (state.integer("solid.scheme") != static_cast<std::int64_t>(scheme_))
    throw StateError(fmt::format("solid checkpoint: entry 'solid.scheme' is {}, this configuration uses {}",
                                 state.integer("solid.scheme"), static_cast<int>(scheme_)));
  const Eigen::Index n = d_n_.size();
  d_n_ = state.vector("solid.d_n", n);
  v_n_ = state.vector("solid.v_n", n);
  a_n_ = state.vector("solid.a_n", n);
  f_n_ = state.vector("solid.f_n", n);
  d_nm1_ = state.vector("solid.d_nm1", n);
  v_nm1_ = state.vector("solid.v_nm1", n);
  accepted_steps_ = static_cast<int>(state.integer("solid.accepted_steps"));
  // Checkpoints written before dt_n was saved: one step per window, the scene's time.dt.
  dt_n_ = state.has("solid.dt_n") ? state.real("solid.dt_n") : setup_.dt;
  contact_stats_ = {};
  if (system_->contact()) contact_stats_.load(state, mesh_.dim);
  d_ = d_n_, v_ = v_n_, a_ = a_n_, f_ = f_n_;
  solved_ = false;
}

std::vector<std::string> FemSolid::write_output(const StepInfo& info) {
  if (!series_ || info.step % output_every_ != 0) return {};
  VtkGrid grid;
  grid.points = mesh_.nodes;
  const int nn = mesh_.num_nodes(), nc = mesh_.num_cells(), dim = mesh_.dim;
  grid.point_data["displacement"] =
      Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(d_n_.data(), nn, dim);
  grid.point_data["velocity"] =
      Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(v_n_.data(), nn, dim);
  for (int c = 0; c < nc; ++c) {
    auto cell = mesh_.cells[c];
    if (mesh_.cell == CellKind::Tet10) std::swap(cell[8], cell[9]);  // VTK: the midpoints of 1-3, then 2-3
    grid.cells.push_back(std::move(cell));
    grid.cell_types.push_back(mesh_.cell == CellKind::Quad4  ? VtkCellType::Quad
                              : mesh_.cell == CellKind::Hex8 ? VtkCellType::Hexahedron
                                                             : VtkCellType::QuadraticTetra);
  }
  if (dim == 3) {  // Cauchy stress at the centre: the full 3x3 tensor (row major) and von Mises
    Eigen::MatrixXd tensor(nc, 9);
    Eigen::VectorXd mises(nc);
    for (int c = 0; c < nc; ++c) {
      const Eigen::Matrix3d F = with_shape(mesh_.cell, [&](auto shape) -> Eigen::Matrix3d {
        using Shape = decltype(shape);
        if constexpr (Shape::dim == 3)
          return deformation_gradient<Shape>(system_->cell_coordinates<Shape>(c), system_->cell_values<Shape>(c, d_n_),
                                             Shape::centre());
        else
          return Eigen::Matrix3d::Constant(NAN);
      });
      const Kinematics3 k = Kinematics3::from_deformation_gradient(F);
      Eigen::Matrix3d sigma = Eigen::Matrix3d::Constant(NAN);
      if (k.J > 0) sigma = from_voigt<3>(cauchy_stress<3>(k, system_->material3().stress(k)));
      tensor.row(c) = Eigen::Map<const Eigen::Matrix<double, 1, 9>>(Eigen::Matrix3d(sigma.transpose()).data());
      const Eigen::Matrix3d dev = sigma - sigma.trace() / 3.0 * Eigen::Matrix3d::Identity();
      mises(c) = std::sqrt(1.5 * (dev.array() * dev.array()).sum());
    }
    grid.cell_data["cauchy_stress"] = tensor;
    grid.cell_data["von_mises_stress"] = mises;
    return {series_->write(info.time, info.step, grid).string()};
  }
  Eigen::MatrixXd stress(nc, 3);
  for (int c = 0; c < nc; ++c) {
    const Matrix2 F = q4_deformation_gradient(system_->cell_coordinates(c), system_->cell_values(c, d_n_), 0, 0);
    const Kinematics k = Kinematics::from_deformation_gradient(F);
    stress.row(c) = k.J > 0 ? Eigen::RowVector3d(cauchy_stress(k, system_->material().stress(k)).transpose())
                            : Eigen::RowVector3d::Constant(NAN);
  }
  grid.cell_data["cauchy_stress"] = plane_stress_tensor(stress);  // 3x3, in-plane components (zz = 0)
  grid.cell_data["von_mises_stress"] = von_mises(stress);
  return {series_->write(info.time, info.step, grid).string()};
}

}  // namespace fsi::solid
