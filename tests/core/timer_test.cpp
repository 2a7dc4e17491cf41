// StageTimers: accumulation of wall time and calls per stage.
#include <gtest/gtest.h>

#include <stdexcept>
#include <thread>

#include <tbb/parallel_for.h>

#include "msim/core/timer.hpp"

using namespace msim;

TEST(StageTimers, AccumulatesCallsAndSecondsInFirstUseOrder) {
  StageTimers timers;
  timers.add("project", 1.5);
  timers.add("advect", 0.5);
  timers.add("project", 2.0);
  const auto rows = timers.table();
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0].name, "project");
  EXPECT_DOUBLE_EQ(rows[0].seconds, 3.5);
  EXPECT_EQ(rows[0].calls, 2u);
  EXPECT_DOUBLE_EQ(rows[0].percent, 87.5);
  EXPECT_EQ(rows[1].name, "advect");
  EXPECT_DOUBLE_EQ(rows[1].percent, 12.5);
  EXPECT_DOUBLE_EQ(timers.totalSeconds(), 4.0);
  const std::string text = timers.formatTable();
  EXPECT_NE(text.find("project"), std::string::npos);
  EXPECT_NE(text.find("87.5"), std::string::npos);
  EXPECT_NE(text.find("total"), std::string::npos);
  timers.reset();
  EXPECT_TRUE(timers.table().empty());
}

TEST(StageTimers, ScopedStageMeasuresWallTime) {
  StageTimers timers;
  for (int i = 0; i < 3; ++i) {
    ScopedStage stage(timers, "sleep");
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  const auto rows = timers.table();
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_EQ(rows[0].calls, 3u);
  EXPECT_GE(rows[0].seconds, 0.030);
  EXPECT_LT(rows[0].seconds, 1.0);
}

TEST(StageTimers, ConcurrentStagesLoseNoCalls) {
  StageTimers timers;
  tbb::parallel_for(0, 4000, [&](int i) { timers.add(i % 2 ? "odd" : "even", 0.001); });
  const auto rows = timers.table();
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0].calls + rows[1].calls, 4000u);
  EXPECT_NEAR(timers.totalSeconds(), 4.0, 1e-9);
}

TEST(StageTimers, MergeAddsAnotherTablesStagesUnderAPrefix) {
  StageTimers solver, run;
  solver.add("project", 1.0);
  solver.add("project", 2.0);
  solver.add("advect", 0.5);
  run.add("setup", 4.0);
  run.add("smoke: project", 1.0);
  run.merge(solver, "smoke: ");
  run.merge(solver, "smoke: ");
  const auto rows = run.table();
  ASSERT_EQ(rows.size(), 3u);
  EXPECT_EQ(rows[1].name, "smoke: project");
  EXPECT_DOUBLE_EQ(rows[1].seconds, 7.0);
  EXPECT_EQ(rows[1].calls, 5u);
  EXPECT_EQ(rows[2].name, "smoke: advect");
  EXPECT_DOUBLE_EQ(rows[2].seconds, 1.0);
  EXPECT_EQ(rows[2].calls, 2u);
  EXPECT_THROW(run.merge(run), std::invalid_argument);
}
