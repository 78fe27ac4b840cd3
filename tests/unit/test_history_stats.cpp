// fsi run's final values (fsi/common/history_stats.hpp) on histories with known answers.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>

#include "fsi/common/history_stats.hpp"

namespace {

struct History {
  std::vector<double> t, y;
};

History sampled(double t_end, double dt, const std::function<double(double)>& f) {
  History h;
  const int n = static_cast<int>(std::llround(t_end / dt));
  for (int i = 0; i <= n; ++i) h.t.push_back(i * dt), h.y.push_back(f(i * dt));
  return h;
}

TEST(HistoryStats, PeriodicSineGivesItsMeanAmplitudeAndFrequency) {
  // 2 + 0.5 sin(2 pi 3 t) over 10 s: the last 4 whole periods of the second half.
  const auto h = sampled(10.0, 1e-3, [](double t) { return 2.0 + 0.5 * std::sin(2 * M_PI * 3.0 * t); });
  const auto s = fsi::history_stats(h.t, h.y);
  ASSERT_EQ(s.kind, fsi::HistoryStats::Kind::Periodic);
  EXPECT_EQ(s.periods, 4);
  EXPECT_NEAR(s.mean, 2.0, 1e-6);
  EXPECT_NEAR(s.amplitude, 0.5, 1e-5);  // the largest sample is within (2 pi 3 dt)^2 / 2 of the peak
  EXPECT_NEAR(s.frequency, 3.0, 1e-6);
  EXPECT_NEAR(s.t1 - s.t0, 4.0 / 3.0, 1e-6);
  EXPECT_NEAR(s.amplitude_change, 0.0, 1e-4);
  EXPECT_NEAR(s.final_value, h.y.back(), 0.0);
  const auto j = fsi::to_json(s);
  EXPECT_EQ(j["kind"], "periodic");
  EXPECT_EQ(j["periods"], 4);
}

TEST(HistoryStats, MeanIsTheTimeAverageNotTheMidrange) {
  // A skewed periodic signal: sin + 0.3 sin(2 w t) has midrange != mean (= 1 exactly).
  const double w = 2 * M_PI * 2.0;
  const auto h = sampled(8.0, 5e-4, [&](double t) { return 1.0 + std::sin(w * t) + 0.3 * std::cos(2 * w * t); });
  const auto s = fsi::history_stats(h.t, h.y);
  ASSERT_EQ(s.kind, fsi::HistoryStats::Kind::Periodic);
  EXPECT_NEAR(s.mean, 1.0, 1e-5);
  EXPECT_NEAR(s.frequency, 2.0, 1e-5);
}

TEST(HistoryStats, GrowingOscillationIsFlagged) {
  const auto h = sampled(10.0, 1e-3, [](double t) { return std::exp(0.1 * t) * std::sin(2 * M_PI * 2.0 * t); });
  const auto s = fsi::history_stats(h.t, h.y);
  ASSERT_EQ(s.kind, fsi::HistoryStats::Kind::Periodic);
  // 4 periods of 0.5 s: the last period's amplitude / the first's = exp(0.1 * 1.5)
  EXPECT_NEAR(s.amplitude_change, std::exp(0.15) - 1.0, 5e-3);
  EXPECT_NE(fsi::describe(s).find("not settled"), std::string::npos) << fsi::describe(s);
}

TEST(HistoryStats, SettledExponentialIsSteady) {
  const auto h = sampled(20.0, 0.01, [](double t) { return 0.1282 * (1 - std::exp(-t)); });
  const auto s = fsi::history_stats(h.t, h.y);
  EXPECT_EQ(s.kind, fsi::HistoryStats::Kind::Steady);
  EXPECT_NEAR(s.final_value, 0.1282, 1e-9);
  EXPECT_EQ(fsi::to_json(s)["kind"], "steady");
}

TEST(HistoryStats, ConstantAndZeroColumnsAreSteady) {
  const auto zero = sampled(1.0, 0.1, [](double) { return 0.0; });
  EXPECT_EQ(fsi::history_stats(zero.t, zero.y).kind, fsi::HistoryStats::Kind::Steady);
  const auto one = sampled(0.0, 0.1, [](double) { return 3.0; });  // a single row
  const auto s = fsi::history_stats(one.t, one.y);
  EXPECT_EQ(s.kind, fsi::HistoryStats::Kind::Steady);
  EXPECT_EQ(s.final_value, 3.0);
}

TEST(HistoryStats, FewerThanThreePeriodsAreNotPeriodic) {
  // 0.2 s of a 5.46 Hz oscillation (FSI3's u_y): the second half holds no whole period;
  // 1 s: 2 whole periods in the second half. Neither gets a mean / amplitude / frequency.
  for (const double t_end : {0.2, 1.0}) {
    const auto h = sampled(t_end, 1e-3, [](double t) { return 0.035 * std::sin(2 * M_PI * 5.46 * t); });
    const auto s = fsi::history_stats(h.t, h.y);
    EXPECT_EQ(s.kind, fsi::HistoryStats::Kind::Changing) << t_end;
    EXPECT_LT(s.periods, 3) << t_end;
    EXPECT_EQ(fsi::to_json(s).count("frequency"), 0u);
  }
  const auto h = sampled(1.0, 1e-3, [](double t) { return 0.035 * std::sin(2 * M_PI * 5.46 * t); });
  const auto s = fsi::history_stats(h.t, h.y);
  EXPECT_EQ(s.periods, 2);
  EXPECT_NE(fsi::describe(s).find("fewer than 3"), std::string::npos) << fsi::describe(s);
}

TEST(HistoryStats, CrossingsWithHysteresisIgnoreRipple) {
  // A sine with a small fast ripple crosses its mean several times per period without
  // hysteresis, once per period with it.
  const auto h = sampled(3.5, 1e-4, [](double t) {  // crossings at t = 1, 2, 3
    return std::sin(2 * M_PI * t) + 0.05 * std::sin(2 * M_PI * 40 * t);
  });
  EXPECT_GT(fsi::upward_crossings(h.t, h.y, 0.0, 0.0).size(), 3u);
  EXPECT_EQ(fsi::upward_crossings(h.t, h.y, 0.0, 0.2).size(), 3u);
}

TEST(HistoryStats, ReadsACsvTableAndStopsAtACutRow) {
  const auto dir = std::filesystem::temp_directory_path() / "fsi_history_stats_test";
  std::filesystem::create_directories(dir);
  {
    std::ofstream f(dir / "probes.csv");
    f << "time,a,b\n0.1,1,2\n0.2,3,nan\n0.3,5";  // the last row cut by a crash
  }
  const auto table = fsi::read_csv_table(dir / "probes.csv");
  ASSERT_EQ(table.names, (std::vector<std::string>{"time", "a", "b"}));
  ASSERT_EQ(table.column("a")->size(), 2u);
  EXPECT_EQ((*table.column("a"))[1], 3.0);
  EXPECT_TRUE(std::isnan((*table.column("b"))[1]));
  EXPECT_EQ(table.column("c"), nullptr);
  std::filesystem::remove_all(dir);
}

}  // namespace
