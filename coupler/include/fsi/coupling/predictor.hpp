#pragma once
// Force predictors: F^(1)_{n+1}, the first iterate of a step, extrapolated from the accepted
// interface forces F_n, F_{n-1}, ... (equal steps) by the polynomial of the scheme's degree
// through the last degree + 1 of them (Lagrange; Kratos' and CoCoNuT's predictors):
//   previous   F_n (the paper)
//   linear     2 F_n - F_{n-1}
//   quadratic  3 F_n - 3 F_{n-1} + F_{n-2}
//   cubic      4 F_n - 6 F_{n-1} + 4 F_{n-2} - F_{n-3}
// With fewer accepted forces than the degree needs (the first steps, a fork from a run that
// kept fewer), the highest degree the history allows. A new predictor is one line in the
// registry (predictor.cpp).
#include <Eigen/Core>
#include <string>
#include <vector>

namespace fsi::coupling {

struct PredictorScheme {
  std::string name, phrase;
  int degree = 0;  // of the extrapolating polynomial: it uses degree + 1 accepted forces
};
// Every predictor, in the order messages list them.
const std::vector<PredictorScheme>& predictor_schemes();
// The predictor of that name (throws std::invalid_argument for an unknown one).
const PredictorScheme& predictor_scheme(const std::string& name);
// F^(1) from the accepted forces, newest first (history[0] = F_n; not empty).
Eigen::VectorXd predict_force(const PredictorScheme& scheme, const std::vector<Eigen::VectorXd>& history);

}  // namespace fsi::coupling
