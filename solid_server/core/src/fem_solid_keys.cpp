// The keys of `solid.model: fem`, declared once beside their reader (fem_solid.cpp).
#include "fsi/common/scene_schema.hpp"
#include "fsi/solid/fem_solid.hpp"

namespace fsi::solid {

const std::vector<schema::Key>& fem_solid_keys() {
  using namespace schema;
  static const std::vector<Key> keys = {
      section(
          "mesh", "the solid mesh",
          {
              choice("type", {"rectangle", "gmsh"}, "built-in structured Q4 rectangle, or a gmsh .msh file").req(),
              vector2("origin", "lower-left corner").req().only_when("type", {"rectangle"}).in_unit("m"),
              vector2("size", "lx, ly (positive)").req().only_when("type", {"rectangle"}).in_unit("m"),
              int_list("elements", 2, "nx, ny Q4 cells (>= 1); edge sets left, right, bottom, top")
                  .req()
                  .only_when("type", {"rectangle"}),
              text("file", "gmsh mesh, relative to the scene file").req().only_when("type", {"gmsh"}),
              text("domain", "2D physical group of the solid; default: every quad group").only_when("type", {"gmsh"}),
          })
          .req(),
      section("material", "hyperelastic material (plane strain); exactly one of youngs_modulus, shear_modulus",
              {
                  choice("law", {"saint_venant_kirchhoff", "svk", "neo_hookean"}, "material law").req(),
                  number("poisson_ratio", "nu").req().gt(-1).lt(0.5),
                  number("youngs_modulus", "E").gt(0).group("modulus").in_unit("Pa"),
                  number("shear_modulus", "mu").gt(0).group("modulus").in_unit("Pa"),
              })
          .req(),
      choice("element", {"q4", "q4_eas"},
             "bilinear Q4, or Q4 with enhanced assumed strains (no shear locking in bending; same nodes)")
          .def("q4"),
      number("density", "rho_s, reference configuration").req().gt(0).in_unit("kg/m^3"),
      vector2("gravity", "body force per unit mass").def("[0, 0]").in_unit("m/s^2"),
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
      names("clamp", "edge set(s) with u = 0").def("none"),
      names("interface", "edge set(s) on the fluid side (coupling, Algorithm 2 damping)").def("none"),
      section_list("tractions", "dead edge loads",
                   {
                       names("boundary", "edge set(s)").req(),
                       vector2("traction", "force per reference length").req().in_unit("N/m"),
                   })
          .def("[]"),
      section_list("point_loads", "dead loads at the node nearest to a point",
                   {
                       vector2("point", "where").req().in_unit("m"),
                       vector2("force", "the load").req().in_unit("N"),
                   })
          .def("[]"),
      section_list("probes", "displacement of points (probes NAME_x, NAME_y)",
                   {
                       text("name", "probe name").req(),
                       vector2("point", "a point inside the mesh").req().in_unit("m"),
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
