// The accelerator schemes and force predictors on problems with known answers: linear
// interface problems x = A x + b (quasi-Newton is a Krylov method on them: at most n + 1
// updates), a sequence of such steps with one A (IQN-IMVJ carries the Jacobian over), the
// filters, checkpoints of every scheme's state, and the predictors on polynomial histories.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cstring>
#include <random>

#include "fsi/common/scene_schema.hpp"
#include "fsi/common/state.hpp"
#include "fsi/coupling/acceleration.hpp"
#include "fsi/coupling/predictor.hpp"

namespace {

using fsi::coupling::Accelerator;
using fsi::coupling::CouplingSettings;
using fsi::coupling::ImvjRestart;
using fsi::coupling::Preconditioner;
using fsi::coupling::QrFilter;

// A random contraction (spectral norm 0.9): the plain iteration x <- A x + b converges, slowly.
Eigen::MatrixXd random_contraction(int n, unsigned seed) {
  std::mt19937 gen(seed);
  std::normal_distribution<double> normal;
  Eigen::MatrixXd a(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) a(i, j) = normal(gen);
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(a);
  return 0.9 * a / svd.singularValues()(0);
}

// Updates F^(k+1) = acc(F^(k), r_k) of one step from x = 0 until |r| < 1e-10 |x*|: their
// number, or -1 after `max`.
int updates_to_converge(Accelerator& acc, const Eigen::MatrixXd& a, const Eigen::VectorXd& b, Eigen::VectorXd& x,
                        int max = 60) {
  const Eigen::Index n = b.size();
  const Eigen::VectorXd exact = (Eigen::MatrixXd::Identity(n, n) - a).lu().solve(b);
  acc.begin_step();
  x = Eigen::VectorXd::Zero(n);
  for (int k = 0; k <= max; ++k) {
    const Eigen::VectorXd r = a * x + b - x;
    if (r.norm() < 1e-10 * exact.norm()) {
      acc.end_step();
      return k;
    }
    x = acc.update(x, r);
  }
  return -1;
}

CouplingSettings quasi_newton(const std::string& scheme, QrFilter filter = QrFilter::Qr2,
                              Preconditioner pre = Preconditioner::None) {
  CouplingSettings s;
  s.acceleration = scheme;
  s.beta = 0.5;
  s.reuse_steps = 0;
  s.iqn_filter_type = filter;
  // qr1 tests |R_ii| against ||R||_F, which the first (largest) columns dominate: its limit
  // is an absolute-like one, orders below qr2's relative 1e-3.
  if (filter == QrFilter::Qr1) s.iqn_filter = 1e-8;
  s.iqn_preconditioner = pre;
  return s;
}

struct Variant {
  std::string scheme;
  QrFilter filter;
  Preconditioner pre;
};

class LinearProblem : public ::testing::TestWithParam<Variant> {};

TEST_P(LinearProblem, ConvergesInAtMostNPlusOneUpdates) {
  const Variant v = GetParam();
  const int n = 10;
  for (unsigned seed : {1u, 2u, 3u}) {
    const Eigen::MatrixXd a = random_contraction(n, seed);
    const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(n, 1.0, -2.0);
    auto acc = fsi::coupling::make_accelerator(quasi_newton(v.scheme, v.filter, v.pre));
    Eigen::VectorXd x;
    const int updates = updates_to_converge(*acc, a, b, x);
    EXPECT_GE(updates, 2) << "seed " << seed;
    EXPECT_LE(updates, n + 1) << "seed " << seed;
    // ... where the plain iteration with the same first relaxation needs far more.
    CouplingSettings plain;
    plain.beta = 1.0;
    auto constant = fsi::coupling::make_accelerator(plain);
    EXPECT_GT(updates_to_converge(*constant, a, b, x, 200), 2 * n) << "seed " << seed;
  }
}

INSTANTIATE_TEST_SUITE_P(Schemes, LinearProblem,
                         ::testing::Values(Variant{"iqn-ils", QrFilter::Qr2, Preconditioner::None},
                                           Variant{"iqn-ils", QrFilter::Qr1, Preconditioner::None},
                                           Variant{"iqn-ils", QrFilter::Qr3, Preconditioner::ResidualSum},
                                           Variant{"iqn-imvj", QrFilter::Qr2, Preconditioner::None},
                                           Variant{"iqn-imvj", QrFilter::Qr1, Preconditioner::None},
                                           Variant{"iqn-imvj", QrFilter::Qr3, Preconditioner::ResidualSum}),
                         [](const auto& info) {
                           std::string name = info.param.scheme + "_qr" +
                                              std::to_string(static_cast<int>(info.param.filter) + 1) +
                                              (info.param.pre == Preconditioner::ResidualSum ? "_residual_sum" : "");
                           std::replace(name.begin(), name.end(), '-', '_');
                           return name;
                         });

// Steps with one A and a new b each: the iterations per step, IQN-IMVJ in a given mode.
std::vector<int> step_updates(CouplingSettings s, int steps, int n = 10) {
  const Eigen::MatrixXd a = random_contraction(n, 7);
  auto acc = fsi::coupling::make_accelerator(s);
  std::vector<int> out;
  Eigen::VectorXd x;
  for (int step = 0; step < steps; ++step)
    out.push_back(updates_to_converge(*acc, a, Eigen::VectorXd::LinSpaced(n, 1.0 + step, -1.0 + 0.3 * step), x));
  return out;
}

TEST(IqnImvj, WithoutRestartLaterStepsConvergeFasterWithTheJacobianCarriedOver) {
  const auto imvj = step_updates(quasi_newton("iqn-imvj"), 5);
  const auto ils = step_updates(quasi_newton("iqn-ils"), 5);  // no reuse: every step starts afresh
  ASSERT_GE(imvj[0], 5);                                      // n + 1 = 11 here
  for (int step = 1; step < 5; ++step) {
    EXPECT_LT(imvj[step], imvj[0]) << "step " << step;
    EXPECT_LE(imvj[step], 2) << "step " << step;          // J exact after the first step: one update (1 here)
    EXPECT_GE(ils[step], ils[0] - 1) << "step " << step;  // IQN-ILS without reuse: n + 1 every step
  }
}

TEST(IqnImvj, RestartModesKeepOrDropWhatTheyShould) {
  auto s = quasi_newton("iqn-imvj");
  s.imvj_chunk_size = 2;
  s.imvj_restart = ImvjRestart::Svd;
  s.imvj_truncation = 1e-12;  // the SVD keeps all of J: as good as no restart
  for (int k : step_updates(s, 6)) EXPECT_GE(k, 1);
  const auto svd = step_updates(s, 6);
  for (int step = 1; step < 6; ++step) EXPECT_LE(svd[step], 3) << "rs-svd step " << step;
  s.imvj_restart = ImvjRestart::LeastSquares;
  s.imvj_restart_reuse_steps = 2;
  const auto ls = step_updates(s, 6);
  for (int step = 1; step < 6; ++step) EXPECT_LE(ls[step], 3) << "rs-ls step " << step;
  s.imvj_restart = ImvjRestart::Zero;
  s.imvj_chunk_size = 1;  // J dropped after every step: each step like the first
  const auto zero = step_updates(s, 4);
  for (int step = 1; step < 4; ++step) EXPECT_GE(zero[step], zero[0] - 2) << "rs-0 step " << step;
}

TEST(IqnIls, ReuseAlsoCarriesTheSecantPairsOver) {
  auto s = quasi_newton("iqn-ils");
  s.reuse_steps = 2;
  const auto reuse = step_updates(s, 4);
  for (int step = 1; step < 4; ++step) EXPECT_LE(reuse[step], 2) << "step " << step;
}

TEST(QuasiNewtonFilters, Qr3GivesQr2sUpdates) {
  // Dependent columns: reused steps of one A give nearly parallel pairs, which qr2 drops; qr3
  // must find the same columns by updating and falling back. (Unconverged steps: pairs of a
  // converged iteration are round-off, which no filter relative to a column's own norm drops.)
  for (const char* scheme : {"iqn-ils", "iqn-imvj"}) {
    auto s2 = quasi_newton(scheme, QrFilter::Qr2), s3 = quasi_newton(scheme, QrFilter::Qr3);
    s2.reuse_steps = s3.reuse_steps = 3;
    s2.iqn_filter = s3.iqn_filter = 0.05;
    const int n = 24;
    const Eigen::MatrixXd a = random_contraction(n, 11);
    auto a2 = fsi::coupling::make_accelerator(s2), a3 = fsi::coupling::make_accelerator(s3);
    int dropped = 0;
    for (int step = 0; step < 5; ++step) {
      const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(n, 1.0 + step, 2.0);
      Eigen::VectorXd x2 = Eigen::VectorXd::Zero(n), x3 = x2;
      a2->begin_step();
      a3->begin_step();
      for (int k = 0; k < 6; ++k) {
        x2 = a2->update(x2, a * x2 + b - x2);
        x3 = a3->update(x3, a * x3 + b - x3);
        EXPECT_EQ(a2->last_columns(), a3->last_columns()) << scheme << " step " << step << " k " << k;
        dropped += std::min(step, 3) * 5 + k - a2->last_columns();
        EXPECT_LT((x2 - x3).norm(), 1e-9 * (1 + x2.norm())) << scheme << " step " << step << " k " << k;
      }
      a2->end_step();
      a3->end_step();
    }
    EXPECT_GT(dropped, 0) << scheme << ": the filter dropped no column; the test tests nothing";
  }
}

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

TEST(Accelerator, EverySchemesSavedStateGivesIdenticalUpdates) {
  std::vector<CouplingSettings> all;
  for (const auto& scheme : fsi::coupling::accelerator_schemes()) all.push_back(quasi_newton(scheme.name));
  for (ImvjRestart mode : {ImvjRestart::Zero, ImvjRestart::LeastSquares, ImvjRestart::Svd}) {
    auto s = quasi_newton("iqn-imvj", QrFilter::Qr3, Preconditioner::ResidualSum);
    s.imvj_restart = mode;
    s.imvj_chunk_size = 3;
    all.push_back(s);
  }
  auto ils = quasi_newton("iqn-ils", QrFilter::Qr1, Preconditioner::ResidualSum);
  ils.reuse_steps = 3;
  all.push_back(ils);
  const Eigen::MatrixXd a = random_contraction(6, 5);
  for (const auto& s : all) {
    auto one = fsi::coupling::make_accelerator(s), two = fsi::coupling::make_accelerator(s);
    auto run_step = [&](Accelerator& acc, Eigen::VectorXd& x, int step) {
      acc.begin_step();
      const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(6, 1.0 + 0.1 * step, -1.0);
      for (int k = 0; k < 5; ++k) x = acc.update(x, a * x + b - x);
      acc.end_step();
    };
    Eigen::VectorXd x1 = Eigen::VectorXd::Zero(6);
    for (int step = 1; step <= 5; ++step) run_step(*one, x1, step);
    fsi::StateArchive state;
    one->save(state, "acc.");
    two->load(fsi::StateArchive::parse(state.serialize(), "test"), "acc.");
    Eigen::VectorXd x2 = x1;
    for (int step = 6; step <= 12; ++step) {
      run_step(*one, x1, step);
      run_step(*two, x2, step);
      for (int i = 0; i < 6; ++i) ASSERT_TRUE(same_bits(x1[i], x2[i])) << s.acceleration << " step " << step;
    }
  }
}

TEST(Accelerator, AnotherSchemesCheckpointStartsAfresh) {
  // A fork from an IQN-ILS run into IQN-IMVJ: the secant pairs are not taken for a Jacobian.
  auto ils_settings = quasi_newton("iqn-ils");
  ils_settings.reuse_steps = 4;
  auto ils = fsi::coupling::make_accelerator(ils_settings);
  const Eigen::MatrixXd a = random_contraction(5, 3);
  Eigen::VectorXd x;
  updates_to_converge(*ils, a, Eigen::VectorXd::Ones(5), x);
  fsi::StateArchive state;
  ils->save(state, "acc.");
  auto imvj_settings = quasi_newton("iqn-imvj");
  imvj_settings.reuse_steps = 4;
  auto imvj = fsi::coupling::make_accelerator(imvj_settings), fresh = fsi::coupling::make_accelerator(imvj_settings);
  imvj->load(state, "acc.");
  Eigen::VectorXd x1, x2;
  EXPECT_EQ(updates_to_converge(*imvj, a, Eigen::VectorXd::Ones(5), x1),
            updates_to_converge(*fresh, a, Eigen::VectorXd::Ones(5), x2));
}

TEST(Registry, NamesAreTheSchemasChoices) {
  const fsi::schema::Key* coupling = &fsi::coupling::coupling_section();
  auto allowed = [&](const std::string& name) {
    for (const auto& k : coupling->children)
      if (k.name == name) return k.allowed;
    return std::vector<std::string>();
  };
  std::vector<std::string> accelerations, predictors;
  for (const auto& s : fsi::coupling::accelerator_schemes()) accelerations.push_back(s.name);
  for (const auto& s : fsi::coupling::predictor_schemes()) predictors.push_back(s.name);
  EXPECT_EQ(accelerations, allowed("acceleration"));
  EXPECT_EQ(predictors, allowed("predictor"));
  EXPECT_THROW(fsi::coupling::accelerator_scheme("iqn-xyz"), std::invalid_argument);
}

// A vector-valued polynomial of degree d in t.
Eigen::VectorXd polynomial(int degree, double t) {
  Eigen::VectorXd f(3);
  for (int i = 0; i < 3; ++i) {
    double v = 0.5 + i, power = 1;
    for (int p = 1; p <= degree; ++p) v += (1.0 + 0.3 * i * p - 0.2 * p) * (power *= t);
    f(i) = v;
  }
  return f;
}

TEST(Predictor, ExactOnPolynomialHistoriesOfItsDegree) {
  const double dt = 0.1, t_n = 1.3;
  for (const auto& scheme : fsi::coupling::predictor_schemes()) {
    for (int degree = 0; degree <= 4; ++degree) {
      std::vector<Eigen::VectorXd> history;  // F_n, F_{n-1}, ...
      for (int j = 0; j < 4; ++j) history.push_back(polynomial(degree, t_n - j * dt));
      const Eigen::VectorXd exact = polynomial(degree, t_n + dt);
      const double error = (fsi::coupling::predict_force(scheme, history) - exact).norm() / exact.norm();
      if (degree <= scheme.degree)
        EXPECT_LT(error, 1e-12) << scheme.name << " on degree " << degree;
      else
        EXPECT_GT(error, 1e-6) << scheme.name << " on degree " << degree << " (not exact beyond its own)";
    }
  }
}

TEST(Predictor, UsesTheHighestDegreeTheHistoryAllows) {
  const auto& cubic = fsi::coupling::predictor_scheme(fsi::coupling::predictor_schemes().back().name);
  ASSERT_EQ(cubic.degree, 3);
  const double dt = 0.2;
  std::vector<Eigen::VectorXd> history{polynomial(1, 1.0), polynomial(1, 1.0 - dt)};
  EXPECT_LT((fsi::coupling::predict_force(cubic, history) - polynomial(1, 1.0 + dt)).norm(), 1e-12);
  history.resize(1);
  EXPECT_EQ(fsi::coupling::predict_force(cubic, history), history[0]);
}

}  // namespace
