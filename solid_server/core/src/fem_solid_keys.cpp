// The keys of `solid.model: fem`, declared once beside their reader (fem_solid.cpp).
#include "fsi/common/scene_schema.hpp"
#include "fsi/solid/fem_solid.hpp"

namespace fsi::solid {

const std::vector<schema::Key>& fem_solid_keys() {
  using namespace schema;
  static const std::vector<Key> keys = {
      section("mesh", "the solid mesh",
              {
                  choice("type", {"rectangle", "box", "tube", "gmsh"},
                         "built-in structured Q4 rectangle (2D), Hex8 box or tube (3D), or a gmsh .msh file (2D "
                         "quadrilaterals; 3D "
                         "10-node tetrahedra or hexahedra)")
                      .req(),
                  vector("origin", "lower-left (back) corner; tube: the start of its axis (the axis is along +z)")
                      .req()
                      .only_when("type", {"rectangle", "box", "tube"})
                      .in_unit("m"),
                  vector("size", "lx, ly (, lz) (positive)").req().only_when("type", {"rectangle", "box"}).in_unit("m"),
                  int_list("elements", 2, "nx, ny Q4 cells (>= 1); edge sets left, right, bottom, top")
                      .req()
                      .only_when("type", {"rectangle"}),
                  int_list("divisions", 3,
                           "box: nx, ny, nz Hex8 cells (>= 1); face sets left, right (x), bottom, top (y), back, front "
                           "(z). tube: n_theta (>= 3) around, n_r through the wall, n_z along; face sets inner, outer, "
                           "start (z = origin), end")
                      .req()
                      .only_when("type", {"box", "tube"}),
                  number("inner_radius", "tube: inner radius").req().gt(0).only_when("type", {"tube"}).in_unit("m"),
                  number("outer_radius", "tube: outer radius (> inner)")
                      .req()
                      .gt(0)
                      .only_when("type", {"tube"})
                      .in_unit("m"),
                  number("length", "tube: length along +z").req().gt(0).only_when("type", {"tube"}).in_unit("m"),
                  text("file", "gmsh .msh, relative to the scene file").group("source").only_when("type", {"gmsh"}),
                  text("geo", "gmsh .geo, meshed at the start (gmsh -3) once per parameter set into the mesh cache")
                      .group("source")
                      .only_when("type", {"gmsh"}),
                  named_map("parameters", "gmsh -setnumber values of the .geo, name: number (e.g. h: 0.005)",
                            number("<name>", "value"))
                      .only_when("geo"),
                  integer("order",
                          "gmsh -order: 2 for 10-node tetrahedra, 1 for hexahedra and 2D quadrilaterals (with "
                          "Recombine in the .geo)")
                      .def("2")
                      .ge(1)
                      .le(2)
                      .only_when("geo"),
                  text("cache_dir", "mesh cache; default $FSI_MESH_CACHE, else ~/.cache/fsi/meshes").only_when("geo"),
                  text("domain",
                       "physical group of the solid cells (2D: quadrilaterals; 3D: 10-node tetrahedra or 8-node "
                       "hexahedra); default: every group of the mesh's dimension")
                      .only_when("type", {"gmsh"}),
              })
          .req(),
      section("material", "hyperelastic material (plane strain in 2D); exactly one of youngs_modulus, shear_modulus",
              {
                  choice("law", {"saint_venant_kirchhoff", "svk", "neo_hookean"}, "material law").req(),
                  number("poisson_ratio", "nu").req().gt(-1).lt(0.5),
                  number("youngs_modulus", "E").gt(0).group("modulus").in_unit("Pa"),
                  number("shear_modulus", "mu").gt(0).group("modulus").in_unit("Pa"),
              })
          .req(),
      choice("element", {"q4", "q4_eas", "hex8", "h8_eas", "tet10"},
             "2D: bilinear Q4, or Q4 with enhanced assumed strains (no shear locking in bending; same nodes); "
             "3D hexahedra: trilinear Hex8, or Hex8 with 9 enhanced strain modes; 3D tetrahedra (gmsh): the "
             "quadratic Tet10")
          .def_computed("q4 (2D), hex8 (hexahedra), tet10 (tetrahedra)"),
      number("density", "rho_s, reference configuration").req().gt(0).in_unit("kg/m^3"),
      vector("gravity", "body force per unit mass").def_computed("0 (every component)").in_unit("m/s^2"),
      choice("analysis", {"static", "dynamic"}, "equilibrium every step, or dynamics").def("dynamic"),
      choice("time_scheme", {"bdf1", "bdf2", "newmark"},
             "dynamic analysis: BDF1 (the paper), BDF2 or Newmark "
             "(trapezoidal)")
          .def("newmark"),
      integer("load_steps", "load increments per step").def("1").ge(1),
      section("newton", "Newton iterations",
              {
                  integer("max_iterations", "per load step / time step").def("25").ge(1),
                  number("residual_tolerance", "|R| <= tol * max(|R_0|, |F_ext|)").def("1e-08").gt(0),
                  number("increment_tolerance", "or |du| <= tol * |u|").def("1e-10").ge(0),
              }),
      choice("linear_solver", {"cholmod", "umfpack"}, "sparse solver of the tangent").def("cholmod"),
      names("clamp", "facet set(s) (edges in 2D, faces in 3D) with u = 0").def("none"),
      section_list("supports", "facet sets with some displacement components held at 0",
                   {
                       names("boundary", "facet set(s)").req(),
                       names("fixed", "the components held: x, y (, z)").req(),
                   })
          .def("[]"),
      names("interface", "facet set(s) on the fluid side (edges in 2D, faces in 3D; coupling, Algorithm 2 damping)")
          .def("none"),
      section_list("tractions", "dead edge loads",
                   {
                       names("boundary", "facet set(s)").req(),
                       vector("traction", "force per reference length (2D) or area (3D)").req().in_unit("N/m"),
                   })
          .def("[]"),
      section_list("pressures", "dead pressures: p times the outward normal of the reference configuration, inwards",
                   {
                       names("boundary", "facet set(s)").req(),
                       number("pressure", "p (> 0 pushes into the solid)").req().in_unit("Pa"),
                   })
          .def("[]"),
      section_list("point_loads", "dead loads at the node nearest to a point",
                   {
                       vector("point", "where").req().in_unit("m"),
                       vector("force", "the load").req().in_unit("N"),
                   })
          .def("[]"),
      section_list(
          "obstacles",
          "rigid obstacles (half-planes in 2D, half-spaces in 3D): the boundary keeps a layer of about contact_gap "
          "from each (a smooth penalty, p = k_n (g_c - g)^2 / g_c below g_c). Nodes that start within contact_gap "
          "(next to a clamp on the obstacle) and clamped nodes are left out",
          {
              vector("point", "a point of the obstacle's surface").req().in_unit("m"),
              vector("normal", "the surface's normal out of the obstacle, towards the solid (any length > 0)").req(),
              number("contact_gap",
                     "g_c: the pressure acts below this gap; about one fluid cell at the wall, so the fluid keeps "
                     "a layer there (thin_beam: hl = 0.008)")
                  .req()
                  .gt(0)
                  .in_unit("m"),
              number("stiffness", "k_n: the pressure per gap below g_c (p(0) = k_n g_c)")
                  .gt(0)
                  .def_computed("E / h, h the shortest edge of the contact facets")
                  .in_unit("Pa/m"),
              names("boundary", "facet set(s) that may touch it").def_computed("every facet set of the mesh"),
          })
          .def("[]"),
      section_list(
          "elastic_supports",
          "elastic supports (a foundation) on boundary facets: the traction -k_s (u . n) n (or -k_s u), n the "
          "outward normal; the tissue around a vessel, or the hoop stiffness a plane-strain tube wall lacks",
          {
              names("boundary", "facet set(s) supported").req(),
              number("stiffness", "k_s: traction per displacement (a 2D stand-in for a tube's wall: E h / (2 R^2))")
                  .req()
                  .gt(0)
                  .in_unit("Pa/m"),
              choice("direction", {"normal", "all"}, "normal: along the outward normal only; all: every component")
                  .def("normal"),
          })
          .def("[]"),
      section_list("probes", "displacement of points (probes NAME_x, NAME_y, and NAME_z in 3D)",
                   {
                       text("name", "probe name").req(),
                       vector("point", "a point inside the mesh").req().in_unit("m"),
                   })
          .def("[]"),
      integer("output_every", "VTK when the run writes output (time.output_every) and step % N == 0; 0 = never")
          .def("1")
          .ge(0)
          .in_unit("steps"),
  };
  return keys;
}

}  // namespace fsi::solid
