// The keys of the point models' interface (solid.model: sdof and fluid.model: surrogate share
// them), declared once beside their reader (model_interface.cpp).
#include "fsi/common/model_interface.hpp"

namespace fsi {

std::vector<schema::Key> model_interface_keys() {
  using namespace schema;
  return {
      integer("dimension", "2 or 3: the space of the interface (3 values per node in 3D)").def("2").ge(2).le(3),
      section("surface",
              "3D only: the interface is a rigid flat plate parallel to the plane z = 0, instead of a point; "
              "its area is the interface measure",
              {vector2("size", "edge lengths [a, b] along x and y").req().in_unit("m"),
               vector("centre", "the plate's centre [x, y, z]").def("[0, 0, 0]").in_unit("m"),
               int_list("divisions", 2, "[n_x, n_y] cells").def("[1, 1]"),
               choice("faces", {"quad", "triangle"}, "cells as quadrilaterals or as two triangles each").def("quad")}),
  };
}

}  // namespace fsi
