#pragma once
// Meshes a gmsh .geo at run time (the fluid's and the solid's `mesh.geo`), once per parameter
// set: the .msh is cached under a name derived from the .geo text, the parameters, the order and
// the dimension, so every later run (and every rank or study job) reads the same file.
//   auto msh = fsi::mesh_geo("meshes/flag.geo", {{"h", 0.01}}, fsi::default_mesh_cache(), 2, 3);
#include <filesystem>
#include <map>
#include <string>

namespace fsi {

// $FSI_MESH_CACHE, else $XDG_CACHE_HOME/fsi/meshes, else ~/.cache/fsi/meshes, else a folder in
// the temporary directory.
std::filesystem::path default_mesh_cache();

// Runs `gmsh -<dimension>` on `geo` with `-setnumber name value` for every parameter and
// `-order <order>` (2: 6-node triangles, 10-node tetrahedra, midpoints on the geometry, so
// curved boundaries are curved), MSH 2.2, into `cache_dir` (made if missing); returns the .msh.
// A failing gmsh is a std::runtime_error with the command and gmsh's log. `who` names the
// logger of the "meshing ..." line.
std::filesystem::path mesh_geo(const std::filesystem::path& geo, const std::map<std::string, double>& parameters,
                               const std::filesystem::path& cache_dir, int order = 1, int dimension = 2,
                               const std::string& who = "fluid");

}  // namespace fsi
