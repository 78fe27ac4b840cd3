#include "fsi/coupling/predictor.hpp"

#include <algorithm>
#include <stdexcept>

namespace fsi::coupling {

const std::vector<PredictorScheme>& predictor_schemes() {
  static const std::vector<PredictorScheme> schemes{
      {"previous", "the paper: F_n", 0},
      {"linear", "2 F_n - F_{n-1}", 1},
      {"quadratic", "3 F_n - 3 F_{n-1} + F_{n-2}", 2},
      {"cubic", "4 F_n - 6 F_{n-1} + 4 F_{n-2} - F_{n-3}", 3},
  };
  return schemes;
}

const PredictorScheme& predictor_scheme(const std::string& name) {
  for (const auto& s : predictor_schemes())
    if (s.name == name) return s;
  throw std::invalid_argument("unknown coupling.predictor '" + name + "'");
}

Eigen::VectorXd predict_force(const PredictorScheme& scheme, const std::vector<Eigen::VectorXd>& history) {
  if (history.empty()) throw std::invalid_argument("predict_force: no accepted force");
  const int degree = std::min(scheme.degree, static_cast<int>(history.size()) - 1);
  // The polynomial of degree p through F_{n-p} .. F_n, at the next step:
  //   F_{n+1} = sum_j (-1)^j binom(p + 1, j + 1) F_{n-j}.
  Eigen::VectorXd f = history[0];
  double binom = degree + 1;  // binom(p + 1, j + 1) for j = 0
  if (degree > 0) f = binom * history[0];
  for (int j = 1; j <= degree; ++j) {
    binom = binom * (degree + 1 - j) / (j + 1);
    f += (j % 2 == 0 ? binom : -binom) * history[j];
  }
  return f;
}

}  // namespace fsi::coupling
