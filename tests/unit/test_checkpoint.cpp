// Checkpoint building blocks: the bit-exact state archive, the on-disk store (atomic,
// checksummed, pruned), scene comparison, table resumption, the --out policy and the
// accelerator's saved history.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>

#include "fsi/common/run_report.hpp"
#include "fsi/common/state.hpp"
#include "fsi/common/table_writer.hpp"
#include "fsi/coupling/acceleration.hpp"
#include "fsi/coupling/checkpoint.hpp"

namespace fs = std::filesystem;
using fsi::StateArchive;
using fsi::StateError;
using fsi::coupling::CheckpointStore;

namespace {

fs::path fresh_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("fsi_unit_checkpoint_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

}  // namespace

TEST(StateArchive, RoundTripIsBitExact) {
  Eigen::VectorXd v(6);
  v << 0.1, -0.0, std::numeric_limits<double>::denorm_min(), 1e308, std::nan("7"), -3.5;
  StateArchive s;
  s.put("v", v);
  s.put("empty", Eigen::VectorXd());
  s.put("x", 1.0 / 3.0);
  s.put("n", std::int64_t{-42});
  s.put("t", std::string("ab\0c", 4));
  Eigen::MatrixXd m(2, 3);
  m << 1, 2, 3, 4, 5, 6;
  s.put_matrix("m", m);
  const StateArchive r = StateArchive::parse(s.serialize(), "test");
  const Eigen::VectorXd w = r.vector("v", 6);
  for (int i = 0; i < 6; ++i) EXPECT_TRUE(same_bits(v[i], w[i])) << i;
  EXPECT_EQ(r.vector("empty").size(), 0);
  EXPECT_TRUE(same_bits(r.real("x"), 1.0 / 3.0));
  EXPECT_EQ(r.integer("n"), -42);
  EXPECT_EQ(r.text("t"), std::string("ab\0c", 4));
  EXPECT_EQ(r.matrix("m"), m);
  EXPECT_EQ(s.serialize(), r.serialize());
}

TEST(StateArchive, BadStatesNameTheProblem) {
  StateArchive s;
  s.put("velocity", Eigen::VectorXd::Ones(4));
  const std::string bytes = s.serialize();
  auto message = [](const std::function<void()>& f) {
    try {
      f();
    } catch (const StateError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const StateArchive r = StateArchive::parse(bytes, "fluid checkpoint of step 5");
  EXPECT_NE(message([&] { r.vector("velocity", 6); }).find("'velocity' has 4 values, this configuration needs 6"),
            std::string::npos);
  EXPECT_NE(message([&] { r.vector("pressure"); }).find("fluid checkpoint of step 5: no entry 'pressure'"),
            std::string::npos);
  EXPECT_NE(message([&] { r.real("velocity"); }).find("is a vector, expected a real"), std::string::npos);
  EXPECT_NE(message([&] { StateArchive::parse(bytes.substr(0, bytes.size() - 3), "s"); }).find("truncated"),
            std::string::npos);
  EXPECT_NE(message([&] { StateArchive::parse(bytes + "x", "s"); }).find("1 trailing bytes"), std::string::npos);
  EXPECT_NE(message([&] { StateArchive::parse("JSON{}", "s"); }).find("no FSISTATE header"), std::string::npos);
  std::string other = bytes;
  other[8] = 9;  // format version
  EXPECT_NE(message([&] { StateArchive::parse(other, "s"); }).find("state format version 9"), std::string::npos);
}

TEST(Crc32, KnownValue) { EXPECT_EQ(fsi::crc32_hex("123456789"), "cbf43926"); }

TEST(CheckpointStore, WritesAtomicallyKeepsTheNewestAndSkipsCorruptOnes) {
  const fs::path dir = fresh_dir("store");
  CheckpointStore store(dir, 2);
  for (int step : {10, 20, 30})
    store.write(step, step * 0.1, {{"scene", "x"}},
                {{"solid", "S" + std::to_string(step)}, {"fluid", std::string(1000, char(step))}});
  EXPECT_FALSE(fs::exists(dir / "step_00000010"));  // pruned: keep 2
  ASSERT_TRUE(fs::exists(dir / "step_00000030" / "manifest.json"));
  auto c = store.newest();
  ASSERT_TRUE(c);
  EXPECT_EQ(c->step, 30);
  EXPECT_DOUBLE_EQ(c->time, 3.0);
  EXPECT_EQ(c->parts.at("solid"), "S30");
  EXPECT_EQ(c->manifest.at("parts").at("fluid").at("bytes"), 1000);
  // Corrupt the newest: the older one is used, and the reason is given.
  { std::ofstream(dir / "step_00000030" / "solid.state", std::ios::binary) << "S3X"; }
  std::vector<std::string> skipped;
  c = store.newest(&skipped);
  ASSERT_TRUE(c);
  EXPECT_EQ(c->step, 20);
  ASSERT_EQ(skipped.size(), 1u);
  EXPECT_NE(skipped[0].find("part 'solid' fails its checksum"), std::string::npos) << skipped[0];
  // A folder without its manifest (a crash mid-write) is incomplete; so is a truncated part.
  fs::remove(dir / "step_00000020" / "manifest.json");
  { std::ofstream(dir / "step_00000030" / "solid.state", std::ios::binary) << "S30"; }
  { std::ofstream(dir / "step_00000030" / "fluid.state", std::ios::binary) << "short"; }
  skipped.clear();
  EXPECT_FALSE(store.newest(&skipped));
  ASSERT_EQ(skipped.size(), 2u);
  EXPECT_NE(skipped[0].find("has 5 bytes, the manifest says 1000"), std::string::npos) << skipped[0];
  EXPECT_NE(skipped[1].find("no manifest.json"), std::string::npos) << skipped[1];
  fs::remove_all(dir);
}

TEST(CheckpointStore, ParameterDifferencesNameTheKeys) {
  const nlohmann::json a = {{"time", {{"dt", 0.01}, {"end", 2}}}, {"solid", {{"mass", 1}}}};
  const nlohmann::json b = {{"time", {{"dt", 0.01}, {"end", 3}}}, {"solid", {{"mass", 1}, {"damping", 0.5}}}};
  const auto d = fsi::coupling::parameter_differences(a, b);
  ASSERT_EQ(d.size(), 2u);
  EXPECT_EQ(d[0], "time.end: 2 (checkpoint) vs 3 (now)");
  EXPECT_EQ(d[1], "solid.damping: absent (checkpoint) vs 0.5 (now)");
  EXPECT_TRUE(fsi::coupling::parameter_differences(a, a).empty());
  const nlohmann::json c = {{"time", {{"dt", 0.01}, {"end", 2.0}}}, {"solid", {{"mass", 1.0}}}};
  EXPECT_TRUE(fsi::coupling::parameter_differences(a, c).empty());  // 2 and 2.0 are the same number
}

TEST(CsvWriter, ResumeKeepsTheFirstRowsAndAppends) {
  const fs::path dir = fresh_dir("csv");
  {
    fsi::CsvWriter w(dir / "t.csv", {"step", "x"});
    for (int i = 1; i <= 5; ++i) w.row(std::vector<double>{double(i), 0.1 * i});
  }
  {
    auto w = fsi::CsvWriter::resume(dir / "t.csv", 3, {"step", "x"});
    w.row(std::vector<double>{4, 0.4});
  }
  EXPECT_EQ(slurp(dir / "t.csv"),
            "step,x\n1,0.10000000000000001\n2,0.20000000000000001\n3,0.30000000000000004\n4,"
            "0.40000000000000002\n");
  EXPECT_THROW(fsi::CsvWriter::resume(dir / "t.csv", 9), std::runtime_error);
  EXPECT_THROW(fsi::CsvWriter::resume(dir / "t.csv", 1, {"step", "y"}), std::runtime_error);
  fs::remove_all(dir);
}

TEST(OutputDir, FreshRefusesForceCleansResumeKeeps) {
  const fs::path dir = fresh_dir("out");
  fsi::prepare_output_dir(dir / "new", fsi::OutputMode::Fresh);  // creates it
  EXPECT_TRUE(fs::is_directory(dir / "new"));
  { std::ofstream(dir / "probes.csv") << "time\n"; }
  { std::ofstream(dir / "notes.txt") << "mine\n"; }
  fs::create_directories(dir / "checkpoints" / "step_00000001");
  try {
    fsi::prepare_output_dir(dir, fsi::OutputMode::Fresh);
    FAIL() << "a non-empty folder was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("is not empty: pass --resume"), std::string::npos) << e.what();
  }
  fsi::prepare_output_dir(dir, fsi::OutputMode::Resume);
  EXPECT_TRUE(fs::exists(dir / "probes.csv"));
  fsi::prepare_output_dir(dir, fsi::OutputMode::Force);
  EXPECT_FALSE(fs::exists(dir / "probes.csv"));
  EXPECT_FALSE(fs::exists(dir / "checkpoints"));
  EXPECT_TRUE(fs::exists(dir / "notes.txt"));  // not a run's file: kept
  fs::remove_all(dir);
}

TEST(Accelerator, SavedIqnHistoryGivesIdenticalUpdates) {
  fsi::coupling::CouplingSettings s;
  s.acceleration = "iqn-ils";
  s.beta = 0.3;
  s.reuse_steps = 3;
  // A linear interface problem F = G(F) = A F + b that changes slowly with the step.
  auto residual = [](const Eigen::VectorXd& x, int step) {
    Eigen::Matrix3d a;
    a << -0.8, 0.3, 0.1, 0.2, -1.5, 0.4, 0.0, 0.5, -0.9;
    Eigen::Vector3d b(1.0, 2.0 + 0.1 * step, -1.0);
    return Eigen::VectorXd(a * x + b - x);
  };
  auto run_step = [&](fsi::coupling::Accelerator& acc, Eigen::VectorXd& x, int step) {
    acc.begin_step();
    for (int k = 0; k < 6; ++k) x = acc.update(x, residual(x, step));
    acc.end_step();
  };
  auto a_ptr = fsi::coupling::make_accelerator(s), b_ptr = fsi::coupling::make_accelerator(s);
  auto &a = *a_ptr, &b = *b_ptr;
  Eigen::VectorXd xa = Eigen::VectorXd::Zero(3);
  for (int step = 1; step <= 4; ++step) run_step(a, xa, step);
  StateArchive state;
  a.save(state, "acc.");
  b.load(StateArchive::parse(state.serialize(), "test"), "acc.");
  Eigen::VectorXd xb = xa;
  for (int step = 5; step <= 8; ++step) {
    run_step(a, xa, step);
    run_step(b, xb, step);
    for (int i = 0; i < 3; ++i) EXPECT_TRUE(same_bits(xa[i], xb[i])) << "step " << step;
  }
}
