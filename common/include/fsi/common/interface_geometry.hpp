#pragma once
// Geometry of interface meshes (InterfaceMeshData), for every dimension: the faces of a 3D
// interface (triangles and quadrilaterals, linear and quadratic, gmsh node order), their
// shape functions, quadrature, areas and closest points, and the interface mass
// M = int N^T N dgamma on segments (2D) or faces (3D). Used by the coupler (mappings,
// Algorithm 2's M_G) and by the models that describe their interface (lumped measures).
//
// Reference elements: a triangle is {xi, eta >= 0, xi + eta <= 1} with nodes (0,0), (1,0),
// (0,1), then the mid-edge nodes of edges 0-1, 1-2, 2-0; a quadrilateral is [-1, 1]^2 with
// nodes (-1,-1), (1,-1), (1,1), (-1,1), then the mid-edge nodes of edges 0-1, 1-2, 2-3, 3-0,
// then (9 nodes) the centre.
#include <Eigen/Core>
#include <vector>

#include "fsi/common/solver_model.hpp"

namespace fsi {

// Whether a face of this many nodes is a triangle (3, 6) or a quadrilateral (4, 8, 9);
// throws std::invalid_argument for any other count.
bool face_is_triangle(int nodes);

// Shape functions N (size nodes) and their derivatives dN (nodes x 2, d/dxi and d/deta) at
// (xi, eta) of the reference element.
void face_shape(int nodes, double xi, double eta, Eigen::VectorXd& N, Eigen::MatrixX2d& dN);

struct FaceQuadraturePoint {
  double xi, eta, weight;  // weights sum to the reference area (1/2 or 4)
};
// Exact for polynomials of degree 5 (triangles, 7 points) or bi-degree 5 (quadrilaterals,
// 3 x 3 Gauss): the products N_i N_j of quadratic faces on flat faces.
const std::vector<FaceQuadraturePoint>& face_quadrature(int nodes);

// x (n x 3): node positions; the face's points use the rows face.nodes.
Eigen::Vector3d face_point(const Eigen::MatrixXd& x, const InterfaceFace& face, double xi, double eta);
double face_area(const Eigen::MatrixXd& x, const InterfaceFace& face);

struct FaceProjection {
  double xi = 0, eta = 0;
  Eigen::Vector3d point = Eigen::Vector3d::Zero();  // the closest point found on the face
  double distance = 0;
};
// The point of the face closest to p: exact for linear triangles; for the other faces a
// projected Gauss-Newton iteration in the reference element (exact for flat bilinear faces,
// converged to round-off on smooth curved ones).
FaceProjection project_on_face(const Eigen::MatrixXd& x, const InterfaceFace& face, const Eigen::Vector3d& p);

// The interface's node positions in the configuration reference + displacement
// (displacement: dimension * n values, or empty = reference).
Eigen::MatrixXd interface_positions(const InterfaceMeshData& mesh, const Eigen::VectorXd& displacement);

// M = int N^T N dgamma (n x n, consistent) on the segments (2D) or faces (3D) in the
// configuration reference + displacement; diag(lumped_measure) for a point interface.
NodalMatrix nodal_interface_mass(const InterfaceMeshData& mesh, const Eigen::VectorXd& displacement);

// The measure of each node's share of the interface: the row sums of the consistent mass
// (for linear faces the usual lumped area), or lumped_measure for a point interface.
Eigen::VectorXd lumped_interface_measure(const InterfaceMeshData& mesh);

// A flat rectangular interface in 3D: centre c, edge lengths (a, b) along the unit vectors
// e1 and e2, divided into n1 x n2 quadrilaterals (or, triangles = true, each split into two
// triangles). Node ids 0..n-1, lumped_measure filled with the nodal areas.
InterfaceMeshData rectangle_surface(const Eigen::Vector3d& c, const Eigen::Vector3d& e1, const Eigen::Vector3d& e2,
                                    double a, double b, int n1, int n2, bool triangles);

}  // namespace fsi
